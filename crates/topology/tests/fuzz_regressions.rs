//! Inputs the fuzz targets (fuzz/, tools/fuzz.sh) found crashing, kept as ordinary tests so
//! `cargo test` guards the fixes without a nightly toolchain.

use topology::{parse_obj, ObjSyntax, TopologyError};

const TRIANGLE: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

/// `t` counts near `usize::MAX` wrapped the "enough words" sum and the parser sliced past
/// the line (obj_parse target: "attempt to add with overflow" / slice index panic).
#[test]
fn tag_counts_that_overflow_are_a_count_mismatch() {
    for counts in [
        "18446744073709551615/1/0",
        "1/18446744073709551615/0",
        "0/0/18446744073709551615",
        "9223372036854775807/9223372036854775807/2",
    ] {
        let text = format!("{TRIANGLE}t crease {counts} 1 2 3\n");
        let err = parse_obj(&text, "t.obj").expect_err(counts);
        assert!(
            matches!(
                err,
                TopologyError::Parse {
                    line: 5,
                    kind: ObjSyntax::TagCountMismatch { .. },
                    ..
                }
            ),
            "{counts}: {err}"
        );
    }
}
