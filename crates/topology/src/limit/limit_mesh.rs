//! A control mesh refined uniformly on the CPU to level k and placed on its limit surface: the
//! mesh a CPU application would draw (M^k on the limit, the baseline of the papers' benchmarks),
//! and for each of its vertices the point of the base mesh it lies at.
//!
//! Steps, each a function:
//! 1. [`uniform_limit_mesh`] refines with the one refiner ([`refine_level`]) and moves every
//!    vertex to its limit position: by the limit masks read straight off the level
//!    ([`mask_limit_positions`], Loop, what a CPU application does), else through the exact
//!    evaluator ([`evaluator_limit_positions`], next to semi-sharp features and for
//!    Catmull-Clark);
//! 2. normals are angle-weighted over the limit positions ([`angle_weighted_normals`]);
//! 3. faces are fan-triangulated into the triangle list;
//! 4. [`level_domain_points`] follows every face corner's domain point down the levels: a
//!    child vertex of a face sits at its parent vertex's point, at the midpoint of its parent
//!    edge's two points, or at the mean of its parent face's corners, all in the base face's own
//!    frame. Under the face domains of this crate (bilinear maps of each quad, linear maps of
//!    each triangle), these averages are exactly the refined vertex's parameter, so the limit
//!    position of vertex `v` is the limit surface at `domains[v]`.
//!
//! Level sizes are known before refining ([`loop_level_size`], [`catmark_level_size`]), so a
//! caller can refuse a level that would not fit.
use crate::error::TopologyError;
use crate::limit::eval::{EvalError, LimitScheme, LocalMesh};
use crate::limit::masks::{dart_position_weights, loop_limit_masks, LimitRule, LimitVertex};
use crate::mesh::{ControlMesh, Topology};
use crate::refine::{refine_level, Level};
use crate::rules::options::SubdivOptions;
use crate::rules::{is_infinite, is_semi_sharp, Scheme};

/// Why a limit mesh could not be made.
#[derive(Debug, thiserror::Error)]
pub enum LimitMeshError {
    #[error(transparent)]
    Topology(#[from] TopologyError),
    #[error("{scheme} level {level}: {source}")]
    Eval {
        scheme: Scheme,
        level: usize,
        source: EvalError,
    },
    #[error("{scheme} has no uniform limit mesh here (loop, catmull-clark or bilinear)")]
    Scheme { scheme: Scheme },
}

/// A point of the base mesh: base face and its (u, v) in the caller's face-domain convention.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DomainPoint {
    pub face: u32,
    pub uv: [f64; 2],
}

/// The refined mesh on its limit surface.
#[derive(Clone, Debug, Default)]
pub struct LimitMesh {
    pub positions: Vec<[f64; 3]>,
    pub normals: Vec<[f64; 3]>,
    /// Counter-clockwise as the faces were, fan-triangulated from each face's first corner.
    pub triangles: Vec<[u32; 3]>,
    /// Per vertex, where it lies on the base mesh (`None` for a vertex no face uses).
    pub domains: Vec<Option<DomainPoint>>,
}

/// Uniform refinement of `mesh` to `level` with `scheme`, every vertex on the limit surface
/// (bilinear: the refined mesh itself, which is its own limit). `base_corners` gives the domain
/// point of every face corner of `mesh` (in face-vertex order), which the levels below inherit.
pub fn uniform_limit_mesh(
    mesh: &ControlMesh,
    scheme: Scheme,
    level: usize,
    base_corners: &[DomainPoint],
) -> Result<LimitMesh, LimitMeshError> {
    if !matches!(
        scheme,
        Scheme::Loop | Scheme::CatmullClark | Scheme::Bilinear
    ) {
        return Err(LimitMeshError::Scheme { scheme });
    }
    let mut levels = vec![Level::from_mesh(mesh, scheme)?];
    for _ in 0..level {
        let next = refine_level(levels.last().expect("base level"), scheme, &mesh.options)?.0;
        levels.push(next);
    }
    let current = levels.last().expect("base level");
    let positions = limit_positions(current, level, &mesh.options, scheme)?;
    let (offsets, corners) = current.topology.face_tables();
    let normals = angle_weighted_normals(&positions, offsets, corners);
    let topologies: Vec<&Topology> = levels.iter().map(|l| &l.topology).collect();
    let drawn = drawn_faces(&topologies, scheme, &mesh.holes);
    Ok(LimitMesh {
        domains: level_domain_points(&topologies, scheme, base_corners),
        triangles: fan_triangles_of(offsets, corners, &drawn),
        positions,
        normals,
    })
}

