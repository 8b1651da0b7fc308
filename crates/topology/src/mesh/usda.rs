//! A polygon mesh written as a USD text layer (`.usda`): one `Mesh` prim with its points,
//! faces and subdivision scheme, which [`crate::mesh::usd::load_usd`] reads back. What
//! `tessera subdivide -o NAME.usda` writes: the USD twin of an OBJ for the load benchmark, or
//! a refined level for a USD pipeline.
//!
//! USD stores points as 32-bit floats (`point3f[]`): the positions are rounded to them.
use crate::rules::Scheme;
use std::io::Write;

/// USD's `subdivisionScheme` token for `scheme`; Doo-Sabin has none.
pub fn scheme_token(scheme: Scheme) -> Option<&'static str> {
    match scheme {
        Scheme::CatmullClark => Some("catmullClark"),
        Scheme::Loop => Some("loop"),
        Scheme::Bilinear => Some("bilinear"),
        Scheme::DooSabin => None,
    }
}

/// Writes `positions` and the faces (`face_offsets` into `face_vertices`) as the `Mesh` prim
/// `/Mesh` whose `subdivisionScheme` is `token` (see [`scheme_token`]).
pub fn write_usda<W: Write>(
    mut out: W,
    positions: &[[f64; 3]],
    face_offsets: &[u32],
    face_vertices: &[u32],
    token: &str,
) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(&mut out);
    writeln!(w, "#usda 1.0\n\ndef Mesh \"Mesh\"\n{{")?;
    writeln!(w, "    uniform token subdivisionScheme = \"{token}\"")?;
    let counts = face_offsets.windows(2).map(|f| (f[1] - f[0]).to_string());
    write_array(&mut w, "int[] faceVertexCounts", counts)?;
    let indices = face_vertices.iter().map(u32::to_string);
    write_array(&mut w, "int[] faceVertexIndices", indices)?;
    let points = positions
        .iter()
        .map(|p| format!("({}, {}, {})", p[0] as f32, p[1] as f32, p[2] as f32));
    write_array(&mut w, "point3f[] points", points)?;
    writeln!(w, "}}")?;
    w.flush()
}

/// `    declaration = [a, b, ...]`, one line.
fn write_array<W: Write>(
    w: &mut W,
    declaration: &str,
    values: impl Iterator<Item = String>,
) -> std::io::Result<()> {
    write!(w, "    {declaration} = [")?;
    for (i, v) in values.enumerate() {
        if i > 0 {
            w.write_all(b", ")?;
        }
        w.write_all(v.as_bytes())?;
    }
    writeln!(w, "]")
}
