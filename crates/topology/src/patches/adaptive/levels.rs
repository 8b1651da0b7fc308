//! Levels of the plan: scaled sharpness, sparse refinement level by level, irregular
//! vertices and the selection (see the parent module for the design).

use super::*;
use crate::refine::SparseRefinement;

/// A copy of `mesh` with every tag's sharpness multiplied by `scale`; rejects NaN or negative
/// sharpness. A tag at or above [`crate::rules::SHARPNESS_INFINITE`] (10, infinitely sharp)
/// counts as exactly 10, so all infinite tags scale alike: kept infinite by any scale ≥ 1,
/// semi-sharp below it, smooth at 0. Boundary edges are infinitely sharp by the boundary rule,
/// not by a tag, and stay so.
pub(super) fn scaled_mesh(mesh: &ControlMesh, scale: f32) -> Result<ControlMesh, TopologyError> {
    let scale_one = |s: f32| {
        if scale == 1.0 {
            s
        } else {
            s.min(crate::rules::SHARPNESS_INFINITE) * scale
        }
    };
    let mut out = mesh.clone();
    for c in &mut out.creases {
        if c.sharpness.is_nan() || c.sharpness < 0.0 {
            return Err(TopologyError::BadEdgeSharpness {
                v0: c.vertices[0],
                v1: c.vertices[1],
                sharpness: c.sharpness,
            });
        }
        c.sharpness = scale_one(c.sharpness);
    }
    for c in &mut out.corners {
        if c.sharpness.is_nan() || c.sharpness < 0.0 {
            return Err(TopologyError::BadVertexSharpness {
                vertex: c.vertex,
                sharpness: c.sharpness,
            });
        }
        c.sharpness = scale_one(c.sharpness);
    }
    Ok(out)
}

/// One level of the plan.
pub(super) struct Lvl {
    /// Topology and sharpness; at the isolation level the sharpness is the *effective* one
    /// (every positive value infinite).
    pub(super) topo: LevelTopology,
    /// Global id of vertex 0 of this level.
    pub(super) base: u32,
    pub(super) complete: Vec<bool>,
    pub(super) hole: Vec<bool>,
    pub(super) selected: Vec<bool>,
    /// Per vertex of a complete face: needs isolating ([`vertex_irregular`]); false elsewhere.
    pub(super) irregular: Vec<bool>,
    /// Per vertex: global id of its coarsest vertex-vertex ancestor (the canonical key).
    pub(super) anc: Vec<u32>,
    /// Maps of the step that made this level (none for level 0).
    pub(super) maps: Option<ChildMaps>,
    /// Stencils of this level's vertices over the parent's (level ≥ 1).
    pub(super) stencils: Option<StencilTable>,
    /// Number of vertex-vertex children in this level (its edge-vertices follow).
    pub(super) kv: usize,
}

impl Lvl {
    pub(super) fn t(&self) -> &Topology {
        &self.topo.topology
    }
    /// Sharp for the patch: positive sharpness or a single face.
    pub(super) fn sharp_edge(&self, e: usize) -> bool {
        self.topo.edge_sharpness[e] > 0.0 || self.t().is_boundary_edge(e)
    }
}

/// Deepest level features are followed to when followed: sharpness 10 is infinite, so every
/// finite sharpness has decayed by level 10 (uniform or Chaikin), and the levels after a decay
/// and the extra levels of [`cap_depth`] stop here. A patch's level is 4 bits on the GPU.
pub(super) const FOLLOW_LIMIT: usize = 14;

const NEVER: u32 = u32::MAX;

/// Whether vertex `v` carries a semi-sharp feature (a finite positive sharpness on an incident
/// edge or on itself) that has not decayed yet.
fn semi_sharp(lvl: &Lvl, v: usize) -> bool {
    let finite = |s: f32| s > 0.0 && !is_infinite(s);
    finite(lvl.topo.vertex_sharpness[v])
        || lvl
            .t()
            .vertex_edges(v)
            .iter()
            .any(|&e| finite(lvl.topo.edge_sharpness[e as usize]))
}

