//! Uniform refinement for Catmull-Clark, Loop, bilinear and Doo-Sabin with OpenSubdiv's
//! semi-sharp crease, corner and boundary rules.
//!
//! Each step produces the child topology, the child sharpness values and one stencil per child
//! vertex over the parent vertices. Composing the steps gives stencils over the base vertices.
//!
//! Child vertex numbering (all schemes but Doo-Sabin): first one vertex-vertex per parent vertex
//! (same index as its parent, so base indices persist), then one edge-vertex per parent edge,
//! then (Catmull-Clark, bilinear) one face-vertex per parent face. Doo-Sabin makes one child
//! vertex per parent face corner.

use crate::error::TopologyError;
use crate::mesh::{
    BoundaryInterpolation, ControlMesh, SubdivOptions, Topology, TriangleSubdivision, INVALID,
};
use crate::sdc::{
    decrement_sharpness, fractional_weight, is_sharp, subdivide_edge_sharpness_at_vertex,
    vertex_rule, Rule, Scheme, SHARPNESS_INFINITE,
};
use crate::stencil::{build_rows, StencilTable};
use rayon::prelude::*;

/// One level of a refinement: topology, positions and (propagated) sharpness.
#[derive(Clone, Debug)]
pub struct Level {
    pub topology: Topology,
    pub positions: Vec<[f64; 3]>,
    /// Per edge (numbered as in `topology`); boundary edges are infinitely sharp.
    pub edge_sharpness: Vec<f32>,
    /// Per vertex; with [`BoundaryInterpolation::EdgesAndCorners`] corners are infinitely sharp.
    pub vertex_sharpness: Vec<f32>,
}

impl Level {
    /// Face offsets (len faces + 1) of this level.
    pub fn face_offsets(&self) -> &[u32] {
        self.topology.face_tables().0
    }
    /// Face corner vertex indices of this level.
    pub fn face_vertices(&self) -> &[u32] {
        self.topology.face_tables().1
    }
    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.topology.num_faces()
    }
    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.topology.num_vertices()
    }

    /// Base level of `mesh`: validated topology plus sharpness from tags and boundary rules.
    pub fn from_mesh(mesh: &ControlMesh, scheme: Scheme) -> Result<Level, TopologyError> {
        let topology = Topology::from_mesh(mesh)?;
        if scheme == Scheme::Loop {
            if let Some(f) =
                (0..topology.num_faces()).find(|&f| topology.face_vertices(f).len() != 3)
            {
                return Err(TopologyError::LoopRequiresTriangles {
                    face: f,
                    size: topology.face_vertices(f).len(),
                });
            }
        }
        let nv = topology.num_vertices();
        let mut edge_sharpness = vec![0.0f32; topology.num_edges()];
        for c in &mesh.creases {
            let [a, b] = c.vertices;
            if a as usize >= nv || b as usize >= nv {
                return Err(TopologyError::InvalidTag {
                    message: format!("crease names vertex {}, mesh has {nv} vertices", a.max(b)),
                });
            }
            match topology.find_edge(a, b) {
                Some(e) => edge_sharpness[e as usize] = c.sharpness.max(0.0),
                None => log::warn!("crease tag on {a}-{b}, which is not an edge: ignored"),
            }
        }
        let mut vertex_sharpness = vec![0.0f32; nv];
        for c in &mesh.corners {
            if c.vertex as usize >= nv {
                return Err(TopologyError::InvalidTag {
                    message: format!("corner names vertex {}, mesh has {nv} vertices", c.vertex),
                });
            }
            vertex_sharpness[c.vertex as usize] = c.sharpness.max(0.0);
        }
        // Boundary edges are always infinitely sharp (OpenSubdiv does this for every rule).
        for (e, s) in edge_sharpness.iter_mut().enumerate() {
            if topology.is_boundary_edge(e) {
                *s = SHARPNESS_INFINITE;
            }
        }
        if mesh.options.boundary == BoundaryInterpolation::EdgesAndCorners {
            for (v, s) in vertex_sharpness.iter_mut().enumerate() {
                if topology.vertex_faces(v).len() == 1 && topology.vertex_edges(v).len() == 2 {
                    *s = SHARPNESS_INFINITE;
                }
            }
        }
        Ok(Level {
            topology,
            positions: mesh.positions.clone(),
            edge_sharpness,
            vertex_sharpness,
        })
    }
}

