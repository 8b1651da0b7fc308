//! Exact limit evaluation at any `(face, u, v)` of a Loop or Catmull-Clark control mesh.
//!
//! Parametric domains are those of [`crate::patch`] (Loop: `P = v0·(1−u−v) + v1·u + v2·v`;
//! Catmull-Clark: unit square, `v0=(0,0)`, `v1=(1,0)`, `v2=(1,1)`, `v3=(0,1)`).
//!
//! Method (Stam-free, recursion on local neighbourhoods):
//! 1. take the face and every face touching one of its vertices (the one-ring of the face —
//!    exactly the support of the limit surface over the face);
//! 2. if the face is a regular patch (all corners regular smooth, or regular boundary/crease
//!    corners whose missing half is replaced by phantom points, or a Catmull-Clark regular
//!    corner), evaluate the box spline / bicubic B-spline in closed form;
//! 3. if `(u, v)` is exactly a corner, apply the vertex's limit masks ([`crate::limit`]) as soon
//!    as no semi-sharp feature remains there;
//! 4. otherwise refine the neighbourhood once (OpenSubdiv rules, semi-sharp creases included),
//!    pick the child face containing the point, and repeat.
//!
//! Because the one-ring of a face refines into a superset of the one-ring of each child face,
//! the local refinement is exact. At dyadic parameters the recursion ends after at most
//! `level + 1` steps on a corner or a regular patch, so results are exact to rounding.
//! Derivatives `du`, `dv` are parametric (exact on regular patches, including regular vertices).
//! Exactly at an extraordinary, crease or corner vertex, where parametric derivatives vanish or
//! diverge, they are built from the limit tangent masks as the tangents toward the face's
//! neighbouring corners (exact directions; `du × dv` is the outward normal; magnitudes are
//! OpenSubdiv's, scaled to match the regular case for smooth vertices).
//!
//! Holes are evaluated like ordinary faces; Loop needs triangles, Catmull-Clark quads (use
//! [`LocalMesh::evaluate_subface`] for other faces).

use std::collections::HashMap;
use std::fmt;

use crate::limit::{
    catmark_limit_masks, loop_limit_masks, smooth_directional_tangent, LimitRule, LimitVertex,
};
use crate::mesh::{BoundaryInterpolation, ControlMesh, CreaseMethod};
use crate::patch::{catmark_regular_weights, loop_regular_weights};

/// Which subdivision surface is evaluated.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LimitScheme {
    Loop,
    CatmullClark,
}

impl std::str::FromStr for LimitScheme {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self, EvalError> {
        match s {
            "loop" => Ok(LimitScheme::Loop),
            "catmull-clark" | "catmark" | "cc" => Ok(LimitScheme::CatmullClark),
            _ => Err(EvalError::Unsupported(format!("unknown scheme {s:?}"))),
        }
    }
}

/// Why a limit evaluation could not be done.
#[derive(Debug, thiserror::Error, PartialEq)]
pub enum EvalError {
    #[error("face {0} out of range")]
    FaceOutOfRange(usize),
    #[error("parameter ({0}, {1}) outside the face domain")]
    ParamOutOfRange(f64, f64),
    #[error("face {face} has {size} corners; {scheme:?} evaluation needs {need}")]
    FaceSize {
        face: usize,
        size: usize,
        scheme: LimitScheme,
        need: usize,
    },
    #[error("non-manifold or inconsistently oriented mesh at vertex {0}")]
    NonManifold(u32),
    #[error("{0}")]
    Unsupported(String),
}

/// Infinite sharpness (OpenSubdiv: 10 and above).
const INF: f32 = 10.0;

fn is_sharp(s: f32) -> bool {
    s > 0.0
}

fn decrement(s: f32) -> f32 {
    if s >= INF {
        INF
    } else if s > 1.0 {
        s - 1.0
    } else {
        0.0
    }
}

/// OpenSubdiv vertex rule from the vertex sharpness and the number of sharp incident edges.
fn rule_of(vs: f32, sharp_edges: usize) -> u8 {
    if is_sharp(vs) {
        return 3;
    }
    match sharp_edges {
        0 | 1 => 0,
        2 => 2,
        _ => 3,
    }
}

/// Ordered neighbourhood of one vertex: faces CCW, and the edge-neighbours `ring[i]` =
/// the vertex after the centre in face `i` (plus the last boundary neighbour for a fan).
#[derive(Clone, Debug, Default)]
struct Fan {
    faces: Vec<(u32, u32)>,
    ring: Vec<u32>,
    boundary: bool,
}

/// A small (or whole) polygon mesh with points of any dimension and OpenSubdiv sharpness tags:
/// the working set of the evaluator and of the basis-function-table generator.
#[derive(Clone, Debug)]
pub struct LocalMesh {
    pub scheme: LimitScheme,
    /// Dimension of each point (3 for geometry; the number of basis functions for tables).
    pub dim: usize,
    /// `dim` values per vertex.
    pub points: Vec<f64>,
    pub face_offsets: Vec<u32>,
    pub face_verts: Vec<u32>,
    /// Sharpness of tagged edges, keyed by `(min, max)` vertex pair (boundary edges are
    /// infinitely sharp without being listed).
    pub edge_sharpness: HashMap<(u32, u32), f32>,
    pub vertex_sharpness: Vec<f32>,
    pub boundary: BoundaryInterpolation,
    pub crease_method: CreaseMethod,
    fans: Vec<Fan>,
    halfedges: HashMap<(u32, u32), u32>,
}

/// Limit position and first derivatives (any dimension).
#[derive(Clone, Debug, PartialEq)]
pub struct LimitSample {
    pub position: Vec<f64>,
    pub du: Vec<f64>,
    pub dv: Vec<f64>,
}

fn key(a: u32, b: u32) -> (u32, u32) {
    if a < b {
        (a, b)
    } else {
        (b, a)
    }
}

fn axpy(out: &mut [f64], w: f64, x: &[f64]) {
    for (o, v) in out.iter_mut().zip(x) {
        *o += w * v;
    }
}

