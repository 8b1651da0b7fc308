//! `tessera bench`: Table I of Holländer & Boubekeur on this machine. The measuring lives in
//! `tess::bench` (so GPU tests can drive it); this is the command line around it: the mesh
//! set, the options, the console table and the CSV / Markdown files.
use crate::cli::{BenchArgs, PlotArgs};
use crate::commands::{check_validation, open_device};
use crate::technique::Factors;
use anyhow::{bail, Context, Result};
use tess::bench::{self, BenchConfig, BenchFactors, BenchMesh};
use tess::Camera;
use vk_core::vk;

/// The default set, embedded so the command runs from any directory: Keenan Crane's spot
/// (control mesh and quadrangulated, both fan-triangulated on load) and two crease-free
/// OpenSubdiv Loop shapes.
const DEFAULT_MESHES: [(&str, &str); 4] = [
    ("spot_control_mesh", crate::commands::DEFAULT_MESH),
    (
        "spot_quadrangulated",
        include_str!("../../../assets/spot_quadrangulated.obj"),
    ),
    (
        "loop_cube",
        include_str!("../../../tests/data/opensubdiv/shapes/loop_cube.obj"),
    ),
    (
        "loop_icosahedron",
        include_str!("../../../tests/data/opensubdiv/shapes/loop_icosahedron.obj"),
    ),
];

/// The bench's meshes, their texture coordinates' interpolation set to `uv_interpolation`
/// (`--uv-interpolation`) when given, else the file's.
fn load_meshes(
    paths: &[std::path::PathBuf],
    uv_interpolation: Option<topology::rules::options::FVarLinearInterpolation>,
) -> Result<Vec<BenchMesh>> {
    let mut out = Vec::new();
    if paths.is_empty() {
        for (name, text) in DEFAULT_MESHES {
            let mut mesh = topology::mesh::obj::parse_obj(text, &format!("{name}.obj (embedded)"))?;
            if let Some(mode) = uv_interpolation {
                mesh.options.fvar_interpolation = mode;
            }
            let prepared = crate::progress::during(format!("preparing {name}"), || {
                BenchMesh::new(name, &mesh)
            });
            out.push(prepared.with_context(|| format!("preparing {name}"))?);
        }
    } else {
        for p in paths {
            let (mut mesh, lines) = crate::commands::load_mesh_with_lines(Some(p))?;
            if let Some(mode) = uv_interpolation {
                mesh.options.fvar_interpolation = mode;
            }
            crate::commands::check_drawable(&mesh, &lines, &p.display().to_string(), true)?;
            let name = p
                .file_stem()
                .map(|s| s.to_string_lossy().into_owned())
                .unwrap_or_else(|| p.display().to_string());
            let prepared = crate::progress::during(format!("preparing {name}"), || {
                BenchMesh::new(&name, &mesh)
            });
            out.push(prepared.with_context(|| format!("preparing {}", p.display()))?);
        }
    }
    Ok(out)
}

/// The run on the terminal: a bar over the groups (mesh × S), and each row as a line (also
/// without a terminal, as before the bar).
struct Progress {
    bar: indicatif::ProgressBar,
}

impl bench::BenchProgress for Progress {
    fn start(&mut self, groups: usize) {
        self.bar.set_length(groups as u64);
    }

    fn building(&mut self, mesh: &str) {
        self.bar
            .set_message(format!("{mesh}: building the techniques"));
    }

    fn measuring(&mut self, mesh: &str, segments: u32) {
        self.bar
            .set_message(format!("{mesh}, {segments} segments per edge"));
    }

    fn row(&mut self, r: &bench::BenchRow) {
        self.bar.suspend(|| {
            eprintln!(
                "  {}, {} segments, {}{}: {} triangles, GPU median {:.3} ms{}{}",
                r.mesh,
                r.segments,
                r.method,
                if r.level == r.segments {
                    String::new()
                } else {
                    format!(" at level {}", r.level)
                },
                r.triangles,
                r.gpu_median_ms,
                r.cpu_median_ms
                    .map(|c| format!(", CPU median {c:.3} ms"))
                    .unwrap_or_default(),
                r.ratio_to_flat
                    .map(|x| format!(", {x:.2}× Flat"))
                    .unwrap_or_default()
            )
        });
    }

    fn group_done(&mut self) {
        self.bar.inc(1);
    }
}