/// Doo-Sabin refinement of `mesh` to `level` on the CPU, the vertices where the refinement puts
/// them (not on the limit: the seed's CPU baseline refines, as its GPU vertex patches do), with
/// angle-weighted normals, fan triangles, and each vertex's point on the base mesh
/// ([`doo_sabin_domain_points`]).
pub fn doo_sabin_level_mesh(mesh: &ControlMesh, level: usize) -> Result<LimitMesh, LimitMeshError> {
    let refinement = doo_sabin_refinement(mesh, level)?;
    let current = refinement.level(level);
    let (offsets, corners) = current.topology.face_tables();
    let positions = current.positions.clone();
    let normals = angle_weighted_normals(&positions, offsets, corners);
    Ok(LimitMesh {
        domains: domain_points_of(mesh, &refinement, level),
        triangles: fan_triangles(offsets, corners),
        positions,
        normals,
    })
}

/// Where each vertex of `mesh`'s Doo-Sabin level `level` lies on the base mesh: where its limit
/// lies ([`crate::limit::doo_sabin_domain`]), in [`crate::limit::face_domain`]'s face domains (a
/// corner quad `(u, v)` mapped bilinearly onto its sub-quad of the face); `None` for a vertex
/// of no face.
///
/// Except boundary points, which map onto their corner's base vertex: a refined boundary edge
/// of a dual scheme cuts the corner of a base boundary vertex, from one base edge to the next,
/// so only there do both its ends lie on one base edge (what a capture's classification of
/// open edges asks of a boundary edge).
pub fn doo_sabin_domain_points(
    mesh: &ControlMesh,
    level: usize,
) -> Result<Vec<Option<DomainPoint>>, LimitMeshError> {
    let refinement = doo_sabin_refinement(mesh, level)?;
    Ok(domain_points_of(mesh, &refinement, level))
}

fn doo_sabin_refinement(
    mesh: &ControlMesh,
    level: usize,
) -> Result<crate::limit::doo_sabin_domain::DomainRefinement, LimitMeshError> {
    crate::limit::doo_sabin_domain::DomainRefinement::new(mesh, level).map_err(|source| {
        LimitMeshError::Eval {
            scheme: Scheme::DooSabin,
            level,
            source,
        }
    })
}

/// [`doo_sabin_domain_points`] of a refinement already made.
fn domain_points_of(
    mesh: &ControlMesh,
    refinement: &crate::limit::doo_sabin_domain::DomainRefinement,
    level: usize,
) -> Vec<Option<DomainPoint>> {
    let boundary = refinement.boundary_points(level);
    (0..refinement.level(level).num_vertices())
        .map(|x| {
            let mut d = refinement.vertex_point(level, x)?;
            if boundary.get(x).copied().unwrap_or(false) {
                d.uv = [0.0, 0.0];
            }
            let n = mesh.face(d.face as usize).len() as u32;
            let q = crate::limit::face_domain::subface_domain(n, d.corner);
            let uv = crate::limit::face_domain::bilinear(&q, d.uv[0], d.uv[1]);
            Some(DomainPoint { face: d.face, uv })
        })
        .collect()
}

/// Limit positions of every vertex of `current` (refined `level` times).
fn limit_positions(
    current: &Level,
    level: usize,
    options: &SubdivOptions,
    scheme: Scheme,
) -> Result<Vec<[f64; 3]>, LimitMeshError> {
    match scheme {
        Scheme::Bilinear => Ok(current.positions.clone()),
        Scheme::Loop => match mask_limit_positions(current) {
            Some(p) => Ok(p),
            None => evaluator_limit_positions(current, level, options, LimitScheme::Loop),
        },
        _ => evaluator_limit_positions(current, level, options, LimitScheme::CatmullClark),
    }
}

/// Every face of `offsets`/`corners` as a fan of triangles from its first corner.
fn fan_triangles(offsets: &[u32], corners: &[u32]) -> Vec<[u32; 3]> {
    fan_triangles_of(
        offsets,
        corners,
        &vec![true; offsets.len().saturating_sub(1)],
    )
}

/// [`fan_triangles`] of the faces marked `drawn`.
fn fan_triangles_of(offsets: &[u32], corners: &[u32], drawn: &[bool]) -> Vec<[u32; 3]> {
    let mut out = Vec::with_capacity(corners.len());
    for (w, _) in offsets.windows(2).zip(drawn).filter(|(_, &d)| d) {
        let f = &corners[w[0] as usize..w[1] as usize];
        for k in 1..f.len().saturating_sub(1) {
            out.push([f[0], f[k], f[k + 1]]);
        }
    }
    out
}

