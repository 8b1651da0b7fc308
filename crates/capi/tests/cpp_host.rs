//! The example C++ host (examples/cpp-host), built by CMake into the target directory through
//! the CMake package (cmake/TesseraConfig.cmake): it creates its own Vulkan instance (validation
//! with synchronization validation, its own messenger counting every warning and error) and
//! device, hands them to Tessera, draws spot with every technique into its own target, runs
//! the misuse checks, destroys Tessera and then its device, and fails on any validation
//! message (the layer reports objects leaked at vkDestroyDevice as errors). Its images must
//! match the Rust-side render of the same view within the golden tolerance.
mod common;
use std::path::PathBuf;
use std::process::Command;

/// Configures and builds the host into `target/<profile>/capi-tests/<name>-build`.
fn build_host(name: &str, asan: bool) -> PathBuf {
    let lib = common::library();
    let build = common::profile_dir()
        .join("capi-tests")
        .join(format!("{name}-build"));
    common::run(
        Command::new("cmake")
            .arg("-S")
            .arg(common::repo().join("examples/cpp-host"))
            .arg("-B")
            .arg(&build)
            .arg(format!(
                "-DTessera_DIR={}",
                common::repo().join("cmake").display()
            ))
            .arg(format!("-DTESSERA_LIBRARY={}", lib.display()))
            .arg(format!(
                "-DTESSERA_HOST_ASAN={}",
                if asan { "ON" } else { "OFF" }
            )),
    );
    common::run(Command::new("cmake").arg("--build").arg(&build));
    build.join("cpp-host")
}

#[test]
fn cpp_host_draws_every_technique_in_its_own_device_like_tessera_render() {
    let exe = build_host("cpp-host", false);
    let dir = common::scratch("cpp-host-out");
    let out = common::run(Command::new(&exe).arg(&dir).arg("misuse"));
    assert!(
        out.contains("5 techniques drawn, 0 validation messages"),
        "{out}"
    );
    common::compare_with_rust_render(&dir, common::HOST_TECHNIQUES);
}

/// The same host built with `-fsanitize=address`: no invalid access, double free or
/// use-after-free anywhere in the process (host, Tessera's library at the C boundary, the
/// driver). Leak detection is off (`detect_leaks=0`): LeakSanitizer reports allocations of the
/// Vulkan driver stack (lavapipe's LLVM keeps static allocations to exit, and the loader
/// dlcloses lavapipe and the validation layer at vkDestroyInstance, after which their frames
/// cannot be named, so no suppression file can target them alone). Leaks of Vulkan objects
/// are what the validation layer checks in the run (errors at vkDestroyDevice), and vk-core's
/// live-object count covers Tessera's own.
#[test]
fn cpp_host_is_clean_under_address_sanitizer() {
    let exe = build_host("cpp-host-asan", true);
    let dir = common::scratch("cpp-host-asan-out");
    let out = common::run(Command::new(&exe).arg(&dir).arg("misuse").env(
        "ASAN_OPTIONS",
        "detect_leaks=0:abort_on_error=0:halt_on_error=1",
    ));
    assert!(
        out.contains("5 techniques drawn, 0 validation messages"),
        "{out}"
    );
    assert!(!out.contains("AddressSanitizer"), "{out}");
}
