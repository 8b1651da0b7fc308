//! The feature-adaptive plan (sparse refinement to the isolation level, patches, end caps,
//! stencil blocks, local points and curves) against uniform stencils, on the shapes the issue
//! compares with OpenSubdiv's `far_perf` (catmark_car, catmark_bishop, catmark_pawn) and spot.
//!
//! `RAYON_NUM_THREADS=1 cargo bench -p topology --bench adaptive` for the single-threaded
//! figures; `TESSERA_BENCH_FACES=1` prints the face counts per level instead (the seed's
//! Fig. 5.2: regular, end caps, faces held, uniform).
//!
//! `TESSERA_BENCH_TIME=row,row,... [TESSERA_BENCH_REPS=n] [TESSERA_BENCH_WARMUP=0|levels]` times
//! the named rows outside criterion (one untimed warm-up run of the row; none with `0`; with
//! `levels` the row's lower levels 1..N-1, as `far_perf -l N` runs them in one process before
//! the level-N figure it is compared at), then `n` timed runs, each printed in ms, the result
//! dropped outside the timer, so a script can interleave them with OpenSubdiv's `far_perf`.
//! `TESSERA_BENCH_FAULTS=1` also prints each timed run's minor page faults. Rows: `<shape>_adaptive4`,
//! `<shape>_adaptive4_follow_creases`, `<shape>_uniform3_stencils`, `<shape>_base_topology`
//! (the base level alone, which `far_perf` builds outside its timers).
use criterion::Criterion;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, EndCap};
use topology::refine::{uniform_stencils, LevelTopology};
use topology::{load_obj, ControlMesh, Scheme};

fn mesh(rel: &str) -> ControlMesh {
    load_obj(
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../..")
            .join(rel),
    )
    .unwrap()
}

fn shapes() -> Vec<(&'static str, ControlMesh)> {
    vec![
        ("spot", mesh("assets/spot_control_mesh.obj")),
        (
            "catmark_car",
            mesh("tests/data/opensubdiv/shapes/catmark_car.obj"),
        ),
        (
            "catmark_bishop",
            mesh("tests/data/opensubdiv/shapes/catmark_bishop.obj"),
        ),
        (
            "catmark_pawn",
            mesh("tests/data/opensubdiv/shapes/catmark_pawn.obj"),
        ),
    ]
}

/// `follow_semi_sharp` off is what OpenSubdiv's `far_perf -a -l N` does (leftover sharpness
/// at the isolation level treated as infinite); on is Tessera's default (exact beside creases).
fn options(isolation: u32, follow_semi_sharp: bool) -> AdaptiveOptions {
    AdaptiveOptions {
        isolation,
        end_cap: EndCap::Gregory,
        sharpness_scale: 1.0,
        follow_semi_sharp,
    }
}

fn print_face_counts() {
    for (name, m) in shapes() {
        for follow in [false, true] {
            let plan = plan_adaptive(&m, &options(4, follow)).unwrap();
            println!(
                "{name} (isolation 4, follow_semi_sharp {follow}, {} patches, {} vertices): \
                 level | regular | end caps | faces held | uniform",
                plan.patches.len(),
                plan.num_vertices
            );
            for (l, s) in plan.level_stats.iter().enumerate() {
                println!(
                    "  {l} | {} | {} | {} | {}",
                    s.regular, s.end_caps, s.faces, s.uniform_faces
                );
            }
        }
    }
}

/// One run of a named row; the result is returned so that its drop is not timed.
fn run_row(row: &str, m: &ControlMesh) -> Box<dyn std::any::Any> {
    run_row_at(row, m, None)
}