/// Result of [`refine_uniform`]: every level from the base (index 0) to the requested one,
/// and the per-step stencils.
#[derive(Clone, Debug)]
pub struct UniformRefinement {
    scheme: Scheme,
    options: SubdivOptions,
    levels: Vec<Level>,
    steps: Vec<StencilTable>,
}

impl UniformRefinement {
    /// The scheme used.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }
    /// The options (boundary rule, crease method, triangle rule) used.
    pub fn options(&self) -> SubdivOptions {
        self.options
    }
    /// The deepest level refined.
    pub fn max_level(&self) -> usize {
        self.levels.len() - 1
    }
    /// Level `k` (0 is the base mesh).
    pub fn level(&self, k: usize) -> &Level {
        &self.levels[k]
    }
    /// All levels, base first.
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }
    /// Stencils of level `k` (k ≥ 1) over the vertices of level `k - 1`.
    pub fn step_stencils(&self, k: usize) -> &StencilTable {
        &self.steps[k - 1]
    }
    /// Stencils of level `k` over the base (control) vertices; level 0 gives the identity.
    pub fn stencils(&self, k: usize) -> StencilTable {
        if k == 0 {
            return StencilTable::identity(self.levels[0].num_vertices());
        }
        let mut table = self.steps[0].clone();
        for step in &self.steps[1..k] {
            table = step.compose(&table);
        }
        table
    }
}

/// Refine `mesh` uniformly `level` times with `scheme`, honouring its creases, corners and
/// options.
pub fn refine_uniform(
    mesh: &ControlMesh,
    scheme: Scheme,
    level: usize,
) -> Result<UniformRefinement, TopologyError> {
    let base = Level::from_mesh(mesh, scheme)?;
    let mut levels = vec![base];
    let mut steps = Vec::with_capacity(level);
    for _ in 0..level {
        let parent = levels.last().expect("base level present");
        let (child, step) = refine_level(parent, scheme, &mesh.options)?;
        levels.push(child);
        steps.push(step);
    }
    Ok(UniformRefinement {
        scheme,
        options: mesh.options,
        levels,
        steps,
    })
}

/// Stencils of the level-`level` vertices over the control vertices of `mesh`.
pub fn uniform_stencils(
    mesh: &ControlMesh,
    scheme: Scheme,
    level: usize,
) -> Result<StencilTable, TopologyError> {
    Ok(refine_uniform(mesh, scheme, level)?.stencils(level))
}

/// One uniform refinement step: child level and its stencils over the parent vertices.
pub fn refine_level(
    parent: &Level,
    scheme: Scheme,
    options: &SubdivOptions,
) -> Result<(Level, StencilTable), TopologyError> {
    let p = &parent.topology;
    let corners = p.face_verts.len();
    let max_children = match scheme {
        Scheme::Loop => p.num_vertices() + p.num_edges() * 4,
        _ => p.num_vertices() + p.num_edges() * 3 + corners * 4,
    };
    if max_children >= (INVALID / 2) as usize {
        return Err(TopologyError::TooLarge {
            what: format!(
                "refining {} faces would overflow 32-bit indices",
                p.num_faces()
            ),
        });
    }
    if scheme == Scheme::DooSabin {
        return refine_doo_sabin(parent);
    }
    let (topology, child_edge_sharpness) = match scheme {
        Scheme::Loop => split_triangles(parent, options),
        _ => split_quads(parent, options),
    };
    let nv = p.num_vertices();
    let mut vertex_sharpness = vec![0.0f32; topology.num_vertices()];
    for (c, &s) in vertex_sharpness.iter_mut().zip(&parent.vertex_sharpness) {
        *c = decrement_sharpness(s);
    }
    let ctx = MaskContext {
        parent,
        scheme,
        options,
        child_edge_sharpness: &child_edge_sharpness,
        child_vertex_sharpness: &vertex_sharpness[..nv],
    };
    let step = build_rows(
        topology.num_vertices(),
        nv,
        || (),
        |_, i, out| ctx.row(i, out),
    );
    let positions = step.apply(&parent.positions);
    Ok((
        Level {
            topology,
            positions,
            edge_sharpness: child_edge_sharpness,
            vertex_sharpness,
        },
        step,
    ))
}

