//! Mesh validation on structured meshes (templates, mutated into invalid ones; any
//! coordinates, any sharpness). Validation must never panic; what it accepts must have
//! consistent adjacency, and the base levels of every scheme must build from it.
//! Bounds: those of `tessera_fuzz::MeshSpec` (≤ 64 vertices, ≤ 72 faces).
#![no_main]

use libfuzzer_sys::fuzz_target;
use tessera_fuzz::MeshSpec;
use topology::mesh::Topology;
use topology::refine::{Level, LevelTopology};
use topology::Scheme;

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        let Some(spec) = MeshSpec::from_bytes(data) else {
            return;
        };
        let mesh = spec.build();
        let (tri, origin) = mesh.triangulated();
        assert_eq!(origin.len(), tri.num_faces());
        let _ = tri.validate();
        let Ok(topo) = Topology::from_mesh(&mesh) else {
            return;
        };
        assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
        assert_eq!(topo.num_faces(), mesh.num_faces());
        for e in 0..topo.num_edges() {
            let [a, b] = topo.edge_vertices(e);
            assert_eq!(topo.find_edge(a, b), Some(e as u32));
            for f in topo.edge_faces(e) {
                if f != topology::mesh::INVALID {
                    let fv = topo.face_vertices(f as usize);
                    assert!(fv.contains(&a) && fv.contains(&b));
                }
            }
        }
        for v in 0..topo.num_vertices() {
            for &f in topo.vertex_faces(v) {
                assert!(topo.face_vertices(f as usize).contains(&(v as u32)));
            }
        }
        for scheme in [Scheme::CatmullClark, Scheme::Bilinear, Scheme::Loop] {
            if let Ok(level) = Level::from_mesh(&mesh, scheme) {
                assert!(level
                    .edge_sharpness
                    .iter()
                    .chain(&level.vertex_sharpness)
                    .all(|s| !s.is_nan() && *s >= 0.0));
            }
            let _ = LevelTopology::from_mesh(&mesh, scheme);
        }
    }
);