impl LocalMesh {
    /// Build from flat faces and points; computes the ordered vertex neighbourhoods.
    #[allow(clippy::too_many_arguments)]
    pub fn new(
        scheme: LimitScheme,
        dim: usize,
        points: Vec<f64>,
        face_offsets: Vec<u32>,
        face_verts: Vec<u32>,
        edge_sharpness: HashMap<(u32, u32), f32>,
        vertex_sharpness: Vec<f32>,
        boundary: BoundaryInterpolation,
        crease_method: CreaseMethod,
    ) -> Result<LocalMesh, EvalError> {
        let nv = points.len() / dim.max(1);
        let mut m = LocalMesh {
            scheme,
            dim,
            points,
            face_offsets,
            face_verts,
            edge_sharpness,
            vertex_sharpness,
            boundary,
            crease_method,
            fans: Vec::new(),
            halfedges: HashMap::new(),
        };
        m.vertex_sharpness.resize(nv, 0.0);
        m.build_fans(nv)?;
        Ok(m)
    }

    /// Geometry of a [`ControlMesh`] (holes are refined like ordinary faces).
    pub fn from_control_mesh(mesh: &ControlMesh, scheme: LimitScheme) -> Result<Self, EvalError> {
        let mut es = HashMap::new();
        for c in &mesh.creases {
            if c.sharpness > 0.0 {
                es.insert(key(c.vertices[0], c.vertices[1]), c.sharpness);
            }
        }
        let mut vs = vec![0.0f32; mesh.positions.len()];
        for c in &mesh.corners {
            if let Some(s) = vs.get_mut(c.vertex as usize) {
                *s = c.sharpness;
            }
        }
        let points = mesh
            .positions
            .iter()
            .flat_map(|p| p.iter().copied())
            .collect();
        LocalMesh::new(
            scheme,
            3,
            points,
            mesh.face_offsets.clone(),
            mesh.face_vertices.clone(),
            es,
            vs,
            mesh.options.boundary,
            mesh.options.crease_method,
        )
    }

    /// A level of T1's uniform refinement (e.g. the level-1 mesh the BFT pipeline starts from).
    pub fn from_refined_level(
        level: &crate::refine::Level,
        scheme: LimitScheme,
        options: &crate::mesh::SubdivOptions,
    ) -> Result<Self, EvalError> {
        let mut es = HashMap::new();
        for e in 0..level.topology.num_edges() {
            let s = level.edge_sharpness[e];
            if s > 0.0 && !level.topology.is_boundary_edge(e) {
                let [a, b] = level.topology.edge_vertices(e);
                es.insert(key(a, b), s);
            }
        }
        LocalMesh::new(
            scheme,
            3,
            level
                .positions
                .iter()
                .flat_map(|p| p.iter().copied())
                .collect(),
            level.face_offsets().to_vec(),
            level.face_vertices().to_vec(),
            es,
            level.vertex_sharpness.clone(),
            options.boundary,
            options.crease_method,
        )
    }

    pub fn num_vertices(&self) -> usize {
        self.fans.len()
    }