/// Child edge index of parent edge `e` at its end vertex `v`.
#[inline]
fn child_edge_at(p: &Topology, e: u32, v: u32) -> u32 {
    2 * e + u32::from(p.edge_verts[e as usize][0] != v)
}

/// Sharpness of the two children of every parent edge (child `2e` at end 0, `2e + 1` at end 1),
/// followed by smooth interior edges (`extra` of them).
fn child_edge_sharpness(parent: &Level, options: &SubdivOptions, extra: usize) -> Vec<f32> {
    let p = &parent.topology;
    let mut out = vec![0.0f32; 2 * p.num_edges() + extra];
    out[..2 * p.num_edges()]
        .par_chunks_mut(2)
        .enumerate()
        .for_each(|(e, pair)| {
            let s = parent.edge_sharpness[e];
            if !is_sharp(s) {
                return;
            }
            for (k, slot) in pair.iter_mut().enumerate() {
                let v = p.edge_verts[e][k] as usize;
                let incident: Vec<f32> = p
                    .vertex_edges(v)
                    .iter()
                    .map(|&x| parent.edge_sharpness[x as usize])
                    .collect();
                *slot = subdivide_edge_sharpness_at_vertex(options.crease_method, s, &incident);
            }
        });
    out
}

/// Catmull-Clark / bilinear split: face `f` with n corners → n quads (one per corner).
fn split_quads(parent: &Level, options: &SubdivOptions) -> (Topology, Vec<f32>) {
    let p = &parent.topology;
    let (nv, ne, nf) = (p.num_vertices(), p.num_edges(), p.num_faces());
    let corners = p.face_verts.len();
    let vert_e = |e: u32| (nv as u32) + e;
    let vert_f = |f: u32| (nv + ne) as u32 + f;
    let face_edge = |c: usize| (2 * ne + c) as u32;

    let mut edge_verts = Vec::with_capacity(2 * ne + corners);
    for (e, &[a, b]) in p.edge_verts.iter().enumerate() {
        edge_verts.push([a, vert_e(e as u32)]);
        edge_verts.push([vert_e(e as u32), b]);
    }
    let mut face_verts = vec![0u32; 4 * corners];
    let mut face_edges = vec![0u32; 4 * corners];
    for f in 0..nf {
        let s = p.face_offsets[f] as usize;
        let fv = p.face_vertices(f);
        let fe = p.face_edge_list(f);
        let n = fv.len();
        for i in 0..n {
            let prev = (i + n - 1) % n;
            edge_verts.push([vert_e(fe[i]), vert_f(f as u32)]);
            let c = 4 * (s + i);
            face_verts[c..c + 4].copy_from_slice(&[
                fv[i],
                vert_e(fe[i]),
                vert_f(f as u32),
                vert_e(fe[prev]),
            ]);
            face_edges[c..c + 4].copy_from_slice(&[
                child_edge_at(p, fe[i], fv[i]),
                face_edge(s + i),
                face_edge(s + prev),
                child_edge_at(p, fe[prev], fv[i]),
            ]);
        }
    }
    let face_offsets: Vec<u32> = (0..=corners as u32).map(|i| 4 * i).collect();
    let sharp = child_edge_sharpness(parent, options, corners);
    let topo = Topology::from_parts(
        nv + ne + nf,
        face_offsets,
        face_verts,
        face_edges,
        edge_verts,
    );
    (topo, sharp)
}

