//! Assembly: patches per level, local points, canonical corners, transitions and curves.

use super::levels::Lvl;
use super::nets::*;
use super::*;

/// Rows per parallel chunk of local points.
pub(super) const CHUNK: usize = 2048;

/// Numbered local points.
pub(super) struct Locals {
    pub(super) first: u32,
    pub(super) table: StencilTable,
}

impl Locals {
    /// Append the rows of `table` (built by [`push_row`]); returns the id of its first row.
    pub(super) fn append(&mut self, table: &StencilTable) -> u32 {
        let id = self.first + self.table.len() as u32;
        let shift = self.table.indices.len() as u32;
        self.table.indices.extend_from_slice(&table.indices);
        self.table.weights.extend_from_slice(&table.weights);
        self.table
            .offsets
            .extend(table.offsets[1..].iter().map(|&o| o + shift));
        id
    }
    /// Appends the rows `build` makes for each item (in item order), built in parallel chunks
    /// of [`CHUNK`] items. Chunks run in rounds of two per thread into tables reused from round
    /// to round: each round is copied out of warm memory, and no chunk table is allocated and
    /// faulted in anew (a fresh table per chunk: catmark_car's plan 108 → 116 ms).
    pub(super) fn append_par<T: Sync, S: Send>(
        &mut self,
        items: &[T],
        scratch: impl Fn() -> S + Sync,
        build: impl Fn(&T, &mut S, &mut StencilTable) + Sync,
    ) {
        let per_round = 2 * rayon::current_num_threads().max(1);
        let mut tables: Vec<(S, StencilTable)> = Vec::new();
        for round in items.chunks(per_round * CHUNK) {
            let chunks: Vec<&[T]> = round.chunks(CHUNK).collect();
            while tables.len() < chunks.len() {
                tables.push((scratch(), StencilTable::default()));
            }
            tables
                .par_iter_mut()
                .zip(chunks.par_iter())
                .for_each(|((s, table), chunk)| {
                    table.clear();
                    for item in chunk.iter() {
                        build(item, s, table);
                    }
                });
            for (_, table) in &tables[..chunks.len()] {
                self.append(table);
            }
        }
    }
}

/// Faces per chunk of the patch pass.
const PATCH_CHUNK: usize = 1024;

/// One chunk of the patch pass: its local points' rows, which of each patch's control points
/// are ids of those rows (bit per slot), the first failure, and scratch terms.
struct PatchChunk {
    table: StencilTable,
    table_len0: usize,
    masks: Vec<u32>,
    error: Option<TopologyError>,
    scratch: Scratch,
}

/// What a chunk of the patch pass reuses from face to face.
struct Scratch {
    terms: Vec<(u32, f64)>,
    /// An end cap's point rows, reused from cap to cap.
    rows: PointRows,
    /// The frames of the faces last met, per level.
    frames: FrameMemo,
}

/// Appends an end cap's point rows to `table` as local points and sets its control points to
/// their ids relative to `rel0`, except each corner's `P` (the canonical corner, numbered
/// later). Point `k` is row `order(k)` of `rows`, its ids shifted by `base` (Gregory points are
/// built in face corner order over the level's vertices: rotated and made global here, without
/// a copy of the rows in patch order). Returns the slots that hold such ids.
fn number_rows(
    patch: &mut AdaptivePatch,
    rows: &PointRows,
    order: impl Fn(usize) -> usize,
    base: u32,
    table: &mut StencilTable,
    rel0: usize,
    terms: &mut Vec<(u32, f64)>,
) -> u32 {
    let corners = patch.kind.corners();
    let mut cps = ControlPoints::with_capacity(rows.len());
    let mut mask = 0u32;
    for k in 0..rows.len() {
        if k < 5 * corners && k % 5 == 0 {
            cps.push(INVALID);
        } else {
            terms.clear();
            terms.extend(rows.row(order(k)).iter().map(|&(i, w)| (i + base, w)));
            cps.push((table.len() - rel0) as u32);
            push_row(table, terms);
            mask |= 1 << k;
        }
    }
    patch.control_points = cps;
    mask
}

/// Bound on the Gregory points' projected stencil terms (~0.8 GB as the plan's table, more
/// while drafted and uploaded): the 1M-triangle grid under Catmull-Clark projects 5.7e8.
pub const MAX_LOCAL_TERMS: u64 = 1 << 26;

/// Projects the Gregory points' terms before any is built: per end-cap face, five points per
/// corner, each about the corner's one-ring (`2·valence + 1` vertices). The estimate came within
/// 10 % of the built count on the meshes measured (docs/benchmarks.md, Scale).
pub(super) fn check_gregory_size(
    mesh: &ControlMesh,
    levels: &[Lvl],
    iso: usize,
    bound: u64,
) -> Result<(), TopologyError> {
    let (patches, estimate) = project_gregory_terms(levels, iso);
    if estimate > bound {
        return Err(TopologyError::GregoryTooLarge {
            faces: mesh.num_faces(),
            patches,
            estimate,
            bound,
        });
    }
    Ok(())
}

/// Gregory end caps from level `iso` on and their projected point-stencil terms.
pub(super) fn project_gregory_terms(levels: &[Lvl], iso: usize) -> (u64, u64) {
    let (mut patches, mut estimate) = (0u64, 0u64);
    for lvl in levels.iter().skip(iso) {
        let t = lvl.t();
        let (p, e) = (0..t.num_faces())
            .into_par_iter()
            .with_min_len(4096)
            .filter(|&f| lvl.complete[f] && !lvl.hole[f] && !lvl.selected[f])
            .filter(|&f| {
                t.face_vertices(f)
                    .iter()
                    .any(|&v| lvl.irregular[v as usize])
            })
            .map(|f| {
                let terms: u64 = t
                    .face_vertices(f)
                    .iter()
                    .map(|&v| 5 * (2 * t.vertex_edges(v as usize).len() as u64 + 1))
                    .sum();
                (1u64, terms)
            })
            .reduce(|| (0, 0), |a, b| (a.0 + b.0, a.1 + b.1));
        patches += p;
        estimate += e;
    }
    (patches, estimate)
}

/// The plan from the refined levels, in the steps of the module documentation: the patches,
/// level by level, with their local points ([`PatchPass::draft_patches`]); the canonical
/// corners and the curves of the patch edges, in one walk over the patches
/// ([`Canonical::walk`]), then numbered for good; the corners' limit rows; the statistics; and
/// the levels' stencil blocks.
///
/// `caps_from`: the first level whose irregular faces become end caps (the isolation level;
/// 0 for single-pass plans). `acc`: irregular faces in ACC-1's scope get ACC-1's Bézier net
/// instead of Gregory points (see [`super::single_pass`]). `triangles`: level-0 triangles
/// become one Gregory triangle patch each.
pub(super) fn assemble(
    mesh: &ControlMesh,
    opts: &AdaptiveOptions,
    mut levels: Vec<Lvl>,
    caps_from: usize,
    acc: bool,
    triangles: bool,
) -> Result<AdaptivePlan, TopologyError> {
    let tri = triangle_patch_faces(&levels, triangles);
    let last = levels.last().expect("levels");
    let first_local = last.base + last.t().num_vertices() as u32;
    let mut locals = Locals {
        first: first_local,
        table: StencilTable {
            offsets: vec![0],
            num_sources: first_local as usize,
            ..StencilTable::default()
        },
    };

    if opts.end_cap == EndCap::Gregory {
        check_gregory_size(mesh, &levels, caps_from, MAX_LOCAL_TERMS)?;
    }
    let pass = PatchPass {
        mesh,
        opts,
        levels: &levels,
        tri: &tri,
        caps_from,
        acc,
    };
    let (mut patches, sites) = pass.draft_patches(&mut locals)?;

    let first_canon = first_local + locals.table.len() as u32;
    let Corners {
        corner_owners,
        curves,
        curve_owners,
        first_regular_corner,
        first_curve_point,
    } = number_corners_and_curves(mesh, &levels, &tri, &sites, &mut patches, &mut locals)?;

    let level_stats = level_stats(&levels, &patches);
    let steps = stencil_blocks(&mut levels);
    let num_vertices = u32::try_from(curves.len())
        .ok()
        .and_then(|n| n.checked_mul(2))
        .and_then(|n| n.checked_add(first_curve_point))
        .ok_or(TopologyError::RefinementTooLarge {
            faces: mesh.num_faces(),
        })?;
    Ok(AdaptivePlan {
        num_base_vertices: levels[0].t().num_vertices() as u32,
        num_vertices,
        steps,
        local_points: StencilBlock {
            first_vertex: first_local,
            table: locals.table,
        },
        patches,
        curves,
        curve_owners,
        first_curve_point,
        first_regular_corner,
        first_corner: first_canon,
        corner_owners,
        level_stats,
        isolation: opts.isolation,
    })
}

