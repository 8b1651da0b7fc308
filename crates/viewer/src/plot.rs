//! `tessera bench --plot` and `tessera plot`: the benchmark as a picture, SVG or PNG (plotters).
//!
//! One row of two charts per mesh: the median frame time (CPU + GPU, the figure the ratio is
//! taken of) per segments per edge and technique, and the ratio to Flat at the same mesh and S.
//! S is on a log2 axis (the paper's levels are powers of two) and the frame time on a log10 axis
//! (rows span three orders of magnitude); both are drawn as plain linear axes over the
//! logarithms, so that each chart's mapping from data to pixels is one affine map, stated in an
//! SVG comment per chart (`<!-- tessera-chart ... -->`) for tests that read the picture back.
//! Each data point is a circle, so the file can be checked point by point against the CSV of
//! the same run.
//!
//! Text goes through ab_glyph with a TrueType font found at run time (DejaVu Sans, installed by
//! tools/setup.sh; `TESSERA_FONT` names another), not through fontconfig and freetype, which
//! would be two more C libraries to build.
use anyhow::{anyhow, bail, Context as _, Result};
use plotters::backend::RGBPixel;
use plotters::coord::ranged1d::{KeyPointHint, NoDefaultFormatting, Ranged, ValueFormatter};
use plotters::coord::Shift;
use plotters::prelude::*;
use std::path::Path;
use tess::bench::BenchRow;

/// Pixels of one chart (two per mesh, side by side).
const CHART: (u32, u32) = (560, 380);

/// Where a TrueType font is looked for, in order, after `TESSERA_FONT`.
const FONT_PATHS: [&str; 5] = [
    "/usr/share/fonts/truetype/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/TTF/DejaVuSans.ttf",
    "/usr/share/fonts/dejavu/DejaVuSans.ttf",
    "/usr/share/fonts/truetype/liberation/LiberationSans-Regular.ttf",
    "/usr/share/fonts/liberation-sans/LiberationSans-Regular.ttf",
];

/// Registers a sans-serif font with plotters once per process.
fn register_font() -> Result<()> {
    static FONT: std::sync::OnceLock<std::result::Result<(), String>> = std::sync::OnceLock::new();
    FONT.get_or_init(|| {
        let candidates: Vec<std::path::PathBuf> = std::env::var_os("TESSERA_FONT")
            .map(std::path::PathBuf::from)
            .into_iter()
            .chain(FONT_PATHS.iter().map(std::path::PathBuf::from))
            .collect();
        let path = candidates.iter().find(|p| p.is_file()).ok_or_else(|| {
            format!(
                "no TrueType font for the plot's text (looked for {}; install fonts-dejavu-core or \
                 set TESSERA_FONT)",
                FONT_PATHS.join(", ")
            )
        })?;
        let bytes = std::fs::read(path).map_err(|e| format!("{}: {e}", path.display()))?;
        // plotters keeps fonts for the life of the process; this runs once.
        let bytes: &'static [u8] = Box::leak(bytes.into_boxed_slice());
        plotters::style::register_font("sans-serif", FontStyle::Normal, bytes)
            .map_err(|_| format!("{}: not a TrueType font plotters can read", path.display()))
    })
    .clone()
    .map_err(|e| anyhow!(e))
}

/// The file kind `path` asks for.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Format {
    Svg,
    Png,
}

/// The format a plot's file name asks for: `.svg` or `.png`; `option` is how the command line
/// gave the name (`--plot` for bench, `-o` for plot).
pub fn format_of(path: &Path, option: &str) -> Result<Format> {
    match path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase)
        .as_deref()
    {
        Some("svg") => Ok(Format::Svg),
        Some("png") => Ok(Format::Png),
        _ => bail!(
            "{option} {}: give a file name ending in .svg or .png",
            path.display()
        ),
    }
}

/// A chart's affine map from its data coordinates (log2 S; log10 ms or the ratio) to pixels,
/// given by two data points and their pixels.
struct ChartMap {
    mesh: String,
    axis: &'static str,
    from: ((f64, f64), (i32, i32)),
    to: ((f64, f64), (i32, i32)),
}

