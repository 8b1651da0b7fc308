//! Pictures: `tessera bench --plot out.svg` and `tessera plot run.csv -o out.png`.
//! A small bench (two meshes, two segment counts, two techniques, one frame) writes its CSV and
//! its SVG; every row of the CSV is found as a circle in the SVG where the chart's axis mapping
//! (stated per chart in a `tessera-chart` comment) puts it, in both the frame-time and the
//! ratio chart of its mesh, and the SVG has no circle the CSV does not explain. The PNG of the
//! same CSV is a real picture of the stated size.
use std::path::Path;
use std::process::Command;

fn shape(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/opensubdiv/shapes")
        .join(name)
        .to_str()
        .unwrap()
        .to_owned()
}

fn tmp(name: &str) -> String {
    let dir = std::env::temp_dir().join(format!("tessera-plot-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name).to_str().unwrap().to_owned()
}

/// (mesh, segments, method, total median ms, ratio to Flat) of each CSV row.
fn csv_rows(text: &str) -> Vec<(String, u32, String, f64, Option<f64>)> {
    let mut lines = text.lines();
    let header: Vec<&str> = lines.next().unwrap().split(',').collect();
    let col = |name: &str| header.iter().position(|h| *h == name).unwrap();
    let (mesh, seg, method, total, ratio) = (
        col("mesh"),
        col("segments"),
        col("method"),
        col("total_median_ms"),
        col("ratio_to_flat"),
    );
    lines
        .map(|l| {
            let f: Vec<&str> = l.split(',').collect();
            (
                f[mesh].to_owned(),
                f[seg].parse().unwrap(),
                f[method].to_owned(),
                f[total].parse().unwrap(),
                f[ratio].parse().ok(),
            )
        })
        .collect()
}

/// `key=value` of a comment or tag.
fn attr<'a>(text: &'a str, key: &str) -> &'a str {
    let start = text
        .find(&format!("{key}="))
        .unwrap_or_else(|| panic!("no {key} in {text}"))
        + key.len()
        + 1;
    let rest = text[start..].trim_start_matches('"');
    let end = rest.find(['"', ' ']).unwrap_or(rest.len());
    &rest[..end]
}

/// A chart's affine map, from its comment: data (x, y) → pixels.
struct Chart {
    mesh: String,
    ratio: bool,
    from: (f64, f64, f64, f64),
    to: (f64, f64, f64, f64),
}

impl Chart {
    fn parse(comment: &str) -> Chart {
        let corner = |s: &str| {
            let (data, px) = s.split_once('@').unwrap();
            let (x, y) = data.split_once(',').unwrap();
            let (px, py) = px.split_once(',').unwrap();
            (
                x.parse().unwrap(),
                y.parse().unwrap(),
                px.parse().unwrap(),
                py.parse().unwrap(),
            )
        };
        Chart {
            mesh: attr(comment, "mesh").to_owned(),
            ratio: attr(comment, "axis").ends_with("ratio"),
            from: corner(attr(comment, "from")),
            to: corner(attr(comment, "to")),
        }
    }

    fn pixel(&self, x: f64, y: f64) -> (f64, f64) {
        let (x0, y0, px0, py0) = self.from;
        let (x1, y1, px1, py1) = self.to;
        (
            px0 + (px1 - px0) * (x - x0) / (x1 - x0),
            py0 + (py1 - py0) * (y - y0) / (y1 - y0),
        )
    }

    fn contains(&self, (cx, cy): (f64, f64)) -> bool {
        let (xs, ys) = (
            [self.from.2, self.to.2],
            [self.from.3.min(self.to.3), self.from.3.max(self.to.3)],
        );
        (xs[0] - 4.0..=xs[1] + 4.0).contains(&cx) && (ys[0] - 4.0..=ys[1] + 4.0).contains(&cy)
    }
}

fn circles(svg: &str) -> Vec<(f64, f64)> {
    svg.lines()
        .filter(|l| l.trim_start().starts_with("<circle"))
        .map(|l| {
            (
                attr(l, "cx").parse().unwrap(),
                attr(l, "cy").parse().unwrap(),
            )
        })
        .collect()
}