/// The canonical corners and curves of the drafted patches, numbered: the end caps' corners
/// set, the corners' limit rows appended to the local points.
struct Corners {
    corner_owners: Vec<[u32; 2]>,
    curves: Vec<[u32; 4]>,
    curve_owners: Vec<CurveOwner>,
    first_regular_corner: u32,
    first_curve_point: u32,
}

/// The canonical corners and the curves of the patch edges ([`Canonical`]): the walk over the
/// patches, the lookups that waited for its end, the final ids, and the limit rows of the
/// corners that have one, appended to `locals`.
fn number_corners_and_curves(
    mesh: &ControlMesh,
    levels: &[Lvl],
    tri: &[bool],
    sites: &[PatchSite],
    patches: &mut [AdaptivePatch],
    locals: &mut Locals,
) -> Result<Corners, TopologyError> {
    let first_canon = locals.first + locals.table.len() as u32;
    let mut canonical = Canonical::new(levels, locals.first, patches.len());
    let walk = canonical.walk(levels, tri, sites, patches);
    // Final ids: the rows' corners in meeting order, then the regular ones in meeting order.
    let rows = canonical.row_owners.len() as u32;
    let regular_corners = canonical.regular_owners.len() as u32;
    if rows >= REGULAR || regular_corners >= REGULAR - 1 {
        return Err(TopologyError::RefinementTooLarge {
            faces: mesh.num_faces(),
        });
    }
    // The waiting lookups come before the walk's failure, if any.
    canonical.resolve_pending(levels, sites, patches)?;
    walk?;
    let ids = FinalIds {
        first_canon,
        first_regular_corner: first_canon + rows,
    };
    let Canonical {
        canon,
        row_owners,
        regular_owners,
        needed,
        cap_corners,
        pending: _,
        curve_of,
        mut curves,
        owners,
    } = canonical;
    number_cap_corners(patches, &cap_corners, ids);
    drop(cap_corners);
    let corner_owners = merge_corner_owners(row_owners, regular_owners);
    append_limit_rows(locals, levels, &needed);
    debug_assert_eq!(
        locals.first + locals.table.len() as u32,
        ids.first_regular_corner
    );

    if let Some(o) = owners.iter().find(|o| o.rank() == u8::MAX) {
        // A sibling half no patch has as its own edge: a level jump next to this patch.
        return Err(TopologyError::AdaptiveUnbalanced {
            level: patches[o.patch() as usize].level as u32,
            face: sites[o.patch() as usize].face as usize,
        });
    }
    drop(curve_of);
    drop(canon);
    let curve_owners = curve_owners(owners, patches);
    // The curves' inner points follow the regular corners: two per curve, in curve order,
    // which the device computes from their owners' control points every frame (no stencil
    // rows).
    let first_curve_point = ids.first_regular_corner + regular_corners;
    number_curves(&mut curves, ids, first_curve_point);

    Ok(Corners {
        corner_owners,
        curves,
        curve_owners,
        first_regular_corner: ids.first_regular_corner,
        first_curve_point,
    })
}

/// Per level-0 face, whether it is drawn as one Gregory triangle patch (single-pass plans with
/// `triangles`). Such triangles are selected (so level 1 holds their corners' complete
/// all-quad rings, where their points are built) but their children make no patches.
fn triangle_patch_faces(levels: &[Lvl], triangles: bool) -> Vec<bool> {
    let l0 = &levels[0];
    (0..l0.t().num_faces())
        .map(|f| {
            triangles
                && levels.len() > 1
                && l0.t().face_vertices(f).len() == 3
                && l0.selected[f]
                && !l0.hole[f]
        })
        .collect()
}

/// Whether face `f` of level `l` is a child of a triangle patch's face (`tri`).
fn triangle_child(levels: &[Lvl], tri: &[bool], l: usize, f: usize) -> bool {
    l == 1
        && levels[1]
            .maps
            .as_ref()
            .is_some_and(|m| tri[m.child_face_parent[f] as usize])
}

/// What the patch pass reads: the mesh, the options and the levels, which level-0 faces are
/// triangle patches, the first level of end caps and whether ACC-1 nets replace Gregory
/// points where they can.
struct PatchPass<'a> {
    mesh: &'a ControlMesh,
    opts: &'a AdaptiveOptions,
    levels: &'a [Lvl],
    tri: &'a [bool],
    caps_from: usize,
    acc: bool,
}

impl PatchPass<'_> {
    /// The faces of each level that make a patch: complete, not a hole, not selected, not a
    /// triangle patch's child; and the triangle patches' faces at level 0.
    fn candidates(&self) -> Vec<Vec<u32>> {
        self.levels
            .iter()
            .enumerate()
            .map(|(l, lvl)| {
                (0..lvl.t().num_faces() as u32)
                    .filter(|&f| {
                        let f = f as usize;
                        (lvl.complete[f]
                            && !lvl.hole[f]
                            && !lvl.selected[f]
                            && !triangle_child(self.levels, self.tri, l, f))
                            || (l == 0 && self.tri[f])
                    })
                    .collect()
            })
            .collect()
    }

    /// Patches, level by level (faces in parallel), written in place into the plan's list: a
    /// regular patch with its 16 gathered ids (`INVALID` where a phantom goes), an end cap
    /// with its local points' ids but not yet its corners, each with its face and rotation in
    /// the returned sites. The candidates of every level are counted first, so the list is
    /// allocated once.
    fn draft_patches(
        &self,
        locals: &mut Locals,
    ) -> Result<(Vec<AdaptivePatch>, Vec<PatchSite>), TopologyError> {
        let candidates = self.candidates();
        let total: usize = candidates.iter().map(Vec::len).sum();
        let mut patches: Vec<AdaptivePatch> = Vec::with_capacity(total);
        let mut sites: Vec<PatchSite> = Vec::with_capacity(total);
        // Local points (phantoms, Gregory points, canonical corners) come to 2 to 7 rows and 15
        // to 29 terms per patch on every shape in tests/data (catmark_car 2.7 and 15.3, spot 2.8
        // and 22.8): reserve once, with room to spare, instead of regrowing (a regrowth copies
        // MBs). Pages never written are never faulted in, so the spare room costs address space
        // only.
        locals.table.offsets.reserve(8 * total);
        locals.table.indices.reserve(32 * total);
        locals.table.weights.reserve(32 * total);
        // Sized once for the largest level that drafts patches: growing it level by level
        // copied and faulted in each level's records anew.
        let mut quads: Vec<QuadRec> = Vec::with_capacity(
            self.levels
                .iter()
                .zip(&candidates)
                .filter(|(_, faces)| !faces.is_empty())
                .map(|(lvl, _)| lvl.t().num_faces())
                .max()
                .unwrap_or(0),
        );
        // Chunk tables of local rows, reused from round to round (see `PatchChunk`).
        let mut chunks: Vec<PatchChunk> = Vec::new();
        for (l, (lvl, faces)) in self.levels.iter().zip(&candidates).enumerate() {
            if !faces.is_empty() {
                quad_records(lvl, &mut quads);
            }
            let level = LevelPatches {
                pass: self,
                l,
                lvl,
                quads: &quads,
                // End caps from the isolation level on (deeper levels follow semi-sharp
                // features).
                is_last: l >= self.caps_from,
            };
            level.draft(faces, &mut patches, &mut sites, &mut chunks, locals)?;
        }
        Ok((patches, sites))
    }
}

