//! USD reader on raw bytes, written once as a `.usda` (text) and once as a `.usdc` (binary
//! crate) file and read with `topology::mesh::usd::load_usd`. A mesh it accepts must be valid
//! (indices in range, finite positions, a scheme); anything else must be a named error, never
//! a panic that escapes. Panics raised inside the USD reader's own crates (openusd and the
//! zip and lz4 decoders it reads with) are caught by `load_usd` and become
//! `UsdProblem::ReaderPanicked`; the panic hook set here keeps those from aborting and aborts
//! on every other panic, as libFuzzer's hook does.
//! Bound: inputs over 64 KiB are skipped.
#![no_main]

use libfuzzer_sys::fuzz_target;
use topology::mesh::usd::load_usd;

/// Whether a panic at `file` comes from the USD reader's crates (caught by `load_usd`).
fn in_reader(file: &str) -> bool {
    ["/openusd-", "/zip-", "/lz4_flex-"]
        .iter()
        .any(|c| file.contains(c))
}

fn init() {
    tessera_fuzz::single_thread_rayon();
    let abort_hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        if !info.location().is_some_and(|l| in_reader(l.file())) {
            abort_hook(info);
        }
    }));
}

fuzz_target!(
    init: init(),
    |data: &[u8]| {
        if data.len() > 64 * 1024 {
            return;
        }
        let dir = std::env::temp_dir().join(format!("tessera-fuzz-usd-{}", std::process::id()));
        std::fs::create_dir_all(&dir).expect("a scratch folder");
        for name in ["fuzz.usda", "fuzz.usdc"] {
            let path = dir.join(name);
            std::fs::write(&path, data).expect("a scratch file");
            let Ok(mesh) = load_usd(&path) else {
                continue;
            };
            let nv = mesh.positions.len();
            assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
            assert!(mesh.face_vertices.iter().all(|&v| (v as usize) < nv));
            assert!(mesh.scheme.is_some());
            mesh.validate().expect("load_usd returned an invalid mesh");
        }
    }
);