/// `--methods` under `--scheme`: each method as render draws it for that scheme (Doo-Sabin's
/// `adaptive` is its limit patches), a method of another scheme refused by name.
fn scheme_methods(a: &BenchArgs) -> Result<Vec<String>> {
    let Some(scheme) = &a.scheme else {
        return Ok(a.methods.clone());
    };
    let wanted = crate::topo_cmds::parse_scheme(scheme)
        .map_err(|e| anyhow::anyhow!("--scheme {scheme}: {e}"))?;
    let mut methods = Vec::with_capacity(a.methods.len());
    for m in &a.methods {
        let (name, path) = match m.split_once('@') {
            Some((n, p)) => (n, format!("@{p}")),
            None => (m.as_str(), String::new()),
        };
        let name = match (name, wanted) {
            ("adaptive", topology::Scheme::DooSabin) => "doo-sabin-limit",
            _ => name,
        };
        let mapped = format!("{name}{path}");
        let (info, _) =
            bench::parse_method(&mapped).map_err(|e| anyhow::anyhow!("--methods {m}: {e}"))?;
        if info.scheme.is_some_and(|s| s != wanted) {
            bail!(
                "--scheme {scheme}: --methods {m} draws another scheme's limit surface (the \
                 {scheme} rows: flat, phong, pn or a {scheme} method)"
            );
        }
        methods.push(mapped);
    }
    Ok(methods)
}

fn config(a: &BenchArgs) -> Result<BenchConfig> {
    let methods = scheme_methods(a)?;
    for m in &methods {
        bench::parse_method(m).map_err(|e| anyhow::anyhow!("--methods {m}: {e}"))?;
    }
    if !(1..=8).contains(&a.isolation) {
        bail!("--isolation {} is outside 1..8", a.isolation);
    }
    if a.frames == 0 {
        bail!("--frames must be at least 1");
    }
    // Frame numbers are u32 (tess::bench refuses this too, after the device is open).
    if a.frames.checked_add(a.warmup).is_none() {
        bail!(
            "--frames {} --warmup {}: a row has at most {} frames in all",
            a.frames,
            a.warmup,
            u32::MAX
        );
    }
    if a.equal_triangles && !methods.iter().any(|m| m == "flat") {
        bail!("--equal-triangles matches Flat's triangle counts: add flat to --methods");
    }
    if let Some(&s) = a.segments.iter().find(|&&s| s == 0 || s > 64) {
        bail!("--segments {s} is outside 1..64");
    }
    // The surface options, checked as render checks them; a method list none of whose
    // techniques takes them is refused as render refuses them for such a --method.
    crate::technique::check_displacement(a.displace, a.height.as_deref())?;
    let given: Vec<&str> = [
        ("--texture", a.texture.is_some()),
        ("--displace", a.displace.is_some()),
        ("--height", a.height.is_some()),
        ("--no-reparam", a.no_reparam),
    ]
    .into_iter()
    .filter_map(|(name, given)| given.then_some(name))
    .collect();
    let takers = tess::techniques::names_with(|f| f.surface);
    if !given.is_empty() && !methods.iter().any(|m| takers.contains(&m.as_str())) {
        bail!(
            "{} only {} to the {} rows, and --methods {} has none",
            given.join(", "),
            if given.len() == 1 { "applies" } else { "apply" },
            takers.join(", "),
            methods.join(",")
        );
    }
    let maps = crate::technique::load_maps(a.texture.as_deref(), a.height.as_deref(), false)?;
    Ok(BenchConfig {
        segments: a.segments.clone(),
        methods,
        frames: a.frames,
        warmup: a.warmup,
        extent: vk::Extent2D {
            width: a.size.0,
            height: a.size.1,
        },
        camera: Camera::default(),
        row_budget_s: a.row_budget,
        min_frames: a.min_frames.max(1),
        cpu_max_vertices: a.cpu_max_vertices,
        isolation: a.isolation,
        follow_semi_sharp: !a.creases_at_isolation,
        equal_triangles: a.equal_triangles,
        maps,
        displace: a.displace.unwrap_or(0.0),
        reparam: !a.no_reparam,
        factors: match a.factors {
            None | Some(Factors::Uniform) => BenchFactors::Uniform,
            Some(Factors::Screen) => BenchFactors::Screen { pixels: a.pixels },
            Some(Factors::Distance) => BenchFactors::Distance {
                diagonals: a.distance,
            },
        },
        spacing: a.spacing,
    })
}

/// The largest CSV `tessera plot` reads: 64 MiB (a run writes a few hundred bytes a row).
const MAX_CSV_BYTES: u64 = 64 << 20;

/// `tessera plot`: a saved run's CSV as a picture. The CSV is read as every input is (a
/// regular file within [`MAX_CSV_BYTES`]), as UTF-8 with or without a byte-order mark; errors
/// name it.
pub fn plot(a: PlotArgs) -> Result<()> {
    crate::plot::format_of(&a.output, "-o")?;
    let csv = a.csv.display().to_string();
    let bytes = topology::mesh::input::read_regular_file(&a.csv, MAX_CSV_BYTES, "a benchmark CSV")
        .with_context(|| format!("{csv}: cannot read file"))?;
    let text = std::str::from_utf8(&bytes).with_context(|| format!("{csv}: not UTF-8 text"))?;
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let rows = bench::parse_csv(text).with_context(|| csv.clone())?;
    if !rows.iter().any(crate::plot::drawable) {
        bail!(
            "{csv}: no measured rows to plot ({} rows in all)",
            rows.len()
        );
    }
    crate::plot::write(&a.output, &rows, "-o")?;
    out!(
        "wrote {} ({} rows of {csv})",
        a.output.display(),
        rows.len()
    );
    Ok(())
}