impl ChartMap {
    fn comment(&self) -> String {
        let ((x0, y0), (px0, py0)) = self.from;
        let ((x1, y1), (px1, py1)) = self.to;
        format!(
            "<!-- tessera-chart mesh={} axis={} from={x0},{y0}@{px0},{py0} to={x1},{y1}@{px1},{py1} -->\n",
            self.mesh.replace(['-', ' '], "_"),
            self.axis
        )
    }
}

/// The meshes in the order the rows first name them, and the techniques likewise (each keeps
/// its colour across panels).
fn order(rows: &[BenchRow]) -> (Vec<String>, Vec<String>) {
    let mut meshes: Vec<String> = Vec::new();
    let mut methods: Vec<String> = Vec::new();
    for r in rows {
        if !meshes.contains(&r.mesh) {
            meshes.push(r.mesh.clone());
        }
        if !methods.contains(&r.method) {
            methods.push(r.method.clone());
        }
    }
    (meshes, methods)
}

/// An axis over a logarithm or a plain value, with its ticks where the figures are round
/// (plotters' own float axis would put them at round logarithms).
#[derive(Clone)]
struct Axis {
    lo: f64,
    hi: f64,
    ticks: Vec<f64>,
    label: fn(f64) -> String,
}

impl Ranged for Axis {
    type ValueType = f64;
    type FormatOption = NoDefaultFormatting;

    fn range(&self) -> std::ops::Range<f64> {
        self.lo..self.hi
    }

    /// Linear from `lo..hi` onto `limit`, as plotters maps its float axes.
    fn map(&self, v: &f64, limit: (i32, i32)) -> i32 {
        let t = (*v - self.lo) / (self.hi - self.lo);
        let span = f64::from(limit.1 - limit.0);
        limit.0 + (span * t + 1e-3).floor() as i32
    }

    fn key_points<H: KeyPointHint>(&self, hint: H) -> Vec<f64> {
        let max = hint.max_num_points().max(1);
        let step = self.ticks.len().div_ceil(max).max(1);
        self.ticks.iter().copied().step_by(step).collect()
    }
}

impl ValueFormatter<f64> for Axis {
    fn format(value: &f64) -> String {
        format!("{value}")
    }

    fn format_ext(&self, value: &f64) -> String {
        (self.label)(*value)
    }
}

/// Ticks at 0, `step`, 2 `step`, ... up to `hi`, the step chosen for at most eight of them.
fn linear_ticks(hi: f64) -> Vec<f64> {
    let step = [0.25, 0.5, 1.0, 2.0, 5.0, 10.0, 20.0, 50.0, 100.0]
        .into_iter()
        .find(|s| hi / s <= 8.0)
        .unwrap_or(hi / 8.0);
    (0..)
        .map(|i| f64::from(i) * step)
        .take_while(|t| *t <= hi)
        .collect()
}

/// A millisecond figure for an axis label: few digits.
fn ms_label(ms: f64) -> String {
    if ms >= 10.0 {
        format!("{ms:.0}")
    } else if ms >= 1.0 {
        format!("{ms:.1}")
    } else {
        format!("{ms:.2}")
    }
}

/// Whether a row's frame time can be drawn on the log axis.
pub fn drawable(r: &BenchRow) -> bool {
    r.total_median_ms.is_finite() && r.total_median_ms > 0.0 && r.segments > 0
}

/// `lo..hi` widened by `pad` on both sides, and to at least `min_span`.
fn padded(lo: f64, hi: f64, pad: f64, min_span: f64) -> (f64, f64) {
    let mid = 0.5 * (lo + hi);
    let half = (0.5 * (hi - lo)).max(0.5 * min_span) + pad;
    (mid - half, mid + half)
}

/// Draws every mesh's two charts on `root` (frame time, ratio to Flat); returns each chart's
/// map.
fn draw<DB: DrawingBackend>(
    root: &DrawingArea<DB, Shift>,
    rows: &[BenchRow],
) -> Result<Vec<ChartMap>>
where
    DB::ErrorType: 'static,
{
    root.fill(&WHITE).map_err(plot_error::<DB>)?;
    let (meshes, methods) = order(rows);
    let panels = root.split_evenly((meshes.len(), 2));
    let mut maps = Vec::new();
    for (i, mesh) in meshes.iter().enumerate() {
        let mine: Vec<&BenchRow> = rows
            .iter()
            .filter(|r| &r.mesh == mesh && drawable(r))
            .collect();
        if mine.is_empty() {
            continue;
        }
        let x_axis = segments_axis(&mine);
        maps.push(time_chart(
            &panels[2 * i],
            mesh,
            &mine,
            &methods,
            x_axis.clone(),
        )?);
        maps.push(ratio_chart(
            &panels[2 * i + 1],
            mesh,
            &mine,
            &methods,
            x_axis,
        )?);
    }
    root.present().map_err(plot_error::<DB>)?;
    Ok(maps)
}

