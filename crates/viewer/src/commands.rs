//! The subcommands' bodies.
use crate::cli::{CameraArgs, Cli, Command, GpuArgs, RenderArgs, SceneArgs};
use crate::technique::{describe, Setup};
use anyhow::{bail, Context as _, Result};
use std::sync::Arc;
use tess::animation::Wave;
use tess::{Camera, Context, FrameParams, Technique, TechniqueId};
use topology::mesh::obj::ObjLines;
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
        Command::Plot(a) => crate::bench::plot(a),
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

/// Loads and validates the mesh (the embedded spot without a path): a `.usda`, `.usdc`,
/// `.usdz` or `.usd` file through `topology::mesh::usd` (errors name the prim and the
/// attribute; no lines), anything else as OBJ (errors say the file, the line and the OBJ's
/// 1-based numbers, `topology::mesh::obj`). With the line of every element, for
/// errors found later ([`in_mesh_file`]).
pub fn load_mesh_with_lines(
    path: Option<&std::path::Path>,
) -> Result<(topology::ControlMesh, ObjLines)> {
    let (mesh, lines) = match path {
        Some(p) => topology::mesh::usd::load_mesh_file(p)?,
        None => topology::mesh::obj::parse_obj_with_lines(
            DEFAULT_MESH,
            "spot_control_mesh.obj (embedded)",
        )?,
    };
    if mesh.num_faces() == 0 {
        bail!(
            "{}: empty mesh (no faces)",
            path.map(|p| p.display().to_string()).unwrap_or_default()
        );
    }
    Ok((mesh, lines))
}

/// The mesh of `path` (as [`load_mesh_with_lines`]) with its coincident vertices merged when
/// `weld` asks for it (`--weld`: the distance, 0 for identical positions), reporting what was
/// merged on stderr, and its texture coordinates' interpolation set to `uv_interpolation`
/// (`--uv-interpolation`) when given, else the file's.
pub fn load_mesh_welded(
    path: Option<&std::path::Path>,
    weld: Option<f64>,
    uv_interpolation: Option<topology::rules::options::FVarLinearInterpolation>,
) -> Result<(topology::ControlMesh, ObjLines)> {
    let (mut mesh, lines) = load_mesh_with_lines(path)?;
    if let Some(mode) = uv_interpolation {
        mesh.options.fvar_interpolation = mode;
    }
    let Some(tolerance) = weld else {
        return Ok((mesh, lines));
    };
    let (welded, kept, report) = topology::mesh::weld::weld_vertices(&mesh, tolerance);
    eprintln!("{}: {}", mesh_name(path), report.summary());
    if welded.num_faces() == 0 {
        bail!(
            "{}: --weld {tolerance} merged every face away",
            mesh_name(path)
        );
    }
    Ok((welded, lines.for_faces(&kept)))
}

/// Refuses, before any device is opened, a mesh the GPU's f32 cannot draw
/// ([`tess::framing::check_drawable`]) or, for a picture (`shaded`), cannot shade
/// ([`tess::framing::check_shaded`]), naming the file and the face's line.
pub fn check_drawable(
    mesh: &topology::ControlMesh,
    lines: &ObjLines,
    name: &str,
    shaded: bool,
) -> Result<()> {
    let checked = if shaded {
        tess::framing::check_shaded(mesh)
    } else {
        tess::framing::check_drawable(mesh)
    };
    checked.map_err(|e| {
        let line = match &e {
            tess::framing::Undrawable::Collapsed { face, .. } => lines.face(*face),
            tess::framing::Undrawable::TooSmallToShade { .. } => None,
        };
        let at = line.map(|l| format!(":{l}")).unwrap_or_default();
        anyhow::anyhow!("{name}{at}: {e}")
    })
}