/// The patch pass at one level: its faces' patches and local points.
struct LevelPatches<'a> {
    pass: &'a PatchPass<'a>,
    l: usize,
    lvl: &'a Lvl,
    /// The level's quad records, for gathering regular patches.
    quads: &'a [QuadRec],
    /// Irregular faces become end caps (else they are an error: they should be selected).
    is_last: bool,
}

impl LevelPatches<'_> {
    /// The patches of `faces`, appended to `patches` and `sites`, their local points to
    /// `locals`. Rounds of chunks of faces, two per thread, each writing its patches in place
    /// and its local points' rows into a chunk table; then, in face order, each chunk's rows
    /// are appended to the local points and its patches' local ids numbered. The rows are
    /// numbered in patch order, as one pass over the patches would, and each end cap's rows die
    /// with its chunk's round instead of waiting for the whole list (catmark_car: 3 MB). On one
    /// thread the rows go straight into the local points.
    fn draft(
        &self,
        faces: &[u32],
        patches: &mut Vec<AdaptivePatch>,
        sites: &mut Vec<PatchSite>,
        chunks: &mut Vec<PatchChunk>,
        locals: &mut Locals,
    ) -> Result<(), TopologyError> {
        let threads = rayon::current_num_threads().max(1);
        let direct = threads == 1;
        let per_round = if direct { 1 } else { 2 * threads };
        for round in faces.chunks(per_round * PATCH_CHUNK) {
            let first = patches.len();
            patches.extend((0..round.len()).map(|_| placeholder_patch()));
            sites.extend(round.iter().map(|&face| PatchSite { face, shift: 0 }));
            let parts: Vec<&[u32]> = round.chunks(PATCH_CHUNK).collect();
            while chunks.len() < parts.len() {
                chunks.push(PatchChunk {
                    table: StencilTable::default(),
                    table_len0: 0,
                    masks: Vec::new(),
                    error: None,
                    scratch: Scratch {
                        terms: Vec::new(),
                        rows: PointRows::default(),
                        frames: FrameMemo::new(self.pass.levels.len()),
                    },
                });
            }
            let (out, out_sites) = (&mut patches[first..], &mut sites[first..]);
            if direct {
                let c = &mut chunks[0];
                c.table_len0 = locals.table.len();
                self.draft_chunk(c, &mut locals.table, out, out_sites, parts[0]);
            } else {
                chunks[..parts.len()]
                    .par_iter_mut()
                    .zip(out.par_chunks_mut(PATCH_CHUNK))
                    .zip(out_sites.par_chunks_mut(PATCH_CHUNK))
                    .zip(parts.par_iter())
                    .for_each(|(((c, out), out_sites), part)| {
                        let mut table = std::mem::take(&mut c.table);
                        table.clear();
                        c.table_len0 = 0;
                        self.draft_chunk(c, &mut table, out, out_sites, part);
                        c.table = table;
                    });
            }
            number_round(&mut chunks[..parts.len()], patches, first, locals, direct)?;
        }
        Ok(())
    }

    /// The patches of the faces `part` into `out` and `out_sites`, their local points' rows
    /// into `table`; per patch the mask of its slots that hold those rows' ids (relative to
    /// the table's length on entry), or the chunk's first failure.
    fn draft_chunk(
        &self,
        c: &mut PatchChunk,
        table: &mut StencilTable,
        out: &mut [AdaptivePatch],
        out_sites: &mut [PatchSite],
        part: &[u32],
    ) {
        c.masks.clear();
        c.error = None;
        let rel0 = table.len();
        for ((slot, site), &f) in out.iter_mut().zip(out_sites.iter_mut()).zip(part) {
            match self.patch(f as usize, slot, table, rel0, &mut c.scratch) {
                Ok((mask, shift)) => {
                    site.shift = shift;
                    c.masks.push(mask);
                }
                Err(e) => {
                    // The first failing face of the chunk; chunks are checked in order.
                    c.error = Some(e);
                    return;
                }
            }
        }
    }

    /// One patch, written in place into its slot of the plan's list (no copy of the patch per
    /// face): its control points, with its local points' rows appended to `table` (their ids
    /// relative to `rel0`, marked in the returned mask for the caller to number), and its
    /// rotation.
    fn patch(
        &self,
        f: usize,
        patch: &mut AdaptivePatch,
        table: &mut StencilTable,
        rel0: usize,
        scratch: &mut Scratch,
    ) -> Result<(u32, u8), TopologyError> {
        let (l, lvl) = (self.l, self.lvl);
        let levels = self.pass.levels;
        if l == 0 && self.pass.tri[f] {
            let rows;
            (*patch, rows) = triangle_patch(self.pass.mesh, levels, f)?;
            let mask = number_rows(patch, &rows, |k| k, 0, table, rel0, &mut scratch.terms);
            return Ok((mask, 0));
        }
        let irregular = lvl
            .t()
            .face_vertices(f)
            .iter()
            .any(|&v| lvl.irregular[v as usize]);
        if irregular && !self.is_last {
            return Err(TopologyError::AdaptivePatch {
                level: l as u32,
                face: f,
            });
        }
        let Frame {
            base: base_face,
            sub: sub_face,
            origin,
            size,
            shift,
            ..
        } = scratch.frames.frame(levels, l, f);
        *patch = AdaptivePatch {
            kind: PatchKind::Regular,
            level: l as u8,
            control_points: ControlPoints::new(),
            base_face,
            sub_face,
            origin,
            size,
            boundary_mask: 0,
            transition_mask: 0,
            edges: [BLANK_EDGE; 4],
            reparam_valences: [0; 4],
            tangent_valences: [0; 4],
        };
        let mask = if irregular {
            self.end_cap(f, shift, patch, table, rel0, scratch)?
        } else {
            self.regular_patch(f, shift, patch, table, rel0)?
        };
        Ok((mask, shift))
    }

    /// An end cap on face `f` (rotated by `shift`): Gregory points (or an ACC-1 net) as local
    /// points, or a bilinear patch's four corners (numbered later); its sharp edges in the
    /// boundary mask. Returns the slots that hold local ids.
    fn end_cap(
        &self,
        f: usize,
        shift: u8,
        patch: &mut AdaptivePatch,
        table: &mut StencilTable,
        rel0: usize,
        scratch: &mut Scratch,
    ) -> Result<u32, TopologyError> {
        let (lvl, mesh) = (self.lvl, self.pass.mesh);
        let (terms, rows) = (&mut scratch.terms, &mut scratch.rows);
        let mut mask = 0;
        patch.kind = match self.pass.opts.end_cap {
            EndCap::Gregory => PatchKind::Gregory,
            EndCap::Bilinear => PatchKind::Bilinear,
        };
        if patch.kind == PatchKind::Gregory {
            match self.pass.acc.then(|| acc_points(mesh, lvl, f, shift)) {
                Some(Ok(points)) => {
                    // An ACC-1 net: its corners' valences shade it; no reparameterization is
                    // fitted to it.
                    patch.tangent_valences = rotated(lvl.t(), f, shift)
                        .0
                        .map(|v| lvl.t().vertex_edges(v as usize).len().min(255) as u8);
                    mask = number_rows(patch, &points, |k| k, 0, table, rel0, terms);
                }
                _ => {
                    patch.reparam_valences = reparam_valences(lvl, f, shift);
                    gregory_face_rows(mesh, lvl, f, rows)?;
                    // Patch corner p is face corner p + shift.
                    let s = shift as usize;
                    let order = |k: usize| 5 * ((k / 5 + s) % 4) + k % 5;
                    mask = number_rows(patch, rows, order, lvl.base, table, rel0, terms);
                }
            }
        } else {
            patch.control_points = ControlPoints::from_elem(INVALID, 4);
        }
        // The end cap handles its sharp edges itself; the mask says which.
        let (_, fe) = rotated(lvl.t(), f, shift);
        for (p, &e) in fe.iter().enumerate() {
            if lvl.sharp_edge(e as usize) {
                patch.boundary_mask |= 1 << p;
            }
        }
        Ok(mask)
    }

    /// A regular patch on face `f` (rotated by `shift`): its 16 gathered points, phantom points
    /// past a boundary or infinitely sharp edge as local points. Returns the slots that hold
    /// local ids.
    fn regular_patch(
        &self,
        f: usize,
        shift: u8,
        patch: &mut AdaptivePatch,
        table: &mut StencilTable,
        rel0: usize,
    ) -> Result<u32, TopologyError> {
        // The error is built only on failure (it has a destructor to run otherwise).
        let not_regular = || TopologyError::AdaptivePatch {
            level: self.l as u32,
            face: f,
        };
        let Some((ids, boundary)) = gather_regular(self.lvl, self.quads, f, shift) else {
            return Err(not_regular());
        };
        patch.control_points = ControlPoints::from_buf(ids);
        patch.boundary_mask = boundary;
        if boundary == 0 && !ids.contains(&INVALID) {
            return Ok(0);
        }
        // Phantom points past the boundary: extrapolated local points.
        let row = |terms: &mut [(u32, f64)]| {
            let id = (table.len() - rel0) as u32;
            push_short_row(table, terms);
            id
        };
        phantom_points(&ids, boundary, &mut patch.control_points, row).ok_or_else(not_regular)
    }
}

