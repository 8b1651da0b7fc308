//! Command-line definition.
use crate::technique::SurfaceArgs;
use clap::{Args, Parser, Subcommand};
use std::path::PathBuf;
use tess::Spacing;
use tess::TechniqueId;

#[derive(Parser, Debug)]
#[command(
    name = "tessera",
    version,
    about = "Subdivision surfaces on the GPU tessellation stage (Vulkan)"
)]
pub struct Cli {
    #[command(subcommand)]
    pub command: Command,
    /// Log more (info level); RUST_LOG overrides.
    #[arg(long, short, global = true)]
    pub verbose: bool,
}

#[derive(Subcommand, Debug)]
pub enum Command {
    /// Render a mesh (the embedded spot control mesh by default) to a PNG.
    Render(RenderArgs),
    /// Open a window: drag to orbit, wheel to zoom, 1/2/3 method, +/- segments, W wireframe, P
    /// screenshot; drop an OBJ or USD file on it to open it.
    View(ViewArgs),
    /// List Vulkan devices, their tessellation features and limits, and which would be chosen.
    Info(GpuArgs),
    /// Uniformly refine a mesh on the CPU and write it as OBJ (optionally at limit positions).
    Subdivide(SubdivideArgs),
    /// Print the exact limit position, tangents and normal at (face, u, v).
    Limit(LimitArgs),
    /// Capture the triangles the GPU's TES emitted (transform feedback), weld them by position
    /// bits, report open edges and cracks, and write them as OBJ.
    Export(ExportArgs),
    /// Measure output triangles and GPU frame times per mesh, segments per edge and technique
    /// (Table I of Holländer & Boubekeur), offscreen.
    Bench(BenchArgs),
    /// Plot a run saved by `bench --csv` (SVG or PNG by the file name), as `bench --plot` does.
    Plot(PlotArgs),
}