    pub fn num_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }

    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_verts[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    pub fn point(&self, v: u32) -> &[f64] {
        &self.points[v as usize * self.dim..(v as usize + 1) * self.dim]
    }

    /// True if `v` lies on the mesh boundary.
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.fans[v as usize].boundary
    }

    /// Edge-neighbours of `v` in CCW order (fan order for boundary vertices).
    pub fn vertex_ring(&self, v: u32) -> &[u32] {
        &self.fans[v as usize].ring
    }

    /// Faces around `v` in CCW order.
    pub fn vertex_faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.fans[v as usize].faces.iter().map(|&(f, _)| f)
    }

    fn build_fans(&mut self, nv: usize) -> Result<(), EvalError> {
        let mut he = HashMap::with_capacity(self.face_verts.len());
        let mut corners: Vec<Vec<(u32, u32)>> = vec![Vec::new(); nv];
        for f in 0..self.num_faces() {
            let fv = self.face(f);
            let n = fv.len();
            for c in 0..n {
                let (a, b) = (fv[c], fv[(c + 1) % n]);
                if he.insert((a, b), f as u32).is_some() {
                    return Err(EvalError::NonManifold(a));
                }
                corners[a as usize].push((f as u32, c as u32));
            }
        }
        let mut fans = Vec::with_capacity(nv);
        for (v, cs) in corners.iter().enumerate() {
            let v = v as u32;
            if cs.is_empty() {
                fans.push(Fan::default());
                continue;
            }
            let next_of = |&(f, c): &(u32, u32)| {
                let fv = self.face(f as usize);
                fv[(c as usize + 1) % fv.len()]
            };
            let prev_of = |&(f, c): &(u32, u32)| {
                let fv = self.face(f as usize);
                fv[(c as usize + fv.len() - 1) % fv.len()]
            };
            // Start at a face whose leading edge has no twin (boundary), else anywhere.
            let start = cs
                .iter()
                .position(|fc| !he.contains_key(&(next_of(fc), v)))
                .unwrap_or(0);
            let boundary = !he.contains_key(&(next_of(&cs[start]), v));
            let mut fan = Fan {
                boundary,
                ..Fan::default()
            };
            let mut cur = cs[start];
            loop {
                fan.faces.push(cur);
                fan.ring.push(next_of(&cur));
                let p = prev_of(&cur);
                match he.get(&(v, p)) {
                    Some(&f2) => {
                        let fv = self.face(f2 as usize);
                        let c2 = fv.iter().position(|&x| x == v).unwrap_or(0) as u32;
                        if f2 == cs[start].0 {
                            break;
                        }
                        cur = (f2, c2);
                    }
                    None => {
                        fan.ring.push(p);
                        break;
                    }
                }
                if fan.faces.len() > cs.len() {
                    return Err(EvalError::NonManifold(v));
                }
            }
            if fan.faces.len() != cs.len() {
                return Err(EvalError::NonManifold(v));
            }
            fans.push(fan);
        }
        self.fans = fans;
        self.halfedges = he;
        Ok(())
    }

    /// True if edge `a–b` has a face on one side only.
    pub fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        !(self.halfedges.contains_key(&(a, b)) && self.halfedges.contains_key(&(b, a)))
    }

    /// Sharpness of edge `a–b` (boundary edges are infinitely sharp).
    pub fn edge_sharp(&self, a: u32, b: u32) -> f32 {
        if self.is_boundary_edge(a, b) {
            INF
        } else {
            self.edge_sharpness.get(&key(a, b)).copied().unwrap_or(0.0)
        }
    }

    /// Vertex sharpness, including OpenSubdiv's "edges and corners" boundary corners.
    pub fn vert_sharp(&self, v: u32) -> f32 {
        let fan = &self.fans[v as usize];
        if self.boundary == BoundaryInterpolation::EdgesAndCorners
            && fan.boundary
            && fan.faces.len() == 1
        {
            return INF;
        }
        self.vertex_sharpness[v as usize]
    }

    fn incident_sharpness(&self, v: u32) -> Vec<f32> {
        self.fans[v as usize]
            .ring
            .iter()
            .map(|&w| self.edge_sharp(v, w))
            .collect()
    }

    fn child_edge_sharpness(&self, s: f32, at: u32) -> f32 {
        match self.crease_method {
            CreaseMethod::Uniform => decrement(s),
            CreaseMethod::Chaikin => {
                if !is_sharp(s) {
                    return 0.0;
                }
                if s >= INF {
                    return INF;
                }
                let inc = self.incident_sharpness(at);
                let semi: Vec<f32> = inc
                    .iter()
                    .copied()
                    .filter(|&x| is_sharp(x) && x < INF)
                    .collect();
                let mut t = s;
                if semi.len() > 1 && inc.len() >= 2 {
                    let others = (semi.iter().sum::<f32>() - s) / (semi.len() - 1) as f32;
                    t = 0.75 * s + 0.25 * others;
                }
                t -= 1.0;
                if is_sharp(t) {
                    t
                } else {
                    0.0
                }
            }
        }
    }

    /// One level of uniform refinement with OpenSubdiv's rules (uniform or Chaikin decay,
    /// fractional rule blending). Child faces: Loop `4f + [corner v0, corner v1, corner v2,
    /// centre]`, child `k<3` = `[v_k', e_{k,k+1}, e_{k−1,k}]` rotated so the param map is as in
    /// [`LocalMesh::evaluate`]; Catmull-Clark: the face's corners in order,
    /// `[v_i', e_{i,i+1}, f, e_{i−1,i}]`, numbered consecutively per parent face.
    pub fn refine(&self) -> Result<LocalMesh, EvalError> {
        let d = self.dim;
        let nv = self.num_vertices();
        let nf = self.num_faces();
        let quad = self.scheme == LimitScheme::CatmullClark;
        if !quad {
            if let Some(f) = (0..nf).find(|&f| self.face(f).len() != 3) {
                return Err(EvalError::FaceSize {
                    face: f,
                    size: self.face(f).len(),
                    scheme: self.scheme,
                    need: 3,
                });
            }
        }
        // Number edges.
        let mut edge_id: HashMap<(u32, u32), u32> = HashMap::new();
        let mut edges: Vec<(u32, u32)> = Vec::new();
        for f in 0..nf {
            let fv = self.face(f);
            for c in 0..fv.len() {
                let k = key(fv[c], fv[(c + 1) % fv.len()]);
                edge_id.entry(k).or_insert_with(|| {
                    edges.push(k);
                    (edges.len() - 1) as u32
                });
            }
        }
        let ne = edges.len();
        let e_base = nv as u32;
        let f_base = (nv + ne) as u32;
        let n_child = nv + ne + if quad { nf } else { 0 };
        let mut pts = vec![0.0; n_child * d];
        // Face points.
        if quad {
            for f in 0..nf {
                let fv = self.face(f);
                let w = 1.0 / fv.len() as f64;
                let o = (f_base as usize + f) * d;
                for &v in fv {
                    axpy(&mut pts[o..o + d], w, self.point(v));
                }
            }
        }
        // Edge points.
        for (ei, &(a, b)) in edges.iter().enumerate() {
            let s = self.edge_sharp(a, b);
            let mut mid = vec![0.0; d];
            axpy(&mut mid, 0.5, self.point(a));
            axpy(&mut mid, 0.5, self.point(b));
            let out = if s >= 1.0 {
                mid
            } else {
                let mut sm = vec![0.0; d];
                let fa = self.halfedges[&(a, b)];
                let fb = self.halfedges[&(b, a)];
                if quad {
                    axpy(&mut sm, 0.25, self.point(a));
                    axpy(&mut sm, 0.25, self.point(b));
                    for f in [fa, fb] {
                        let o = (f_base + f) as usize * d;
                        let fp: Vec<f64> = pts[o..o + d].to_vec();
                        axpy(&mut sm, 0.25, &fp);
                    }
                } else {
                    axpy(&mut sm, 0.375, self.point(a));
                    axpy(&mut sm, 0.375, self.point(b));
                    for f in [fa, fb] {
                        let opp = self
                            .face(f as usize)
                            .iter()
                            .copied()
                            .find(|&x| x != a && x != b);
                        axpy(&mut sm, 0.125, self.point(opp.unwrap_or(a)));
                    }
                }
                if s > 0.0 {
                    let s = s as f64;
                    sm.iter_mut()
                        .zip(&mid)
                        .for_each(|(x, m)| *x = (1.0 - s) * *x + s * m);
                }
                sm
            };
            let o = (nv + ei) * d;
            pts[o..o + d].copy_from_slice(&out);
        }
        // Vertex points.
        for v in 0..nv as u32 {
            let fan = &self.fans[v as usize];
            let o = v as usize * d;
            if fan.faces.is_empty() {
                let p = self.point(v).to_vec();
                pts[o..o + d].copy_from_slice(&p);
                continue;
            }
            let inc = self.incident_sharpness(v);
            let p_vs = self.vert_sharp(v);
            let p_sharp: Vec<usize> = (0..inc.len()).filter(|&i| is_sharp(inc[i])).collect();
            let p_rule = rule_of(p_vs, p_sharp.len());
            let c_inc: Vec<f32> = inc
                .iter()
                .map(|&s| self.child_edge_sharpness(s, v))
                .collect();
            let c_vs = decrement(p_vs);
            let c_sharp: Vec<usize> = (0..c_inc.len()).filter(|&i| is_sharp(c_inc[i])).collect();
            let c_rule = rule_of(c_vs, c_sharp.len());
            let p_mask = self.vertex_rule_point(v, p_rule, &p_sharp, f_base, &pts);
            let out = if p_rule == 0 || p_rule == c_rule {
                p_mask
            } else {
                // OpenSubdiv's fractional weight: mean sharpness of what decayed this level.
                let (mut cnt, mut sum) = (0usize, 0.0f32);
                if is_sharp(p_vs) && !is_sharp(c_vs) {
                    cnt = 1;
                    sum = p_vs;
                }
                for i in 0..inc.len() {
                    let decayed = match self.crease_method {
                        CreaseMethod::Uniform => is_sharp(inc[i]) && inc[i] <= 1.0,
                        CreaseMethod::Chaikin => is_sharp(inc[i]) && !is_sharp(c_inc[i]),
                    };
                    if decayed {
                        sum += inc[i];
                        cnt += 1;
                    }
                }
                let pw = if cnt == 0 {
                    0.0
                } else {
                    (sum / cnt as f32).min(1.0) as f64
                };
                let c_mask = self.vertex_rule_point(v, c_rule, &c_sharp, f_base, &pts);
                p_mask
                    .iter()
                    .zip(&c_mask)
                    .map(|(p, c)| pw * p + (1.0 - pw) * c)
                    .collect()
            };
            pts[o..o + d].copy_from_slice(&out);
        }
        // Child topology and sharpness.
        let mut fo = vec![0u32];
        let mut fvs = Vec::new();
        let ev = |a: u32, b: u32| e_base + edge_id[&key(a, b)];
        for f in 0..nf {
            let fv = self.face(f);
            let n = fv.len();
            if quad {
                for i in 0..n {
                    let v = fv[i];
                    let nx = fv[(i + 1) % n];
                    let pv = fv[(i + n - 1) % n];
                    fvs.extend_from_slice(&[v, ev(v, nx), f_base + f as u32, ev(pv, v)]);
                    fo.push(fvs.len() as u32);
                }
            } else {
                let (a, b, c) = (fv[0], fv[1], fv[2]);
                let (ab, bc, ca) = (ev(a, b), ev(b, c), ev(c, a));
                for t in [[a, ab, ca], [ab, b, bc], [ca, bc, c], [bc, ca, ab]] {
                    fvs.extend_from_slice(&t);
                    fo.push(fvs.len() as u32);
                }
            }
        }
        let mut es = HashMap::new();
        for (&(a, b), &s) in &self.edge_sharpness {
            if !is_sharp(s) {
                continue;
            }
            if let Some(&id) = edge_id.get(&(a, b)) {
                let e = e_base + id;
                let sa = self.child_edge_sharpness(s, a);
                let sb = self.child_edge_sharpness(s, b);
                if is_sharp(sa) {
                    es.insert(key(a, e), sa);
                }
                if is_sharp(sb) {
                    es.insert(key(b, e), sb);
                }
            }
        }
        let mut vs = vec![0.0f32; n_child];
        for (c, &p) in vs.iter_mut().zip(&self.vertex_sharpness) {
            *c = decrement(p);
        }
        LocalMesh::new(
            self.scheme,
            d,
            pts,
            fo,
            fvs,
            es,
            vs,
            self.boundary,
            self.crease_method,
        )
    }

    /// The new position of vertex `v` under one rule (0 smooth, 2 crease, 3 corner).
    fn vertex_rule_point(
        &self,
        v: u32,
        rule: u8,
        sharp: &[usize],
        f_base: u32,
        child_pts: &[f64],
    ) -> Vec<f64> {
        let d = self.dim;
        let fan = &self.fans[v as usize];
        let mut out = vec![0.0; d];
        match rule {
            2 => {
                axpy(&mut out, 0.75, self.point(v));
                for &i in sharp {
                    axpy(&mut out, 0.125, self.point(fan.ring[i]));
                }
            }
            3 => axpy(&mut out, 1.0, self.point(v)),
            _ => {
                let n = fan.ring.len();
                let nf = n as f64;
                if self.scheme == LimitScheme::Loop {
                    let beta = 0.25 * (2.0 * std::f64::consts::PI / nf).cos() + 0.375;
                    let e = (0.625 - beta * beta) / nf;
                    axpy(&mut out, 1.0 - e * nf, self.point(v));
                    for &w in &fan.ring {
                        axpy(&mut out, e, self.point(w));
                    }
                } else {
                    axpy(&mut out, (nf - 2.0) / nf, self.point(v));
                    let w = 1.0 / (nf * nf);
                    for &x in &fan.ring {
                        axpy(&mut out, w, self.point(x));
                    }
                    for &(f, _) in &fan.faces {
                        let o = (f_base + f) as usize * d;
                        axpy(&mut out, w, &child_pts[o..o + d]);
                    }
                }
            }
        }
        out
    }

    /// The face plus every face touching one of its vertices, as a new mesh; returns it and the
    /// face's index there (always 0).
    pub fn face_neighbourhood(&self, face: usize) -> Result<LocalMesh, EvalError> {
        let mut faces = vec![face as u32];
        for &v in self.face(face) {
            for (f, _) in &self.fans[v as usize].faces {
                if !faces.contains(f) {
                    faces.push(*f);
                }
            }
        }
        let mut remap: HashMap<u32, u32> = HashMap::new();
        let mut pts = Vec::new();
        let mut vs = Vec::new();
        let mut fo = vec![0u32];
        let mut fvs = Vec::new();
        for &f in &faces {
            for &v in self.face(f as usize) {
                let id = *remap.entry(v).or_insert_with(|| {
                    pts.extend_from_slice(self.point(v));
                    vs.push(self.vertex_sharpness[v as usize]);
                    (vs.len() - 1) as u32
                });
                fvs.push(id);
            }
            fo.push(fvs.len() as u32);
        }
        let mut es = HashMap::new();
        for &f in &faces {
            let fv = self.face(f as usize);
            for c in 0..fv.len() {
                let (a, b) = (fv[c], fv[(c + 1) % fv.len()]);
                let s = self.edge_sharp(a, b);
                if is_sharp(s) {
                    es.insert(key(remap[&a], remap[&b]), s);
                }
            }
        }
        // Boundary corners of the original mesh stay corners: carry their sharpness.
        for (&v, &id) in &remap {
            let s = self.vert_sharp(v);
            vs[id as usize] = s;
        }
        LocalMesh::new(
            self.scheme,
            self.dim,
            pts,
            fo,
            fvs,
            es,
            vs,
            self.boundary,
            self.crease_method,
        )
    }

    /// Limit rule of `v` if no semi-sharp feature is left there (else `None`: refine first).
    /// Crease ends are oriented so the CCW span `ends[0] → ends[1]` contains face `face`.
    fn limit_vertex(&self, v: u32, face: Option<u32>) -> Option<LimitVertex> {
        let fan = &self.fans[v as usize];
        let vs = self.vert_sharp(v);
        if is_sharp(vs) && vs < INF {
            return None;
        }
        let inc = self.incident_sharpness(v);
        if inc.iter().any(|&s| is_sharp(s) && s < INF) {
            return None;
        }
        let sharp: Vec<usize> = (0..inc.len()).filter(|&i| inc[i] >= INF).collect();
        let n = fan.ring.len();
        let rule = match rule_of(vs, sharp.len()) {
            0 => LimitRule::Smooth,
            2 => {
                let (a, b) = (sharp[0], sharp[1]);
                let ends = if fan.boundary {
                    [0, n - 1]
                } else {
                    // Face j lies between ring[j] and ring[j+1]: inside the CCW span a → b?
                    let j = face
                        .and_then(|f| fan.faces.iter().position(|&(g, _)| g == f))
                        .unwrap_or(a);
                    if (j + n - a) % n < (b + n - a) % n {
                        [a, b]
                    } else {
                        [b, a]
                    }
                };
                LimitRule::Crease { ends }
            }
            _ => LimitRule::Corner,
        };
        Some(LimitVertex {
            valence: n,
            boundary: fan.boundary,
            rule,
        })
    }

    /// Limit position of vertex `v` by its limit mask, if no semi-sharp feature remains and (for
    /// Catmull-Clark smooth vertices) all incident faces are quads.
    pub fn vertex_limit_position(&self, v: u32) -> Option<Vec<f64>> {
        self.vertex_limit(v, None).map(|(p, _, _)| p)
    }

    /// Limit position and the two mask tangents (see [`crate::limit`]) of vertex `v`.
    fn vertex_limit(&self, v: u32, face: Option<u32>) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        let lv = self.limit_vertex(v, face)?;
        let fan = &self.fans[v as usize];
        let quad = self.scheme == LimitScheme::CatmullClark;
        let masks = if quad {
            if lv.rule != LimitRule::Corner
                && fan
                    .faces
                    .iter()
                    .any(|&(f, _)| self.face(f as usize).len() != 4)
            {
                return None;
            }
            catmark_limit_masks(&lv)
        } else {
            loop_limit_masks(&lv)
        };
        let edges: Vec<&[f64]> = fan.ring.iter().map(|&w| self.point(w)).collect();
        let faces: Vec<&[f64]> = if quad {
            fan.faces
                .iter()
                .map(|&(f, c)| {
                    let fv = self.face(f as usize);
                    self.point(fv[(c as usize + 2) % fv.len()])
                })
                .collect()
        } else {
            Vec::new()
        };
        let fcount = masks.position.faces.len();
        let p = masks
            .position
            .apply(self.point(v), &edges, &faces[..fcount]);
        let t1 = masks
            .tangent1
            .apply(self.point(v), &edges, &faces[..masks.tangent1.faces.len()]);
        let t2 = masks
            .tangent2
            .apply(self.point(v), &edges, &faces[..masks.tangent2.faces.len()]);
        Some((p, t1, t2))
    }

    /// Loop limit tangent masks of vertex `v` as stencils: control indices `[v, ring…]` and the
    /// weights of `tangent1` and `tangent2` over them (`tangent1 × tangent2` points outward).
    /// For the GPU's limit normals of the once-refined mesh. `None` for Catmull-Clark meshes
    /// and where [`Self::vertex_limit_position`] has no mask.
    pub fn loop_tangent_stencils(&self, v: u32) -> Option<(Vec<u32>, Vec<f64>, Vec<f64>)> {
        if self.scheme != LimitScheme::Loop {
            return None;
        }
        let lv = self.limit_vertex(v, None)?;
        let masks = loop_limit_masks(&lv);
        let fan = &self.fans[v as usize];
        let mut idx = vec![v];
        idx.extend_from_slice(&fan.ring);
        let flat = |m: &crate::limit::Mask| {
            let mut w = vec![m.vertex];
            w.extend_from_slice(&m.edges);
            w
        };
        Some((idx, flat(&masks.tangent1), flat(&masks.tangent2)))
    }

    /// Smooth directional tangent of `v` along its ring neighbour index `k`.
    fn directional(&self, v: u32, k: usize) -> Vec<f64> {
        let fan = &self.fans[v as usize];
        let n = fan.ring.len();
        let quad = self.scheme == LimitScheme::CatmullClark;
        let (ew, fw) = smooth_directional_tangent(!quad, n, k);
        let mut out = vec![0.0; self.dim];
        for (i, &w) in fan.ring.iter().enumerate() {
            axpy(&mut out, ew[i], self.point(w));
        }
        for (i, &(f, c)) in fan.faces.iter().enumerate().take(fw.len()) {
            let fv = self.face(f as usize);
            axpy(&mut out, fw[i], self.point(fv[(c as usize + 2) % fv.len()]));
        }
        out
    }

    /// Limit at corner `c` of face `f`: position and the face-relative tangents. `D(k)` is the
    /// limit tangent toward ring neighbour `k` (smooth: rotated cos masks, exact at regular
    /// vertices; crease: `cos θ·T_along + sin θ·T_across` with `θ` spread over the sector;
    /// corner: `e_k − v`); `du`, `dv` are the combinations a regular patch would give, so
    /// `du × dv` is the outward normal and mirrored faces see swapped `du`/`dv`.
    fn corner_limit(&self, f: usize, c: usize) -> Option<LimitSample> {
        let fv = self.face(f);
        let v = fv[c];
        let (p, t1, t2) = self.vertex_limit(v, Some(f as u32))?;
        let lv = self.limit_vertex(v, Some(f as u32))?;
        let fan = &self.fans[v as usize];
        let n = fan.ring.len();
        let j = fan.faces.iter().position(|&(g, _)| g == f as u32)?;
        let dir = |k: usize| -> Vec<f64> {
            match lv.rule {
                LimitRule::Smooth => self.directional(v, k % n),
                LimitRule::Crease { ends } => {
                    let m = ((ends[1] + n - ends[0]) % n).max(1);
                    let th = std::f64::consts::PI * ((k + n - ends[0]) % n) as f64 / m as f64;
                    t1.iter()
                        .zip(&t2)
                        .map(|(a, b)| th.cos() * a + th.sin() * b)
                        .collect()
                }
                LimitRule::Corner => self
                    .point(fan.ring[k % n])
                    .iter()
                    .zip(self.point(v))
                    .map(|(a, b)| a - b)
                    .collect(),
            }
        };
        // Tangents toward the next and previous face vertices.
        let dn = dir(j);
        let dp = dir(j + 1);
        let neg = |x: &[f64]| x.iter().map(|a| -a).collect::<Vec<f64>>();
        let sub = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a - b).collect::<Vec<f64>>();
        let (du, dv) = if fv.len() == 3 {
            // D(next), D(prev) at v0: (du, dv); at v1: D(v2)=dv−du, D(v0)=−du;
            // at v2: D(v0)=−dv, D(v1)=du−dv, so du = D(v1) − D(v0).
            match c {
                0 => (dn, dp),
                1 => (neg(&dp), sub(&dn, &dp)),
                _ => (sub(&dp, &dn), neg(&dn)),
            }
        } else {
            match c {
                0 => (dn, dp),
                1 => (neg(&dp), dn),
                2 => (neg(&dn), neg(&dp)),
                _ => (dp, neg(&dn)),
            }
        };
        Some(LimitSample {
            position: p,
            du,
            dv,
        })
    }

    /// Sequence of ring positions (Loop: 6 edge-neighbours; Catmull-Clark: 8 interleaved
    /// edge-neighbours and diagonals) around corner `c` of face `f`, starting at the face's
    /// next vertex, with phantoms for regular boundary/crease/corner configurations. `None` if
    /// the corner is not regular.
    fn regular_corner_ring(&self, f: usize, c: usize) -> Option<Vec<Vec<f64>>> {
        let quad = self.scheme == LimitScheme::CatmullClark;
        let fv = self.face(f);
        let v = fv[c];
        let fan = &self.fans[v as usize];
        let n = fan.ring.len();
        let vs = self.vert_sharp(v);
        if is_sharp(vs) && vs < INF {
            return None;
        }
        let inc = self.incident_sharpness(v);
        if inc.iter().any(|&s| is_sharp(s) && s < INF) {
            return None;
        }
        let need = if quad { 4 } else { 3 };
        if fan
            .faces
            .iter()
            .any(|&(g, _)| self.face(g as usize).len() != need)
        {
            return None;
        }
        let j = fan.faces.iter().position(|&(g, _)| g == f as u32)?;
        let sharp: Vec<usize> = (0..n).filter(|&i| inc[i] >= INF).collect();
        let opp = |i: usize| {
            let (g, cc) = fan.faces[i];
            let gv = self.face(g as usize);
            self.point(gv[(cc as usize + 2) % 4]).to_vec()
        };
        let pt = |w: u32| self.point(w).to_vec();
        let lin = |terms: &[(f64, &[f64])]| {
            let mut o = vec![0.0; self.dim];
            for (w, x) in terms {
                axpy(&mut o, *w, x);
            }
            o
        };
        let center = self.point(v);
        if sharp.is_empty() && !is_sharp(vs) {
            if fan.boundary || n != if quad { 4 } else { 6 } {
                return None;
            }
            let mut seq = Vec::new();
            for k in 0..n {
                let i = (j + k) % n;
                seq.push(pt(fan.ring[i]));
                if quad {
                    seq.push(opp(i));
                }
            }
            return Some(seq);
        }
        if sharp.len() != 2 {
            return None;
        }
        // The sector of faces containing f, bounded by the two sharp edges.
        let nfaces = fan.faces.len();
        let (a, b) = if fan.boundary {
            (0, nfaces)
        } else {
            let (x, y) = (sharp[0], sharp[1]);
            if (j + n - x) % n < (y + n - x) % n {
                (x, y)
            } else {
                (y, x)
            }
        };
        let size = (b + n - a) % n;
        let size = if fan.boundary { nfaces } else { size };
        let ring_at = |i: usize| fan.ring[if fan.boundary { i } else { i % n }];
        let corner_rule = is_sharp(vs);
        let mut seq: Vec<Vec<f64>>;
        if !quad {
            if size != 3 || corner_rule {
                return None;
            }
            let r: Vec<Vec<f64>> = (0..4).map(|k| pt(ring_at(a + k))).collect();
            let p4 = lin(&[(1.0, center), (1.0, &r[3]), (-1.0, &r[2])]);
            let p5 = lin(&[(1.0, center), (1.0, &r[0]), (-1.0, &r[1])]);
            seq = r;
            seq.push(p4);
            seq.push(p5);
        } else if size == 2 && !corner_rule {
            let e0 = pt(ring_at(a));
            let f0 = opp(a % nfaces.max(1));
            let e1 = pt(ring_at(a + 1));
            let f1 = opp((a + 1) % nfaces.max(1));
            let e2 = pt(ring_at(a + 2));
            let p5 = lin(&[(2.0, &e2), (-1.0, &f1)]);
            let p6 = lin(&[(2.0, center), (-1.0, &e1)]);
            let p7 = lin(&[(2.0, &e0), (-1.0, &f0)]);
            seq = vec![e0, f0, e1, f1, e2, p5, p6, p7];
        } else if size == 1 && corner_rule {
            let e0 = pt(ring_at(a));
            let f0 = opp(a % nfaces.max(1));
            let e1 = pt(ring_at(a + 1));
            let p3 = lin(&[(2.0, &e1), (-1.0, &f0)]);
            let p4 = lin(&[(2.0, center), (-1.0, &e0)]);
            let p5 = lin(&[(4.0, center), (-2.0, &e0), (-2.0, &e1), (1.0, &f0)]);
            let p6 = lin(&[(2.0, center), (-1.0, &e1)]);
            let p7 = lin(&[(2.0, &e0), (-1.0, &f0)]);
            seq = vec![e0, f0, e1, p3, p4, p5, p6, p7];
        } else {
            return None;
        }
        // Rotate so the face's next vertex comes first.
        let per = if quad { 2 } else { 1 };
        let shift = ((j + n - a) % n.max(1)) * per;
        let shift = if fan.boundary { (j - a) * per } else { shift };
        let len = seq.len();
        seq.rotate_left(shift % len);
        Some(seq)
    }

    /// Control points of face `f` as a regular patch (ordering of [`crate::patch`]), or `None`.
    pub fn regular_patch(&self, f: usize) -> Option<Vec<Vec<f64>>> {
        let quad = self.scheme == LimitScheme::CatmullClark;
        let fv = self.face(f);
        let (corner_slots, ring_slots): (&[usize], &[&[usize]]) = if quad {
            if fv.len() != 4 {
                return None;
            }
            (
                &[5, 6, 10, 9],
                &[
                    &[6, 10, 9, 8, 4, 0, 1, 2],
                    &[10, 9, 5, 1, 2, 3, 7, 11],
                    &[9, 5, 6, 7, 11, 15, 14, 13],
                    &[5, 6, 10, 14, 13, 12, 8, 4],
                ],
            )
        } else {
            if fv.len() != 3 {
                return None;
            }
            (
                &[3, 6, 7],
                &[
                    &[6, 7, 4, 1, 0, 2],
                    &[7, 3, 2, 5, 9, 10],
                    &[3, 6, 10, 11, 8, 4],
                ],
            )
        };
        let mut net: Vec<Option<Vec<f64>>> = vec![None; if quad { 16 } else { 12 }];
        for (c, &s) in corner_slots.iter().enumerate() {
            net[s] = Some(self.point(fv[c]).to_vec());
        }
        for (c, slots) in ring_slots.iter().enumerate().take(fv.len()) {
            let seq = self.regular_corner_ring(f, c)?;
            for (k, p) in seq.into_iter().enumerate() {
                let s = slots[k];
                if net[s].is_none() {
                    net[s] = Some(p);
                }
            }
        }
        net.into_iter().collect()
    }

    /// Exact limit position and parametric derivatives at `(face, u, v)`.
    pub fn evaluate(&self, face: usize, u: f64, v: f64) -> Result<LimitSample, EvalError> {
        if face >= self.num_faces() {
            return Err(EvalError::FaceOutOfRange(face));
        }
        let quad = self.scheme == LimitScheme::CatmullClark;
        let size = self.face(face).len();
        let need = if quad { 4 } else { 3 };
        if size != need {
            return Err(EvalError::FaceSize {
                face,
                size,
                scheme: self.scheme,
                need,
            });
        }
        let bad = !(u.is_finite() && v.is_finite())
            || u < 0.0
            || v < 0.0
            || if quad {
                u > 1.0 || v > 1.0
            } else {
                u + v > 1.0
            };
        if bad {
            return Err(EvalError::ParamOutOfRange(u, v));
        }
        let mesh = self.face_neighbourhood(face)?;
        evaluate_local(mesh, u, v)
    }

    /// Catmull-Clark faces of any size: `(u, v) ∈ [0,1]²` on sub-quad `sub` of `face` after one
    /// refinement (`[v_sub', e_{sub,sub+1}, face point, e_{sub−1,sub}]`, `v_sub'` at `(0,0)`, the
    /// face point at `(1,1)`), as OpenSubdiv parameterises non-quads. Derivatives are with
    /// respect to the sub-quad's parameters.
    pub fn evaluate_subface(
        &self,
        face: usize,
        sub: usize,
        u: f64,
        v: f64,
    ) -> Result<LimitSample, EvalError> {
        if face >= self.num_faces() {
            return Err(EvalError::FaceOutOfRange(face));
        }
        let size = self.face(face).len();
        if self.scheme != LimitScheme::CatmullClark || sub >= size {
            return Err(EvalError::Unsupported(format!(
                "sub-face {sub} of a {size}-sided {:?} face",
                self.scheme
            )));
        }
        if !(u.is_finite() && v.is_finite() && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v))
        {
            return Err(EvalError::ParamOutOfRange(u, v));
        }
        let child = self.face_neighbourhood(face)?.refine()?;
        evaluate_local(child.face_neighbourhood(sub)?, u, v)
    }
}