/// The plan's levels: irregular faces isolated to `iso`; with `follow_semi_sharp`, faces at
/// semi-sharp features further, until the sharpness has decayed, and then `iso` more levels
/// ([`cap_depth`] gives slowly converging vertices more; at most [`FOLLOW_LIMIT`] in all), so
/// the patches beside a crease of sharpness 7.5 are exact instead of treating the leftover
/// sharpness as infinite. The `iso` levels after the decay are what every other irregular
/// vertex gets: an end cap placed on the level where a crease just decayed sits on a net that
/// has had no smooth step yet, and its error does not shrink with the isolation level
/// (catmark_bishop's caps at its sharpness-6 rims were 6.3e-4 of the diagonal at isolation 4,
/// 5 and 6 alike). Faces that stop being selected at or past `iso` while still irregular
/// become end caps at their level.
///
/// `single_pass` (the single-pass plans, [`super::single_pass`]) selects at level 0 only the
/// faces a one-patch-per-face approximation cannot cover (the faces with a corner next to a
/// non-quad) and never refines past level 1.
pub(super) fn build_levels(
    mesh: &ControlMesh,
    iso: usize,
    follow_semi_sharp: bool,
    max_refined_faces: u64,
    single_pass: bool,
) -> Result<Vec<Lvl>, TopologyError> {
    let mut levels = vec![base_level(mesh)?];
    let nf = levels[0].t().num_faces();
    // Refined faces held so far (every level past 0); see "Size bound" in the module docs.
    let mut refined = 0u64;
    // Per vertex of the current level: the last level at which it carried a semi-sharp feature
    // (`NEVER` if it never did).
    let mut last_semi_sharp = vec![NEVER; levels[0].t().num_vertices()];
    let deepest = if follow_semi_sharp {
        FOLLOW_LIMIT.max(iso)
    } else {
        iso
    };
    for l in 0..=deepest {
        let last = l == deepest;
        let lvl = levels.last_mut().expect("level present");
        if last {
            make_sharpness_effective(lvl);
        }
        lvl.irregular = irregular_vertices(lvl);
        let follow = if single_pass {
            next_to_non_quads(lvl.t())
        } else {
            let semi_sharp = follow_semi_sharp.then_some(&mut last_semi_sharp[..]);
            followed(lvl, l, iso, semi_sharp)
        };
        lvl.selected = if last {
            vec![false; lvl.t().num_faces()]
        } else {
            selected_faces(lvl, &follow)
        };
        let t = &lvl.topo.topology;
        let none = !lvl.selected.iter().any(|&x| x);
        if last || (none && (l >= iso || single_pass)) {
            break;
        }
        let selection: Vec<u32> = (0..t.num_faces() as u32)
            .filter(|&f| lvl.selected[f as usize])
            .collect();
        let children: u64 = selection
            .iter()
            .map(|&f| t.face_vertices(f as usize).len() as u64)
            .sum();
        let estimate =
            refined.saturating_add(children.saturating_mul(iso.saturating_sub(l).max(1) as u64));
        if estimate > max_refined_faces {
            return Err(TopologyError::AdaptiveTooLarge {
                faces: nf,
                isolation: iso as u32,
                level: l,
                estimate,
                bound: max_refined_faces,
            });
        }
        let r = refine_sparse_region(
            lvl.topo.view(),
            Scheme::CatmullClark,
            &mesh.options,
            &selection,
            SparseRegion::SelectedCorners,
        )?;
        let child = child_level(
            lvl,
            r,
            &mut refined,
            follow_semi_sharp,
            &mut last_semi_sharp,
        )?;
        levels.push(child);
    }
    Ok(levels)
}

/// Level 0: the mesh's topology, every face complete, its holes; faces past the 256 corners
/// a patch can number and holes that name no face are errors.
fn base_level(mesh: &ControlMesh) -> Result<Lvl, TopologyError> {
    let topo = LevelTopology::from_mesh(mesh, Scheme::CatmullClark)?;
    if let Some((face, size)) = (0..topo.topology.num_faces())
        .map(|f| (f, topo.topology.face_vertices(f).len()))
        .find(|&(_, n)| n > 256)
    {
        return Err(TopologyError::AdaptiveFaceTooLarge { face, size });
    }
    let nf = topo.topology.num_faces();
    let nv = topo.topology.num_vertices();
    let mut hole = vec![false; nf];
    for &h in &mesh.holes {
        match hole.get_mut(h as usize) {
            Some(x) => *x = true,
            None => {
                return Err(TopologyError::TagOutOfRange {
                    tag: crate::error::TagKind::Hole,
                    index: h,
                    count: nf,
                })
            }
        }
    }
    Ok(Lvl {
        topo,
        base: 0,
        complete: vec![true; nf],
        hole,
        selected: Vec::new(),
        irregular: Vec::new(),
        anc: (0..nv as u32).collect(),
        maps: None,
        stencils: None,
        kv: 0,
    })
}

