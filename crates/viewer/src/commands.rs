//! The subcommands' bodies.
use crate::cli::{Cli, Command, GpuArgs, RenderArgs, SceneArgs};
use anyhow::{bail, Context, Result};
use std::sync::Arc;
use tess::renderer::GpuMesh;
use tess::{Camera, DrawParams, RenderMesh, Renderer};
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

pub fn draw_params(s: &SceneArgs) -> Result<DrawParams> {
    if !(1.0..=64.0).contains(&s.level) {
        bail!("--level {} is outside 1..64", s.level);
    }
    Ok(DrawParams {
        method: s.method,
        spacing: s.spacing,
        level: s.level,
        wireframe: s.wireframe,
        camera: Camera {
            yaw: s.yaw,
            pitch: s.pitch,
            zoom: s.zoom,
            ..Camera::default()
        },
        phong_alpha: s.alpha,
        ..DrawParams::default()
    })
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
    let params = draw_params(&a.scene)?;
    let rm = RenderMesh::from_control_mesh(&mesh).context("preparing the mesh for drawing")?;
    let (instance, device) = open_device(&a.scene.gpu, vec![], &[])?;
    {
        let gm = GpuMesh::upload(&device, &rm)?;
        let mut renderer = Renderer::offscreen(&device)?;
        let img = renderer.render_offscreen(
            &gm,
            &params,
            vk::Extent2D {
                width: a.size.0,
                height: a.size.1,
            },
        )?;
        img.save_png(&a.output)?;
    }
    drop(device);
    check_validation(&instance)?;
    println!(
        "wrote {} ({}x{}, {:?}, level {})",
        a.output.display(),
        a.size.0,
        a.size.1,
        params.method,
        params.level
    );
    Ok(())
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