/// After a round of chunks, in face order: the first failure, else each chunk's rows appended
/// to the local points (on one thread they are there already) and its patches' local ids made
/// global.
fn number_round(
    chunks: &mut [PatchChunk],
    patches: &mut [AdaptivePatch],
    first: usize,
    locals: &mut Locals,
    direct: bool,
) -> Result<(), TopologyError> {
    for (k, c) in chunks.iter_mut().enumerate() {
        if let Some(e) = c.error.take() {
            return Err(e);
        }
        let offset = if direct {
            locals.first + c.table_len0 as u32
        } else {
            locals.append(&c.table)
        };
        let at = first + k * PATCH_CHUNK;
        for (p, &mask) in patches[at..at + c.masks.len()].iter_mut().zip(&c.masks) {
            let mut m = mask;
            while m != 0 {
                let slot = m.trailing_zeros() as usize;
                p.control_points[slot] += offset;
                m &= m - 1;
            }
        }
    }
    Ok(())
}

/// Marks a provisional corner id of a corner first met on a regular patch (the others are
/// the rows' corners).
const REGULAR: u32 = 1 << 31;

/// The canonical corners and the curves of the patch edges, made in one walk over the patches
/// (module documentation, "Canonical corners and curves").
///
/// Each canonical corner is numbered at the coarsest level where it is a patch corner
/// (patches are level-ordered). A corner first met on a regular patch is a regular vertex,
/// and its limit point is the B-spline patch's value at that corner: the smooth valence-4
/// mask over the patch's 3×3 points there, phantoms included (across a boundary or crease
/// they reproduce the crease and corner limit rules exactly). No stencil row is planned for
/// it: the device evaluates it from the patch each frame, as it does the curves, so it is
/// numbered after the local points. The others get limit-stencil rows at the end of the
/// local points. The walk numbers them provisionally in meeting order, per class; they are
/// made final ([`FinalIds`]) with the rows' corners first and the regular ones after,
/// contiguous from the first canonical id.
///
/// The same walk does the patches' edges (neighbour levels, balance, curves) on the
/// provisional ids: they map to the final ones monotonically (rows' corners, then `REGULAR`
/// ones), so the ends' order, `reversed` and the owners' directions are the same; the
/// curves' ends are made final at the end. A coarse edge's midpoint is a corner of a finer
/// patch, met later: its lookups wait in `pending` until the walk is done.
struct Canonical {
    /// Per vertex-vertex ancestor (a vertex of any level, by its coarsest ancestor): its
    /// provisional corner id, `INVALID` until met.
    canon: Vec<u32>,
    /// The owner (patch, corner) of each corner with a limit row, in meeting order.
    row_owners: Vec<[u32; 2]>,
    /// The owner of each regular corner (no row), in meeting order.
    regular_owners: Vec<[u32; 2]>,
    /// Per row corner: the level and vertex whose limit stencil is its row.
    needed: Vec<(u8, u32)>,
    /// End caps' corners (provisional): their control points get the final ids at the end.
    cap_corners: Vec<(u32, [u32; 4])>,
    /// Lookups waiting for the walk's end.
    pending: Vec<Pending>,
    /// Per level and edge, its curve (`INVALID`: none yet).
    curve_of: Vec<Vec<u32>>,
    /// Each curve's points: its ends (provisional corner ids) and two inner points.
    curves: Vec<[u32; 4]>,
    /// Each curve's owner so far.
    owners: Vec<Owner>,
}

impl Canonical {
    fn new(levels: &[Lvl], first_local: u32, patches: usize) -> Canonical {
        let canon = vec![INVALID; first_local as usize];
        // About 1.2 corners per patch on catmark_car: reserved so they are not regrown (a
        // regrowth copies and faults in both); the rows' owners get room for all, as the
        // plan's corner owners are they followed by the regular ones.
        let row_owners = Vec::with_capacity(patches * 5 / 4);
        let regular_owners = Vec::with_capacity(patches * 5 / 4);
        let curve_of = levels
            .iter()
            .map(|l| vec![INVALID; l.t().num_edges()])
            .collect();
        let curves: Vec<[u32; 4]> = Vec::with_capacity(patches * 5 / 2);
        let owners = Vec::with_capacity(curves.capacity());
        Canonical {
            canon,
            row_owners,
            regular_owners,
            needed: Vec::new(),
            cap_corners: Vec::new(),
            pending: Vec::new(),
            curve_of,
            curves,
            owners,
        }
    }

    /// The curve of edge `e` of level `l`, made with `ends` (`INVALID` ones wait in
    /// `pending`); `owner` takes it if it ranks before its owner so far.
    fn curve_id(&mut self, l: usize, e: u32, ends: [u32; 2], owner: Owner) -> u32 {
        let slot = &mut self.curve_of[l][e as usize];
        if *slot == INVALID {
            *slot = self.curves.len() as u32;
            let (a, b) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
            self.curves.push([a, INVALID, INVALID, b]);
            self.owners.push(owner);
        } else if owner < self.owners[*slot as usize] {
            self.owners[*slot as usize] = owner;
        }
        *slot
    }

    /// The provisional corner id of vertex `v` of level `l` (`INVALID`: not met yet).
    fn canon_at(&self, levels: &[Lvl], l: usize, v: u32) -> u32 {
        self.canon[levels[l].anc[v as usize] as usize]
    }

    /// The walk over the patches in list order: each patch's canonical corners, then its
    /// edges.
    fn walk(
        &mut self,
        levels: &[Lvl],
        tri: &[bool],
        sites: &[PatchSite],
        patches: &mut [AdaptivePatch],
    ) -> Result<(), TopologyError> {
        for (pi, (site, patch)) in sites.iter().zip(patches.iter_mut()).enumerate() {
            let lvl = &levels[patch.level as usize];
            let (fv, fe, n) = patch_corners(lvl, patch.kind, *site);
            let ids = self.number_corners(levels, pi, *site, patch, &fv[..n], &fe)?;
            let walk = EdgeWalk {
                levels,
                tri,
                pi,
                site: *site,
                fv,
                fe,
                n,
                ids,
            };
            for p in 0..n {
                walk.edge(self, patch, p)?;
            }
        }
        Ok(())
    }