/// At the deepest level, every positive sharpness becomes infinite (the effective sharpness
/// of the module documentation's "Patches").
fn make_sharpness_effective(lvl: &mut Lvl) {
    for s in lvl
        .topo
        .edge_sharpness
        .iter_mut()
        .chain(lvl.topo.vertex_sharpness.iter_mut())
    {
        if *s > 0.0 {
            *s = SHARPNESS_INFINITE;
        }
    }
}

/// Per vertex: whether it needs isolating ([`vertex_irregular`]). Only the vertices of
/// complete faces are ever asked (patches, the selection and the end-cap projection are made
/// of complete faces); the rest of a level is its one-ring, false here.
fn irregular_vertices(lvl: &Lvl) -> Vec<bool> {
    let mut asked = vec![false; lvl.t().num_vertices()];
    for f in 0..lvl.t().num_faces() {
        if lvl.complete[f] && !lvl.hole[f] {
            for &v in lvl.t().face_vertices(f) {
                asked[v as usize] = true;
            }
        }
    }
    (0..lvl.t().num_vertices())
        .into_par_iter()
        .with_min_len(1024)
        .map(|v| asked[v] && vertex_irregular(lvl, v))
        .collect()
}

/// Per vertex of level `l`: whether the faces at it are selected. Irregular vertices are
/// isolated to `iso`; past it only semi-sharp features are followed, when `last_semi_sharp`
/// is given (updated here with the vertices that carry one at `l`), until [`cap_depth`]
/// levels after their sharpness decayed.
fn followed(lvl: &Lvl, l: usize, iso: usize, last_semi_sharp: Option<&mut [u32]>) -> Vec<bool> {
    let Some(last_semi_sharp) = last_semi_sharp else {
        return (0..lvl.t().num_vertices())
            .map(|v| lvl.irregular[v] && l < iso)
            .collect();
    };
    for (v, last) in last_semi_sharp.iter_mut().enumerate() {
        if lvl.irregular[v] && semi_sharp(lvl, v) {
            *last = l as u32;
        }
    }
    (0..lvl.t().num_vertices())
        .map(|v| {
            lvl.irregular[v] && (l < iso || l < start(last_semi_sharp[v]) + cap_depth(lvl, v, iso))
        })
        .collect()
}

/// Per face: whether it is selected for the next step, a complete face (not a hole) at a
/// followed vertex.
fn selected_faces(lvl: &Lvl, follow: &[bool]) -> Vec<bool> {
    let t = lvl.t();
    (0..t.num_faces())
        .map(|f| {
            lvl.complete[f]
                && !lvl.hole[f]
                && t.face_vertices(f).iter().any(|&v| follow[v as usize])
        })
        .collect()
}

/// Per vertex: whether a face at it is not a quad (what single-pass plans select around).
fn next_to_non_quads(t: &Topology) -> Vec<bool> {
    (0..t.num_vertices())
        .map(|v| {
            t.vertex_faces(v)
                .iter()
                .any(|&f| t.face_vertices(f as usize).len() != 4)
        })
        .collect()
}

