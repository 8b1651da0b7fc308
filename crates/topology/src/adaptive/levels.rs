//! Levels of the plan: scaled sharpness, sparse refinement level by level, irregular
//! vertices and the selection (see the parent module for the design).

use super::*;

/// A copy of `mesh` with tag sharpness scaled (infinite tags stay infinite); rejects NaN or
/// negative sharpness.
pub(super) fn scaled_mesh(mesh: &ControlMesh, scale: f32) -> Result<ControlMesh, TopologyError> {
    let scale_one = |s: f32| {
        if is_infinite(s) {
            s
        } else {
            s * scale
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

/// Deepest level semi-sharp features are followed to: sharpness 10 is infinite, so every
/// finite sharpness has decayed by then (uniform or Chaikin).
pub(super) const SEMI_SHARP_LIMIT: usize = 10;

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
/// (at most [`SEMI_SHARP_LIMIT`] in all), so the patches beside a crease of sharpness 7.5 are
/// exact instead of treating the leftover sharpness as infinite. The `iso` levels after the
/// decay are what every other irregular vertex gets: an end cap placed on the level where a
/// crease just decayed sits on a net that has had no smooth step yet, and its error does not
/// shrink with the isolation level (catmark_bishop's caps at its sharpness-6 rims were
/// 6.3e-4 of the diagonal at isolation 4, 5 and 6 alike). Faces that stop being selected at
/// or past `iso` while still irregular become end caps at their level.
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
    let mut levels = vec![Lvl {
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
    }];
    // Refined faces held so far (every level past 0); see "Size bound" in the module docs.
    let mut refined = 0u64;
    // Per vertex of the current level: the last level at which it carried a semi-sharp feature
    // (`NEVER` if it never did).
    let mut last_semi_sharp = vec![NEVER; nv];
    let deepest = if follow_semi_sharp {
        SEMI_SHARP_LIMIT.max(iso)
    } else {
        iso
    };
    for l in 0..=deepest {
        let last = l == deepest;
        let lvl = levels.last_mut().expect("level present");
        if last {
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
        // Only the vertices of complete faces are ever asked (patches, the selection and the
        // end-cap projection are made of complete faces); the rest of a level is its one-ring.
        let mut asked = vec![false; lvl.t().num_vertices()];
        for f in 0..lvl.t().num_faces() {
            if lvl.complete[f] && !lvl.hole[f] {
                for &v in lvl.t().face_vertices(f) {
                    asked[v as usize] = true;
                }
            }
        }
        let irregular: Vec<bool> = (0..lvl.t().num_vertices())
            .into_par_iter()
            .with_min_len(1024)
            .map(|v| asked[v] && vertex_irregular(lvl, v))
            .collect();
        lvl.irregular = irregular;
        // Past the isolation level only semi-sharp features are followed.
        let follow: Vec<bool> = if single_pass {
            let t = lvl.t();
            (0..t.num_vertices())
                .map(|v| {
                    t.vertex_faces(v)
                        .iter()
                        .any(|&f| t.face_vertices(f as usize).len() != 4)
                })
                .collect()
        } else {
            if follow_semi_sharp {
                for (v, last) in last_semi_sharp.iter_mut().enumerate() {
                    if lvl.irregular[v] && semi_sharp(lvl, v) {
                        *last = l as u32;
                    }
                }
            }
            (0..lvl.t().num_vertices())
                .map(|v| {
                    lvl.irregular[v]
                        && (l < iso
                            || (follow_semi_sharp
                                && last_semi_sharp[v] != NEVER
                                && l < last_semi_sharp[v] as usize + 1 + iso))
                })
                .collect()
        };
        let t = &lvl.topo.topology;
        lvl.selected = (0..t.num_faces())
            .map(|f| {
                !last
                    && lvl.complete[f]
                    && !lvl.hole[f]
                    && t.face_vertices(f).iter().any(|&v| follow[v as usize])
            })
            .collect();
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
        let r = refine_sparse(
            lvl.topo.view(),
            Scheme::CatmullClark,
            &mesh.options,
            &selection,
        )?;
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
        refined = refined.saturating_add(r.child.topology.num_faces() as u64);
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
            last_semi_sharp = maps
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
        levels.push(Lvl {
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
        });
    }
    Ok(levels)
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