/// `level` replaces the row's isolation (or uniform) level: the warm-up that mirrors
/// `far_perf`, which plans levels 1, 2, .. N in one process and reports each.
fn run_row_at(row: &str, m: &ControlMesh, level: Option<u32>) -> Box<dyn std::any::Any> {
    if row.ends_with("_adaptive4_follow_creases") {
        Box::new(plan_adaptive(m, &options(level.unwrap_or(4), true)).unwrap())
    } else if row.ends_with("_adaptive4") {
        Box::new(plan_adaptive(m, &options(level.unwrap_or(4), false)).unwrap())
    } else if row.ends_with("_uniform3_stencils") {
        Box::new(uniform_stencils(m, Scheme::CatmullClark, level.unwrap_or(3) as usize).unwrap())
    } else if row.ends_with("_base_topology") {
        Box::new(LevelTopology::from_mesh(m, Scheme::CatmullClark).unwrap())
    } else {
        panic!("unknown row {row}")
    }
}

/// The process's minor page faults so far (Linux `/proc`), `None` elsewhere: each is a fresh
/// page zeroed and mapped, the part of a cold run that a warm one does not pay.
fn minor_faults() -> Option<u64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    // Fields after the command name (which may hold spaces) start at the state, field 3.
    let rest = &stat[stat.rfind(')')? + 2..];
    rest.split(' ').nth(7)?.parse().ok()
}

fn time_rows(rows: &str) {
    let reps: usize = std::env::var("TESSERA_BENCH_REPS")
        .ok()
        .and_then(|r| r.parse().ok())
        .unwrap_or(1);
    // `TESSERA_BENCH_WARMUP=0`: no warm-up run, so the first timed run is cold (fresh
    // process: every page of the plan faulted in, caches cold). `=levels`: the lower levels
    // first, as `far_perf -l N` runs them in one process before level N (its reported figure).
    let warm_up = std::env::var("TESSERA_BENCH_WARMUP").unwrap_or_default();
    let lower_levels = warm_up == "levels";
    let warm_up = warm_up != "0" && !lower_levels;
    let shapes = shapes();
    for row in rows.split(',') {
        let (_, m) = shapes
            .iter()
            .find(|(name, _)| row.starts_with(&format!("{name}_")))
            .unwrap_or_else(|| panic!("no shape for row {row}"));
        if warm_up {
            drop(run_row(row, m));
        }
        if lower_levels {
            let top = if row.contains("_uniform3") { 3 } else { 4 };
            for level in 1..top {
                drop(run_row_at(row, m, Some(level)));
            }
        }
        let mut ms = Vec::with_capacity(reps);
        let mut faults = Vec::with_capacity(reps);
        for _ in 0..reps {
            let f = minor_faults();
            let t = Instant::now();
            let out = run_row(row, m);
            ms.push(t.elapsed().as_secs_f64() * 1e3);
            faults.push(minor_faults().zip(f).map(|(b, a)| b - a));
            drop(out);
        }
        let list: Vec<String> = ms.iter().map(|t| format!("{t:.3}")).collect();
        println!("{row} ms {}", list.join(" "));
        if std::env::var_os("TESSERA_BENCH_FAULTS").is_some() {
            let list: Vec<String> = faults
                .iter()
                .map(|f| f.map_or("?".into(), |f| f.to_string()))
                .collect();
            println!("{row} minor_faults {}", list.join(" "));
        }
    }
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("plan");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for (name, m) in shapes() {
        g.bench_function(format!("{name}_adaptive4"), |b| {
            b.iter(|| plan_adaptive(&m, &options(4, false)).unwrap())
        });
        g.bench_function(format!("{name}_adaptive4_follow_creases"), |b| {
            b.iter(|| plan_adaptive(&m, &options(4, true)).unwrap())
        });
        if name == "catmark_car" {
            g.bench_function(format!("{name}_uniform3_stencils"), |b| {
                b.iter(|| uniform_stencils(&m, Scheme::CatmullClark, 3).unwrap())
            });
        }
    }
    g.finish();
}

fn main() {
    if std::env::var_os("TESSERA_BENCH_FACES").is_some() {
        print_face_counts();
        return;
    }
    if let Ok(rows) = std::env::var("TESSERA_BENCH_TIME") {
        time_rows(&rows);
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    bench(&mut c);
    c.final_summary();
}
