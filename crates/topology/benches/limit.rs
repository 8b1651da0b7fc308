//! Exact limit evaluation per point and Loop basis-function-table generation.
//!
//! `cargo bench -p topology --bench limit`. Figures are recorded in `benches/README.md`.

use criterion::Criterion;
use std::path::PathBuf;
use std::time::Duration;
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::load_obj;
use topology::patches::bft::{BasisTables, BftCase, BftKey};

fn shape(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/opensubdiv/shapes")
        .join(name)
}

fn bench_eval(c: &mut Criterion) {
    let mut g = c.benchmark_group("limit_eval_point");
    let cube = load_obj(shape("catmark_cube.obj")).expect("cube");
    let cc = LocalMesh::from_control_mesh(&cube, LimitScheme::CatmullClark).expect("cc");
    let ico = load_obj(shape("loop_icosahedron.obj")).expect("icosahedron");
    let lp = LocalMesh::from_control_mesh(&ico, LimitScheme::Loop).expect("loop");
    // Non-dyadic points: the recursion runs until a regular sub-patch contains the point.
    let params = [(0.3, 0.2), (0.1, 0.05), (0.013, 0.021), (0.45, 0.3)];
    g.bench_function("catmark_cube_4pts", |b| {
        b.iter(|| {
            for &(u, v) in &params {
                std::hint::black_box(cc.evaluate(0, u, v).expect("eval"));
            }
        })
    });
    g.bench_function("loop_icosahedron_4pts", |b| {
        b.iter(|| {
            for &(u, v) in &params {
                std::hint::black_box(lp.evaluate(0, u, v).expect("eval"));
            }
        })
    });
    g.finish();
}

fn bench_bft(c: &mut Criterion) {
    let mut g = c.benchmark_group("bft_generation");
    g.sample_size(10)
        .measurement_time(Duration::from_secs(3))
        .warm_up_time(Duration::from_millis(500));
    for n in [3u32, 6, 12, 18] {
        let key = BftKey {
            valence: n,
            case: BftCase::Interior,
        };
        g.bench_function(format!("interior_valence_{n}_level5"), |b| {
            b.iter(|| BasisTables::build(&[key], 5).expect("table"))
        });
    }
    g.bench_function("boundary_valence_5_all_positions_level5", |b| {
        let keys: Vec<BftKey> = (0..4)
            .map(|k| BftKey {
                valence: 5,
                case: BftCase::Boundary { fan_position: k },
            })
            .collect();
        b.iter(|| BasisTables::build(&keys, 5).expect("tables"))
    });
    g.finish();
    // One timed build of the whole interior set (valences 3–18, level 5).
    let t = std::time::Instant::now();
    let all = BasisTables::build_for_valences(3..=18, false, 5).expect("tables");
    println!(
        "interior valences 3-18 at level 5: {:.2} s, {} bytes",
        t.elapsed().as_secs_f64(),
        all.memory_bytes()
    );
}

fn main() {
    let mut c = Criterion::default()
        .sample_size(10)
        .measurement_time(Duration::from_secs(2))
        .warm_up_time(Duration::from_millis(300))
        .configure_from_args();
    bench_eval(&mut c);
    bench_bft(&mut c);
    c.final_summary();
}