/// Loop split: each triangle → three corner triangles and a middle one.
fn split_triangles(parent: &Level, options: &SubdivOptions) -> (Topology, Vec<f32>) {
    let p = &parent.topology;
    let (nv, ne, nf) = (p.num_vertices(), p.num_edges(), p.num_faces());
    let vert_e = |e: u32| (nv as u32) + e;
    let inner = |f: usize, j: usize| (2 * ne + 3 * f + j) as u32;

    let mut edge_verts = Vec::with_capacity(2 * ne + 3 * nf);
    for (e, &[a, b]) in p.edge_verts.iter().enumerate() {
        edge_verts.push([a, vert_e(e as u32)]);
        edge_verts.push([vert_e(e as u32), b]);
    }
    let mut face_verts = vec![0u32; 12 * nf];
    let mut face_edges = vec![0u32; 12 * nf];
    for f in 0..nf {
        let fv = p.face_vertices(f);
        let fe = p.face_edge_list(f);
        for j in 0..3 {
            let prev = (j + 2) % 3;
            // Inner edge j joins the midpoints of the two edges at corner j.
            edge_verts.push([vert_e(fe[j]), vert_e(fe[prev])]);
            let c = 12 * f + 3 * j;
            face_verts[c..c + 3].copy_from_slice(&[fv[j], vert_e(fe[j]), vert_e(fe[prev])]);
            face_edges[c..c + 3].copy_from_slice(&[
                child_edge_at(p, fe[j], fv[j]),
                inner(f, j),
                child_edge_at(p, fe[prev], fv[j]),
            ]);
        }
        let c = 12 * f + 9;
        face_verts[c..c + 3].copy_from_slice(&[vert_e(fe[0]), vert_e(fe[1]), vert_e(fe[2])]);
        face_edges[c..c + 3].copy_from_slice(&[inner(f, 1), inner(f, 2), inner(f, 0)]);
    }
    let face_offsets: Vec<u32> = (0..=4 * nf as u32).map(|i| 3 * i).collect();
    let sharp = child_edge_sharpness(parent, options, 3 * nf);
    let topo = Topology::from_parts(nv + ne, face_offsets, face_verts, face_edges, edge_verts);
    (topo, sharp)
}

/// Everything the vertex masks need for one refinement step.
struct MaskContext<'a> {
    parent: &'a Level,
    scheme: Scheme,
    options: &'a SubdivOptions,
    child_edge_sharpness: &'a [f32],
    child_vertex_sharpness: &'a [f32],
}