/// The recursion of [`LocalMesh::evaluate`] on a neighbourhood whose face 0 holds the point.
fn evaluate_local(mut mesh: LocalMesh, u: f64, v: f64) -> Result<LimitSample, EvalError> {
    let quad = mesh.scheme == LimitScheme::CatmullClark;
    let (mut u, mut v) = (u, v);
    {
        let mut jac = [[1.0, 0.0], [0.0, 1.0]];
        const MAX_DEPTH: usize = 56;
        for depth in 0..=MAX_DEPTH {
            if depth == MAX_DEPTH {
                // 2^-56 from a corner: snap (far below f64 resolution of the surface).
                u = u.round();
                v = v.round();
                if !quad && u + v > 1.0 {
                    v = 0.0;
                }
            }
            if let Some(net) = mesh.regular_patch(0) {
                let (w, wu, wv) = if quad {
                    let w = catmark_regular_weights(u, v);
                    (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
                } else {
                    let w = loop_regular_weights(u, v);
                    (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
                };
                let mut p = vec![0.0; mesh.dim];
                let mut du = vec![0.0; mesh.dim];
                let mut dv = vec![0.0; mesh.dim];
                for (i, x) in net.iter().enumerate() {
                    axpy(&mut p, w[i], x);
                    axpy(&mut du, wu[i], x);
                    axpy(&mut dv, wv[i], x);
                }
                return Ok(chain(p, du, dv, &jac));
            }
            let corners: &[(f64, f64)] = if quad {
                &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
            } else {
                &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
            };
            if let Some(c) = corners.iter().position(|&(a, b)| a == u && b == v) {
                if let Some(s) = mesh.corner_limit(0, c) {
                    return Ok(chain(s.position, s.du, s.dv, &jac));
                }
            }
            let child = mesh.refine()?;
            let (k, nu, nv, l) = child_of(quad, u, v);
            u = nu;
            v = nv;
            jac = [
                [
                    l[0][0] * jac[0][0] + l[0][1] * jac[1][0],
                    l[0][0] * jac[0][1] + l[0][1] * jac[1][1],
                ],
                [
                    l[1][0] * jac[0][0] + l[1][1] * jac[1][0],
                    l[1][0] * jac[0][1] + l[1][1] * jac[1][1],
                ],
            ];
            mesh = child.face_neighbourhood(k)?;
        }
        Err(EvalError::Unsupported("evaluation did not converge".into()))
    }
}

/// Derivatives with respect to the original parameters.
fn chain(p: Vec<f64>, du: Vec<f64>, dv: Vec<f64>, jac: &[[f64; 2]; 2]) -> LimitSample {
    let gu = du
        .iter()
        .zip(&dv)
        .map(|(a, b)| a * jac[0][0] + b * jac[1][0])
        .collect();
    let gv = du
        .iter()
        .zip(&dv)
        .map(|(a, b)| a * jac[0][1] + b * jac[1][1])
        .collect();
    LimitSample {
        position: p,
        du: gu,
        dv: gv,
    }
}

/// Child face (index among the face's children, which are the first children of face 0),
/// child parameters and the Jacobian d(u',v')/d(u,v).
fn child_of(quad: bool, u: f64, v: f64) -> (usize, f64, f64, [[f64; 2]; 2]) {
    if quad {
        if u <= 0.5 && v <= 0.5 {
            (0, 2.0 * u, 2.0 * v, [[2.0, 0.0], [0.0, 2.0]])
        } else if u > 0.5 && v <= 0.5 {
            (1, 2.0 * v, 2.0 * (1.0 - u), [[0.0, 2.0], [-2.0, 0.0]])
        } else if u > 0.5 && v > 0.5 {
            (
                2,
                2.0 * (1.0 - u),
                2.0 * (1.0 - v),
                [[-2.0, 0.0], [0.0, -2.0]],
            )
        } else {
            (3, 2.0 * (1.0 - v), 2.0 * u, [[0.0, -2.0], [2.0, 0.0]])
        }
    } else if u + v <= 0.5 {
        (0, 2.0 * u, 2.0 * v, [[2.0, 0.0], [0.0, 2.0]])
    } else if u >= 0.5 {
        (1, 2.0 * u - 1.0, 2.0 * v, [[2.0, 0.0], [0.0, 2.0]])
    } else if v >= 0.5 {
        (2, 2.0 * u, 2.0 * v - 1.0, [[2.0, 0.0], [0.0, 2.0]])
    } else {
        (3, 1.0 - 2.0 * u, 1.0 - 2.0 * v, [[-2.0, 0.0], [0.0, -2.0]])
    }
}

/// Cross product and normalisation (zero if degenerate).
pub fn normal_of(du: &[f64; 3], dv: &[f64; 3]) -> [f64; 3] {
    let n = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// A limit point of a 3D surface: what `tessera limit` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitPoint {
    pub scheme: LimitScheme,
    pub face: usize,
    /// Sub-quad of a non-quad Catmull-Clark face (see [`LocalMesh::evaluate_subface`]).
    pub subface: Option<usize>,
    pub u: f64,
    pub v: f64,
    pub position: [f64; 3],
    pub du: [f64; 3],
    pub dv: [f64; 3],
    pub normal: [f64; 3],
}

impl fmt::Display for LimitPoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v3 = |a: &[f64; 3]| format!("{:.12} {:.12} {:.12}", a[0], a[1], a[2]);
        write!(f, "scheme {:?} face {}", self.scheme, self.face)?;
        if let Some(s) = self.subface {
            write!(f, " subface {s}")?;
        }
        writeln!(f, " uv {} {}", self.u, self.v)?;
        writeln!(f, "position {}", v3(&self.position))?;
        writeln!(f, "du {}", v3(&self.du))?;
        writeln!(f, "dv {}", v3(&self.dv))?;
        write!(f, "normal {}", v3(&self.normal))
    }
}

