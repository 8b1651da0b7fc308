//! Standalone mode from plain C: tests/c/standalone.c, compiled with `cc -std=c99 -Wall
//! -Werror` against include/tessera.h and the cdylib, renders spot with every technique; each
//! image must match the Rust-side render of the same view within the golden tolerance. It
//! also draws spot (gregory, acc) with a texture and a height map set through the new fields
//! of TesseraSurfaceDesc/TesseraFrameDesc and checks that each changes the image.
mod common;
use std::process::Command;

#[test]
fn c99_program_renders_every_technique_like_the_rust_side() {
    let lib = common::library();
    let dir = common::scratch("c-standalone");
    let exe = dir.join("standalone");
    let lib_dir = lib.parent().unwrap();
    common::run(
        Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
            .args(["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"])
            .arg("-I")
            .arg(common::repo().join("include"))
            .arg(common::repo().join("crates/capi/tests/c/standalone.c"))
            .arg("-o")
            .arg(&exe)
            .arg(format!("-L{}", lib_dir.display()))
            // DT_RPATH, not RUNPATH: cargo's LD_LIBRARY_PATH lists target/<profile>, where a
            // `cargo build` of an older tree may have left another libtessera_capi.so.
            .arg("-Wl,--disable-new-dtags")
            .arg(format!("-Wl,-rpath,{}", lib_dir.display()))
            .arg("-ltessera_capi"),
    );
    let out = common::run(Command::new(&exe).arg(&dir));
    assert!(
        out.contains("7 techniques rendered, texture and height map drawn"),
        "{out}"
    );
    common::compare_with_rust_render(&dir, common::ALL_TECHNIQUES);
}