#[derive(Args, Debug)]
pub struct PlotArgs {
    /// CSV written by `tessera bench --csv`.
    pub csv: PathBuf,
    /// Output .svg or .png: frame time and ratio to Flat per segments and technique, one row of
    /// charts per mesh.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct ExportArgs {
    /// OBJ or USD (.usda, .usdc, .usdz) control mesh; the embedded spot control mesh when absent.
    pub input: Option<PathBuf>,
    /// The technique (the list: --help); by default the limit surface of --scheme.
    #[arg(long, value_parser = crate::technique::parse_technique,
          long_help = crate::technique::method_long_help())]
    pub method: Option<TechniqueId>,
    /// Segments per base edge, the tessellation level (outer and inner): 1 to 64; flat, phong
    /// and pn on the pattern path up to 256; bft takes powers of two from 2 to
    /// 2^(table level + 1), any level in that range with --spacing fractional-even; adaptive: segments per patch edge, 1 to 32. Ignored with --factors screen or distance.
    #[arg(long, alias = "level", default_value_t = 8.0, allow_hyphen_values = true, value_parser = parse_segments)]
    pub segments: f32,
    /// The level of a uniform refinement (Doo-Sabin's `doo-sabin`, `vertex-patches`,
    /// `cpu-doo-sabin`): depth D draws 2^D segments per base edge, 1 to 6; instead of --segments.
    #[arg(long, conflicts_with = "segments", allow_hyphen_values = true, value_parser = parse_depth)]
    pub depth: Option<u32>,
    #[arg(long, default_value = "equal", value_parser = parse_spacing)]
    pub spacing: Spacing,
    #[command(flatten)]
    pub surface: SurfaceArgs,
    /// Phong tessellation shape factor α, 0 to 1.
    #[arg(long, default_value_t = 0.75, allow_hyphen_values = true, value_parser = parse_alpha)]
    pub alpha: f32,
    /// The view --factors screen and distance see.
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Viewport --factors screen sees, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", allow_hyphen_values = true, value_parser = parse_size)]
    pub size: (u32, u32),
    /// Exit with status 1 when any crack (an open edge not on the base mesh's boundary or a
    /// hole's border) is found.
    #[arg(long)]
    pub fail_on_cracks: bool,
    #[command(flatten)]
    pub gpu: GpuArgs,
    /// Output OBJ.
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct BenchArgs {
    /// Segments per base edge S, a comma-separated list (4, 16, 32 are the paper's subdivision
    /// levels 2, 4, 5).
    #[arg(
        long,
        alias = "level",
        value_delimiter = ',',
        default_value = "4,16,32",
        allow_hyphen_values = true,
        value_parser = parse_bench_segments
    )]
    pub segments: Vec<u32>,
    /// Techniques to measure, comma-separated (the list: --help).
    #[arg(long, value_delimiter = ',', default_value = "flat,phong,pn,bft,cpu",
          long_help = crate::technique::methods_long_help())]
    pub methods: Vec<String>,
    /// Subdivision scheme of the rows, as on render: `--scheme doo-sabin` makes `adaptive` the
    /// Doo-Sabin limit patches (doo-sabin-limit); a method that draws another scheme's limit
    /// surface is refused by name (flat, phong and pn take any).
    #[arg(long)]
    pub scheme: Option<String>,
    /// Timed frames per row (at least 1).
    #[arg(long, default_value_t = 30, allow_hyphen_values = true, value_parser = parse_frames)]
    pub frames: u32,
    /// Untimed frames before them.
    #[arg(long, default_value_t = 5, allow_hyphen_values = true, value_parser = parse_warmup)]
    pub warmup: u32,
    /// OBJ or USD (.usda, .usdc, .usdz) control mesh (repeatable); replaces the default set.
    #[arg(long)]
    pub mesh: Vec<PathBuf>,
    /// Offscreen size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720", allow_hyphen_values = true, value_parser = parse_size)]
    pub size: (u32, u32),
    /// Seconds a row's timed frames may take; slower rows get fewer frames (noted in the row).
    /// The first measured frame of each row (the last warm-up frame, or the first timed one
    /// with --warmup 0) sets how many fit.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_row_budget)]
    pub row_budget: Option<f64>,
    /// The fewest timed frames --row-budget may leave (at most --frames).
    #[arg(long, default_value_t = 5, allow_hyphen_values = true, value_parser = parse_min_frames)]
    pub min_frames: u32,
    /// The CPU baseline skips subdivision levels with more vertices than this (Loop level 5
    /// of the quadrangulated spot, 3.0 M vertices, peaks at about 1.6 GB of memory).
    #[arg(long, default_value_t = 4_000_000, allow_hyphen_values = true, value_parser = parse_cpu_max_vertices)]
    pub cpu_max_vertices: u64,
    /// Isolation level of the adaptive rows (segments are then per patch edge): 1 to 8.
    #[arg(long, default_value_t = tess::techniques::adaptive::DEFAULT_ISOLATION, allow_hyphen_values = true, value_parser = crate::technique::parse_isolation)]
    pub isolation: u32,
    /// Adaptive rows stop semi-sharp creases at the isolation level (OpenSubdiv's behaviour).
    #[arg(long)]
    pub creases_at_isolation: bool,
    /// Edge factors of the methods that take them (bft, adaptive, gregory, acc, doo-sabin-limit):
    /// uniform (each row's S, the default), screen (projected edge length / --pixels) or
    /// distance (--distance); under screen and distance factors S only names the rows, and the
    /// other methods keep S.
    #[arg(long, value_parser = crate::technique::parse_factors)]
    pub factors: Option<crate::technique::Factors>,
    /// --factors screen: target pixels per segment, 0.5 to 16384.
    #[arg(long, default_value_t = 8.0, allow_hyphen_values = true, value_parser = crate::technique::parse_pixels)]
    pub pixels: f32,
    /// --factors distance: eye distance, in bounding-box diagonals, at which an edge gets the
    /// largest level (above 0, at most 1000000).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = crate::technique::parse_distance)]
    pub distance: f32,
    /// Spacing of the methods that take it (fractional-even geomorphs between levels on the
    /// pattern path of bft and the planned surfaces); the others draw equal spacing.
    #[arg(long, default_value = "equal", value_parser = parse_spacing)]
    pub spacing: Spacing,
    /// Compare at equal output triangles: at each mesh and S, Flat draws S segments per base
    /// edge and every other technique the whole segments per (patch) edge whose triangle count
    /// is nearest Flat's (rows give the level drawn and the triangles over Flat's). Needs flat
    /// in --methods.
    #[arg(long)]
    pub equal_triangles: bool,
    /// Colour texture (PNG) shown at the mesh's `vt` coordinates by the methods that take
    /// surface maps (adaptive, gregory, acc); their rows' notes say so, the others draw as
    /// always.
    #[arg(long, value_name = "PNG")]
    pub texture: Option<PathBuf>,
    /// How texture coordinates are interpolated (OpenSubdiv's face-varying linear
    /// interpolation, USD's `faceVaryingLinearInterpolation`): none, cornersOnly,
    /// cornersPlus1, cornersPlus2, boundaries or all (bilinear on each face). Default: the
    /// file's (a USD mesh's attribute, cornersPlus1 when unauthored; an OBJ's `t
    /// facevaryinginterpolateboundary` tag, else all). See docs/face-varying.md.
    #[arg(long, value_name = "MODE")]
    pub uv_interpolation: Option<topology::rules::options::FVarLinearInterpolation>,
    /// Displace along the normal by S times the height (the --height map's, else a procedural
    /// bump pattern) in the same rows: -1000 to 1000.
    #[arg(long, value_name = "S", allow_hyphen_values = true, value_parser = crate::technique::parse_displace)]
    pub displace: Option<f32>,
    /// Height map (PNG, luminance in [0, 1]) for --displace.
    #[arg(long, value_name = "PNG")]
    pub height: Option<PathBuf>,
    /// Texture coordinates at the Gregory patches' own parameter instead of the rational
    /// reparameterization of Schäfer et al. (seed 003, Eq. 3), in the same rows.
    #[arg(long)]
    pub no_reparam: bool,
    /// Reproduce the refinement-pattern seed's Fig. 7 instead of the table: 10, 100 and 1,000
    /// coarse triangles at 64×64 and 128×128 segments, flat, a static pre-tessellated mesh (one
    /// indexed draw) against one refinement pattern, measured together; --markdown writes it.
    #[arg(long)]
    pub figure7: bool,
    /// Time loading instead of drawing: for each --mesh (e.g. a USD asset and the same asset
    /// as OBJ) and each --methods entry, parse, plan and the first frame at the first
    /// --segments value, in rounds (--warmup untimed, --frames timed); medians, and each
    /// total over its OBJ twin's (the --mesh of the same name ending .obj). --markdown writes
    /// the table.
    #[arg(long, conflicts_with = "figure7")]
    pub load_to_first_frame: bool,
    /// Write the rows as CSV.
    #[arg(long)]
    pub csv: Option<PathBuf>,
    /// Write a Markdown report (device, date, build profile, table).
    #[arg(long)]
    pub markdown: Option<PathBuf>,
    /// Plot the rows, .svg or .png: frame time and ratio to Flat per segments and technique, one
    /// row of charts per mesh.
    #[arg(long)]
    pub plot: Option<PathBuf>,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