    /// The provisional ids of a patch's corners `fv` (in patch order), numbering those met
    /// for the first time, with the limit rows they need; a triangle patch's edge midpoints
    /// (of its edges `fe`) too.
    fn number_corners(
        &mut self,
        levels: &[Lvl],
        pi: usize,
        site: PatchSite,
        patch: &AdaptivePatch,
        fv: &[u32],
        fe: &[u32; 4],
    ) -> Result<[u32; 4], TopologyError> {
        let (lv, pk) = (patch.level, patch.kind);
        let lvl = &levels[lv as usize];
        let regular = pk == PatchKind::Regular;
        let mut ids = [INVALID; 4];
        for (p, &v) in fv.iter().enumerate() {
            let key = lvl.anc[v as usize] as usize;
            if self.canon[key] == INVALID {
                let owner = [pi as u32, p as u32];
                self.canon[key] = if regular {
                    // No row: evaluated from this patch.
                    self.regular_owners.push(owner);
                    REGULAR | (self.regular_owners.len() as u32 - 1)
                } else {
                    self.row_owners.push(owner);
                    if pk == PatchKind::GregoryTriangle {
                        // The limit mask needs an all-quad ring: the vertex's child's, at
                        // level 1.
                        let maps = level1_maps(levels, site.face)?;
                        self.needed.push((1, maps.vertex_child_vertex[v as usize]));
                    } else {
                        self.needed.push((lv, v));
                    }
                    self.row_owners.len() as u32 - 1
                };
            }
            ids[p] = self.canon[key];
        }
        if pk == PatchKind::GregoryTriangle {
            // Its edges are level-1 halves (see `triangle_draft`): the edge midpoints are
            // canonical corners too; a triangle owning one says so by corner index 4 + edge.
            let maps = level1_maps(levels, site.face)?;
            let l1 = &levels[1];
            for (p, &e) in fe[..3].iter().enumerate() {
                let m = maps.edge_child_vertex[e as usize];
                if m == INVALID {
                    continue;
                }
                let key = l1.anc[m as usize] as usize;
                if self.canon[key] == INVALID {
                    self.row_owners.push([pi as u32, 4 + p as u32]);
                    self.canon[key] = self.row_owners.len() as u32 - 1;
                    self.needed.push((1, m));
                }
            }
        }
        if !regular {
            self.cap_corners.push((pi as u32, ids));
        }
        Ok(ids)
    }

    /// The waiting lookups, in walk order: the curves' ends and `reversed` of fine edges'
    /// siblings and coarse edges' halves. A curve whose ends are `INVALID` was made by the
    /// waiting edge (or its twin: the same ends).
    fn resolve_pending(
        &mut self,
        levels: &[Lvl],
        sites: &[PatchSite],
        patches: &mut [AdaptivePatch],
    ) -> Result<(), TopologyError> {
        for w in &self.pending {
            let pi = w.patch as usize;
            let patch = &mut patches[pi];
            let pe = &mut patch.edges[w.edge as usize];
            let coarse = pe.kind == EdgeKind::Coarse;
            let l = patch.level as usize + usize::from(coarse);
            let look = |v: u32| match self.canon_at(levels, l, v) {
                INVALID => Err(TopologyError::AdaptiveUnbalanced {
                    level: l as u32,
                    face: sites[pi].face as usize,
                }),
                c => Ok(c),
            };
            let (ends, curves_of) = if coarse {
                let cm = look(w.verts[0])?;
                let [ca, cb] = w.ids;
                pe.reversed = [ca > cm, cm > cb];
                ([[ca, cm], [cm, cb]], pe.curves)
            } else {
                let (cs, ce) = (look(w.verts[0])?, look(w.verts[1])?);
                pe.reversed[1] = cs > ce;
                ([[cs, ce]; 2], [pe.curves[1]; 2])
            };
            for ([a, b], c) in ends.into_iter().zip(curves_of) {
                let c = &mut self.curves[c as usize];
                if c[0] == INVALID {
                    *c = [a.min(b), INVALID, INVALID, a.max(b)];
                }
            }
        }
        Ok(())
    }
}

/// One patch as the edge walk sees it: its place in the list and its level's face, its
/// corners and edges in patch order (`n` of them) and its corners' provisional ids.
struct EdgeWalk<'a> {
    levels: &'a [Lvl],
    tri: &'a [bool],
    pi: usize,
    site: PatchSite,
    fv: [u32; 4],
    fe: [u32; 4],
    n: usize,
    ids: [u32; 4],
}

