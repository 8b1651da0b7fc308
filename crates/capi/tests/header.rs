//! The committed C header must be what cbindgen generates from the crate today: CI runs this,
//! so an API change without `TESSERA_UPDATE_HEADER=1 cargo test -p tessera-capi --test header`
//! fails.
use std::path::Path;

#[test]
fn committed_header_matches_a_fresh_generation() {
    let crate_dir = Path::new(env!("CARGO_MANIFEST_DIR"));
    let header = crate_dir.join("../../include/tessera.h");
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml")).unwrap();
    let mut fresh = Vec::new();
    cbindgen::Builder::new()
        .with_crate(crate_dir)
        .with_config(config)
        .generate()
        .expect("cbindgen generates the header")
        .write(&mut fresh);
    let fresh = String::from_utf8(fresh).unwrap();
    if std::env::var_os("TESSERA_UPDATE_HEADER").is_some() {
        std::fs::write(&header, &fresh).unwrap();
    }
    let committed = std::fs::read_to_string(&header).unwrap_or_default();
    assert!(
        committed == fresh,
        "include/tessera.h differs from cbindgen's output for crates/capi; regenerate it with \
         TESSERA_UPDATE_HEADER=1 cargo test -p tessera-capi --test header and commit it"
    );
}
