//! The subcommands' bodies.
use crate::cli::{CameraArgs, Cli, Command, GpuArgs, RenderArgs, SceneArgs};
use crate::technique::{loop_control_mesh, BftSetup, Technique, Wave};
use anyhow::{bail, Context, Result};
use std::sync::Arc;
use tess::bft::BftSurface;
use tess::renderer::GpuMesh;
use tess::{Camera, DrawParams, Method, RenderMesh, Renderer};
use vk_core::{vk, Device, DeviceDesc, Instance, InstanceDesc, Validation};

/// The spot control mesh by Keenan Crane (public domain), embedded so `tessera render` works
/// with no file at hand.
pub const DEFAULT_MESH: &str = include_str!("../../../assets/spot_control_mesh.obj");

pub fn run(cli: Cli) -> Result<()> {
    match cli.command {
        Command::Render(a) => render(a),
        Command::View(a) => crate::view::run(a),
        Command::Info(g) => info(&g),
        Command::Subdivide(a) => crate::topo_cmds::subdivide(a),
        Command::Limit(a) => crate::topo_cmds::limit(a),
        Command::Export(a) => crate::export::run(a),
        Command::Bench(a) => crate::bench::run(a),
    }
}

pub fn validation(g: &GpuArgs) -> Validation {
    if g.sync_validation {
        Validation::Synchronization
    } else if g.validation {
        Validation::On
    } else {
        Validation::default_for_build()
    }
}

pub fn load_mesh(path: Option<&std::path::Path>) -> Result<topology::ControlMesh> {
    let mesh = match path {
        Some(p) => topology::load_obj(p)?,
        None => topology::parse_obj(DEFAULT_MESH, "spot_control_mesh.obj (embedded)")?,
    };
    if mesh.num_faces() == 0 {
        bail!(
            "{}: empty mesh (no faces)",
            path.map(|p| p.display().to_string()).unwrap_or_default()
        );
    }
    Ok(mesh)
}

/// The name a mesh goes by in messages: its path, or the embedded default's.
pub fn mesh_name(path: Option<&std::path::Path>) -> String {
    path.map(|p| p.display().to_string())
        .unwrap_or_else(|| "spot_control_mesh.obj (embedded)".into())
}

pub fn camera(c: &CameraArgs) -> Camera {
    Camera {
        yaw: c.yaw,
        pitch: c.pitch,
        zoom: c.zoom,
        ..Camera::default()
    }
}

/// Draw parameters and, for `--method bft`, its setup, checked against each other.
pub fn draw_params(s: &SceneArgs) -> Result<(DrawParams, Option<BftSetup>)> {
    let bft = s.surface.setup(s.method, s.level, s.spacing, s.animate)?;
    if bft.is_none() && !(1.0..=64.0).contains(&s.level) {
        bail!("--level {} is outside 1..64", s.level);
    }
    let method = match s.method {
        Technique::Tessellated(m) => m,
        // Unused by the BFT pipeline; the frame uniforms only need a valid one.
        Technique::Bft => Method::Flat,
    };
    let params = DrawParams {
        method,
        spacing: s.spacing,
        level: s.level.clamp(1.0, 64.0),
        wireframe: s.wireframe,
        camera: camera(&s.camera),
        phong_alpha: s.alpha,
        ..DrawParams::default()
    };
    Ok((params, bft))
}

/// Instance + device as the command line asks; errors list the devices seen.
pub fn open_device(
    g: &GpuArgs,
    surface_extensions: Vec<&'static std::ffi::CStr>,
    device_extensions: &[&'static std::ffi::CStr],
) -> Result<(Arc<Instance>, Device)> {
    let instance = Instance::new(&InstanceDesc {
        app_name: "tessera".into(),
        validation: validation(g),
        surface_extensions,
    })?;
    let selector = g.device.parse().unwrap_or_default();
    let cache = std::env::var_os("XDG_CACHE_HOME")
        .map(std::path::PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| std::path::PathBuf::from(h).join(".cache")))
        .map(|d| d.join("tessera").join("pipeline-cache.bin"));
    let device = Device::new(
        &instance,
        &DeviceDesc {
            selector,
            pipeline_cache_path: cache,
            ..DeviceDesc::default()
        },
        device_extensions,
    )?;
    log::info!("using {}", device.info);
    Ok((instance, device))
}

/// Fails when the validation layer reported an error-severity message.
pub fn check_validation(instance: &Instance) -> Result<()> {
    let n = instance.messages().error_count();
    if n > 0 {
        bail!(
            "the Vulkan validation layer reported {n} error(s): {:#?}",
            instance.messages().error_messages()
        );
    }
    Ok(())
}