#[derive(Args, Debug)]
pub struct SubdivideArgs {
    /// OBJ or USD (.usda, .usdc, .usdz) control mesh; the embedded spot control mesh when absent.
    pub input: Option<PathBuf>,
    #[arg(long, value_parser = crate::topo_cmds::parse_scheme)]
    pub scheme: topology::Scheme,
    /// Refinement level, 0 to 6 (meshes grow 4× per level).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_subdivide_level)]
    pub level: usize,
    /// Move every vertex to its limit position (Doo-Sabin: the limit at the centre of the
    /// vertex's domain square, a boundary vertex's on the boundary's quadratic B-spline).
    #[arg(long)]
    pub limit: bool,
    /// Output: OBJ, or a USD text layer when named .usda (one Mesh prim: the level's points,
    /// faces and subdivision scheme).
    #[arg(short, long)]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct LimitArgs {
    /// OBJ or USD (.usda, .usdc, .usdz) control mesh; the embedded spot control mesh when absent.
    pub input: Option<PathBuf>,
    /// loop, catmull-clark or doo-sabin (doo-sabin needs --corner, or `F C U V` points)
    #[arg(long)]
    pub scheme: String,
    /// Face number, 1-based as in the OBJ (the N-th `f` line), like every message.
    #[arg(
        long,
        allow_hyphen_values = true,
        value_parser = parse_face,
        required_unless_present = "points",
        conflicts_with = "points"
    )]
    pub face: Option<usize>,
    /// Domain coordinate U,V (the evaluator's patch domain: Loop triangles weigh corners 1
    /// and 2; Catmull-Clark quads the unit square).
    #[arg(
        long,
        value_parser = parse_uv,
        allow_hyphen_values = true,
        required_unless_present = "points",
        conflicts_with = "points"
    )]
    pub uv: Option<(f64, f64)>,
    /// Doo-Sabin: corner K of --face, 1-based (the K-th vertex of its `f` line). --uv is then
    /// the point of that corner's quad, 0 to 1 in u and v: (0,0) the corner's vertex, (1,0) the
    /// midpoint of the edge leaving it, (1,1) the face's centre, (0,1) the midpoint of the edge
    /// entering it.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_corner, conflicts_with = "points")]
    pub corner: Option<usize>,
    /// Many points at once: a file of `F U V` lines in the domain of `tessera export`'s
    /// `# p F U V` lines (F 0-based; triangles weigh corners 0 and 1, quads the unit square,
    /// n-gons the regular n-gon); `# p` lines count as points too and other OBJ lines are
    /// skipped, so an exported OBJ can be given as it is. Writes one `X Y Z` line per point.
    /// Doo-Sabin: `F C U V` lines, face and corner from 0, (U, V) in the corner's quad as for
    /// --corner.
    #[arg(long)]
    pub points: Option<PathBuf>,
    /// Where --points writes its positions (default: standard output).
    #[arg(short, long, requires = "points")]
    pub output: Option<PathBuf>,
    /// With --points: also the derivatives along U and V and the unit normal on each line
    /// (X Y Z DUX DUY DUZ DVX DVY DVZ NX NY NZ).
    #[arg(long, requires = "points")]
    pub derivatives: bool,
}