impl MaskContext<'_> {
    /// Stencil row of child vertex `i` over the parent vertices.
    fn row(&self, i: usize, out: &mut Vec<(u32, f64)>) {
        let p = &self.parent.topology;
        let (nv, ne) = (p.num_vertices(), p.num_edges());
        if i < nv {
            self.vertex_vertex(i, out);
        } else if i < nv + ne {
            self.edge_vertex(i - nv, out);
        } else {
            self.face_center(i - nv - ne, 1.0, out);
        }
    }

    fn face_center(&self, f: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let fv = self.parent.topology.face_vertices(f);
        let w = scale / fv.len() as f64;
        out.extend(fv.iter().map(|&v| (v, w)));
    }

    fn edge_vertex(&self, e: usize, out: &mut Vec<(u32, f64)>) {
        let p = &self.parent.topology;
        let [a, b] = p.edge_verts[e];
        if self.scheme == Scheme::Bilinear {
            out.extend([(a, 0.5), (b, 0.5)]);
            return;
        }
        let s = self.parent.edge_sharpness[e];
        if !is_sharp(s) {
            self.smooth_edge(e, 1.0, out);
            return;
        }
        let child_is_crease = is_sharp(self.child_edge_sharpness[2 * e])
            && is_sharp(self.child_edge_sharpness[2 * e + 1]);
        if child_is_crease {
            out.extend([(a, 0.5), (b, 0.5)]);
            return;
        }
        // Crease → smooth transition: blend by the parent sharpness (as OpenSubdiv does).
        let pw = s as f64;
        self.smooth_edge(e, 1.0 - pw, out);
        out.extend([(a, 0.5 * pw), (b, 0.5 * pw)]);
    }

    fn smooth_edge(&self, e: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let p = &self.parent.topology;
        let [a, b] = p.edge_verts[e];
        let [f0, f1] = p.edge_faces[e];
        let face_pair = [f0, f1];
        let faces: &[u32] = if f1 == INVALID {
            &face_pair[..1]
        } else {
            &face_pair[..]
        };
        match self.scheme {
            Scheme::Loop => {
                let (vw, fw) = if faces.len() == 2 {
                    (0.375, 0.125)
                } else {
                    (0.375, 0.25 / faces.len() as f64)
                };
                out.extend([(a, scale * vw), (b, scale * vw)]);
                for &f in faces {
                    if let Some(&o) = p
                        .face_vertices(f as usize)
                        .iter()
                        .find(|&&x| x != a && x != b)
                    {
                        out.push((o, scale * fw));
                    }
                }
            }
            _ => {
                let tri = |f: u32| p.face_vertices(f as usize).len() == 3;
                let smooth_tris = self.options.triangle_subdivision == TriangleSubdivision::Smooth
                    && faces.len() == 2
                    && (tri(faces[0]) || tri(faces[1]));
                let (vw, fw) = if smooth_tris {
                    const TRI_EDGE_WEIGHT: f64 = 0.470;
                    let f0 = if tri(faces[0]) { TRI_EDGE_WEIGHT } else { 0.25 };
                    let f1 = if tri(faces[1]) { TRI_EDGE_WEIGHT } else { 0.25 };
                    let fw = 0.5 * (f0 + f1);
                    (0.5 * (1.0 - 2.0 * fw), fw)
                } else if faces.len() == 2 {
                    (0.25, 0.25)
                } else {
                    (0.25, 0.5 / faces.len() as f64)
                };
                out.extend([(a, scale * vw), (b, scale * vw)]);
                for &f in faces {
                    self.face_center(f as usize, scale * fw, out);
                }
            }
        }
    }

    fn vertex_vertex(&self, v: usize, out: &mut Vec<(u32, f64)>) {
        let p = &self.parent.topology;
        let edges = p.vertex_edges(v);
        if self.scheme == Scheme::Bilinear || edges.is_empty() {
            out.push((v as u32, 1.0));
            return;
        }
        let es = &self.parent.edge_sharpness;
        let pvs = self.parent.vertex_sharpness[v];
        let sharp_count = edges.iter().filter(|&&e| is_sharp(es[e as usize])).count();
        let p_rule = vertex_rule(pvs, sharp_count);
        if matches!(p_rule, Rule::Smooth | Rule::Dart) {
            self.smooth_vertex(v, 1.0, out);
            return;
        }
        let parent_edges: Vec<f32> = edges.iter().map(|&e| es[e as usize]).collect();
        let child_edges: Vec<f32> = edges
            .iter()
            .map(|&e| self.child_edge_sharpness[child_edge_at(p, e, v as u32) as usize])
            .collect();
        let cvs = self.child_vertex_sharpness[v];
        let c_rule = vertex_rule(cvs, child_edges.iter().filter(|&&s| is_sharp(s)).count());
        if c_rule == p_rule {
            self.sharp_vertex(v, p_rule, &parent_edges, 1.0, out);
            return;
        }
        let pw = fractional_weight(
            self.options.crease_method,
            pvs,
            cvs,
            &parent_edges,
            &child_edges,
        ) as f64;
        self.sharp_vertex(v, p_rule, &parent_edges, pw, out);
        match c_rule {
            Rule::Smooth | Rule::Dart => self.smooth_vertex(v, 1.0 - pw, out),
            r => self.sharp_vertex(v, r, &child_edges, 1.0 - pw, out),
        }
    }

    /// Crease (3/4, 1/8, 1/8 along the two sharp edges) or corner (the vertex itself).
    fn sharp_vertex(
        &self,
        v: usize,
        rule: Rule,
        sharpness: &[f32],
        scale: f64,
        out: &mut Vec<(u32, f64)>,
    ) {
        if rule == Rule::Crease {
            let p = &self.parent.topology;
            out.push((v as u32, 0.75 * scale));
            for (k, &e) in p.vertex_edges(v).iter().enumerate() {
                if is_sharp(sharpness[k]) {
                    out.push((other_end(p, e, v), 0.125 * scale));
                }
            }
        } else {
            out.push((v as u32, scale));
        }
    }

    fn smooth_vertex(&self, v: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let p = &self.parent.topology;
        let edges = p.vertex_edges(v);
        let n = edges.len() as f64;
        match self.scheme {
            Scheme::Loop => {
                let (vw, ew) = loop_vertex_weights(edges.len());
                out.push((v as u32, scale * vw));
                for &e in edges {
                    out.push((other_end(p, e, v), scale * ew));
                }
            }
            _ => {
                let ew = 1.0 / (n * n);
                out.push((v as u32, scale * (n - 2.0) / n));
                for &e in edges {
                    out.push((other_end(p, e, v), scale * ew));
                }
                for &f in p.vertex_faces(v) {
                    self.face_center(f as usize, scale * ew, out);
                }
            }
        }
    }
}

/// Loop's smooth vertex weights (vertex, each neighbour) for valence `n`.
fn loop_vertex_weights(n: usize) -> (f64, f64) {
    if n == 6 {
        return (0.625, 0.0625);
    }
    let inv = 1.0 / n as f64;
    let beta = 0.25 * (2.0 * std::f64::consts::PI * inv).cos() + 0.375;
    let ew = (0.625 - beta * beta) * inv;
    (1.0 - ew * n as f64, ew)
}