fn plot_error<DB: DrawingBackend>(e: DrawingAreaErrorKind<DB::ErrorType>) -> anyhow::Error
where
    DB::ErrorType: 'static,
{
    anyhow!("drawing the plot: {e}")
}

/// The x axis of a mesh's charts: log2 of the segments, ticks at the measured ones.
fn segments_axis(mine: &[&BenchRow]) -> Axis {
    let xs: Vec<f64> = mine.iter().map(|r| f64::from(r.segments).log2()).collect();
    let (x_lo, x_hi) = padded(
        xs.iter().copied().fold(f64::INFINITY, f64::min),
        xs.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        0.3,
        1.0,
    );
    let mut segments: Vec<u32> = mine.iter().map(|r| r.segments).collect();
    segments.sort_unstable();
    segments.dedup();
    let x_keys: Vec<f64> = segments.iter().map(|&s| f64::from(s).log2()).collect();
    Axis {
        lo: x_lo,
        hi: x_hi,
        ticks: x_keys,
        label: |x| format!("{:.0}", 2f64.powf(x)),
    }
}

/// A mesh's frame-time chart (log10 ms, one line per method) on `panel`.
fn time_chart<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    mesh: &str,
    mine: &[&BenchRow],
    methods: &[String],
    x_axis: Axis,
) -> Result<ChartMap>
where
    DB::ErrorType: 'static,
{
    let err = plot_error::<DB>;
    let (x_lo, x_hi) = (x_axis.lo, x_axis.hi);
    let ys: Vec<f64> = mine.iter().map(|r| r.total_median_ms.log10()).collect();
    let (y_lo, y_hi) = padded(
        ys.iter().copied().fold(f64::INFINITY, f64::min),
        ys.iter().copied().fold(f64::NEG_INFINITY, f64::max),
        0.08,
        0.5,
    );
    let y_keys: Vec<f64> = (-3..=5)
        .flat_map(|e| [1.0, 2.0, 5.0].map(|m| (m * 10f64.powi(e)).log10()))
        .filter(|y| (y_lo..=y_hi).contains(y))
        .collect();
    let mut chart = ChartBuilder::on(panel)
        .caption(format!("{mesh}: frame time"), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(
            x_axis.clone(),
            Axis {
                lo: y_lo,
                hi: y_hi,
                ticks: y_keys,
                label: |y| ms_label(10f64.powf(y)),
            },
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("segments per edge")
        .y_desc("median ms per frame (CPU + GPU)")
        .draw()
        .map_err(err)?;
    for (k, method) in methods.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let points: Vec<(f64, f64)> = mine
            .iter()
            .filter(|r| &r.method == method)
            .map(|r| (f64::from(r.segments).log2(), r.total_median_ms.log10()))
            .collect();
        if points.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
            .map_err(err)?
            .label(method.as_str())
            .legend(move |(x, y)| {
                PathElement::new(vec![(x, y), (x + 16, y)], colour.stroke_width(2))
            });
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
    }
    chart
        .configure_series_labels()
        .position(SeriesLabelPosition::LowerRight)
        .background_style(WHITE.mix(0.85))
        .border_style(BLACK.mix(0.4))
        .label_font(("sans-serif", 12))
        .draw()
        .map_err(err)?;
    let spec = chart.as_coord_spec();
    Ok(ChartMap {
        mesh: mesh.to_string(),
        axis: "log2-segments,log10-ms",
        from: ((x_lo, y_lo), spec.translate(&(x_lo, y_lo))),
        to: ((x_hi, y_hi), spec.translate(&(x_hi, y_hi))),
    })
}

/// A mesh's ratio-to-Flat chart (linear, one line per method) on `panel`.
fn ratio_chart<DB: DrawingBackend>(
    panel: &DrawingArea<DB, Shift>,
    mesh: &str,
    mine: &[&BenchRow],
    methods: &[String],
    x_axis: Axis,
) -> Result<ChartMap>
where
    DB::ErrorType: 'static,
{
    let err = plot_error::<DB>;
    let (x_lo, x_hi) = (x_axis.lo, x_axis.hi);
    let ratios: Vec<(u32, &str, f64)> = mine
        .iter()
        .filter_map(|r| {
            let x = r.ratio_to_flat?;
            x.is_finite().then_some((r.segments, r.method.as_str(), x))
        })
        .collect();
    let r_hi = ratios.iter().map(|r| r.2).fold(1.0f64, f64::max) * 1.1;
    let mut chart = ChartBuilder::on(panel)
        .caption(format!("{mesh}: ratio to Flat"), ("sans-serif", 18))
        .margin(10)
        .x_label_area_size(40)
        .y_label_area_size(56)
        .build_cartesian_2d(
            x_axis,
            Axis {
                lo: 0.0,
                hi: r_hi,
                ticks: linear_ticks(r_hi),
                label: |y| format!("{y:.2}"),
            },
        )
        .map_err(err)?;
    chart
        .configure_mesh()
        .x_desc("segments per edge")
        .y_desc("× Flat (median total ms)")
        .draw()
        .map_err(err)?;
    chart
        .draw_series(LineSeries::new(
            [(x_lo, 1.0), (x_hi, 1.0)],
            BLACK.mix(0.3).stroke_width(1),
        ))
        .map_err(err)?;
    for (k, method) in methods.iter().enumerate() {
        let colour = Palette99::pick(k).to_rgba();
        let points: Vec<(f64, f64)> = ratios
            .iter()
            .filter(|r| r.1 == method)
            .map(|r| (f64::from(r.0).log2(), r.2))
            .collect();
        if points.is_empty() {
            continue;
        }
        chart
            .draw_series(LineSeries::new(points.clone(), colour.stroke_width(2)))
            .map_err(err)?;
        chart
            .draw_series(points.iter().map(|&p| Circle::new(p, 3, colour.filled())))
            .map_err(err)?;
    }
    let spec = chart.as_coord_spec();
    Ok(ChartMap {
        mesh: mesh.to_string(),
        axis: "log2-segments,ratio",
        from: ((x_lo, 0.0), spec.translate(&(x_lo, 0.0))),
        to: ((x_hi, r_hi), spec.translate(&(x_hi, r_hi))),
    })
}

/// Writes the plot of `rows` to `path` (SVG or PNG by its extension; `option` names how the
/// command line gave it), whole or not at all.
pub fn write(path: &Path, rows: &[BenchRow], option: &str) -> Result<()> {
    let format = format_of(path, option)?;
    if !rows.iter().any(drawable) {
        bail!("{option} {}: no measured rows to plot", path.display());
    }
    register_font()?;
    let (meshes, _) = order(rows);
    let size = (2 * CHART.0, CHART.1 * meshes.len() as u32);
    match format {
        Format::Svg => {
            let mut svg = String::new();
            let maps = {
                let root = SVGBackend::with_string(&mut svg, size).into_drawing_area();
                draw(&root, rows)?
            };
            let comments: String = maps.iter().map(ChartMap::comment).collect();
            match svg.rfind("</svg>") {
                Some(end) => svg.insert_str(end, &comments),
                None => bail!("the SVG backend wrote no closing tag"),
            }
            crate::output::write_text(path, &svg)
        }
        Format::Png => {
            let mut pixels = vec![0u8; size.0 as usize * size.1 as usize * 3];
            {
                let root = BitMapBackend::<RGBPixel>::with_buffer_and_format(&mut pixels, size)
                    .map_err(|e| anyhow!("drawing the plot: {e}"))?
                    .into_drawing_area();
                draw(&root, rows)?;
            }
            let mut png = Vec::new();
            image::ImageEncoder::write_image(
                image::codecs::png::PngEncoder::new(&mut png),
                &pixels,
                size.0,
                size.1,
                image::ExtendedColorType::Rgb8,
            )
            .context("encoding the plot as PNG")?;
            Ok(tess::output::write_bytes(path, &png)?)
        }
    }
}