impl EdgeWalk<'_> {
    fn unbalanced(&self, l: usize) -> TopologyError {
        TopologyError::AdaptiveUnbalanced {
            level: l as u32,
            face: self.site.face as usize,
        }
    }

    /// Edge `p` of the patch: its kind (the neighbour's level), its curves and `reversed`.
    fn edge(
        &self,
        canonical: &mut Canonical,
        patch: &mut AdaptivePatch,
        p: usize,
    ) -> Result<(), TopologyError> {
        let l = patch.level as usize;
        let rank = kind_rank(patch.kind);
        // The next corner without a division (`n` is 3 or 4, known only at run time).
        let q = if p + 1 == self.n { 0 } else { p + 1 };
        let e = self.fe[p];
        let kind = self.edge_kind(patch.kind, l, e)?;
        let (ca, cb) = (self.ids[p], self.ids[q]);
        patch.edges[p].kind = kind;
        match kind {
            EdgeKind::Plain => {
                let owner = Owner::new(rank, self.pi as u32, p as u8, 0);
                let c = canonical.curve_id(l, e, [ca, cb], owner);
                let pe = &mut patch.edges[p];
                pe.curves = [c, c];
                pe.reversed = [ca > cb; 2];
            }
            EdgeKind::Fine => self.fine_edge(canonical, patch, p, q)?,
            EdgeKind::Coarse => self.coarse_edge(canonical, patch, p)?,
        }
        Ok(())
    }

    /// The level of the neighbour across edge `e` of a patch of kind `pk` at level `l`, as an
    /// edge kind; an error where it is more than one level away.
    fn edge_kind(&self, pk: PatchKind, l: usize, e: u32) -> Result<EdgeKind, TopologyError> {
        let lvl = &self.levels[l];
        let [x, y] = lvl.t().edge_faces(e as usize);
        let g = if x == self.site.face { y } else { x };
        Ok(if pk == PatchKind::GregoryTriangle {
            // Every edge of a triangle patch is the two level-1 curves of its children's
            // Gregory points (a finer neighbour's, or its own on a boundary or next to another
            // triangle): through the exact limit at the edge's midpoint.
            EdgeKind::Coarse
        } else if g == INVALID || lvl.hole[g as usize] {
            EdgeKind::Plain
        } else if triangle_child(self.levels, self.tri, l, g as usize) {
            // Half of a triangle patch's edge: its level is the two halves' (as the triangle's
            // is), like any fine side of a transition.
            EdgeKind::Fine
        } else if lvl.complete[g as usize] {
            if lvl.selected[g as usize] {
                EdgeKind::Coarse
            } else {
                EdgeKind::Plain
            }
        } else {
            let maps = lvl.maps.as_ref().ok_or_else(|| self.unbalanced(l))?;
            let gp = maps.child_face_parent[g as usize] as usize;
            let parent = &self.levels[l - 1];
            if parent.hole[gp] {
                EdgeKind::Plain
            } else if parent.complete[gp] && !parent.selected[gp] {
                EdgeKind::Fine
            } else {
                return Err(self.unbalanced(l));
            }
        })
    }

    /// Edge `p` (corners `p`, `q`) is half of a coarser neighbour's edge: its own curve, and
    /// the curve of the other half, whose ends may wait for the walk's end.
    fn fine_edge(
        &self,
        canonical: &mut Canonical,
        patch: &mut AdaptivePatch,
        p: usize,
        q: usize,
    ) -> Result<(), TopologyError> {
        let l = patch.level as usize;
        let lvl = &self.levels[l];
        let t = lvl.t();
        let rank = kind_rank(patch.kind);
        let e = self.fe[p];
        let (a, b) = (self.fv[p], self.fv[q]);
        let (ca, cb) = (self.ids[p], self.ids[q]);
        let owner = Owner::new(rank, self.pi as u32, p as u8, 0);
        let c = canonical.curve_id(l, e, [ca, cb], owner);
        // The other half of the parent edge this one halves (at the midpoint, the end that is
        // an edge-vertex).
        let maps = lvl.maps.as_ref().ok_or_else(|| self.unbalanced(l))?;
        let mid = [a, b]
            .into_iter()
            .find(|&x| matches!(maps.child_vertex_origin[x as usize], ChildOrigin::Edge(_)))
            .ok_or_else(|| self.unbalanced(l))?;
        let pair = maps.edge_child_halves[mid as usize - lvl.kv];
        let sib = if pair[0] == e { pair[1] } else { pair[0] };
        if sib == INVALID || (pair[0] != e && pair[1] != e) {
            return Err(self.unbalanced(l));
        }
        let [s0, s1] = t.edge_vertices(sib as usize);
        // The shared end is the midpoint of the coarse edge.
        let (start, end) = if s0 == a || s1 == a {
            (if s0 == a { s1 } else { s0 }, a)
        } else if s0 == b || s1 == b {
            (b, if s0 == b { s1 } else { s0 })
        } else {
            return Err(self.unbalanced(l));
        };
        // The far end is a corner of the coarse patch, met already; otherwise the lookup
        // waits for the walk's end.
        let (cs, ce) = (
            canonical.canon_at(self.levels, l, start),
            canonical.canon_at(self.levels, l, end),
        );
        // The sibling's owner is its own fine patch; this one only holds the place (rank
        // u8::MAX) until that patch registers it.
        let owner = Owner::new(u8::MAX, self.pi as u32, 0, 0);
        let wait = cs == INVALID || ce == INVALID;
        let ends = if wait { [INVALID; 2] } else { [cs, ce] };
        let sc = canonical.curve_id(l, sib, ends, owner);
        let pe = &mut patch.edges[p];
        pe.curves = [c, sc];
        pe.reversed = [ca > cb, cs > ce];
        if wait {
            canonical.pending.push(Pending {
                patch: self.pi as u32,
                edge: p as u8,
                verts: [start, end],
                ids: [INVALID; 2],
            });
        }
        Ok(())
    }

    /// Edge `p` borders the finer patches of a refined neighbour: the curves of its two
    /// halves at the next level, whose midpoint waits for the walk's end.
    fn coarse_edge(
        &self,
        canonical: &mut Canonical,
        patch: &mut AdaptivePatch,
        p: usize,
    ) -> Result<(), TopologyError> {
        let l = patch.level as usize;
        let t = self.levels[l].t();
        let e = self.fe[p];
        let a = self.fv[p];
        let q = if p + 1 == self.n { 0 } else { p + 1 };
        let (ca, cb) = (self.ids[p], self.ids[q]);
        patch.transition_mask |= 1 << p;
        // A fine patch owns each half before a coarse end cap (single-pass plans put Gregory
        // patches on the coarse side): its own edge is the finer approximation. A regular
        // coarse patch keeps its rank: its halves are exactly the fine B-spline's.
        let rank = kind_rank(patch.kind);
        let rank = if patch.kind == PatchKind::Regular {
            rank
        } else {
            rank + HALF_RANK
        };
        let next = &self.levels[l + 1];
        let maps = next.maps.as_ref().ok_or_else(|| self.unbalanced(l))?;
        let m = maps.edge_child_vertex[e as usize];
        if m == INVALID || (m as usize) < next.kv {
            return Err(self.unbalanced(l));
        }
        let pair = maps.edge_child_halves[m as usize - next.kv];
        let at_a = usize::from(t.edge_vertices(e as usize)[0] != a);
        let (h0, h1) = (pair[at_a], pair[1 - at_a]);
        if h0 == INVALID || h1 == INVALID {
            return Err(self.unbalanced(l));
        }
        // Both halves must be patches of level l + 1.
        for h in [h0, h1] {
            for cf in next.t().edge_faces(h as usize) {
                if cf != INVALID
                    && next.complete[cf as usize]
                    && next.selected.get(cf as usize).copied().unwrap_or(false)
                {
                    return Err(self.unbalanced(l));
                }
            }
        }
        // The midpoint's id (a finer patch's corner) waits for the walk's end.
        let owner = Owner::new(rank, self.pi as u32, p as u8, 1);
        let c0 = canonical.curve_id(l + 1, h0, [INVALID; 2], owner);
        let owner = Owner::new(rank, self.pi as u32, p as u8, 2);
        let c1 = canonical.curve_id(l + 1, h1, [INVALID; 2], owner);
        patch.edges[p].curves = [c0, c1];
        canonical.pending.push(Pending {
            patch: self.pi as u32,
            edge: p as u8,
            verts: [m, INVALID],
            ids: [ca, cb],
        });
        Ok(())
    }
}

/// Where the canonical corners' final ids start: the rows' corners (in meeting order) from
/// `first_canon`, then the regular ones (in meeting order) from `first_regular_corner`.
#[derive(Clone, Copy)]
struct FinalIds {
    first_canon: u32,
    first_regular_corner: u32,
}

impl FinalIds {
    /// The final id of provisional corner id `c`.
    fn of(self, c: u32) -> u32 {
        if c & REGULAR != 0 {
            self.first_regular_corner + (c & !REGULAR)
        } else {
            self.first_canon + c
        }
    }
}

/// The end caps' corner control points (`P` of each Gregory corner, a bilinear patch's
/// corners) set to their corners' final ids.
fn number_cap_corners(
    patches: &mut [AdaptivePatch],
    cap_corners: &[(u32, [u32; 4])],
    ids: FinalIds,
) {
    for &(pi, corners) in cap_corners {
        let patch = &mut patches[pi as usize];
        let n = patch.corners();
        for (p, &id) in corners[..n].iter().enumerate() {
            match patch.kind {
                PatchKind::Gregory | PatchKind::GregoryTriangle => {
                    patch.control_points[5 * p] = ids.of(id)
                }
                PatchKind::Bilinear => patch.control_points[p] = ids.of(id),
                PatchKind::Regular => {}
            }
        }
    }
}

/// The corners' owners: the rows' corners, then the regular ones. The larger class's
/// allocation takes the other's: no third array faulted in.
fn merge_corner_owners(
    mut row_owners: Vec<[u32; 2]>,
    mut regular_owners: Vec<[u32; 2]>,
) -> Vec<[u32; 2]> {
    if regular_owners.len() > row_owners.len() {
        regular_owners.splice(0..0, row_owners);
        regular_owners
    } else {
        row_owners.extend_from_slice(&regular_owners);
        row_owners
    }
}

/// The limit-stencil rows of the corners that have one (`needed`: level and vertex), at the
/// end of the local points.
fn append_limit_rows(locals: &mut Locals, levels: &[Lvl], needed: &[(u8, u32)]) {
    locals.append_par(
        needed,
        || Vec::with_capacity(32),
        |&(l, v), terms, table| {
            let lvl = &levels[l as usize];
            terms.clear();
            limit_stencil(lvl, v as usize, terms);
            for t in terms.iter_mut() {
                t.0 += lvl.base;
            }
            push_row(table, terms);
        },
    );
}

/// Who defines each curve's normals and texture coordinates (seamless displacement): the
/// owner patch, its edge, the part of the edge, and whether the curve runs with the edge:
/// from its point 0 (the smaller end id), so not `reversed`. Collected into the owners' own
/// allocation (same size): no second array faulted in.
fn curve_owners(owners: Vec<Owner>, patches: &[AdaptivePatch]) -> Vec<CurveOwner> {
    owners
        .into_iter()
        .map(|o| {
            let (pi, p, part) = (o.patch(), o.edge(), o.part());
            let patch = &patches[pi as usize];
            CurveOwner {
                patch: pi,
                edge: p,
                part,
                forward: !patch.edges[p as usize].reversed[usize::from(part == 2)],
                triangle: patch.kind == PatchKind::GregoryTriangle,
            }
        })
        .collect()
}

