//! Face-varying subdivision of texture coordinates: the channel refined as a control mesh of
//! its own, the *value mesh*, under OpenSubdiv's face-varying rules
//! ([`FVarLinearInterpolation`]).
//!
//! A texture layout gives every face corner a value; corners around a vertex that share a
//! value (and are joined across edges whose ends share values on both sides) form one
//! *span*. The value mesh has one vertex per span, the mesh's faces with their corners
//! renamed to spans, and the values as positions `(u, v, 0)`. Where the layout is continuous
//! the value mesh is the mesh, and refining it is the vertex refinement; a seam (an edge whose
//! faces disagree at either end) is two boundary edges of the value mesh, refined with the
//! boundary rule as OpenSubdiv refines a smooth face-varying boundary. Every subdivision,
//! limit and patch tool of the crate then serves the channel unchanged: the value mesh's
//! limit at a face's parameter is the texture coordinate there.
//!
//! The interpolation mode decides which values are pinned (infinitely sharp corners of the
//! value mesh), following OpenSubdiv's analysis of each vertex with a discontinuity
//! (`Vtr::FVarLevel`):
//! - every mode but `none` pins the corners of the layout (a span of one face); `none` pins
//!   them only where the mesh itself is an "edges and corners" boundary corner;
//! - `cornersPlus1` and `cornersPlus2` pin every value of a vertex with three or more values,
//!   and both values of a two-valued vertex when either span holds an infinitely sharp edge;
//!   `cornersPlus2` also when either span is a single face, and pins darts (a seam ending
//!   inside the mesh);
//! - `boundaries` pins every value on a seam or a boundary, so the layout's boundaries are
//!   linear between their values; `all` is bilinear on each face
//!   ([`crate::patches::texcoord`]) and has no value mesh;
//! - a value whose corners at a vertex fall into separate spans (a layout that touches
//!   itself at a vertex), and every value at an infinitely sharp vertex, is pinned.
//!
//! The mesh's creases apply to the value mesh's edges between the same vertices, its corner
//! tags to every value of the vertex, and its holes stay holes.
//!
//! Two approximations, both only where a semi-sharp feature meets a seam: Chaikin decay on
//! the value mesh sees only the semi-sharp edges of the value's own span (OpenSubdiv's sees
//! the vertex's), and a value that `cornersPlus1`/`cornersPlus2` makes depend on the
//! semi-sharp edges of the other span gets a corner sharpness equal to their greatest
//! (OpenSubdiv pins it while they are sharp).
use crate::error::TopologyError;
use crate::mesh::{corner_faces, ControlMesh, EdgeCrease, Topology, VertexCorner, INVALID};
use crate::refine::LevelTopology;
use crate::rules::options::{BoundaryInterpolation, FVarLinearInterpolation};
use crate::rules::{is_infinite, is_semi_sharp, Scheme, SHARPNESS_INFINITE};
use std::collections::HashMap;

/// The value mesh of `mesh`'s texture coordinates under its
/// [`fvar_interpolation`](crate::rules::options::SubdivOptions::fvar_interpolation), refined
/// with `scheme`; `None` when the mesh has no texture coordinate at every corner or the mode
/// is [`FVarLinearInterpolation::All`] (bilinear per face).
pub fn texcoord_mesh(
    mesh: &ControlMesh,
    scheme: Scheme,
) -> Option<Result<ValueMesh, TopologyError>> {
    let mode = mesh.options.fvar_interpolation;
    let uvs = mesh.uvs.as_ref()?;
    if mode.is_linear() || uvs.len() != mesh.face_vertices.len() {
        return None;
    }
    Some(value_mesh(mesh, scheme, mode))
}

/// A face-varying channel as a control mesh ([`texcoord_mesh`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ValueMesh {
    /// Positions `(u, v, 0)`; faces as the mesh's, corners renamed to their spans; creases,
    /// corners (the pinned values among them), holes and options as described in the module
    /// documentation.
    pub mesh: ControlMesh,
    /// Per value-mesh vertex, the mesh vertex it is a value of.
    pub vertex_of: Vec<u32>,
}

impl ValueMesh {
    /// The texture coordinate of value-mesh vertex `v`.
    pub fn value(&self, v: usize) -> [f64; 2] {
        let p = self.mesh.positions[v];
        [p[0], p[1]]
    }
}