fn parse_uv(s: &str) -> Result<(f64, f64), String> {
    let bad = || {
        "--uv takes U,V: two finite numbers (0 to 1 on a quad; u, v ≥ 0 and u + v ≤ 1 on a triangle)".to_string()
    };
    let (u, v) = s.split_once(',').ok_or_else(bad)?;
    let coordinate = |t: &str| {
        t.trim()
            .parse::<f64>()
            .ok()
            .filter(|x| x.is_finite())
            .ok_or_else(bad)
    };
    Ok((coordinate(u)?, coordinate(v)?))
}

fn parse_row_budget(s: &str) -> Result<f64, String> {
    let x = numbers::float64_in(s, "--row-budget", 0.0, 1e6)?;
    if x <= 0.0 {
        return Err("--row-budget takes a number of seconds above 0, at most 1000000".into());
    }
    Ok(x)
}

fn parse_frames(s: &str) -> Result<u32, String> {
    numbers::whole_in(s, "--frames", 1, u32::MAX)
}

fn parse_warmup(s: &str) -> Result<u32, String> {
    numbers::whole_in(s, "--warmup", 0, u32::MAX)
}

fn parse_min_frames(s: &str) -> Result<u32, String> {
    numbers::whole_in(s, "--min-frames", 1, u32::MAX)
}