/// The curves' ends get their final ids, their inner points two ids each from
/// `first_curve_point`, in curve order.
fn number_curves(curves: &mut [[u32; 4]], ids: FinalIds, first_curve_point: u32) {
    for (ci, c) in curves.iter_mut().enumerate() {
        c[0] = ids.of(c[0]);
        c[1] = first_curve_point + 2 * ci as u32;
        c[2] = c[1] + 1;
        c[3] = ids.of(c[3]);
    }
}

/// Per level: its regular patches and end caps, its faces, and the faces a uniform
/// refinement would have there.
fn level_stats(levels: &[Lvl], patches: &[AdaptivePatch]) -> Vec<LevelStats> {
    let mut level_stats: Vec<LevelStats> = Vec::with_capacity(levels.len());
    let corners0 = levels[0].t().face_tables().1.len() as u64;
    for (l, lvl) in levels.iter().enumerate() {
        let uniform_faces = if l == 0 {
            levels[0].t().num_faces() as u64
        } else {
            corners0.saturating_mul(4u64.saturating_pow(l as u32 - 1))
        };
        level_stats.push(LevelStats {
            regular: 0,
            end_caps: 0,
            faces: lvl.t().num_faces() as u32,
            uniform_faces,
        });
    }
    for p in patches {
        let s = &mut level_stats[p.level as usize];
        if p.kind == PatchKind::Regular {
            s.regular += 1;
        } else {
            s.end_caps += 1;
        }
    }
    level_stats
}

/// One stencil block per refined level, taken from the levels: its rows over the parent
/// level's global ids.
fn stencil_blocks(levels: &mut [Lvl]) -> Vec<StencilBlock> {
    let bases: Vec<u32> = levels.iter().map(|l| l.base).collect();
    levels
        .iter_mut()
        .skip(1)
        .zip(bases)
        .map(|(child, parent_base)| {
            let mut table = child.stencils.take().unwrap_or_default();
            for i in table.indices.iter_mut() {
                *i += parent_base;
            }
            table.num_sources = child.base as usize;
            StencilBlock {
                first_vertex: child.base,
                table,
            }
        })
        .collect()
}

/// A lookup of the edge walk that waits for the walk's end, for its curves' ends and `reversed`:
/// a fine edge's sibling ends (`verts`, at the patch's level) or a coarse edge's midpoint
/// (`verts[0]`, a level finer, between the patch's corners `ids`).
struct Pending {
    patch: u32,
    edge: u8,
    verts: [u32; 2],
    ids: [u32; 2],
}

/// The refinement maps into level 1, which a triangle patch's points and corners come from (a
/// plan with a triangle patch always has them; a named error otherwise, not a panic).
fn level1_maps(levels: &[Lvl], face: u32) -> Result<&ChildMaps, TopologyError> {
    levels
        .get(1)
        .and_then(|l| l.maps.as_ref())
        .ok_or(TopologyError::AdaptivePatch {
            level: 0,
            face: face as usize,
        })
}

/// The corners and edges of a patch's face in patch order, and how many (3 for a triangle
/// patch, whose face is never rotated).
fn patch_corners(lvl: &Lvl, kind: PatchKind, site: PatchSite) -> ([u32; 4], [u32; 4], usize) {
    if kind == PatchKind::GregoryTriangle {
        let t = lvl.t();
        let (fv, fe) = (
            t.face_vertices(site.face as usize),
            t.face_edge_list(site.face as usize),
        );
        let pad = |x: &[u32]| [x[0], x[1], x[2], INVALID];
        return (pad(fv), pad(fe), 3);
    }
    let (fv, fe) = rotated(lvl.t(), site.face as usize, site.shift);
    (fv, fe, 4)
}

/// The Gregory triangle patch of level-0 triangle `f` ([`crate::patches::gregory::gregory_triangle_from_children`]
/// over its three level-1 children).
fn triangle_patch(
    mesh: &ControlMesh,
    levels: &[Lvl],
    f: usize,
) -> Result<(AdaptivePatch, PointRows), TopologyError> {
    let maps = level1_maps(levels, f as u32)?;
    let l1 = &levels[1];
    let first = maps.face_first_child[f];
    if first == INVALID {
        return Err(TopologyError::AdaptivePatch { level: 0, face: f });
    }
    let basis: Vec<[crate::refine::stencil::Stencil; 20]> = (0..3)
        .map(|k| {
            crate::patches::gregory::gregory_basis(
                l1.topo.view(),
                first as usize + k,
                &mesh.options,
            )
        })
        .collect::<Result<_, _>>()?;
    let mut points =
        crate::patches::gregory::gregory_triangle_from_children([&basis[0], &basis[1], &basis[2]]);
    // Per edge p (corner p to p + 1), the inner points of its two level-1 halves in the edge's
    // direction: child p's `Ep` at the corner and `Em` at the edge midpoint (its corner 1),
    // then child p + 1's `Ep` at the midpoint (its corner 3) and `Em` at the corner.
    let halves: Vec<&crate::refine::stencil::Stencil> = (0..3)
        .flat_map(|p| {
            let (a, b) = (&basis[p], &basis[(p + 1) % 3]);
            [&a[1], &a[5 + 2], &b[15 + 1], &b[2]]
        })
        .collect();
    // Centre: the patch passes through the limit point of the triangle's face point (the
    // centroid of the domain is that point's parameter, [`AdaptivePatch::base_param`]).
    let fc = maps.face_child_vertex[f];
    let edges = levels[0].t().face_edge_list(f);
    let ec: Vec<u32> = edges
        .iter()
        .map(|&e| maps.edge_child_vertex[e as usize])
        .collect();
    if fc != INVALID && !ec.contains(&INVALID) {
        let limit = |v: u32| {
            let mut out = Vec::new();
            limit_stencil(l1, v as usize, &mut out);
            out
        };
        let centre = limit(fc);
        let mids = [limit(ec[0]), limit(ec[1]), limit(ec[2])];
        crate::patches::gregory::gregory_triangle_through_centre(
            &mut points,
            &centre,
            [&mids[0], &mids[1], &mids[2]],
        );
    }
    let mut boundary_mask = 0u8;
    for (p, &e) in levels[0].t().face_edge_list(f).iter().enumerate() {
        if levels[0].sharp_edge(e as usize) {
            boundary_mask |= 1 << p;
        }
    }
    let patch = AdaptivePatch {
        kind: PatchKind::GregoryTriangle,
        level: 0,
        control_points: ControlPoints::new(),
        base_face: f as u32,
        sub_face: 0,
        origin: [0.0, 0.0],
        size: 1.0,
        boundary_mask,
        transition_mask: 0,
        edges: [BLANK_EDGE; 4],
        reparam_valences: [0; 4],
        tangent_valences: [0; 4],
    };
    Ok((
        patch,
        PointRows::from_stencils(l1.base, points.iter().chain(halves)),
    ))
}

/// Gregory points of face `f` into `rows` (level-local ids, face corner order).
fn gregory_face_rows(
    mesh: &ControlMesh,
    lvl: &Lvl,
    f: usize,
    rows: &mut PointRows,
) -> Result<(), TopologyError> {
    rows.clear();
    crate::patches::gregory::gregory_basis_each(lvl.topo.view(), f, &mesh.options, |_, terms| {
        rows.push(terms.iter().copied());
    })
}

/// The 20 Gregory points in patch corner order (patch corner p, point j = P, Ep, Em, Fp, Fm),
/// where patch corner p is face corner p + `shift`, as weighted global ids (`base` + local).
fn rotated_points<'a>(
    base: u32,
    shift: u8,
    point: impl Fn(usize, usize) -> &'a crate::refine::stencil::Stencil,
) -> PointRows {
    let s = shift as usize;
    PointRows::from_stencils(base, (0..20).map(|k| point((k / 5 + s) % 4, k % 5)))
}