/// What the face-varying analysis knows of one span of one vertex.
#[derive(Clone, Debug, Default)]
struct Span {
    /// Faces in the span.
    size: usize,
    /// Its value's key (the corner's uv index or value bits).
    key: u64,
    /// Another span of the vertex has the same key (the layout touches itself here).
    disjoint: bool,
    /// Interior edges of the span that are infinitely sharp / semi-sharp (greatest sharpness).
    inf_sharp_edges: usize,
    semi_sharp: f32,
}

/// Per corner, its value's key: its uv index when the mesh has one per corner, else the
/// number of its value's bits among the distinct ones.
fn corner_keys(mesh: &ControlMesh, uvs: &[[f64; 2]]) -> Vec<u64> {
    if let Some(ix) = mesh.uv_indices.as_ref().filter(|ix| ix.len() == uvs.len()) {
        return ix.iter().map(|&i| i as u64).collect();
    }
    let mut ids: HashMap<[u64; 2], u64> = HashMap::new();
    uvs.iter()
        .map(|uv| {
            let n = ids.len() as u64;
            *ids.entry(uv.map(f64::to_bits)).or_insert(n)
        })
        .collect()
}

/// The corner after and before `c` in its face.
fn next_prev(topo: &Topology, corner_face: &[u32], c: usize) -> (usize, usize) {
    let f = corner_face[c] as usize;
    let (s, e) = (
        topo.face_offsets[f] as usize,
        topo.face_offsets[f + 1] as usize,
    );
    let next = if c + 1 == e { s } else { c + 1 };
    let prev = if c == s { e - 1 } else { c - 1 };
    (next, prev)
}

/// The corner of face `f` at vertex `v`.
fn corner_at(topo: &Topology, f: usize, v: u32) -> Option<usize> {
    let s = topo.face_offsets[f] as usize;
    topo.face_vertices(f)
        .iter()
        .position(|&x| x == v)
        .map(|i| s + i)
}

/// The corners at vertex `v` in fan order (each next one across the outgoing edge of the one
/// before), from the corner whose incoming edge is a boundary edge on a boundary vertex;
/// with, per corner, its outgoing edge, `INVALID` after the last corner of a boundary fan (a
/// closed fan's last edge leads back to the first corner).
fn fan(topo: &Topology, corner_face: &[u32], v: u32) -> Vec<(usize, u32)> {
    let faces = topo.vertex_faces(v as usize);
    let other_face = |c: usize, e: u32| {
        let [a, b] = topo.edge_faces[e as usize];
        let f = corner_face[c];
        if a == f {
            b
        } else {
            a
        }
    };
    let Some(mut c) = faces.first().and_then(|&f| corner_at(topo, f as usize, v)) else {
        return Vec::new();
    };
    // Walk back to the first corner of a boundary fan.
    for _ in 0..faces.len() {
        let (_, prev) = next_prev(topo, corner_face, c);
        let g = other_face(c, topo.face_edges[prev]);
        match (g != INVALID)
            .then(|| corner_at(topo, g as usize, v))
            .flatten()
        {
            Some(x) => c = x,
            None => break,
        }
    }
    let start = c;
    let mut out = Vec::with_capacity(faces.len());
    for _ in 0..faces.len() {
        let e = topo.face_edges[c];
        let g = other_face(c, e);
        let Some(x) = (g != INVALID)
            .then(|| corner_at(topo, g as usize, v))
            .flatten()
        else {
            out.push((c, INVALID));
            break;
        };
        out.push((c, e));
        if x == start {
            break;
        }
        c = x;
    }
    out
}

/// Whether the edge from corner `c` (at its vertex) to the next fan corner `d` is a seam:
/// the two faces disagree at either end of the edge.
fn is_seam(
    topo: &Topology,
    corner_face: &[u32],
    key: &impl Fn(usize) -> u64,
    c: usize,
    d: usize,
) -> bool {
    let (c_next, _) = next_prev(topo, corner_face, c);
    let (_, d_prev) = next_prev(topo, corner_face, d);
    key(c) != key(d) || key(c_next) != key(d_prev)
}