fn parse_cpu_max_vertices(s: &str) -> Result<u64, String> {
    numbers::whole_in(s, "--cpu-max-vertices", 0, u64::MAX)
}

// The range of these is checked after parsing, by the command (its message names the value).
fn parse_bench_segments(s: &str) -> Result<u32, String> {
    numbers::whole(s, "--segments", 1, 64)
}

fn parse_subdivide_level(s: &str) -> Result<usize, String> {
    numbers::whole(s, "--level", 0, 6)
}

fn parse_face(s: &str) -> Result<usize, String> {
    numbers::whole(s, "--face", 1, u32::MAX as usize)
}

fn parse_corner(s: &str) -> Result<usize, String> {
    numbers::whole(s, "--corner", 1, u32::MAX as usize)
}

/// `--segments` of render, view and export: a number (from 1 to
/// [`crate::technique::MAX_SEGMENTS`], and what the technique takes, checked with the
/// technique: `crate::technique::check_segments`).
fn parse_segments(s: &str) -> Result<f32, String> {
    numbers::float(s, "--segments", 1.0, 64.0)
}

/// `--depth`: a level 1..=6 of a uniform refinement.
fn parse_depth(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(d) if (1..=6).contains(&d) => Ok(d),
        _ => Err(format!(
            "--depth {s}: expected a level from 1 to 6 (2^D segments per base edge)"
        )),
    }
}

/// The segments a command draws: `--depth D`'s 2^D, else `--segments`.
pub fn segments_or_depth(segments: f32, depth: Option<u32>) -> f32 {
    depth.map_or(segments, |d| (1u32 << d) as f32)
}

/// `--device`: `auto`, an index from `tessera info`, or part of a device's name; never empty.
fn parse_device(s: &str) -> Result<String, String> {
    if s.trim().is_empty() {
        return Err(
            "--device takes auto, an index from `tessera info` or part of a device's name".into(),
        );
    }
    Ok(s.to_string())
}

#[derive(Args, Debug, Clone)]
pub struct GpuArgs {
    /// Device to use: auto, an index from `tessera info` or a name substring.
    #[arg(long, default_value = "auto", value_parser = parse_device)]
    pub device: String,
    /// Enable the Vulkan validation layer (always on in debug builds).
    #[arg(long)]
    pub validation: bool,
    /// Also run synchronization validation.
    #[arg(long)]
    pub sync_validation: bool,
    /// Compile every pipeline afresh: neither read nor write the pipeline cache kept in the
    /// user's cache directory ($XDG_CACHE_HOME/tessera/pipelines or ~/.cache/tessera/pipelines;
    /// TESSERA_PIPELINE_CACHE=off does the same for every run).
    #[arg(long)]
    pub no_pipeline_cache: bool,
    /// Create the device without tessellation shaders even where it has them (as a device
    /// without them): techniques with a refinement-pattern path draw through it, the others
    /// are refused by name.
    #[arg(long)]
    pub no_tessellation_shader: bool,
}

#[derive(Args, Debug, Clone)]
pub struct CameraArgs {
    /// Orbit angle around the vertical axis, degrees (-360 to 360).
    #[arg(long, default_value_t = 145.0, allow_hyphen_values = true, value_parser = parse_yaw)]
    pub yaw: f32,
    /// Elevation of the eye, degrees (-90 to 90).
    #[arg(long, default_value_t = 20.0, allow_hyphen_values = true, value_parser = parse_pitch)]
    pub pitch: f32,
    /// Closer (> 1) or farther (< 1) than the fitted view: 0.1 to 20, the window's wheel range.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = parse_zoom)]
    pub zoom: f32,
}

use crate::numbers::{self, float_in};

fn parse_yaw(s: &str) -> Result<f32, String> {
    float_in(s, "--yaw", -360.0, 360.0)
}

fn parse_pitch(s: &str) -> Result<f32, String> {
    float_in(s, "--pitch", -90.0, 90.0)
}

fn parse_zoom(s: &str) -> Result<f32, String> {
    float_in(s, "--zoom", 0.1, 20.0)
}

