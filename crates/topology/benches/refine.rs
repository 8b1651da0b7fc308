//! Mesh building and uniform stencil tables on the spot meshes and large generated quad grids.
//!
//! `TESSERA_BENCH_PHASES=250,1000 cargo bench -p topology --bench refine` skips criterion and
//! prints one-shot phase timings (best of a few runs) for those grid sizes instead.

use criterion::Criterion;
use std::path::PathBuf;
use std::time::{Duration, Instant};
use topology::mesh::Topology;
use topology::refine::{refine_uniform, uniform_stencils};
use topology::{load_obj, ControlMesh, Scheme};

fn asset(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../assets")
        .join(name)
}

/// A flat `n` x `n` quad grid (open boundary).
fn grid(n: usize) -> ControlMesh {
    let mut positions = Vec::with_capacity((n + 1) * (n + 1));
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f64, j as f64, ((i * 7 + j * 13) % 5) as f64 * 0.1]);
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|j| (0..n).map(move |i| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)]))
        .collect();
    ControlMesh::from_polygons(positions, &faces)
}

fn spot(c: &mut Criterion) {
    let mut g = c.benchmark_group("spot_load_and_level3_stencils");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    for name in ["spot_control_mesh.obj", "spot_quadrangulated.obj"] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let mesh = load_obj(asset(name)).unwrap();
                uniform_stencils(&mesh, Scheme::CatmullClark, 3).unwrap()
            })
        });
    }
    g.finish();
}

fn grids(c: &mut Criterion) {
    let mut g = c.benchmark_group("grid_mesh_and_level2_stencils");
    g.sample_size(10)
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3));
    // 250^2 base faces refine to 1M faces at level 2; 1000^2 is a 1M-face control mesh.
    let mut sizes = vec![250usize];
    if std::env::var_os("TESSERA_BENCH_1M_BASE").is_some() {
        sizes.push(1000);
    }
    for n in sizes {
        let mesh = grid(n);
        g.bench_function(format!("{n}x{n}_topology"), |b| {
            b.iter(|| Topology::from_mesh(&mesh).unwrap())
        });
        g.bench_function(format!("{n}x{n}_level1_stencils"), |b| {
            b.iter(|| uniform_stencils(&mesh, Scheme::CatmullClark, 1).unwrap())
        });
        g.bench_function(format!("{n}x{n}_level2_stencils"), |b| {
            b.iter(|| uniform_stencils(&mesh, Scheme::CatmullClark, 2).unwrap())
        });
    }
    g.finish();
}

/// Best wall time of `runs` calls of `f`, in milliseconds.
fn best_ms<T>(runs: usize, mut f: impl FnMut() -> T) -> f64 {
    let mut best = f64::INFINITY;
    for _ in 0..runs {
        let t = Instant::now();
        let out = f();
        best = best.min(t.elapsed().as_secs_f64() * 1e3);
        drop(out);
    }
    best
}

/// One-shot phase timings for grids of the given sizes.
fn phases(sizes: &str) {
    for n in sizes
        .split(',')
        .filter_map(|s| s.trim().parse::<usize>().ok())
    {
        let mesh = grid(n);
        let runs = if n >= 1000 { 2 } else { 5 };
        let topo = best_ms(runs, || Topology::from_mesh(&mesh).unwrap());
        let l1 = best_ms(runs, || {
            uniform_stencils(&mesh, Scheme::CatmullClark, 1).unwrap()
        });
        let r1 = best_ms(runs, || {
            refine_uniform(&mesh, Scheme::CatmullClark, 1).unwrap()
        });
        let l2 = best_ms(runs, || {
            uniform_stencils(&mesh, Scheme::CatmullClark, 2).unwrap()
        });
        let t = uniform_stencils(&mesh, Scheme::CatmullClark, 2).unwrap();
        println!(
            "{n}x{n}: topology {topo:.1} ms | level-1 stencils {l1:.1} ms | refine_uniform(1) \
             {r1:.1} ms | level-2 stencils {l2:.1} ms ({} stencils, {} weights)",
            t.len(),
            t.weights.len()
        );
    }
}

fn main() {
    if let Ok(sizes) = std::env::var("TESSERA_BENCH_PHASES") {
        phases(&sizes);
        return;
    }
    let mut c = Criterion::default().configure_from_args();
    spot(&mut c);
    grids(&mut c);
    c.final_summary();
}