/// Per face of the last of `levels` (uniform refinements of the first by `scheme`), whether
/// it is drawn: whether the base face it refines is not among `holes`. A uniform step keeps a
/// face's children together: Catmull-Clark's child face `c` is the parent's face corner `c`,
/// Loop's children of face `f` are `4f..4f + 4`.
fn drawn_faces(levels: &[&Topology], scheme: Scheme, holes: &[u32]) -> Vec<bool> {
    let mut drawn = vec![true; levels[0].num_faces()];
    for &h in holes {
        if let Some(d) = drawn.get_mut(h as usize) {
            *d = false;
        }
    }
    for parent in &levels[..levels.len() - 1] {
        drawn = match scheme {
            Scheme::Loop => drawn.iter().flat_map(|&d| [d; 4]).collect(),
            _ => {
                let (offsets, _) = parent.face_tables();
                (0..parent.num_faces())
                    .flat_map(|f| {
                        std::iter::repeat_n(drawn[f], (offsets[f + 1] - offsets[f]) as usize)
                    })
                    .collect()
            }
        };
    }
    drawn
}

/// The domain point of every vertex of the last of `levels` (uniform refinements of the first,
/// by `scheme`), following each face corner down from `base_corners` (see the module docs).
/// A vertex takes the point of the first face corner that uses it.
pub fn level_domain_points(
    levels: &[&Topology],
    scheme: Scheme,
    base_corners: &[DomainPoint],
) -> Vec<Option<DomainPoint>> {
    let mut corners = base_corners.to_vec();
    for pair in levels.windows(2) {
        corners = child_corner_points(pair[0], pair[1], scheme, &corners);
    }
    let Some(last) = levels.last() else {
        return Vec::new();
    };
    let mut out = vec![None; last.num_vertices()];
    let (_, verts) = last.face_tables();
    for (&v, &d) in verts.iter().zip(&corners) {
        out[v as usize].get_or_insert(d);
    }
    out
}

/// Face-corner domain points of `child` (one uniform step of `parent`) from those of `parent`.
/// Children of a parent face are consecutive: `n` quads (Catmull-Clark, bilinear) or four
/// triangles (Loop).
fn child_corner_points(
    parent: &Topology,
    child: &Topology,
    scheme: Scheme,
    parent_corners: &[DomainPoint],
) -> Vec<DomainPoint> {
    let (nv, ne) = (parent.num_vertices() as u32, parent.num_edges() as u32);
    let (p_offsets, p_verts) = parent.face_tables();
    let (_, c_verts) = child.face_tables();
    let mut out = Vec::with_capacity(c_verts.len());
    let mut child_face = 0usize;
    for f in 0..parent.num_faces() {
        let range = p_offsets[f] as usize..p_offsets[f + 1] as usize;
        let (fverts, fdoms) = (&p_verts[range.clone()], &parent_corners[range]);
        let at = |v: u32| fdoms[fverts.iter().position(|&x| x == v).unwrap_or(0)].uv;
        let children = if scheme == Scheme::Loop {
            4
        } else {
            fverts.len()
        };
        for _ in 0..children {
            for &cv in child.face_vertices(child_face) {
                let uv = if cv < nv {
                    at(cv)
                } else if cv < nv + ne {
                    let [a, b] = parent.edge_vertices((cv - nv) as usize);
                    mean(&[at(a), at(b)])
                } else {
                    mean(&fdoms.iter().map(|d| d.uv).collect::<Vec<_>>())
                };
                out.push(DomainPoint {
                    face: fdoms.first().map_or(0, |d| d.face),
                    uv,
                });
            }
            child_face += 1;
        }
    }
    out
}

fn mean(points: &[[f64; 2]]) -> [f64; 2] {
    let n = points.len().max(1) as f64;
    let s = points
        .iter()
        .fold([0.0, 0.0], |s, p| [s[0] + p[0], s[1] + p[1]]);
    [s[0] / n, s[1] / n]
}