/// The spans of vertex `v`: per fan corner its span, and the spans.
fn spans_of(
    topo: &Topology,
    level: &LevelTopology,
    corner_face: &[u32],
    key: &impl Fn(usize) -> u64,
    fan: &[(usize, u32)],
) -> (Vec<usize>, Vec<Span>, bool) {
    let closed = fan.last().is_some_and(|&(_, e)| e != INVALID);
    let n = fan.len();
    let mut span_of = vec![0usize; n];
    let mut spans: Vec<Span> = Vec::new();
    let mut any_seam = false;
    // Seam after each fan corner (the last one closes the fan of an interior vertex).
    let seam_after: Vec<bool> = (0..n)
        .map(|i| {
            let (c, e) = fan[i];
            e != INVALID && is_seam(topo, corner_face, key, c, fan[(i + 1) % n].0)
        })
        .collect();
    any_seam |= seam_after.iter().any(|&s| s);
    // Start an interior fan just after a seam, so no span wraps around.
    let first = if closed {
        seam_after
            .iter()
            .position(|&s| s)
            .map_or(0, |i| (i + 1) % n)
    } else {
        0
    };
    for k in 0..n {
        let i = (first + k) % n;
        let prev = (i + n - 1) % n;
        if k == 0 || seam_after[prev] {
            spans.push(Span {
                key: key(fan[i].0),
                ..Span::default()
            });
        }
        let s = spans.len() - 1;
        span_of[i] = s;
        spans[s].size += 1;
        // The edge after this corner, when it lies inside the span.
        let (_, e) = fan[i];
        if e != INVALID && !seam_after[i] {
            let sharp = level.edge_sharpness[e as usize];
            if is_infinite(sharp) {
                spans[s].inf_sharp_edges += 1;
            } else if is_semi_sharp(sharp) {
                spans[s].semi_sharp = spans[s].semi_sharp.max(sharp);
            }
        }
    }
    for i in 0..spans.len() {
        spans[i].disjoint = (0..spans.len()).any(|j| j != i && spans[j].key == spans[i].key);
    }
    (span_of, spans, any_seam)
}

/// The corner sharpness OpenSubdiv's face-varying analysis gives each span of a vertex with a
/// discontinuity (`mismatch`): infinite for a pinned value, the other span's semi-sharpness
/// for a value made dependent on it, else the vertex's own.
fn span_sharpness(
    mode: FVarLinearInterpolation,
    spans: &[Span],
    vertex_sharpness: f32,
    boundary: bool,
) -> Vec<f32> {
    use FVarLinearInterpolation as M;
    let linear_boundaries = matches!(mode, M::Boundaries | M::All);
    let dependent = matches!(mode, M::CornersPlus1 | M::CornersPlus2);
    let corners_sharp = mode != M::None;
    let sharpen_darts = mode == M::CornersPlus2 || linear_boundaries;
    let mut keys: Vec<u64> = spans.iter().map(|s| s.key).collect();
    keys.sort_unstable();
    keys.dedup();
    let values = keys.len();
    let mut all = linear_boundaries
        || is_infinite(vertex_sharpness)
        || (dependent && values > 2)
        || (sharpen_darts && values == 1 && !boundary);
    let mut depends_on = [None, None];
    if !all && dependent && values == 2 && spans.len() == 2 {
        all = spans.iter().any(|s| s.inf_sharp_edges > 0 || s.disjoint)
            || (mode == M::CornersPlus2 && spans.iter().any(|s| s.size == 1));
        let (a, b) = (spans[0].semi_sharp, spans[1].semi_sharp);
        if (a > 0.0) != (b > 0.0) {
            depends_on = if a > 0.0 {
                [None, Some(a)]
            } else {
                [Some(b), None]
            };
        }
    }
    spans
        .iter()
        .enumerate()
        .map(|(i, s)| {
            let pinned =
                all || s.disjoint || s.inf_sharp_edges > 0 || (s.size == 1 && corners_sharp);
            if pinned {
                SHARPNESS_INFINITE
            } else {
                let dep = depends_on.get(i).copied().flatten().unwrap_or(0.0);
                vertex_sharpness.max(dep)
            }
        })
        .collect()
}