#[inline]
fn other_end(p: &Topology, e: u32, v: usize) -> u32 {
    let [a, b] = p.edge_verts[e as usize];
    if a as usize == v {
        b
    } else {
        a
    }
}

/// Doo-Sabin: one child vertex per face corner; faces from parent faces, interior edges and
/// interior vertices. At a boundary no face is made for boundary edges or boundary vertices,
/// so the refined mesh pulls away from the control boundary (sharpness is ignored).
fn refine_doo_sabin(parent: &Level) -> Result<(Level, StencilTable), TopologyError> {
    let p = &parent.topology;
    let corners = p.face_verts.len();
    let corner_face = {
        let mut cf = vec![0u32; corners];
        for f in 0..p.num_faces() {
            for c in p.face_offsets[f]..p.face_offsets[f + 1] {
                cf[c as usize] = f as u32;
            }
        }
        cf
    };
    let corner_of = |f: u32, v: u32| -> u32 {
        let s = p.face_offsets[f as usize];
        let i = p
            .face_vertices(f as usize)
            .iter()
            .position(|&x| x == v)
            .unwrap_or(0);
        s + i as u32
    };
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for f in 0..p.num_faces() {
        faces.push((p.face_offsets[f]..p.face_offsets[f + 1]).collect());
    }
    for e in 0..p.num_edges() {
        let [f, g] = p.edge_faces[e];
        if g == INVALID {
            continue;
        }
        // Orient by the face that traverses the edge as a → b.
        let (f, g) = {
            let s = p.face_offsets[f as usize] as usize;
            let i = p
                .face_edge_list(f as usize)
                .iter()
                .position(|&x| x == e as u32)
                .unwrap_or(0);
            if p.face_verts[s + i] == p.edge_verts[e][0] {
                (f, g)
            } else {
                (g, f)
            }
        };
        let [a, b] = p.edge_verts[e];
        faces.push(vec![
            corner_of(f, b),
            corner_of(f, a),
            corner_of(g, a),
            corner_of(g, b),
        ]);
    }
    for v in 0..p.num_vertices() {
        let vf = p.vertex_faces(v);
        if vf.is_empty()
            || p.vertex_edges(v)
                .iter()
                .any(|&e| p.is_boundary_edge(e as usize))
        {
            continue;
        }
        // Walk around v through each face's incoming edge.
        let mut ring = Vec::with_capacity(vf.len());
        let mut f = vf[0];
        for _ in 0..vf.len() {
            ring.push(corner_of(f, v as u32));
            let fv = p.face_vertices(f as usize);
            let fe = p.face_edge_list(f as usize);
            let i = fv.iter().position(|&x| x == v as u32).unwrap_or(0);
            let e_in = fe[(i + fv.len() - 1) % fv.len()];
            let [x, y] = p.edge_faces[e_in as usize];
            f = if x == f { y } else { x };
            if f == vf[0] || f == INVALID {
                break;
            }
        }
        faces.push(ring);
    }
    let step = build_rows(
        corners,
        p.num_vertices(),
        || (),
        |_, c, out| {
            let f = corner_face[c] as usize;
            let fv = p.face_vertices(f);
            let n = fv.len();
            let i = c - p.face_offsets[f] as usize;
            let nf = n as f64;
            for (j, &v) in fv.iter().enumerate() {
                let w = if i == j {
                    (nf + 5.0) / (4.0 * nf)
                } else {
                    let d = (i + n - j) % n;
                    (3.0 + 2.0 * (2.0 * std::f64::consts::PI * d as f64 / nf).cos()) / (4.0 * nf)
                };
                out.push((v, w));
            }
        },
    );
    let positions = step.apply(&parent.positions);
    let mesh = ControlMesh::from_polygons(positions.clone(), &faces);
    let topology = Topology::from_mesh(&mesh)?;
    let edge_sharpness = (0..topology.num_edges())
        .map(|e| {
            if topology.is_boundary_edge(e) {
                SHARPNESS_INFINITE
            } else {
                0.0
            }
        })
        .collect();
    let vertex_sharpness = vec![0.0; topology.num_vertices()];
    Ok((
        Level {
            topology,
            positions,
            edge_sharpness,
            vertex_sharpness,
        },
        step,
    ))
}