/// Vertices, edges and faces of a closed or open triangle mesh after `level` Loop steps:
/// V' = V + E, E' = 2E + 3F, F' = 4F. Known before refining, to skip levels that would not fit.
pub fn loop_level_size(mesh: &ControlMesh, level: usize) -> (u64, u64, u64) {
    let (mut v, mut e, mut f) = (
        mesh.positions.len() as u64,
        edge_count(mesh),
        mesh.num_faces() as u64,
    );
    for _ in 0..level {
        (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
    }
    (v, e, f)
}

/// Vertices, edges and faces after `level` Catmull-Clark (or bilinear) steps:
/// V' = V + E + F, E' = 2E + (face corners), F' = face corners.
pub fn catmark_level_size(mesh: &ControlMesh, level: usize) -> (u64, u64, u64) {
    let (mut v, mut e, mut f) = (
        mesh.positions.len() as u64,
        edge_count(mesh),
        mesh.num_faces() as u64,
    );
    let mut corners = mesh.faces().map(|f| f.len() as u64).sum::<u64>();
    for _ in 0..level {
        (v, e, f) = (v + e + f, 2 * e + corners, corners);
        corners = 4 * f;
    }
    (v, e, f)
}

fn edge_count(mesh: &ControlMesh) -> u64 {
    let mut edges = std::collections::HashSet::new();
    for f in mesh.faces() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    edges.len() as u64
}

/// The edge-neighbours of interior vertex `v` in cyclic order (either way round) from `first`,
/// walking its triangles; `None` if they do not close into one cycle.
fn cyclic_ring(t: &Topology, v: usize, first: u32) -> Option<Vec<u32>> {
    let faces = t.vertex_faces(v);
    let (vv, mut prev) = (v as u32, u32::MAX);
    let mut ring = vec![first];
    loop {
        let cur = *ring.last()?;
        let f = faces.iter().copied().find(|&f| {
            let fv = t.face_vertices(f as usize);
            f != prev && fv.contains(&vv) && fv.contains(&cur)
        })?;
        let next = t
            .face_vertices(f as usize)
            .iter()
            .copied()
            .find(|&x| x != vv && x != cur)?;
        prev = f;
        if next == first {
            break;
        }
        ring.push(next);
        if ring.len() > faces.len() {
            return None;
        }
    }
    (ring.len() == t.vertex_edges(v).len() && ring.len() == faces.len()).then_some(ring)
}

/// Limit positions of every vertex of a Loop level by the limit masks of
/// [`loop_limit_masks`], read straight off the level's edge lists and sharpness: what a CPU
/// application does, without building an evaluator. `None` when a semi-sharp feature is left
/// (its vertices need more refinement first).
pub fn mask_limit_positions(level: &Level) -> Option<Vec<[f64; 3]>> {
    let t = &level.topology;
    // Smooth weights (vertex, each neighbour) depend on the valence only.
    let mut smooth: std::collections::HashMap<usize, (f64, f64)> = Default::default();
    let mut out = Vec::with_capacity(level.num_vertices());
    for v in 0..level.num_vertices() {
        // A vertex no face uses has no surface: it keeps its position (as in OpenSubdiv).
        if t.vertex_faces(v).is_empty() {
            out.push(level.positions[v]);
            continue;
        }
        let vs = level.vertex_sharpness[v];
        if is_semi_sharp(vs) {
            return None;
        }
        let mut sharp = Vec::with_capacity(2);
        for &e in t.vertex_edges(v) {
            let s = level.edge_sharpness[e as usize];
            if is_semi_sharp(s) {
                return None;
            }
            if is_infinite(s) {
                let [a, b] = t.edge_vertices(e as usize);
                sharp.push(if a as usize == v { b } else { a });
            }
        }
        let q = if is_infinite(vs) || sharp.len() > 2 {
            level.positions[v]
        } else if sharp.len() == 2 {
            crease_limit(level, v, [sharp[0], sharp[1]])
        } else if sharp.len() == 1 {
            dart_limit(level, v, sharp[0])?
        } else {
            smooth_limit(level, v, &mut smooth)
        };
        out.push(q);
    }
    Some(out)
}

/// A crease vertex (boundaries included): only the two crease neighbours weigh.
fn crease_limit(level: &Level, v: usize, ends: [u32; 2]) -> [f64; 3] {
    let m = loop_limit_masks(&LimitVertex {
        valence: 2,
        boundary: false,
        rule: LimitRule::Crease { ends: [0, 1] },
    });
    let w = &m.position;
    let (p, a, b) = (
        level.positions[v],
        level.positions[ends[0] as usize],
        level.positions[ends[1] as usize],
    );
    std::array::from_fn(|k| w.vertex * p[k] + w.edges[0] * a[k] + w.edges[1] * b[k])
}

/// A dart: its own mask ([`dart_position_weights`]) over the ring in cyclic order from the
/// sharp edge; `None` for a ring that cannot be walked (the evaluator's path then).
fn dart_limit(level: &Level, v: usize, sharp: u32) -> Option<[f64; 3]> {
    let ring = cyclic_ring(&level.topology, v, sharp)?;
    let w = dart_position_weights(true, ring.len());
    let mut q = level.positions[v].map(|c| w[0] * c);
    for (j, &x) in ring.iter().enumerate() {
        let r = level.positions[x as usize];
        for k in 0..3 {
            q[k] += w[1 + j] * r[k];
        }
    }
    Some(q)
}

/// A smooth vertex: the valence's mask over its edge neighbours.
fn smooth_limit(
    level: &Level,
    v: usize,
    cache: &mut std::collections::HashMap<usize, (f64, f64)>,
) -> [f64; 3] {
    let t = &level.topology;
    let edges = t.vertex_edges(v);
    let (wv, we) = *cache.entry(edges.len()).or_insert_with(|| {
        let m = loop_limit_masks(&LimitVertex {
            valence: edges.len(),
            boundary: false,
            rule: LimitRule::Smooth,
        });
        (
            m.position.vertex,
            m.position.edges.first().copied().unwrap_or(0.0),
        )
    });
    let mut q = level.positions[v].map(|c| wv * c);
    for &e in edges {
        let [a, b] = t.edge_vertices(e as usize);
        let w = level.positions[if a as usize == v { b } else { a } as usize];
        for k in 0..3 {
            q[k] += we * w[k];
        }
    }
    q
}

/// Limit positions through the general evaluator ([`LocalMesh::vertex_limit_exact`]: masks,
/// or exact evaluation next to semi-sharp features), for levels [`mask_limit_positions`]
/// declines.
pub fn evaluator_limit_positions(
    current: &Level,
    level: usize,
    options: &SubdivOptions,
    scheme: LimitScheme,
) -> Result<Vec<[f64; 3]>, LimitMeshError> {
    let err = |source| LimitMeshError::Eval {
        scheme: scheme.scheme(),
        level,
        source,
    };
    let local = LocalMesh::from_refined_level(current, scheme, options).map_err(err)?;
    (0..current.num_vertices())
        .map(|v| {
            // A vertex no face uses has no surface: it keeps its position (as in OpenSubdiv).
            if current.topology.vertex_faces(v).is_empty() {
                return Ok(current.positions[v]);
            }
            let p = local.vertex_limit_exact(v as u32).map_err(err)?;
            Ok([p[0], p[1], p[2]])
        })
        .collect()
}

/// Per-vertex normals: each face's Newell normal weighted by the corner angle, summed and
/// normalized (`[0, 0, 1]` for a vertex with no proper face).
pub fn angle_weighted_normals(
    positions: &[[f64; 3]],
    face_offsets: &[u32],
    corners: &[u32],
) -> Vec<[f64; 3]> {
    let mut acc = vec![[0.0f64; 3]; positions.len()];
    for f in 0..face_offsets.len().saturating_sub(1) {
        let face = &corners[face_offsets[f] as usize..face_offsets[f + 1] as usize];
        let Some(n) = normalize(newell_normal(positions, face)) else {
            continue;
        };
        for i in 0..face.len() {
            let v = face[i] as usize;
            let prev = positions[face[(i + face.len() - 1) % face.len()] as usize];
            let next = positions[face[(i + 1) % face.len()] as usize];
            let (Some(e0), Some(e1)) = (
                normalize(sub(prev, positions[v])),
                normalize(sub(next, positions[v])),
            ) else {
                continue;
            };
            let angle = dot(e0, e1).clamp(-1.0, 1.0).acos();
            for k in 0..3 {
                acc[v][k] += angle * n[k];
            }
        }
    }
    acc.into_iter()
        .map(|n| normalize(n).unwrap_or([0.0, 0.0, 1.0]))
        .collect()
}

/// Newell's method: robust for non-planar polygons.
fn newell_normal(positions: &[[f64; 3]], face: &[u32]) -> [f64; 3] {
    let mut n = [0.0; 3];
    for i in 0..face.len() {
        let a = positions[face[i] as usize];
        let b = positions[face[(i + 1) % face.len()] as usize];
        n[0] += (a[1] - b[1]) * (a[2] + b[2]);
        n[1] += (a[2] - b[2]) * (a[0] + b[0]);
        n[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    n
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(v: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(v, v).sqrt();
    (l > 0.0 && l.is_finite()).then(|| [v[0] / l, v[1] / l, v[2] / l])
}