/// The level a sparse step `r` of `lvl` made: its global ids after the parent's, which of its
/// faces are complete (children of selected faces) and holes, each vertex's canonical
/// ancestor. Counts its faces into `refined`; with `follow_semi_sharp`, carries
/// `last_semi_sharp` over to its vertex-vertices.
fn child_level(
    lvl: &Lvl,
    r: SparseRefinement,
    refined: &mut u64,
    follow_semi_sharp: bool,
    last_semi_sharp: &mut Vec<u32>,
) -> Result<Lvl, TopologyError> {
    let t = lvl.t();
    let base = lvl
        .base
        .checked_add(t.num_vertices() as u32)
        .filter(|b| {
            b.checked_add(r.child.topology.num_vertices() as u32)
                .is_some()
        })
        .ok_or(TopologyError::RefinementTooLarge {
            faces: t.num_faces(),
        })?;
    *refined = refined.saturating_add(r.child.topology.num_faces() as u64);
    let maps = r.maps;
    let complete = maps
        .child_face_parent
        .iter()
        .map(|&p| lvl.selected[p as usize])
        .collect();
    let hole = maps
        .child_face_parent
        .iter()
        .map(|&p| lvl.hole[p as usize])
        .collect();
    let anc = maps
        .child_vertex_origin
        .iter()
        .enumerate()
        .map(|(c, o)| match *o {
            ChildOrigin::Vertex(p) => lvl.anc[p as usize],
            _ => base + c as u32,
        })
        .collect();
    if follow_semi_sharp {
        *last_semi_sharp = maps
            .child_vertex_origin
            .iter()
            .map(|o| match *o {
                ChildOrigin::Vertex(p) => last_semi_sharp[p as usize],
                _ => NEVER,
            })
            .collect();
    }
    let kv = maps
        .child_vertex_origin
        .iter()
        .take_while(|o| matches!(o, ChildOrigin::Vertex(_)))
        .count();
    Ok(Lvl {
        topo: r.child,
        base,
        complete,
        hole,
        selected: Vec::new(),
        irregular: Vec::new(),
        anc,
        maps: Some(maps),
        stencils: Some(r.stencils),
        kv,
    })
}

/// Subdominant eigenvalue of Catmull-Clark's smooth subdivision matrix at valence `n`: the
/// factor by which the region around the vertex shrinks per level (1/2 at valence 4).
fn subdominant(n: usize) -> f64 {
    let c = (2.0 * std::f64::consts::PI / n as f64).cos();
    (c + 5.0 + ((c + 9.0) * (c + 1.0)).sqrt()) / 16.0
}

/// First level after the last one at which a vertex carried a semi-sharp feature (0 if never).
fn start(last: u32) -> usize {
    if last == NEVER {
        0
    } else {
        last as usize + 1
    }
}

/// Extra levels for an interior vertex where an infinitely sharp feature makes the limit
/// surface something no polynomial cap follows: a cone (an infinitely sharp corner on fewer
/// than two sharp edges, or a smooth valence-2 vertex: not tangent-plane continuous), a dart
/// (one sharp edge ending there: its characteristic map is not the smooth one the caps'
/// tangents assume), a corner of three or more sharp edges with a sector of several faces, or
/// an irregular crease (two sharp edges, not straight through a valence-4 vertex). Their caps'
/// distance to the surface shrinks by 0.41 to 0.54 per level, from up to 1.8e-3 of the diagonal
/// at isolation 4 (catmark_cube_corner4's cone); six more levels bring the slowest measured,
/// catmark_inf_crease1's corner (9.1e-4, ×0.54), to 3.0e-5 (nearest points to 9×9 points of
/// each cap), and the cone to 8.5e-6. These vertices are rare, so the cost is small on most
/// meshes (none on car, bishop, pawn or spot) and largest on meshes made of such features
/// (catmark_cubes_infsharp 978 → 1518 patches).
pub(super) const FEATURE_EXTRA_LEVELS: usize = 6;

/// Extra levels for a boundary vertex of three or more faces (a regular boundary vertex has
/// two). Its caps converged like an interior vertex's of twice the faces but kept `iso`:
/// catmark_xord_boundary's fans of 3 to 6 faces were 5.9e-5 of the diagonal off the limit at
/// isolation 4, 3.6e-5 with one more level (the GPU capture test); catmark_gregory_test1 to
/// test6 went from at most 3.2e-5 to 1.3e-5.
pub(super) const BOUNDARY_EXTRA_LEVELS: usize = 1;

/// Smallest valence whose end caps are isolated by their reach (see [`cap_depth`]); up to
/// valence 5 the caps meet 5e-5 of the diagonal at isolation 4 on every shape in tests/data.
pub(super) const REACH_MIN_VALENCE: usize = 6;