fn render(a: RenderArgs) -> Result<()> {
    let mesh = load_mesh(a.scene.mesh.as_deref())?;
    let name = mesh_name(a.scene.mesh.as_deref());
    let (params, bft) = draw_params(&a.scene)?;
    let extent = vk::Extent2D {
        width: a.size.0,
        height: a.size.1,
    };
    let (instance, device) = open_device(&a.scene.gpu, vec![], &[])?;
    let what = match &bft {
        None => render_tessellated(&device, &mesh, &params, extent, &a.output),
        Some(setup) => render_bft(
            &device,
            &mesh,
            &name,
            &params,
            setup,
            a.scene.animate,
            extent,
            &a.output,
        ),
    };
    drop(device);
    check_validation(&instance)?;
    println!(
        "wrote {} ({}x{}, {})",
        a.output.display(),
        a.size.0,
        a.size.1,
        what?
    );
    Ok(())
}

fn render_tessellated(
    device: &Device,
    mesh: &topology::ControlMesh,
    params: &DrawParams,
    extent: vk::Extent2D,
    output: &std::path::Path,
) -> Result<String> {
    let rm = RenderMesh::from_control_mesh(mesh).context("preparing the mesh for drawing")?;
    let gm = GpuMesh::upload(device, &rm)?;
    let mut renderer = Renderer::offscreen(device)?;
    let img = renderer.render_offscreen(&gm, params, extent)?;
    img.save_png(output)?;
    Ok(format!("{:?}, level {}", params.method, params.level))
}

#[allow(clippy::too_many_arguments)]
fn render_bft(
    device: &Device,
    mesh: &topology::ControlMesh,
    name: &str,
    params: &DrawParams,
    setup: &BftSetup,
    animate: bool,
    extent: vk::Extent2D,
    output: &std::path::Path,
) -> Result<String> {
    let (loop_mesh, _, note) = loop_control_mesh(mesh, name);
    if let Some(n) = note {
        eprintln!("{n}");
    }
    let mut renderer = Renderer::offscreen(device)?;
    let mut surface = BftSurface::new(
        &renderer,
        &loop_mesh,
        name,
        setup.table_level,
        setup.params.geometric_normals,
        1,
    )?;
    if animate || setup.frame.is_some() {
        let positions = Wave::new(&loop_mesh).at(setup.frame.unwrap_or(0.0));
        surface.update_base(0, &positions)?;
    }
    let bft = setup.world_params((surface.bbox_min, surface.bbox_max));
    let (img, _, counts) = surface.render_offscreen(&mut renderer, params, &bft, extent, false)?;
    img.save_png(output)?;
    Ok(format!(
        "bft, {:?}{}, {} patches in {} draws",
        bft.factors,
        if bft.fractional { " fractional" } else { "" },
        surface.patch_count(),
        counts.draws
    ))
}

fn info(g: &GpuArgs) -> Result<()> {
    let instance = Instance::new(&InstanceDesc {
        app_name: "tessera info".into(),
        validation: validation(g),
        surface_extensions: vec![],
    })?;
    let v = instance.api_version;
    println!(
        "Vulkan loader: {}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    );
    println!("validation layer: {:?}", instance.validation());
    let adapters = vk_core::device::enumerate_adapters(&instance)?;
    if adapters.is_empty() {
        println!("no Vulkan devices");
    }
    for a in &adapters {
        println!("{a}");
        let c = &a.caps;
        println!(
            "    tessellationShader {} fillModeNonSolid {} pipelineStatisticsQuery {} vertexPipelineStoresAndAtomics {} timestamps {}",
            c.tessellation_shader, c.fill_mode_non_solid, c.pipeline_statistics_query, c.vertex_pipeline_stores_and_atomics, c.timestamps
        );
        println!(
            "    maxTessellationGenerationLevel {} maxTessellationPatchSize {} maxTessellationEvaluationOutputComponents {} score {}",
            c.max_tessellation_generation_level, c.max_tessellation_patch_size, c.max_tess_evaluation_output_components, a.score()
        );
        println!(
            "    transformFeedback {} (queries {}, maxTransformFeedbackBufferSize {}, stride ≤ {}) — optional, used by `tessera export`",
            c.transform_feedback, c.transform_feedback_queries, c.max_transform_feedback_buffer_size, c.max_transform_feedback_stride
        );
    }
    let selector = g.device.parse().unwrap_or_default();
    match vk_core::device::choose_adapter(&adapters, &selector) {
        Ok(i) => {
            let a = &adapters[i];
            let why = match selector {
                vk_core::DeviceSelector::Auto => format!("highest score ({}: discrete 4 > integrated 3 > virtual 2 > CPU 1; ties by lowest index)", a.type_name()),
                s => format!("selected by --device {s:?}"),
            };
            println!("chosen: [{}] {} — {why}", a.index, a.name);
            let w = vk_core::workarounds::Workarounds::for_adapter(a);
            for w in w.active() {
                println!("    workaround: {}", w.summary);
            }
        }
        Err(e) => println!("chosen: none — {e}"),
    }
    Ok(())
}
