//! One hash per plan variant, for checking that a change to the planner is bit-identical.
//!
//! For every mesh given (default: every `.obj` under `tests/data` and `assets`), prints a line
//! `<mesh> <variant> <plan hash> <surface hash>` for the feature-adaptive plans (isolation
//! 1, 2 and 4, Gregory and bilinear end caps, features followed or not; two with sharpness
//! scale 0.5), the single-pass
//! plans (Gregory or ACC-1, triangle patches or split triangles) and the uniform stencils
//! (Catmull-Clark to level 2). The plan hash covers the plan's `Debug` text, which prints
//! every `f64` weight to its last bit (shortest round-trip form); the surface hash covers what
//! is drawn, whatever the numbering of the vertices (a change that renumbers them keeps it).
//! An error is hashed as its message.
//!
//! ```sh
//! cargo run --release -p topology --example plan_fingerprint > before.txt
//! # change the planner, then
//! cargo run --release -p topology --example plan_fingerprint > after.txt && diff before.txt after.txt
//! ```
//!
//! Run it with `RAYON_NUM_THREADS=1` and without: plans must not depend on the thread count.
use std::collections::hash_map::DefaultHasher;
use std::hash::{Hash, Hasher};
use std::path::{Path, PathBuf};
use topology::patches::adaptive::single_pass::{
    plan_single_pass, SinglePassOptions, SinglePassPatch,
};
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, AdaptivePlan, EndCap};
use topology::refine::uniform_stencils;
use topology::{load_obj, Scheme};

fn hash_debug<T: std::fmt::Debug>(value: &T) -> u64 {
    let mut h = DefaultHasher::new();
    format!("{value:?}").hash(&mut h);
    h.finish()
}

/// The surface a plan draws, independent of how its vertices are numbered: per patch its
/// kind, level, place in its base face and edge kinds, and the bits of its position and
/// derivatives at a 3×3 lattice of parameters; per canonical curve, four of its points.
fn surface_hash(plan: &AdaptivePlan, base: &[[f64; 3]]) -> u64 {
    let verts = plan.apply(base);
    let mut h = DefaultHasher::new();
    plan.patches.len().hash(&mut h);
    for (i, p) in plan.patches.iter().enumerate() {
        format!(
            "{:?} {} {} {} {:?} {} {:?}",
            p.kind,
            p.level,
            p.base_face,
            p.sub_face,
            p.origin,
            p.size,
            p.edges.map(|e| e.kind)
        )
        .hash(&mut h);
        for u in [0.0, 0.5, 1.0] {
            for v in [0.0, 0.25, 1.0] {
                if p.corners() == 3 && u + v > 1.0 {
                    continue;
                }
                let s = plan.evaluate(&verts, i, u, v);
                for x in s.position.iter().chain(&s.du).chain(&s.dv) {
                    x.to_bits().hash(&mut h);
                }
            }
        }
    }
    plan.curves.len().hash(&mut h);
    for c in 0..plan.curves.len() {
        for t in [0.0, 0.25, 0.5, 1.0] {
            for x in plan.curve_point(&verts, c, t) {
                x.to_bits().hash(&mut h);
            }
        }
    }
    h.finish()
}

fn objs(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = std::fs::read_dir(dir) else {
        return;
    };
    let mut entries: Vec<PathBuf> = entries.flatten().map(|e| e.path()).collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            objs(&p, out);
        } else if p.extension().is_some_and(|e| e == "obj") {
            out.push(p);
        }
    }
}

fn main() {
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../..");
    let mut meshes: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    if meshes.is_empty() {
        objs(&root.join("tests/data"), &mut meshes);
        objs(&root.join("assets"), &mut meshes);
    }
    for path in meshes {
        let name = path
            .strip_prefix(&root)
            .unwrap_or(&path)
            .display()
            .to_string();
        let mesh = match load_obj(&path) {
            Ok(m) => m,
            Err(e) => {
                println!("{name} load {}", hash_debug(&e.to_string()));
                continue;
            }
        };
        let mut variants = Vec::new();
        for isolation in [1, 2, 4] {
            for end_cap in [EndCap::Gregory, EndCap::Bilinear] {
                for follow in [false, true] {
                    variants.push((isolation, end_cap, follow, 1.0f32));
                }
            }
        }
        variants.push((2, EndCap::Gregory, true, 0.5));
        variants.push((4, EndCap::Gregory, false, 0.5));
        for (isolation, end_cap, follow, scale) in variants {
            let opts = AdaptiveOptions {
                isolation,
                end_cap,
                sharpness_scale: scale,
                follow_semi_sharp: follow,
            };
            let (plan, surface) = match plan_adaptive(&mesh, &opts) {
                Ok(p) => (hash_debug(&p), surface_hash(&p, &mesh.positions)),
                Err(e) => (hash_debug(&e.to_string()), 0),
            };
            println!(
                "{name} adaptive-{isolation}-{end_cap:?}-follow{follow}-x{scale} {plan:016x} {surface:016x}"
            );
        }
        for patch in [SinglePassPatch::Gregory, SinglePassPatch::Acc1] {
            for gregory_triangles in [true, false] {
                let opts = SinglePassOptions {
                    patch,
                    sharpness_scale: 1.0,
                    gregory_triangles,
                };
                let (plan, surface) = match plan_single_pass(&mesh, &opts) {
                    Ok(p) => (hash_debug(&p), surface_hash(&p, &mesh.positions)),
                    Err(e) => (hash_debug(&e.to_string()), 0),
                };
                println!(
                    "{name} single-{patch:?}-tri{gregory_triangles} {plan:016x} {surface:016x}"
                );
            }
        }
        let h = match uniform_stencils(&mesh, Scheme::CatmullClark, 2) {
            Ok(t) => hash_debug(&t),
            Err(e) => hash_debug(&e.to_string()),
        };
        println!("{name} uniform-catmark-2 {h:016x}");
    }
}