/// Builds the value mesh (see the module documentation).
fn value_mesh(
    mesh: &ControlMesh,
    scheme: Scheme,
    mode: FVarLinearInterpolation,
) -> Result<ValueMesh, TopologyError> {
    let uvs = mesh.uvs.as_deref().unwrap_or_default();
    let level = LevelTopology::from_mesh(mesh, scheme)?;
    let topo = &level.topology;
    let corner_face = corner_faces(&topo.face_offsets, topo.face_verts.len());
    let keys = corner_keys(mesh, uvs);
    let key = |c: usize| keys[c];
    let mut corner_value = vec![INVALID; topo.face_verts.len()];
    let mut positions = Vec::new();
    let mut vertex_of = Vec::new();
    let mut corners = Vec::new();
    let geometric_corners = mesh.options.boundary == BoundaryInterpolation::EdgesAndCorners;
    for v in 0..topo.num_vertices() as u32 {
        let fan = fan(topo, &corner_face, v);
        if fan.is_empty() {
            continue;
        }
        let (span_of, spans, any_seam) = spans_of(topo, &level, &corner_face, &key, &fan);
        let boundary = fan.last().is_some_and(|&(_, e)| e == INVALID);
        let vs = level.vertex_sharpness[v as usize];
        // OpenSubdiv's "mismatch": a discontinuity at the vertex, or a boundary the mode
        // makes linear, or a layout corner the mode pins where the mesh's corner is smooth.
        let linear_boundaries = matches!(
            mode,
            FVarLinearInterpolation::Boundaries | FVarLinearInterpolation::All
        );
        let pinned_corner =
            fan.len() == 1 && mode != FVarLinearInterpolation::None && !geometric_corners;
        let mismatch = any_seam || (boundary && linear_boundaries) || pinned_corner;
        let sharpness = if mismatch {
            span_sharpness(mode, &spans, vs, boundary)
        } else {
            vec![vs; spans.len()]
        };
        let first = positions.len() as u32;
        for s in 0..spans.len() {
            let c = fan[span_of.iter().position(|&x| x == s).unwrap_or(0)].0;
            let [u, w] = uvs[c];
            positions.push([u, w, 0.0]);
            vertex_of.push(v);
            if sharpness[s] > 0.0 {
                corners.push(VertexCorner {
                    vertex: first + s as u32,
                    sharpness: sharpness[s],
                });
            }
        }
        for (i, &(c, _)) in fan.iter().enumerate() {
            corner_value[c] = first + span_of[i] as u32;
        }
    }
    let creases = value_creases(mesh, topo, &corner_face, &corner_value, &level);
    let holes = mesh.holes.clone();
    let mut options = mesh.options;
    options.boundary = BoundaryInterpolation::EdgesOnly;
    options.fvar_interpolation = FVarLinearInterpolation::All;
    let out = ControlMesh {
        positions,
        face_offsets: topo.face_offsets.clone(),
        face_vertices: corner_value,
        creases,
        corners,
        holes,
        options,
        ..ControlMesh::default()
    };
    out.validate()?;
    Ok(ValueMesh {
        mesh: out,
        vertex_of,
    })
}

/// The mesh's creases on the value mesh: every value-mesh edge over a creased edge gets its
/// sharpness (on a seam both boundary edges; they are infinitely sharp anyway).
fn value_creases(
    mesh: &ControlMesh,
    topo: &Topology,
    corner_face: &[u32],
    corner_value: &[u32],
    level: &LevelTopology,
) -> Vec<EdgeCrease> {
    if mesh.creases.is_empty() {
        return Vec::new();
    }
    let mut seen: HashMap<(u32, u32), ()> = HashMap::new();
    let mut out = Vec::new();
    for c in 0..topo.face_verts.len() {
        let e = topo.face_edges[c] as usize;
        let s = level.edge_sharpness[e];
        if s <= 0.0 || topo.is_boundary_edge(e) {
            continue;
        }
        let (next, _) = next_prev(topo, corner_face, c);
        let (a, b) = (corner_value[c], corner_value[next]);
        if seen.insert((a.min(b), a.max(b)), ()).is_none() {
            out.push(EdgeCrease {
                vertices: [a, b],
                sharpness: s,
            });
        }
    }
    out
}