/// A technique's build error about the mesh read from `name`, in the file's terms: a topology
/// error (an adaptive plan's face too large, a patch that cannot be built) gets the 1-based
/// numbers and the line of the face or vertex at fault. A technique that fan-triangulates
/// polygons (its faces are not the file's) keeps its own words.
pub fn in_mesh_file(
    e: tess::TessError,
    technique: TechniqueId,
    mesh: &topology::ControlMesh,
    lines: &ObjLines,
) -> anyhow::Error {
    let own_faces = !tess::techniques::info(technique).features.triangles_only
        || mesh.faces().all(|f| f.len() == 3);
    match e {
        tess::TessError::Mesh { name, source } if own_faces => {
            match source.downcast::<topology::TopologyError>() {
                Ok(t) => lines.locate(*t, mesh, &name).into(),
                Err(source) => tess::TessError::Mesh { name, source }.into(),
            }
        }
        other => other.into(),
    }
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

/// What `render` and `view` draw: the technique, how to build it and each frame's
/// parameters, checked against the technique's features (before any device is opened).
pub fn scene_setup(s: &SceneArgs, name: &str, mesh: &topology::ControlMesh) -> Result<Setup> {
    let method = crate::technique::resolve_method(s.method, s.surface.scheme.as_deref(), mesh)?;
    let params = FrameParams {
        wireframe: s.wireframe,
        camera: camera(&s.camera),
        phong_alpha: s.alpha,
        ..FrameParams::default()
    };
    let mut setup = s.surface.setup(
        method,
        crate::cli::segments_or_depth(s.segments, s.depth),
        s.spacing,
        s.animate,
        params,
    )?;
    crate::technique::check_segments(&setup)?;
    setup.build.name = name.to_string();
    // A texture or height map without `vt`: said before the device is opened (the build
    // checks it too).
    tess::surface::check_texcoords(mesh, &setup.build.maps, name)?;
    Ok(setup)
}

/// Builds `setup`'s technique for `mesh` on `ctx`, says how it took the mesh (stderr), and
/// poses an animated base at `--frame` (0 by default) in every frame slot. Errors about the
/// mesh name its file and line ([`in_mesh_file`]).
pub fn build_technique(
    ctx: &mut Context,
    mesh: &topology::ControlMesh,
    lines: &ObjLines,
    setup: &Setup,
) -> Result<Box<dyn Technique>> {
    let built = crate::progress::during(
        format!("building {} for {}", setup.technique, setup.build.name),
        || tess::build(ctx, setup.technique, mesh, &setup.build),
    )
    .map_err(|e| in_mesh_file(e, setup.technique, mesh, lines))?;
    for n in &built.notes {
        eprintln!("{n}");
    }
    let mut technique = built.technique;
    if setup.moved() {
        if let Some(base) = technique.base_mesh() {
            let t = setup.frame.unwrap_or(0.0);
            let posed = Wave::new(base).at(t);
            for slot in 0..ctx.frames_in_flight() {
                technique.update_base(slot, &posed).with_context(|| {
                    format!(
                        "{}: the wave at --frame {}",
                        setup.build.name,
                        crate::numbers::number32(t)
                    )
                })?;
            }
        }
    }
    Ok(technique)
}

/// `--device` resolved against the adapters the instance sees: the adapter's index, or an
/// error naming the option as given (with the devices seen).
fn choose_device(g: &GpuArgs, instance: &Instance) -> Result<vk_core::DeviceSelector> {
    let selector = device_selector(g)?;
    let adapters = vk_core::device::enumerate_adapters(instance)?;
    match vk_core::device::choose_adapter(&adapters, &selector) {
        Ok(i) => Ok(vk_core::DeviceSelector::Index(adapters[i].index)),
        Err(vk_core::VkError::NoSuchDevice { devices, .. }) => bail!(
            "--device {}: no device has that index or name (see `tessera info`); devices \
             seen:\n{devices}",
            g.device
        ),
        Err(e) => Err(e.into()),
    }
}

/// `--device` as a selector (never empty: `crate::cli` refuses that, which vk-core would take
/// for `auto`).
fn device_selector(g: &GpuArgs) -> Result<vk_core::DeviceSelector> {
    let selector: std::result::Result<vk_core::DeviceSelector, std::convert::Infallible> =
        g.device.parse();
    Ok(selector.unwrap_or_else(|never| match never {}))
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
    let selector = choose_device(g, &instance)?;
    let cache = if g.no_pipeline_cache {
        None
    } else {
        vk_core::pipeline_cache::user_dir()
    };
    let device = Device::new(
        &instance,
        &DeviceDesc {
            selector,
            pipeline_cache_dir: cache,
            without_tessellation_shader: g.no_tessellation_shader,
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
            "the Vulkan validation layer reported {n} error(s):\n{}",
            instance.messages().error_messages().join("\n")
        );
    }
    Ok(())
}

fn render(a: RenderArgs) -> Result<()> {
    let name = mesh_name(a.scene.mesh.as_deref());
    let (mesh, lines) = load_mesh_welded(
        a.scene.mesh.as_deref(),
        a.scene.surface.weld,
        a.scene.surface.uv_interpolation,
    )?;
    check_drawable(&mesh, &lines, &name, true)?;
    let setup = scene_setup(&a.scene, &name, &mesh)?;
    // Before the device and any work.
    crate::output::check_png_name(&a.output, "-o")?;
    let extent = vk::Extent2D {
        width: a.size.0,
        height: a.size.1,
    };
    let (instance, device) = open_device(&a.scene.gpu, vec![], &[])?;
    let what = render_offscreen(&device, (&mesh, &lines), &setup, extent);
    drop(device);
    check_validation(&instance)?;
    let (image, what) = what?;
    crate::output::write_png(&a.output, &image)?;
    out!(
        "wrote {} ({}x{}, {})",
        a.output.display(),
        a.size.0,
        a.size.1,
        what
    );
    Ok(())
}

/// One frame of `setup` offscreen, and what it drew; a picture with nothing drawn in it (every
/// pixel the background) is an error, not a file.
fn render_offscreen(
    device: &Device,
    (mesh, lines): (&topology::ControlMesh, &ObjLines),
    setup: &Setup,
    extent: vk::Extent2D,
) -> Result<(vk_core::target::Rgba8, String)> {
    let mut ctx = Context::offscreen(device)?;
    let mut technique = build_technique(&mut ctx, mesh, lines, setup)?;
    let params = setup.world_params(technique.bbox());
    let frame = ctx.render_offscreen_stats(technique.as_mut(), &params, extent, false)?;
    let patches: u32 = technique.patch_arrays().iter().map(|a| a.patches).sum();
    // The scheme whose surface the technique drew (none for flat, Phong and PN).
    let scheme = tess::techniques::info(setup.technique)
        .scheme
        .map(|s| format!(", {s} scheme"))
        .unwrap_or_default();
    let what = format!(
        "{}, {} path, {patches} patches in {} draws{scheme}",
        describe(setup.technique, &params),
        technique.draw_path(),
        frame.counts.draws
    );
    if crate::output::is_blank(&frame.image, params.clear_color) {
        bail!(
            "{}: nothing was drawn ({what}; every pixel is the background); nothing written",
            setup.build.name
        );
    }
    Ok((frame.image, what))
}

fn info(g: &GpuArgs) -> Result<()> {
    let instance = Instance::new(&InstanceDesc {
        app_name: "tessera info".into(),
        validation: validation(g),
        surface_extensions: vec![],
    })?;
    let v = instance.api_version;
    out!(
        "Vulkan loader: {}.{}.{}",
        vk::api_version_major(v),
        vk::api_version_minor(v),
        vk::api_version_patch(v)
    );
    out!(
        "validation layer: {}",
        match instance.validation() {
            Validation::Off => "off",
            Validation::On => "on",
            Validation::Synchronization => "on, with synchronization validation",
        }
    );
    let adapters = vk_core::device::enumerate_adapters(&instance)?;
    if adapters.is_empty() {
        out!("no Vulkan devices");
    }
    for a in &adapters {
        out!("{a}");
        let c = &a.caps;
        out!(
            "    tessellationShader {} fillModeNonSolid {} pipelineStatisticsQuery {} vertexPipelineStoresAndAtomics {} timestamps {}",
            c.tessellation_shader, c.fill_mode_non_solid, c.pipeline_statistics_query, c.vertex_pipeline_stores_and_atomics, c.timestamps
        );
        out!(
            "    maxTessellationGenerationLevel {} maxTessellationPatchSize {} maxTessellationEvaluationOutputComponents {} score {}",
            c.max_tessellation_generation_level, c.max_tessellation_patch_size, c.max_tess_evaluation_output_components, a.score()
        );
        out!(
            "    transformFeedback {} (queries {}, maxTransformFeedbackBufferSize {}, stride ≤ {}) — optional, used by `tessera export`",
            c.transform_feedback, c.transform_feedback_queries, c.max_transform_feedback_buffer_size, c.max_transform_feedback_stride
        );
    }
    let selector = device_selector(g)?;
    match vk_core::device::choose_adapter(&adapters, &selector) {
        Ok(i) => {
            let a = &adapters[i];
            let why = match selector {
                vk_core::DeviceSelector::Auto => format!("highest score ({}: discrete 4 > integrated 3 > virtual 2 > CPU 1; ties by lowest index)", a.type_name()),
                _ => format!("selected by --device {}", g.device),
            };
            out!("chosen: [{}] {} — {why}", a.index, a.name);
            let w = vk_core::workarounds::Workarounds::for_adapter(a);
            for w in w.active() {
                out!("    workaround: {}", w.summary);
            }
        }
        // Asked for a device that is not there (or cannot be used): a failure, after the
        // listing that shows what is.
        Err(vk_core::VkError::NoSuchDevice { .. }) => {
            bail!(
                "--device {}: no device has that index or name (listed above)",
                g.device
            )
        }
        Err(e) if !matches!(selector, vk_core::DeviceSelector::Auto) => {
            bail!("--device {}: {e}", g.device)
        }
        Err(e) => out!("chosen: none — {e}"),
    }
    // Enumeration and capability queries go through the layer too: an error there fails the
    // command like any other.
    check_validation(&instance)
}
