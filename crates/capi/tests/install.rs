//! `cmake --install` of the repository's CMakeLists.txt into a fresh prefix: the library, the
//! headers, the CMake package and tessera.pc land there; both example hosts configure and build
//! against the installed package with `find_package(Tessera)` and no hint but the prefix in
//! CMAKE_PREFIX_PATH (as for any package outside the system prefixes), and fail to configure
//! without it (so nothing else was found); the dynamic-rendering host runs. The C program
//! builds with nothing but `pkg-config --cflags --libs tessera` and runs.
mod common;
use common::{library, repo, run, scratch};
use std::path::Path;
use std::process::Command;

/// A command that sees no CMake or pkg-config search path from the test's environment.
fn clean(program: &str) -> Command {
    let mut c = Command::new(program);
    c.env_remove("CMAKE_PREFIX_PATH")
        .env_remove("Tessera_DIR")
        .env_remove("PKG_CONFIG_PATH");
    c
}

/// Configures `examples/<example>` in `build` (with `prefix` in CMAKE_PREFIX_PATH when given).
fn configure(example: &str, build: &Path, prefix: Option<&Path>) -> std::process::Output {
    let mut c = clean("cmake");
    c.arg("-S")
        .arg(repo().join("examples").join(example))
        .arg("-B")
        .arg(build);
    if let Some(p) = prefix {
        c.env("CMAKE_PREFIX_PATH", p);
    }
    c.output().expect("cmake runs")
}

#[test]
fn installed_package_is_found_by_find_package_and_pkg_config() {
    let prefix = scratch("install-prefix");
    let build = scratch("install-build");
    run(clean("cmake")
        .arg("-S")
        .arg(repo())
        .arg("-B")
        .arg(&build)
        .arg(format!("-DTESSERA_LIBRARY={}", library().display())));
    run(clean("cmake").arg("--build").arg(&build));
    run(clean("cmake")
        .arg("--install")
        .arg(&build)
        .arg("--prefix")
        .arg(&prefix));
    for file in [
        "lib/libtessera_capi.so",
        "include/tessera.h",
        "include/tessera.hpp",
        "lib/cmake/Tessera/TesseraConfig.cmake",
        "lib/cmake/Tessera/TesseraConfigVersion.cmake",
        "lib/pkgconfig/tessera.pc",
    ] {
        assert!(prefix.join(file).is_file(), "{file} not installed");
    }

    // Without the prefix, nothing named Tessera is found.
    let none = configure("cpp-host", &scratch("install-none"), None);
    assert!(!none.status.success(), "found a Tessera outside the prefix");
    assert!(
        String::from_utf8_lossy(&none.stderr).contains("Tessera"),
        "{}",
        String::from_utf8_lossy(&none.stderr)
    );

    for (example, done) in [
        (
            "cpp-host",
            Some("cpp-host: 7 techniques drawn, 0 validation messages"),
        ),
        ("cpp-host-renderpass", None),
    ] {
        let dir = scratch(&format!("install-{example}"));
        let out = configure(example, &dir, Some(&prefix));
        let text = String::from_utf8_lossy(&out.stdout).into_owned()
            + &String::from_utf8_lossy(&out.stderr);
        assert!(out.status.success(), "{example}: {text}");
        let cache = std::fs::read_to_string(dir.join("CMakeCache.txt")).unwrap();
        let found = prefix.join("lib/cmake/Tessera");
        assert!(
            cache.contains(&format!("Tessera_DIR:PATH={}", found.display())),
            "{example}: Tessera_DIR is not the installed package"
        );
        run(clean("cmake").arg("--build").arg(&dir));
        if let Some(done) = done {
            let out_dir = scratch(&format!("install-{example}-out"));
            // Not cargo's LD_LIBRARY_PATH (target/<profile>/deps): the installed library.
            let text = run(Command::new(dir.join(example))
                .arg(&out_dir)
                .env_remove("LD_LIBRARY_PATH"));
            assert!(text.contains(done), "{text}");
        }
    }

    // pkg-config, relocatable: the prefix comes from the file's own place.
    let pc = |args: &[&str]| -> String {
        run(clean("pkg-config")
            .env("PKG_CONFIG_PATH", prefix.join("lib/pkgconfig"))
            .args(args))
        .trim()
        .to_owned()
    };
    assert_eq!(pc(&["--modversion", "tessera"]), env!("CARGO_PKG_VERSION"));
    let libdir = pc(&["--variable=libdir", "tessera"]);
    assert_eq!(
        Path::new(&libdir).canonicalize().unwrap(),
        prefix.join("lib").canonicalize().unwrap()
    );
    let flags = pc(&["--cflags", "--libs", "tessera"]);
    let exe = scratch("install-c").join("standalone");
    run(
        Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
            .args(["-std=c99", "-Wall", "-Wextra", "-pedantic", "-Werror"])
            .arg(repo().join("crates/capi/tests/c/standalone.c"))
            .arg("-o")
            .arg(&exe)
            .args(flags.split_whitespace())
            .arg(format!("-Wl,--disable-new-dtags,-rpath,{libdir}")),
    );
    let out_dir = scratch("install-c-out");
    let text = run(Command::new(&exe)
        .arg(&out_dir)
        .env_remove("LD_LIBRARY_PATH"));
    assert!(
        text.contains("7 techniques rendered, texture and height map drawn"),
        "{text}"
    );
}
