//! The example C++ hosts, built by CMake into the target directory through the CMake package
//! (cmake/TesseraConfig.cmake). Each creates its own Vulkan instance (validation with
//! synchronization validation, its own messenger counting every warning and error) and
//! device, hands them to Tessera, draws spot with every technique into its own target, runs
//! its misuse checks, destroys Tessera and then its device, and fails on any validation
//! message (the layer reports objects leaked at vkDestroyDevice as errors).
//! - examples/cpp-host records into dynamic-rendering scopes; its images must match the
//!   Rust-side render of the same view within the golden tolerance, and what it captures in
//!   host-owned mode must equal a standalone capture of the same view, byte for byte.
//! - examples/cpp-host-renderpass records into a subpass of its own VkRenderPass, on a device
//!   without dynamicRendering; its images must equal the dynamic-rendering host's.
mod common;
use common::{Host, ALL_TECHNIQUES};
use std::process::Command;

const DYNAMIC: Host = Host {
    example: "cpp-host",
    done: "cpp-host: 7 techniques drawn, 0 validation messages",
};
const RENDER_PASS: Host = Host {
    example: "cpp-host-renderpass",
    done: "cpp-host-renderpass: 7 techniques drawn, 0 validation messages",
};

#[test]
fn cpp_host_draws_every_technique_in_its_own_device_like_tessera_render() {
    let dir = DYNAMIC.run_in_tree("cpp-host-out", false);
    common::compare_with_rust_render(&dir, ALL_TECHNIQUES);
}

/// What the dynamic-rendering host captured through its own device (between frames,
/// `tessera_capture`) is what a standalone context captures for the same surface and frame
/// description: the same OBJ file, bit for bit (weld, `# p` lines and all), and no cracks.
#[test]
fn host_mode_capture_equals_standalone_capture() {
    let dir = DYNAMIC.run_in_tree("cpp-host-capture", false);
    for &(name, _) in ALL_TECHNIQUES {
        let host = std::fs::read(dir.join(format!("{name}.obj"))).unwrap();
        let (standalone, report) = common::standalone_capture(name, &dir);
        assert_eq!(report.cracks, 0, "{name}: {report:?}");
        assert!(report.triangles > 0, "{name}: {report:?}");
        assert!(
            host == standalone,
            "{name}: the host-mode capture ({} bytes) differs from the standalone one ({} bytes)",
            host.len(),
            standalone.len()
        );
    }
}

/// The render-pass host's images equal the dynamic-rendering host's for every technique (the
/// same pipelines but for how they are bound to attachments); its 4-sample render pass draws
/// the same surface, antialiased: edge pixels change, nothing else.
#[test]
fn render_pass_host_draws_what_the_dynamic_rendering_host_draws() {
    let dynamic = DYNAMIC.run_in_tree("cpp-host-for-renderpass", false);
    let pass = RENDER_PASS.run_in_tree("cpp-host-renderpass-out", false);
    let pixels = 160 * 120;
    for &(name, _) in ALL_TECHNIQUES {
        let a = std::fs::read(dynamic.join(format!("{name}.rgba"))).unwrap();
        let b = std::fs::read(pass.join(format!("{name}.rgba"))).unwrap();
        let d = common::differing_fraction(&a, &b, pixels);
        eprintln!("{name}: {d:.5} of pixels differ between the render pass and dynamic rendering");
        assert!(a == b, "{name}: {d:.5} of pixels differ");
    }
    let single = std::fs::read(pass.join("adaptive.rgba")).unwrap();
    let msaa = std::fs::read(pass.join("adaptive_msaa4.rgba")).unwrap();
    let d = common::differing_fraction(&single, &msaa, pixels);
    eprintln!("adaptive, 4 samples: {d:.5} of pixels differ from 1 sample");
    assert!(single != msaa, "4 samples changed nothing");
    assert!(
        d <= 0.05,
        "4 samples: {d:.5} of pixels differ (more than the edges)"
    );
}

/// Each host built with `-fsanitize=address`: no invalid access, double free or
/// use-after-free anywhere in the process (host, Tessera's library at the C boundary, the
/// driver), the limit evaluator shared by four threads included. Leak detection is off
/// (`detect_leaks=0`): LeakSanitizer reports allocations of the Vulkan driver stack (lavapipe's
/// LLVM keeps static allocations to exit, and the loader dlcloses lavapipe and the validation
/// layer at vkDestroyInstance, after which their frames cannot be named, so no suppression
/// file can target them alone). Leaks of Vulkan objects are what the validation layer checks
/// in the run (errors at vkDestroyDevice), and vk-core's live-object count covers Tessera's own.
#[test]
fn cpp_hosts_are_clean_under_address_sanitizer() {
    for host in [DYNAMIC, RENDER_PASS] {
        let exe = host.build_in_tree(&format!("{}-asan", host.example), true);
        let dir = common::scratch(&format!("{}-asan-out", host.example));
        let out = common::run(Command::new(&exe).arg(&dir).arg("misuse").env(
            "ASAN_OPTIONS",
            "detect_leaks=0:abort_on_error=0:halt_on_error=1",
        ));
        assert!(out.contains(host.done), "{out}");
        assert!(!out.contains("AddressSanitizer"), "{out}");
    }
}