fn to3(x: &[f64]) -> [f64; 3] {
    [x[0], x[1], x[2]]
}

/// `tessera limit`: exact limit position, tangents and normal of a control mesh at
/// `(face, u, v)` (face indices of the control mesh itself). Non-quad Catmull-Clark faces need
/// a sub-quad: see [`limit_point_subface`].
pub fn limit_point(
    mesh: &ControlMesh,
    scheme: LimitScheme,
    face: usize,
    u: f64,
    v: f64,
) -> Result<LimitPoint, EvalError> {
    let lm = LocalMesh::from_control_mesh(mesh, scheme)?;
    let s = lm.evaluate(face, u, v)?;
    Ok(to_point(scheme, face, None, u, v, &s))
}

/// [`limit_point`] on sub-quad `sub` of a Catmull-Clark face of any size.
pub fn limit_point_subface(
    mesh: &ControlMesh,
    face: usize,
    sub: usize,
    u: f64,
    v: f64,
) -> Result<LimitPoint, EvalError> {
    let lm = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark)?;
    let s = lm.evaluate_subface(face, sub, u, v)?;
    Ok(to_point(
        LimitScheme::CatmullClark,
        face,
        Some(sub),
        u,
        v,
        &s,
    ))
}

fn to_point(
    scheme: LimitScheme,
    face: usize,
    subface: Option<usize>,
    u: f64,
    v: f64,
    s: &LimitSample,
) -> LimitPoint {
    let (du, dv) = (to3(&s.du), to3(&s.dv));
    LimitPoint {
        scheme,
        face,
        subface,
        u,
        v,
        position: to3(&s.position),
        du,
        dv,
        normal: normal_of(&du, &dv),
    }
}
