//! `tessera bench --load-to-first-frame`: what a user waits for between naming a file and
//! seeing it, for each `--mesh` (typically a USD asset and the same asset as OBJ) and each
//! `--methods` entry, in three phases:
//! - **parse**: the file read and checked as `render` reads it (OBJ or USD, by its name);
//! - **plan**: a fresh drawing context and the technique built on it (refinement, patches,
//!   tables, uploads);
//! - **first frame**: one frame at the first `--segments` value, pipelines created on the
//!   way, drawn offscreen and read back.
//!
//! Rounds visit every (method, mesh) pair in turn (`--warmup` untimed rounds, then `--frames`
//! timed ones), so the medians and a file's ratio to its OBJ twin (the `.obj` of the same
//! name among the `--mesh` files) are within one run.
use crate::cli::BenchArgs;
use crate::commands::{check_drawable, check_validation, load_mesh_with_lines, open_device};
use anyhow::{bail, Context as _, Result};
use std::path::Path;
use std::time::Instant;
use tess::techniques::TechniqueInfo;
use tess::{BuildOptions, Context, FrameParams};
use vk_core::{vk, Device};

/// One (method, mesh) pair's medians, in milliseconds.
struct Row {
    method: &'static str,
    file: String,
    parse_ms: f64,
    plan_ms: f64,
    frame_ms: f64,
}

impl Row {
    fn total_ms(&self) -> f64 {
        self.parse_ms + self.plan_ms + self.frame_ms
    }
}

/// The phases' times of one load, in milliseconds: parse, plan, first frame.
fn load_once(
    device: &Device,
    path: &Path,
    info: &TechniqueInfo,
    a: &BenchArgs,
) -> Result<[f64; 3]> {
    let name = path.display().to_string();
    let start = Instant::now();
    let (mesh, lines) = load_mesh_with_lines(Some(path))?;
    check_drawable(&mesh, &lines, &name, true)?;
    let parsed = Instant::now();
    let mut ctx = Context::offscreen(device)?;
    let options = BuildOptions {
        name: name.clone(),
        tangents: info.features.geometric_normals,
        isolation: a.isolation,
        ..BuildOptions::default()
    };
    let mut technique = tess::techniques::build(&mut ctx, info.id, &mesh, &options)
        .with_context(|| format!("{} on {name}", info.id))?
        .technique;
    let planned = Instant::now();
    let extent = vk::Extent2D {
        width: a.size.0,
        height: a.size.1,
    };
    let params = FrameParams::uniform(a.segments[0] as f32);
    ctx.render_offscreen(technique.as_mut(), &params, extent)?;
    let drawn = Instant::now();
    let ms = |from: Instant, to: Instant| (to - from).as_secs_f64() * 1e3;
    Ok([ms(start, parsed), ms(parsed, planned), ms(planned, drawn)])
}

/// Every pair measured round by round; the medians per pair.
fn measure(device: &Device, a: &BenchArgs, methods: &[&'static TechniqueInfo]) -> Result<Vec<Row>> {
    let pairs: Vec<(&TechniqueInfo, &Path)> = methods
        .iter()
        .flat_map(|&m| a.mesh.iter().map(move |p| (m, p.as_path())))
        .collect();
    let mut times: Vec<[Vec<f64>; 3]> = vec![Default::default(); pairs.len()];
    for round in 0..a.warmup + a.frames {
        eprintln!("round {} of {}", round + 1, a.warmup + a.frames);
        for ((info, path), t) in pairs.iter().zip(&mut times) {
            let phases = load_once(device, path, info, a)?;
            if round >= a.warmup {
                for (k, ms) in phases.into_iter().enumerate() {
                    t[k].push(ms);
                }
            }
        }
    }
    let median = |v: &[f64]| tess::bench::stats::median(v).unwrap_or(f64::NAN);
    Ok(pairs
        .iter()
        .zip(&times)
        .map(|((info, path), t)| Row {
            method: info.id.name(),
            file: path.display().to_string(),
            parse_ms: median(&t[0]),
            plan_ms: median(&t[1]),
            frame_ms: median(&t[2]),
        })
        .collect())
}

/// The row of the same method whose file is `row`'s OBJ twin: the same path with the
/// extension `.obj` (the row itself for an OBJ).
fn obj_twin<'a>(rows: &'a [Row], row: &Row) -> Option<&'a Row> {
    let twin = Path::new(&row.file).with_extension("obj");
    rows.iter()
        .find(|r| r.method == row.method && Path::new(&r.file) == twin)
}

/// The rows in markdown, each total also over its OBJ twin's ("-" without one).
fn markdown(rows: &[Row], device: &str, settings: &str) -> String {
    let mut out = format!(
        "Device: {device}. {settings}\n\n| method | file | parse ms | plan ms | first frame ms | \
         total ms | total / OBJ twin's |\n|-|-|---:|---:|---:|---:|---:|\n"
    );
    for r in rows {
        let ratio = obj_twin(rows, r).map_or_else(
            || "-".to_string(),
            |t| format!("{:.3}", r.total_ms() / t.total_ms()),
        );
        out.push_str(&format!(
            "| {} | {} | {:.1} | {:.1} | {:.1} | {:.1} | {ratio} |\n",
            r.method,
            r.file,
            r.parse_ms,
            r.plan_ms,
            r.frame_ms,
            r.total_ms(),
        ));
    }
    out
}

/// `--load-to-first-frame`: measured, printed and (with --markdown) written.
pub fn run(a: &BenchArgs) -> Result<()> {
    if a.csv.is_some() || a.plot.is_some() {
        bail!("--load-to-first-frame writes its table with --markdown only (not --csv or --plot)");
    }
    if a.mesh.is_empty() {
        bail!(
            "--load-to-first-frame needs the files to load: --mesh FILE, repeated (e.g. a USD \
             asset and the same asset as OBJ)"
        );
    }
    let methods = a
        .methods
        .iter()
        .map(|m| tess::techniques::named(m).map_err(anyhow::Error::from))
        .collect::<Result<Vec<_>>>()?;
    let (instance, device) = open_device(&a.gpu, vec![], &[])?;
    let rows = measure(&device, a, &methods);
    let name = device.info.to_string();
    drop(device);
    check_validation(&instance)?;
    let settings = format!(
        "{} build, {}×{} pixels, {} segments, medians of {} timed rounds after {} warm-up \
         rounds, wall-clock time.",
        tess::bench::build_profile(),
        a.size.0,
        a.size.1,
        a.segments[0],
        a.frames,
        a.warmup
    );
    let table = markdown(&rows?, &name, &settings);
    out!("{table}");
    if let Some(p) = &a.markdown {
        crate::output::write_text(p, &table)?;
        out!("wrote {}", p.display());
    }
    Ok(())
}