/// Per patch corner (patch order): the valence whose corner block of the texture
/// reparameterization ([`crate::patches::reparam`]) applies — that of a smooth interior vertex — or 0
/// (identity) at boundary, crease and corner vertices, where no characteristic map was fitted.
fn reparam_valences(lvl: &Lvl, f: usize, shift: u8) -> [u8; 4] {
    let (fv, _) = rotated(lvl.t(), f, shift);
    fv.map(|v| {
        let v = v as usize;
        let edges = lvl.t().vertex_edges(v);
        let smooth = lvl.topo.vertex_sharpness[v] <= 0.0
            && edges.iter().all(|&e| !lvl.sharp_edge(e as usize));
        if smooth {
            edges.len().min(u8::MAX as usize) as u8
        } else {
            0
        }
    })
}

/// ACC-1's 16 Bézier points of face `f` as a Gregory patch's 20 (global ids, patch corner
/// order): each corner's `Fp` and `Fm` are both its inner Bézier point, which makes the
/// Gregory patch that bicubic Bézier patch. Then 8 more: per patch corner the Gregory edge
/// points `Ep, Em`, which lie on the limit tangents, for the tangent patches
/// ([`crate::patches::acc::tangent_normal`]). Fails outside ACC-1's scope ([`crate::patches::acc`]).
pub(super) fn acc_points(
    mesh: &ControlMesh,
    lvl: &Lvl,
    f: usize,
    shift: u8,
) -> Result<PointRows, TopologyError> {
    let net = crate::patches::acc::acc1_patch(lvl.topo.view(), f)?;
    let basis = crate::patches::gregory::gregory_basis(lvl.topo.view(), f, &mesh.options)?;
    let tangents = rotated_points(lvl.base, shift, |corner, j| &basis[5 * corner + j]);
    // Per face corner: the Bézier (i, j) of P, Ep, Em, F (module docs of crate::patches::gregory).
    const SLOTS: [[(usize, usize); 4]; 4] = [
        [(0, 0), (1, 0), (0, 1), (1, 1)],
        [(3, 0), (3, 1), (2, 0), (2, 1)],
        [(3, 3), (2, 3), (3, 2), (2, 2)],
        [(0, 3), (0, 2), (1, 3), (1, 2)],
    ];
    let mut points = rotated_points(lvl.base, shift, |corner, j| {
        let (bi, bj) = SLOTS[corner][j.min(3)];
        &net[bi][bj]
    });
    for corner in 0..4 {
        for j in 1..3 {
            points.push(tangents.row(5 * corner + j).iter().copied());
        }
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// An `n`×`n` grid of quads, each split into two triangles: under Catmull-Clark every face
    /// is an end cap's parent (three level-1 quads around an extraordinary vertex).
    fn triangle_grid(n: u32) -> ControlMesh {
        let mut p = Vec::new();
        for y in 0..=n {
            for x in 0..=n {
                p.push([x as f64, y as f64, ((x * 7 + y * 3) % 5) as f64 * 0.1]);
            }
        }
        let id = |x: u32, y: u32| y * (n + 1) + x;
        let mut faces = Vec::new();
        for y in 0..n {
            for x in 0..n {
                faces.push(vec![id(x, y), id(x + 1, y), id(x + 1, y + 1)]);
                faces.push(vec![id(x, y), id(x + 1, y + 1), id(x, y + 1)]);
            }
        }
        ControlMesh::from_polygons(p, &faces)
    }

    /// Terms of the rows of every Gregory patch's 20 points as built.
    fn built_gregory_terms(plan: &AdaptivePlan) -> (u64, u64) {
        let first = plan.local_points.first_vertex;
        let mut terms = 0u64;
        let mut patches = 0u64;
        for p in plan
            .patches
            .iter()
            .filter(|p| matches!(p.kind, PatchKind::Gregory | PatchKind::GregoryTriangle))
        {
            patches += 1;
            for &id in &p.control_points {
                terms += if id >= plan.first_regular_corner {
                    // A corner evaluated from its regular owner: the 3×3 mask.
                    9
                } else if id >= first {
                    plan.local_points
                        .table
                        .stencil((id - first) as usize)
                        .0
                        .len() as u64
                } else {
                    1
                };
            }
        }
        (patches, terms)
    }

    /// The projection counts the patches the plan builds and is within 2× of their terms, so
    /// the bound refuses what would be too large and not what fits.
    #[test]
    fn gregory_projection_tracks_the_built_terms() {
        let quads_and_triangles = {
            let mut m = triangle_grid(3);
            // A quad region next to the triangles: mixed valences 3 to 8.
            let base = m.positions.len() as u32;
            m.positions
                .extend([[0., -1., 0.], [1., -1., 0.2], [2., -1., 0.]]);
            let mut faces: Vec<Vec<u32>> = (0..m.num_faces()).map(|f| m.face(f).to_vec()).collect();
            faces.push(vec![base, base + 1, 1, 0]);
            faces.push(vec![base + 1, base + 2, 2, 1]);
            ControlMesh::from_polygons(m.positions.clone(), &faces)
        };
        for (name, mesh) in [
            ("triangle grid", triangle_grid(6)),
            ("quads and triangles", quads_and_triangles),
        ] {
            let levels =
                levels::build_levels(&mesh, 1, false, MAX_REFINED_FACES, true).expect("levels");
            let (patches, estimate) = project_gregory_terms(&levels, 0);
            // The projection counts a triangle's three level-1 quads, as split triangles are.
            let split = single_pass::SinglePassOptions {
                gregory_triangles: false,
                ..Default::default()
            };
            let plan = single_pass::plan_single_pass(&mesh, &split).expect("plan");
            let (built_patches, built) = built_gregory_terms(&plan);
            // Gregory triangle patches: fewer patches and no more terms than projected.
            let tri = single_pass::plan_single_pass(&mesh, &Default::default()).expect("plan");
            let (tri_patches, tri_built) = built_gregory_terms(&tri);
            assert!(
                tri_patches < patches && tri_built <= estimate,
                "{name}: {tri_built} terms"
            );
            assert_eq!(patches, built_patches, "{name}");
            let ratio = estimate as f64 / built as f64;
            eprintln!(
                "{name}: {patches} Gregory patches, projected {estimate} terms, built {built}"
            );
            assert!(
                (0.5..=2.0).contains(&ratio),
                "{name}: {estimate} vs {built}"
            );
        }
    }

    /// The remembered frames are the chain walk's, bit for bit, in any order of faces.
    #[test]
    fn frame_memo_matches_the_chain_walk() {
        let mesh = triangle_grid(3);
        let levels =
            levels::build_levels(&mesh, 3, false, MAX_REFINED_FACES, false).expect("levels");
        let mut memo = FrameMemo::new(levels.len());
        for (l, lvl) in levels.iter().enumerate() {
            let n = lvl.t().num_faces();
            // Forward, then scattered (every 7th face, from the back).
            for f in (0..n).chain((0..n).rev().step_by(7)) {
                let (base, sub, origin, size, shift) = frame(&levels, l, f);
                let fr = memo.frame(&levels, l, f);
                assert_eq!(
                    (fr.base, fr.sub, fr.shift),
                    (base, sub, shift),
                    "level {l} face {f}"
                );
                assert_eq!(fr.origin.map(f64::to_bits), origin.map(f64::to_bits));
                assert_eq!(fr.size.to_bits(), size.to_bits());
            }
        }
    }

    #[test]
    fn gregory_past_the_bound_is_a_named_error() {
        let mesh = triangle_grid(4);
        let levels =
            levels::build_levels(&mesh, 1, false, MAX_REFINED_FACES, true).expect("levels");
        let err = check_gregory_size(&mesh, &levels, 0, 1000).expect_err("over the bound");
        match err {
            TopologyError::GregoryTooLarge {
                faces,
                patches,
                estimate,
                bound,
            } => {
                assert_eq!((faces, patches, bound), (32, 96, 1000));
                assert!(estimate > bound);
            }
            e => panic!("unexpected {e}"),
        }
        assert!(check_gregory_size(&mesh, &levels, 0, MAX_LOCAL_TERMS).is_ok());
    }
}