/// `--figure7`: the seed's Fig. 7 on the chosen device, printed and (with --markdown) written.
fn figure7(a: &BenchArgs) -> Result<()> {
    if a.csv.is_some() || a.plot.is_some() {
        bail!("--figure7 writes its table with --markdown only (not --csv or --plot)");
    }
    let config = config(a)?;
    let (instance, device) = open_device(&a.gpu, vec![], &[])?;
    let cases = bench::figure7::SEED_CASES;
    eprintln!(
        "measuring Fig. 7's {} cases: {} timed frames after {} warm-up frames per row",
        cases.len(),
        config.frames,
        config.warmup
    );
    let rows = crate::progress::during("Fig. 7".to_string(), || {
        bench::figure7::run_figure7(&device, &cases, &config)
    });
    let settings = format!(
        "{} build, {}×{} pixels, {} timed frames after {} warm-up frames, medians of GPU time.",
        bench::build_profile(),
        config.extent.width,
        config.extent.height,
        config.frames,
        config.warmup
    );
    let name = device.info.to_string();
    drop(device);
    check_validation(&instance)?;
    let table = bench::figure7::figure7_markdown(&rows?, &name, &settings);
    out!("{table}");
    if let Some(p) = &a.markdown {
        crate::output::write_text(p, &table)?;
        out!("wrote {}", p.display());
    }
    Ok(())
}

pub fn run(a: BenchArgs) -> Result<()> {
    if a.figure7 {
        return figure7(&a);
    }
    if a.load_to_first_frame {
        return crate::load_bench::run(&a);
    }
    if let Some(p) = &a.plot {
        // Before minutes of measuring, not after.
        crate::plot::format_of(p, "--plot")?;
    }
    let config = config(&a)?;
    let meshes = load_meshes(&a.mesh, a.uv_interpolation)?;
    // A texture or height map needs `vt` on every mesh the surface techniques draw (as
    // loaded: they take the mesh before fan triangulation); said before the device is opened.
    let takers = tess::techniques::names_with(|f| f.surface);
    if config.methods.iter().any(|m| takers.contains(&m.as_str())) {
        for (i, m) in meshes.iter().enumerate() {
            let file = a.mesh.get(i).map_or_else(
                || format!("{}.obj (embedded)", m.name),
                |p| p.display().to_string(),
            );
            tess::surface::check_texcoords(&m.input, &config.maps, &file)?;
        }
    }
    if bench::build_profile() != "release" {
        eprintln!(
            "WARNING: this is a debug build; the timings are not representative. \
             Run `cargo run --release -p tessera-viewer -- bench`."
        );
    }
    let (instance, device) = open_device(&a.gpu, vec![], &[])?;
    if device.info.is_lavapipe() {
        eprintln!(
            "note: {} is lavapipe, a CPU rasterizer: only ratios on lavapipe mean anything.",
            device.info.name
        );
    }
    for m in &meshes {
        for n in &m.notes {
            eprintln!("note: {n}");
        }
    }
    let segments: Vec<String> = config.segments.iter().map(u32::to_string).collect();
    eprintln!(
        "measuring {} meshes × segments {} × {}: {} timed frames after {} warm-up frames per row",
        meshes.len(),
        segments.join(", "),
        config.methods.join(", "),
        config.frames,
        config.warmup
    );
    let mut progress = Progress {
        bar: crate::progress::bar(0),
    };
    let report = bench::run_bench_with_progress(&device, &meshes, &config, &mut progress);
    progress.bar.finish_and_clear();
    let mut report = report?;
    if let Some(p) = vk_core::host_heap::policy() {
        report.extra_notes.push(format!("Host heap: {p}"));
    }
    drop(device);
    check_validation(&instance)?;
    out!("{}", report.to_text());
    if let Some(p) = &a.csv {
        crate::output::write_text(p, &report.to_csv())?;
        out!("wrote {}", p.display());
    }
    if let Some(p) = &a.markdown {
        crate::output::write_text(p, &report.to_markdown())?;
        out!("wrote {}", p.display());
    }
    if let Some(p) = &a.plot {
        crate::progress::during(format!("plotting {}", p.display()), || {
            crate::plot::write(p, &report.rows, "--plot")
        })?;
        out!("wrote {}", p.display());
    }
    Ok(())
}