#[test]
fn bench_plot_matches_its_csv() {
    let (csv, svg, png) = (tmp("run.csv"), tmp("run.svg"), tmp("run.png"));
    let o = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["bench", "--mesh", &shape("loop_cube.obj")])
        .args(["--mesh", &shape("loop_icosahedron.obj")])
        .args(["--segments", "2,4", "--methods", "flat,pn"])
        .args(["--frames", "1", "--warmup", "0", "--size", "64x48"])
        .args(["--csv", &csv, "--plot", &svg])
        .args(["--validation", "--sync-validation"])
        .output()
        .expect("tessera runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert!(String::from_utf8_lossy(&o.stdout).contains(&format!("wrote {svg}")));

    let rows = csv_rows(&std::fs::read_to_string(&csv).unwrap());
    assert_eq!(rows.len(), 8, "{rows:?}");
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(text.len() > 10_000, "a trivial SVG: {} bytes", text.len());
    for title in [
        "loop_cube: frame time",
        "loop_cube: ratio to Flat",
        "loop_icosahedron: frame time",
        "loop_icosahedron: ratio to Flat",
    ] {
        assert!(text.contains(title), "no chart {title:?}");
    }
    let charts: Vec<Chart> = text
        .lines()
        .filter(|l| l.starts_with("<!-- tessera-chart "))
        .map(Chart::parse)
        .collect();
    assert_eq!(charts.len(), 4);
    let dots = circles(&text);
    let mut explained = vec![false; dots.len()];
    let mut plotted = 0;
    for (mesh, segments, method, total, ratio) in &rows {
        for chart in charts.iter().filter(|c| &c.mesh == mesh) {
            let y = if chart.ratio {
                ratio.expect("every row of a run with flat has a ratio")
            } else {
                total.log10()
            };
            let (px, py) = chart.pixel(f64::from(*segments).log2(), y);
            let hit = dots.iter().enumerate().position(|(i, &(cx, cy))| {
                !explained[i] && (cx - px).abs() <= 1.5 && (cy - py).abs() <= 1.5
            });
            let Some(i) = hit else {
                panic!(
                    "{mesh} S={segments} {method} ({}) is not plotted at ({px:.1}, {py:.1}); circles: {dots:?}",
                    if chart.ratio { "ratio" } else { "frame time" }
                );
            };
            assert!(chart.contains(dots[i]));
            explained[i] = true;
            plotted += 1;
        }
    }
    assert_eq!(plotted, 16);
    // The check can fail: the first row at 1.5 times its frame time is not where a circle is.
    let (mesh, segments, _, total, _) = &rows[0];
    let chart = charts.iter().find(|c| &c.mesh == mesh && !c.ratio).unwrap();
    let (px, py) = chart.pixel(f64::from(*segments).log2(), (1.5 * total).log10());
    assert!(!dots
        .iter()
        .any(|&(cx, cy)| (cx - px).abs() <= 1.5 && (cy - py).abs() <= 1.5));
    assert!(
        explained.iter().all(|&e| e),
        "circles the CSV does not explain: {:?}",
        dots.iter()
            .zip(&explained)
            .filter(|(_, e)| !**e)
            .collect::<Vec<_>>()
    );

    // The same run as PNG, from the CSV.
    let o = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["plot", &csv, "-o", &png])
        .output()
        .expect("tessera runs");
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let img = image::open(&png).unwrap().to_rgb8();
    assert_eq!(img.dimensions(), (1120, 760));
    let mut colours: Vec<[u8; 3]> = img.pixels().map(|p| p.0).collect();
    let inked = colours.iter().filter(|c| **c != [255, 255, 255]).count();
    colours.sort_unstable();
    colours.dedup();
    assert!(inked > 20_000, "{inked} non-white pixels");
    assert!(colours.len() > 20, "{} colours", colours.len());
}

#[test]
fn plot_needs_svg_or_png() {
    let o = Command::new(env!("CARGO_BIN_EXE_tessera"))
        .args(["bench", "--plot", "out.pdf", "--methods", "flat"])
        .output()
        .expect("tessera runs");
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "{err}");
    assert!(
        err.contains("--plot out.pdf: give a file name ending in .svg or .png"),
        "{err}"
    );
    assert!(
        !err.contains("measuring"),
        "refused before measuring: {err}"
    );
}