/// Phong tessellation's shape factor: 0 (flat) to 1 (full projection), Boubekeur & Alexa.
pub fn parse_alpha(s: &str) -> Result<f32, String> {
    float_in(s, "--alpha", 0.0, 1.0)
}

#[derive(Args, Debug, Clone)]
pub struct SceneArgs {
    /// OBJ or USD (.usda, .usdc, .usdz) control mesh; the embedded spot control mesh when absent.
    pub mesh: Option<PathBuf>,
    /// The technique (the list: --help); by default the limit surface of --scheme.
    #[arg(long, value_parser = crate::technique::parse_technique,
          long_help = crate::technique::method_long_help())]
    pub method: Option<TechniqueId>,
    /// Segments per base edge, the tessellation level (outer and inner): 1 to 64; bft takes
    /// powers of two from 2 to 2^(table level + 1), any level in that range with --spacing fractional-even; adaptive: segments per
    /// patch edge, 1 to 32 (a coarse transition edge gets twice as many).
    #[arg(long, alias = "level", default_value_t = 8.0, allow_hyphen_values = true, value_parser = parse_segments)]
    pub segments: f32,
    /// The level of a uniform refinement (Doo-Sabin's `doo-sabin`, `vertex-patches`,
    /// `cpu-doo-sabin`): depth D draws 2^D segments per base edge, 1 to 6; instead of --segments.
    #[arg(long, conflicts_with = "segments", allow_hyphen_values = true, value_parser = parse_depth)]
    pub depth: Option<u32>,
    #[arg(long, default_value = "equal", value_parser = parse_spacing)]
    pub spacing: Spacing,
    /// Draw the tessellated wireframe over the shaded surface.
    #[arg(long)]
    pub wireframe: bool,
    #[command(flatten)]
    pub camera: CameraArgs,
    /// Phong tessellation shape factor α, 0 to 1.
    #[arg(long, default_value_t = 0.75, allow_hyphen_values = true, value_parser = parse_alpha)]
    pub alpha: f32,
    #[command(flatten)]
    pub surface: SurfaceArgs,
    /// Move the base vertices along their normals with a travelling wave (bft, adaptive): only the base
    /// positions are uploaded per frame. `render` shows time --frame (default 0).
    #[arg(long)]
    pub animate: bool,
    #[command(flatten)]
    pub gpu: GpuArgs,
}

#[derive(Args, Debug)]
pub struct RenderArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "800x600", allow_hyphen_values = true, value_parser = parse_size)]
    pub size: (u32, u32),
    /// Output PNG.
    #[arg(short, long, default_value = "tessera.png")]
    pub output: PathBuf,
}

#[derive(Args, Debug)]
pub struct ViewArgs {
    #[command(flatten)]
    pub scene: SceneArgs,
    /// Window size, WIDTHxHEIGHT.
    #[arg(long, default_value = "1024x768", allow_hyphen_values = true, value_parser = parse_size)]
    pub size: (u32, u32),
    /// Render this many frames (at least 1), then exit (with --screenshot: save the last one).
    #[arg(long, allow_hyphen_values = true, value_parser = parse_frames)]
    pub frames: Option<u32>,
    /// PNG to save the last frame to (needs --frames).
    #[arg(long)]
    pub screenshot: Option<PathBuf>,
    /// Print the GPU memory allocated and the live Vulkan objects after a warm-up, every 1,000
    /// frames and at exit (for soak runs: tools/soak.sh).
    #[arg(long)]
    pub stats: bool,
    /// Start with the HUD hidden (H shows it). `--screenshot` runs start with it hidden too:
    /// their picture is the scene alone, as `tessera render` draws it.
    #[arg(long)]
    pub no_hud: bool,
}

fn parse_spacing(s: &str) -> Result<Spacing, String> {
    s.parse()
}

pub fn parse_size(s: &str) -> Result<(u32, u32), String> {
    numbers::size(s)
}