/// Smooth levels after `start` to which irregular vertex `v` of the current level is isolated
/// when features are followed: `iso` for most vertices, more where an end cap placed after
/// `iso` levels would be far off the limit.
///
/// * An end cap at an extraordinary vertex of valence `n` covers a region that shrinks by
///   `λ_n` ([`subdominant`]) per level, not by 1/2: 0.58 at valence 6, 0.65 at valence 24. From
///   valence [`REACH_MIN_VALENCE`] on, the vertex is isolated until that region is no larger
///   than a regular patch's after `iso` levels, times `6 / n`: `⌈(iso · ln 2 + ln(n / 6)) /
///   −ln λ_n⌉` (6 at valence 6, 8 at valence 10 and 12, 10 at valence 24 for isolation 4). The
///   `6 / n` is there because the caps' error at the same region size grows with the valence:
///   without it catmark_xord_interior's valence-10 and 12 fans stayed at 5.8e-5 and 5.4e-5
///   (levels 6 and 7); with it 2.8e-5. Spot's valence-6 caps went from 6.8e-5 to 1.5e-5 and
///   catmark_bishop's valence-24 poles from 2.0e-4 to 8e-6 of the diagonal.
/// * Interior sharp features whose caps converge slowly get [`FEATURE_EXTRA_LEVELS`] more.
/// * Boundary vertices of three or more faces get [`BOUNDARY_EXTRA_LEVELS`] more.
///
/// Only a handful of faces per level surround such a vertex, so the cost is small: +3.5 % of
/// spot's patches, +2.2 % of catmark_bishop's.
fn cap_depth(lvl: &Lvl, v: usize, iso: usize) -> usize {
    let t = lvl.t();
    let edges = t.vertex_edges(v);
    let n = edges.len();
    let faces = t.vertex_faces(v).len();
    if faces != n {
        return if faces >= 3 {
            iso + BOUNDARY_EXTRA_LEVELS
        } else {
            iso
        };
    }
    let sharp = edges
        .iter()
        .filter(|&&e| lvl.sharp_edge(e as usize))
        .count();
    let vs = lvl.topo.vertex_sharpness[v];
    // Only irregular vertices get here, so a crease is not straight through valence 4.
    let rule = vertex_rule(vs, sharp);
    let slow_feature = match rule {
        Rule::Smooth => n < 3,
        Rule::Dart | Rule::Crease => true,
        // Cones and wide corners; not a semi-sharp vertex (followed until it decays) nor a
        // vertex whose every edge is sharp (each sector a single face).
        Rule::Corner => (is_infinite(vs) || sharp >= 3) && sharp < n,
    };
    if slow_feature {
        return iso + FEATURE_EXTRA_LEVELS;
    }
    if rule != Rule::Smooth || n < REACH_MIN_VALENCE {
        return iso;
    }
    let margin = (n as f64 / REACH_MIN_VALENCE as f64).ln();
    let reach = (iso as f64 * std::f64::consts::LN_2 + margin) / -subdominant(n).ln();
    iso.max(reach.ceil() as usize)
}

/// Whether vertex `v` (of a complete face) needs isolating: see the module docs.
pub(super) fn vertex_irregular(lvl: &Lvl, v: usize) -> bool {
    let t = lvl.t();
    let faces = t.vertex_faces(v);
    let edges = t.vertex_edges(v);
    if faces
        .iter()
        .any(|&f| t.face_vertices(f as usize).len() != 4)
    {
        return true;
    }
    let vs = lvl.topo.vertex_sharpness[v];
    let (nf, ne) = (faces.len(), edges.len());
    let sharp = |e: u32| lvl.sharp_edge(e as usize);
    let infinite =
        |e: u32| t.is_boundary_edge(e as usize) || is_infinite(lvl.topo.edge_sharpness[e as usize]);
    if ne == nf {
        if vs > 0.0 || ne != 4 {
            return true;
        }
        let mut sharp_edges = edges.iter().copied().filter(|&e| sharp(e));
        match (sharp_edges.next(), sharp_edges.next(), sharp_edges.next()) {
            (None, _, _) => false,
            (Some(a), Some(b), None) => {
                if !(infinite(a) && infinite(b)) {
                    return true;
                }
                // Consecutive edges share a face; a regular crease runs straight through.
                let fa = t.edge_faces(a as usize);
                let fb = t.edge_faces(b as usize);
                fa.iter().any(|&x| x != INVALID && fb.contains(&x))
            }
            _ => true,
        }
    } else if ne == nf + 1 {
        match nf {
            2 => {
                vs > 0.0
                    || edges.iter().any(|&e| {
                        let boundary = t.is_boundary_edge(e as usize);
                        boundary != sharp(e) || (boundary && !infinite(e))
                    })
            }
            1 => !is_infinite(vs),
            _ => true,
        }
    } else {
        true
    }
}
