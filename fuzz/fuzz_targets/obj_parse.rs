//! OBJ + `t` tag parser on raw bytes. Accepted text must give a valid mesh with finite
//! positions and finite, non-negative sharpness, and must survive a write/parse round trip
//! unchanged (positions, faces, creases, corners).
//! Bound: inputs over 64 KiB are skipped (the parser is linear; this only keeps runs fast).
#![no_main]

use libfuzzer_sys::fuzz_target;
use topology::mesh::obj::{parse_obj, write_control_mesh};

fuzz_target!(
    init: tessera_fuzz::single_thread_rayon(),
    |data: &[u8]| {
        if data.len() > 64 * 1024 {
            return;
        }
        let text = String::from_utf8_lossy(data);
        let Ok(mesh) = parse_obj(&text, "fuzz.obj") else {
            return;
        };
        assert!(mesh.positions.iter().flatten().all(|c| c.is_finite()));
        assert!(mesh
            .creases
            .iter()
            .map(|c| c.sharpness)
            .chain(mesh.corners.iter().map(|c| c.sharpness))
            .all(|s| s.is_finite() && s >= 0.0));
        let nv = mesh.positions.len();
        assert!(mesh.face_vertices.iter().all(|&v| (v as usize) < nv));
        mesh.validate().expect("parse_obj returned an invalid mesh");

        let mut out = Vec::new();
        write_control_mesh(&mut out, &mesh).expect("writing to a Vec cannot fail");
        let text2 = String::from_utf8(out).expect("the writer writes UTF-8");
        let again = parse_obj(&text2, "roundtrip.obj").expect("written mesh must parse");
        assert_eq!(again.positions, mesh.positions);
        assert_eq!(again.face_offsets, mesh.face_offsets);
        assert_eq!(again.face_vertices, mesh.face_vertices);
        assert_eq!(again.creases, mesh.creases);
        assert_eq!(again.corners, mesh.corners);
    }
);
