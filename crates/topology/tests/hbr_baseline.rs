//! Reproduce OpenSubdiv's Hbr uniform-refinement baselines: same vertex and face counts and the
//! same vertex set (order-independent) within 2e-6 of the bounding-box diagonal.

use std::collections::HashMap;
use std::path::PathBuf;
use topology::refine::refine_uniform;
use topology::{load_obj, Scheme};

fn data_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/opensubdiv")
}

/// Tolerance relative to the bounding-box diagonal (Hbr computed in float32).
const REL_TOL: f64 = 2e-6;

/// Shapes whose baselines follow Hbr's older Chaikin transition rule from this level on:
/// when an edge of sharpness ≥ 1 decays to 0 in one Chaikin step, Hbr blends the vertex rules
/// differently from OpenSubdiv's Sdc, which this crate follows. They must differ by ~1e-2.
const KNOWN_DIFFERENCES: &[(&str, usize)] = &[("catmark_chaikin1", 2), ("loop_chaikin1", 2)];

struct Baseline {
    vertices: Vec<[f64; 3]>,
    faces: usize,
}

fn read_baseline(name: &str, level: usize) -> Option<Baseline> {
    let path = data_dir().join(format!("hbr_baseline/{name}.L{level}.obj"));
    let text = std::fs::read_to_string(path).ok()?;
    let mut vertices = Vec::new();
    let mut faces = 0;
    for line in text.lines() {
        let mut w = line.split_whitespace();
        match w.next() {
            Some("v") => {
                let c: Vec<f64> = w.take(3).map(|x| x.parse().unwrap()).collect();
                vertices.push([c[0], c[1], c[2]]);
            }
            Some("f") => faces += 1,
            _ => {}
        }
    }
    Some(Baseline { vertices, faces })
}

fn diagonal(points: &[[f64; 3]]) -> f64 {
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    ((hi[0] - lo[0]).powi(2) + (hi[1] - lo[1]).powi(2) + (hi[2] - lo[2]).powi(2)).sqrt()
}

/// Largest distance from one of `ours` to its matched baseline vertex, matching each baseline
/// vertex at most once (nearest unused within a uniform grid neighbourhood), relative to the
/// diagonal. Unmatched vertices count as the diagonal itself.
fn max_set_distance(ours: &[[f64; 3]], theirs: &[[f64; 3]], diag: f64, cell: f64) -> f64 {
    let key = |p: &[f64; 3]| {
        [
            (p[0] / cell).floor() as i64,
            (p[1] / cell).floor() as i64,
            (p[2] / cell).floor() as i64,
        ]
    };
    let mut grid: HashMap<[i64; 3], Vec<usize>> = HashMap::new();
    for (i, p) in theirs.iter().enumerate() {
        grid.entry(key(p)).or_default().push(i);
    }
    let mut used = vec![false; theirs.len()];
    let mut worst: f64 = 0.0;
    for p in ours {
        let k = key(p);
        let mut best: Option<(f64, usize)> = None;
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    if let Some(list) = grid.get(&[k[0] + dx, k[1] + dy, k[2] + dz]) {
                        for &i in list {
                            if used[i] {
                                continue;
                            }
                            let q = theirs[i];
                            let d = ((p[0] - q[0]).powi(2)
                                + (p[1] - q[1]).powi(2)
                                + (p[2] - q[2]).powi(2))
                            .sqrt();
                            if best.is_none_or(|b| d < b.0) {
                                best = Some((d, i));
                            }
                        }
                    }
                }
            }
        }
        match best {
            Some((d, i)) => {
                used[i] = true;
                worst = worst.max(d / diag);
            }
            None => worst = worst.max(1.0),
        }
    }
    worst
}

#[test]
fn hbr_baselines() {
    let mut shapes: Vec<String> = std::fs::read_dir(data_dir().join("shapes"))
        .expect("test data present")
        .map(|e| {
            e.unwrap()
                .file_name()
                .to_string_lossy()
                .trim_end_matches(".obj")
                .to_string()
        })
        // Shapes kept only for the GPU tests have no Hbr baseline.
        .filter(|s| {
            data_dir()
                .join("hbr_baseline")
                .join(format!("{s}.L1.obj"))
                .exists()
        })
        .collect();
    shapes.sort();
    assert_eq!(
        shapes.len(),
        33,
        "expected the 33 shapes with Hbr baselines"
    );

    let mut failures = Vec::new();
    let mut checked = 0;
    let mut known_checked = 0;
    for name in &shapes {
        let scheme = Scheme::from_shape_name(name).expect("scheme prefix");
        let mesh = load_obj(data_dir().join(format!("shapes/{name}.obj"))).unwrap();
        let max_level = (1..=4)
            .take_while(|&l| read_baseline(name, l).is_some())
            .count();
        assert!(max_level >= 3, "{name}: levels 1-3 expected");
        let refined = refine_uniform(&mesh, scheme, max_level).unwrap();
        for level in 1..=max_level {
            let base = read_baseline(name, level).unwrap();
            let ours = refined.level(level);
            if ours.num_vertices() != base.vertices.len() || ours.num_faces() != base.faces {
                failures.push(format!(
                    "{name} L{level}: counts v {} vs {}, f {} vs {}",
                    ours.num_vertices(),
                    base.vertices.len(),
                    ours.num_faces(),
                    base.faces
                ));
                continue;
            }
            let diag = diagonal(&base.vertices);
            let known = KNOWN_DIFFERENCES
                .iter()
                .any(|&(n, from)| n == name && level >= from);
            let cell = if known {
                0.05 * diag
            } else {
                4.0 * REL_TOL * diag
            };
            let d = max_set_distance(&ours.positions, &base.vertices, diag, cell);
            if known {
                // Documented difference: must really differ, by about 1e-2 of the diagonal.
                if !(1e-3..=5e-2).contains(&d) {
                    failures.push(format!(
                        "{name} L{level}: known difference expected ~1e-2, got {d:.3e}"
                    ));
                }
                known_checked += 1;
            } else if d > REL_TOL {
                failures.push(format!("{name} L{level}: max distance {d:.3e} of diagonal"));
            }
            eprintln!(
                "{name} L{level}: v {} f {} max rel distance {d:.2e}{}",
                base.vertices.len(),
                base.faces,
                if known { " (known difference)" } else { "" }
            );
            checked += 1;
        }
    }
    assert!(
        failures.is_empty(),
        "{} of {checked} levels differ:\n{}",
        failures.len(),
        failures.join("\n")
    );
    assert_eq!(
        known_checked, 4,
        "chaikin1 levels 2-3 of both schemes are the known differences"
    );
    assert!(checked >= 33 * 3);
}
