//! The BFT technique's GPU data: every storage buffer `glsl/bft/bft.glsl` reads, as named
//! `#[repr(C)]` + `Pod` structs, and the packing of `topology`'s plain data ([`LoopBft`]: stencils,
//! patch records, basis-function tables) into them.
//!
//! Design decisions:
//! - **Topology hands over plain Rust data; the GPU layout is tess's.** `topology` knows no
//!   buffer, binding or word order; this module is the only writer of the BFT buffers and
//!   `bft.glsl` their only reader, both through the same field names.
//! - **One struct per header and element**, mirrored field by field in `bft.glsl`, so a record is
//!   read by name (`patches[f].ring_offset`), never by position. A test reads each block's
//!   binding, member offsets and array stride back from the SPIR-V (`gpu::tests`).
//! - **Bindings from one place**: the `BFT_*_BINDING` constants of [`crate::gpu::bindings`],
//!   which the build script also writes into `bindings.glsl`.
//! - **No `vec3` in a buffer** (std430 would pad it to 16 bytes): level-1 points are `vec4`
//!   written and read only on the GPU. The base → level-1 stencils and the base positions are
//!   the stencil evaluator's ([`crate::stencil`]).
//! - **Owners stay packed** (`face << 2 | local index`, like OpenSubdiv's `PatchParam`), read
//!   only through [`owner_face`] / [`owner_local`] here and their namesakes in GLSL.
//! - **Checked before upload**: [`GpuBft::validate`] proves every index the shaders can form is
//!   in range, so a bad mesh fails here, not as an out-of-bounds read on the device.
//! - [`GpuBft::eval_tess`] is the f32 mirror of `bft.glsl`'s evaluation, operation for operation
//!   (the shader sums with `precise`), so tests can demand the GPU's bits.
use crate::gpu::bindings::{
    BFT_KIND_BOUNDARY, BFT_KIND_EXTRAORDINARY, BFT_KIND_PRIVATE, BFT_KIND_REGULAR,
    BFT_LEVEL1_NORMALS_BINDING, BFT_LEVEL1_POSITIONS_BINDING, BFT_OWNER_LOCAL_MASK,
    BFT_OWNER_SHIFT, BFT_PATCH_HEADERS_BINDING, BFT_PATCH_RINGS_BINDING, BFT_SET,
    BFT_TANGENT_OFFSETS_BINDING, BFT_TANGENT_TERMS_BINDING, FRAME_SET,
};
use crate::stencil::{GpuStencils, StencilError};
use bytemuck::{Pod, Zeroable};
use std::mem::{offset_of, size_of};
use topology::patches::bft::{
    BasisTables, BftCase, BftKey, LoopBft, Owner, PatchRecords, TangentStencils,
};

/// `TangentTerm`: one term of both limit-tangent masks of a level-1 vertex
/// ([`BFT_TANGENT_TERMS_BINDING`], rows by [`BFT_TANGENT_OFFSETS_BINDING`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TangentTerm {
    /// Level-1 vertex.
    pub index: u32,
    /// Weight in the first tangent mask.
    pub weight_t1: f32,
    /// Weight in the second tangent mask.
    pub weight_t2: f32,
}

/// `PatchHeader`: one level-1 face ([`BFT_PATCH_HEADERS_BINDING`]). Its control ring (level-1
/// vertex indices, in table slot order) is `patch_rings[ring_offset..ring_offset + ring_size]`
/// ([`BFT_PATCH_RINGS_BINDING`]).
///
/// A point on an edge or corner is evaluated by its owner face, in the owner's frame, so both
/// faces sharing it produce the same bits; owners are packed by [`pack_owner`]. Edge `e` runs
/// `v_e → v_(e+1)`, corner `c` is `v_c`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct PatchHeader {
    pub ring_offset: u32,
    pub ring_size: u32,
    /// Index of the face's table in [`GpuBft::table_entries`].
    pub entry: u32,
    /// 1 when the table is the mirror image of the face's configuration: rows are read
    /// transposed and slots through the entry's mirror permutation.
    pub mirrored: u32,
    pub edge_owner: [u32; 3],
    pub corner_owner: [u32; 3],
}

/// `TableHeader`: the first member of the `Tables` block (read by address,
/// [`BFT_TABLE_ARRAYS_BINDING`](crate::gpu::bindings::BFT_TABLE_ARRAYS_BINDING)), followed by one [`TableEntry`] per table.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct TableHeader {
    /// `L`: the tables' level.
    pub level: u32,
    /// `2^L` segments per patch edge.
    pub segments: u32,
    /// `3 · 2^L`: the lattice the row maps are indexed on (tessellator points included).
    pub grid: u32,
    pub entry_count: u32,
    /// Offset of the full tables' row map in `row_maps`.
    pub full_map_offset: u32,
    /// Offset of the half (mirror-symmetric) tables' row map.
    pub half_map_offset: u32,
}

/// `TableEntry`: one basis-function table.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct TableEntry {
    pub ring_size: u32,
    /// 1: only grid points `a ≥ b` are stored (the configuration is mirror-symmetric).
    pub half_table: u32,
    pub rows: u32,
    /// Weight blocks in `table_weights`, `rows × ring_size`
    /// each; `du_offset`, `dv_offset` are [`NO_WEIGHTS`] without tangent tables.
    pub position_offset: u32,
    pub du_offset: u32,
    pub dv_offset: u32,
    /// The table's slot permutation in `mirror_perms`.
    pub perm_offset: u32,
    /// `BFT_KIND_*`: regular, extraordinary, boundary, private.
    pub kind: u32,
}

/// A level-1 position or normal on the GPU (`vec4`, `w` unused): written by the stencil
/// evaluator into [`BFT_LEVEL1_POSITIONS_BINDING`] and by `normals.comp` into
/// [`BFT_LEVEL1_NORMALS_BINDING`].
pub type Level1Point = [f32; 4];

/// A weight offset that names no block (tangent tables not built).
pub const NO_WEIGHTS: u32 = u32::MAX;
/// A row-map entry of a grid point without a row (`NO_ROW` in `bft.glsl`).
pub const NO_ROW: u32 = u32::MAX;

const _: () = {
    assert!(size_of::<TangentTerm>() == 12);
    assert!(size_of::<PatchHeader>() == 40);
    assert!(offset_of!(PatchHeader, edge_owner) == 16);
    assert!(offset_of!(PatchHeader, corner_owner) == 28);
    assert!(size_of::<TableHeader>() == 24);
    assert!(size_of::<TableEntry>() == 32);
};

// Pipeline layouts list the frame set, then the BFT set: their numbers must be that order.
const _: () = assert!(FRAME_SET == 0 && BFT_SET == FRAME_SET + 1);

/// Every storage-buffer binding of the BFT descriptor set, in binding order: each bound in
/// windows ([`crate::techniques::windows`]). The set's last binding,
/// [`BFT_TABLE_ARRAYS_BINDING`](crate::gpu::bindings::BFT_TABLE_ARRAYS_BINDING), is the uniform block of the tables' addresses.
pub const STORAGE_BINDINGS: [u32; 6] = [
    BFT_TANGENT_OFFSETS_BINDING,
    BFT_TANGENT_TERMS_BINDING,
    BFT_LEVEL1_POSITIONS_BINDING,
    BFT_LEVEL1_NORMALS_BINDING,
    BFT_PATCH_HEADERS_BINDING,
    BFT_PATCH_RINGS_BINDING,
];

/// Packs an owner: face `face`, local edge or corner `local` (0..=2).
pub fn pack_owner(face: u32, local: u8) -> u32 {
    face << BFT_OWNER_SHIFT | local as u32
}

/// The owner face of a packed owner.
pub fn owner_face(owner: u32) -> u32 {
    owner >> BFT_OWNER_SHIFT
}

/// The owner's local edge or corner index.
pub fn owner_local(owner: u32) -> u32 {
    owner & BFT_OWNER_LOCAL_MASK
}

/// Why BFT data cannot go to the GPU.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum LayoutError {
    /// A level-1 face whose configuration has no table.
    #[error("level-1 face {face} has no basis-function table for {key:?}")]
    NoTable { face: usize, key: BftKey },
    /// An index the shaders would form lies outside its buffer.
    #[error("BFT GPU data invalid in {buffer}: {detail}")]
    Invalid {
        /// The buffer at fault (its `bft.glsl` block).
        buffer: &'static str,
        detail: String,
    },
    /// The base → level-1 stencils.
    #[error("BFT base → level-1 stencils: {0}")]
    Stencil(#[from] StencilError),
}

fn invalid(buffer: &'static str, detail: impl Into<String>) -> LayoutError {
    LayoutError::Invalid {
        buffer,
        detail: detail.into(),
    }
}

/// Everything the BFT pipeline reads, packed into the buffers the shaders index, and checked:
/// every index the shaders can form from these arrays is in range ([`GpuBft::validate`]).
#[derive(Clone, Debug, PartialEq)]
pub struct GpuBft {
    /// The base → level-1 stencils: one row per level-1 vertex over the base vertices.
    pub stencils: GpuStencils,
    /// CSR offsets of the level-1 limit-tangent stencils.
    pub tangent_offsets: Vec<u32>,
    pub tangent_terms: Vec<TangentTerm>,
    /// One header per level-1 face.
    pub patches: Vec<PatchHeader>,
    /// Every face's ring, back to back.
    pub patch_rings: Vec<u32>,
    pub table: TableHeader,
    pub table_entries: Vec<TableEntry>,
    pub mirror_perms: Vec<u32>,
    /// Full tables' row map, then the half tables' (offsets in [`GpuBft::table`]).
    pub row_maps: Vec<u32>,
    pub table_weights: Vec<f32>,
    pub base_vertices: u32,
    pub level1_vertices: u32,
    pub patch_count: u32,
}

fn patch_kind(key: BftKey) -> u32 {
    match key.case {
        BftCase::Interior if key.valence == 6 => BFT_KIND_REGULAR,
        BftCase::Interior => BFT_KIND_EXTRAORDINARY,
        BftCase::Boundary { .. } => BFT_KIND_BOUNDARY,
        BftCase::Private { .. } => BFT_KIND_PRIVATE,
    }
}

/// What the TES computes for one tessellated vertex ([`GpuBft::eval_tess`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct TessSample {
    pub position: [f32; 3],
    /// Unnormalised: subdivision-shading sum, or `du × dv` for geometric normals.
    pub normal: [f32; 3],
    /// The point is a table point (exact limit); else it was interpolated on the level-`L`
    /// virtual mesh (fractional factors: the paper's linear geomorph).
    pub exact: bool,
}

type Acc = ([f32; 3], [f32; 3], [f32; 3]);

/// The basis-function tables as the shaders read them: the `Tables` block (header and
/// entries), `MirrorPerms`, `RowMaps` and `TableWeights`.
#[derive(Clone, Debug, PartialEq)]
pub struct PackedTables {
    pub table: TableHeader,
    pub entries: Vec<TableEntry>,
    pub mirror_perms: Vec<u32>,
    /// Full tables' row map, then the half tables' (offsets in [`PackedTables::table`]).
    pub row_maps: Vec<u32>,
    pub weights: Vec<f32>,
}

impl PackedTables {
    /// Packs `t`.
    pub fn new(t: &BasisTables) -> PackedTables {
        let entries: Vec<TableEntry> = t
            .entries
            .iter()
            .map(|e| TableEntry {
                ring_size: e.ring_size,
                half_table: e.half as u32,
                rows: e.rows,
                position_offset: e.offset_position,
                du_offset: e.offset_du,
                dv_offset: e.offset_dv,
                perm_offset: e.offset_perm,
                kind: patch_kind(e.key),
            })
            .collect();
        let mut row_maps = t.row_map_full.clone();
        row_maps.extend_from_slice(&t.row_map_half);
        PackedTables {
            table: TableHeader {
                level: t.level,
                segments: t.segments(),
                grid: t.grid(),
                entry_count: entries.len() as u32,
                full_map_offset: 0,
                half_map_offset: t.row_map_full.len() as u32,
            },
            entries,
            mirror_perms: t.mirror_perm.clone(),
            row_maps,
            weights: t.weights.clone(),
        }
    }

    /// The `Tables` block: header, then entries.
    pub fn header_bytes(&self) -> Vec<u8> {
        header_bytes(&self.table, &self.entries)
    }

    /// Bytes on the GPU (header, entries, permutations, row maps, weights).
    pub fn bytes(&self) -> usize {
        size_of::<TableHeader>()
            + size_of::<TableEntry>() * self.entries.len()
            + 4 * (self.mirror_perms.len() + self.row_maps.len() + self.weights.len())
    }

    /// Every table read the shaders make is in range, and every dyadic point has a row (the
    /// interpolating path reads them unchecked).
    pub fn validate(&self) -> Result<(), LayoutError> {
        validate_tables(
            &self.table,
            &self.entries,
            &self.mirror_perms,
            &self.row_maps,
            &self.weights,
        )
    }
}

/// The `Tables` block's bytes.
fn header_bytes(table: &TableHeader, entries: &[TableEntry]) -> Vec<u8> {
    let mut out = bytemuck::bytes_of(table).to_vec();
    out.extend_from_slice(bytemuck::cast_slice(entries));
    out
}

/// The level-1 limit-tangent stencils as CSR offsets and f32 terms, taking `ts`.
pub fn pack_tangents(ts: TangentStencils) -> (Vec<u32>, Vec<TangentTerm>) {
    let terms = ts
        .indices
        .iter()
        .zip(ts.t1.iter().zip(&ts.t2))
        .map(|(&index, (&a, &b))| TangentTerm {
            index,
            weight_t1: a as f32,
            weight_t2: b as f32,
        })
        .collect();
    let offsets = if ts.offsets.is_empty() {
        vec![0u32]
    } else {
        ts.offsets
    };
    (offsets, terms)
}

/// One header per record and the ring buffer, taking `records`: the rings are already one
/// array in slot order, the ring buffer as it is (moved, not copied).
pub fn pack_patches(
    records: PatchRecords,
    tables: &BasisTables,
) -> Result<(Vec<PatchHeader>, Vec<u32>), LayoutError> {
    let mut patches = Vec::with_capacity(records.len());
    for (face, r) in records.faces.iter().enumerate() {
        let (entry, mirrored) = tables
            .lookup(r.key)
            .ok_or(LayoutError::NoTable { face, key: r.key })?;
        let owners = |o: &[Owner; 3]| o.map(|o| pack_owner(o.face(), o.local()));
        patches.push(PatchHeader {
            ring_offset: r.ring_offset,
            ring_size: r.ring_size,
            entry: entry as u32,
            mirrored: mirrored as u32,
            edge_owner: owners(&r.edge_owner),
            corner_owner: owners(&r.corner_owner),
        });
    }
    Ok((patches, records.rings))
}

impl GpuBft {
    /// Packs `bft` and validates the result (a copy: `bft` stays whole for the CPU reference;
    /// the technique packs stage by stage instead, freeing each input once packed).
    pub fn new(bft: &LoopBft) -> Result<GpuBft, LayoutError> {
        let stencils = GpuStencils::from_table(bft.stencils.clone());
        let (tangent_offsets, tangent_terms) = pack_tangents(bft.tangent_stencils.clone());
        let (patches, patch_rings) = pack_patches(bft.records.clone(), &bft.tables)?;
        let PackedTables {
            table,
            entries,
            mirror_perms,
            row_maps,
            weights,
        } = PackedTables::new(&bft.tables);
        let g = GpuBft {
            stencils,
            tangent_offsets,
            tangent_terms,
            patches,
            patch_rings,
            table,
            table_entries: entries,
            mirror_perms,
            row_maps,
            table_weights: weights,
            base_vertices: bft.base_vertices as u32,
            level1_vertices: bft.level1.num_vertices() as u32,
            patch_count: bft.records.len() as u32,
        };
        g.validate()?;
        Ok(g)
    }

    /// Bytes of one level-1 buffer (positions or normals).
    pub fn level1_bytes(&self) -> u64 {
        (size_of::<Level1Point>() * self.level1_vertices.max(1) as usize) as u64
    }

    /// Bytes of the basis-function tables on the GPU (header, entries, permutations, row maps,
    /// weights).
    pub fn table_bytes(&self) -> usize {
        size_of::<TableHeader>()
            + size_of::<TableEntry>() * self.table_entries.len()
            + 4 * (self.mirror_perms.len() + self.row_maps.len() + self.table_weights.len())
    }

    /// Bytes of the patch headers and rings.
    pub fn patch_bytes(&self) -> usize {
        size_of::<PatchHeader>() * self.patches.len() + 4 * self.patch_rings.len()
    }

    /// Bytes of the base → level-1 stencils.
    pub fn stencil_bytes(&self) -> usize {
        self.stencils.bytes() as usize
    }

    /// Proves every read the shaders make is in bounds: stencil and ring indices name existing
    /// vertices, owners existing faces and corners, entries existing tables whose ring size
    /// equals the face's, rows and permutations lie inside the weight and permutation arrays,
    /// and every dyadic point has a row (the interpolating path reads them unchecked).
    pub fn validate(&self) -> Result<(), LayoutError> {
        self.stencils
            .validate(self.level1_vertices, self.base_vertices)?;
        validate_tangents(
            &self.tangent_offsets,
            &self.tangent_terms,
            self.level1_vertices,
        )?;
        validate_tables(
            &self.table,
            &self.table_entries,
            &self.mirror_perms,
            &self.row_maps,
            &self.table_weights,
        )?;
        if self.patches.len() != self.patch_count as usize {
            return Err(invalid("PatchHeaders", "one header per patch"));
        }
        validate_patches(
            &self.patches,
            &self.patch_rings,
            &self.table_entries,
            self.level1_vertices,
        )
    }
}

/// The tangent stencils: one CSR row per level-1 vertex over the level-1 vertices.
pub fn validate_tangents(
    offsets: &[u32],
    terms: &[TangentTerm],
    level1_vertices: u32,
) -> Result<(), LayoutError> {
    csr(
        offsets,
        terms.iter().map(|t| t.index),
        level1_vertices,
        level1_vertices,
        "TangentTerms",
    )
}

/// Every read of the tables in range; every dyadic point has a row.
fn validate_tables(
    t: &TableHeader,
    table_entries: &[TableEntry],
    mirror_perms: &[u32],
    row_maps: &[u32],
    table_weights: &[f32],
) -> Result<(), LayoutError> {
    let grid = t.grid as usize;
    let map_len = (grid + 1) * (grid + 1);
    if t.entry_count as usize != table_entries.len()
        || t.full_map_offset as usize + map_len > row_maps.len()
        || t.half_map_offset as usize + map_len > row_maps.len()
        || t.segments as usize * 3 != grid
    {
        return Err(invalid("Tables", "table header"));
    }
    let full = &row_maps[t.full_map_offset as usize..][..map_len];
    let half = &row_maps[t.half_map_offset as usize..][..map_len];
    for (e, ent) in table_entries.iter().enumerate() {
        let (rs, rows) = (ent.ring_size as usize, ent.rows as usize);
        if ent.position_offset == NO_WEIGHTS {
            return Err(invalid(
                "Tables",
                format!("entry {e} has no position weights"),
            ));
        }
        for off in [ent.position_offset, ent.du_offset, ent.dv_offset] {
            if off != NO_WEIGHTS && off as usize + rows * rs > table_weights.len() {
                return Err(invalid("TableWeights", format!("entry {e} weights")));
            }
        }
        let start = ent.perm_offset as usize;
        let Some(perm) = mirror_perms.get(start..start + rs) else {
            return Err(invalid("MirrorPerms", format!("entry {e} permutation")));
        };
        if perm.iter().any(|&p| p as usize >= rs) {
            return Err(invalid("MirrorPerms", format!("entry {e} permutation")));
        }
        let map = if ent.half_table != 0 { half } else { full };
        if map.iter().any(|&r| r != NO_ROW && r as usize >= rows) {
            return Err(invalid("RowMaps", format!("entry {e} row map")));
        }
    }
    let n = t.segments as usize;
    for j in 0..=n {
        for i in 0..=n - j {
            let (a, b) = (3 * i, 3 * j);
            let (ha, hb) = if a >= b { (a, b) } else { (b, a) };
            if full[a * (grid + 1) + b] == NO_ROW || half[ha * (grid + 1) + hb] == NO_ROW {
                return Err(invalid(
                    "RowMaps",
                    format!("dyadic point ({i}, {j}) has no row"),
                ));
            }
        }
    }
    Ok(())
}

/// Every patch: a ring of ≥ 3 level-1 vertices inside the ring buffer, a table entry of the
/// ring's size, owners naming existing patches and corners.
pub fn validate_patches(
    patches: &[PatchHeader],
    patch_rings: &[u32],
    table_entries: &[TableEntry],
    level1_vertices: u32,
) -> Result<(), LayoutError> {
    let nf = patches.len();
    for (f, h) in patches.iter().enumerate() {
        let (off, rs) = (h.ring_offset as usize, h.ring_size as usize);
        let Some(ring) = patch_rings.get(off..off + rs).filter(|_| rs >= 3) else {
            return Err(invalid("PatchRings", format!("patch {f} ring")));
        };
        match table_entries.get(h.entry as usize) {
            Some(e) if e.ring_size as usize == rs && h.mirrored <= 1 => {}
            _ => return Err(invalid("PatchHeaders", format!("patch {f} table entry"))),
        }
        if let Some(&x) = ring.iter().find(|&&x| x >= level1_vertices) {
            return Err(invalid("PatchRings", format!("patch {f} ring index {x}")));
        }
        for (k, &o) in h.edge_owner.iter().chain(&h.corner_owner).enumerate() {
            if owner_face(o) as usize >= nf || owner_local(o) > 2 {
                return Err(invalid("PatchHeaders", format!("patch {f} owner {k}")));
            }
        }
    }
    Ok(())
}

/// A CSR stencil table: `n_rows + 1` non-decreasing offsets ending at the term count, and term
/// indices below `n_src`.
fn csr(
    offsets: &[u32],
    indices: impl ExactSizeIterator<Item = u32>,
    n_rows: u32,
    n_src: u32,
    buffer: &'static str,
) -> Result<(), LayoutError> {
    let len = indices.len();
    if offsets.len() != n_rows as usize + 1
        || offsets.windows(2).any(|w| w[0] > w[1])
        || offsets.first().copied().unwrap_or(0) != 0
        || *offsets.last().unwrap_or(&0) as usize != len
    {
        return Err(invalid(buffer, "CSR offsets"));
    }
    for (k, i) in indices.enumerate() {
        if i >= n_src {
            return Err(invalid(buffer, format!("index {i} at {k} ≥ {n_src}")));
        }
    }
    Ok(())
}

impl GpuBft {
    /// Row of grid point `(a, b)` in the patch's table, and whether slots are mirrored;
    /// [`NO_ROW`] when the point has no row. Mirrors `bft_row` in `glsl/bft/bft.glsl`.
    fn row_of(&self, face: usize, a: u32, b: u32) -> (u32, bool) {
        let h = &self.patches[face];
        let mirrored = h.mirrored != 0;
        let ent = &self.table_entries[h.entry as usize];
        let half_table = ent.half_table != 0;
        let grid = self.table.grid;
        let (mut a, mut b, mut flip) = if mirrored {
            (b, a, true)
        } else {
            (a, b, false)
        };
        if half_table && a < b {
            std::mem::swap(&mut a, &mut b);
            flip = !flip;
        }
        let map = if half_table {
            self.table.half_map_offset
        } else {
            self.table.full_map_offset
        };
        (self.row_maps[(map + a * (grid + 1) + b) as usize], flip)
    }

    /// Σ w·P over the patch ring for one row (position, normal source, and for geometric
    /// normals `du`, `dv`), in slot order with separate multiply and add (GLSL `precise`).
    /// Mirrors `bft_accumulate`.
    fn accumulate(
        &self,
        face: usize,
        row: u32,
        flip: bool,
        pos: &[Level1Point],
        nrm: &[Level1Point],
        geometric: bool,
    ) -> Acc {
        let h = &self.patches[face];
        let (ring, rs) = (h.ring_offset as usize, h.ring_size as usize);
        let ent = &self.table_entries[h.entry as usize];
        let perm = ent.perm_offset as usize;
        let (mut p, mut q, mut r) = ([0f32; 3], [0f32; 3], [0f32; 3]);
        let (off_du, off_dv) = if flip {
            (ent.dv_offset, ent.du_offset)
        } else {
            (ent.du_offset, ent.dv_offset)
        };
        for s in 0..rs {
            let slot = if flip {
                self.mirror_perms[perm + s] as usize
            } else {
                s
            };
            let at = |off: u32| self.table_weights[off as usize + row as usize * rs + slot];
            let v = self.patch_rings[ring + s] as usize;
            let w = at(ent.position_offset);
            for k in 0..3 {
                let t = w * pos[v][k];
                p[k] += t;
            }
            if geometric {
                let (wu, wv) = (at(off_du), at(off_dv));
                for k in 0..3 {
                    let t = wu * pos[v][k];
                    q[k] += t;
                    let t = wv * pos[v][k];
                    r[k] += t;
                }
            } else {
                for k in 0..3 {
                    let t = w * nrm[v][k];
                    q[k] += t;
                }
            }
        }
        (p, q, r)
    }

    /// The TES of `glsl/bft/bft.tese` in f32, for tess coordinate `b` (weights of the patch's
    /// `v0`, `v1`, `v2`) of patch `face`: points on an edge or corner are evaluated by the
    /// owner in its frame, table points exactly, other points by linear interpolation on the
    /// level-`L` lattice. `pos`/`nrm`: level-1 positions and normals (`w` unused). The shader
    /// sums a row from its patch block or from the global buffers, both in this slot order;
    /// its equal-spacing variant makes only table points, where it equals this.
    pub fn eval_tess(
        &self,
        pos: &[Level1Point],
        nrm: &[Level1Point],
        face: usize,
        b: [f32; 3],
        geometric: bool,
    ) -> TessSample {
        let h = &self.patches[face];
        let (mut g, mut u, mut v) = (face, b[1], b[2]);
        let corner = if b[0] == 1.0 {
            Some(0)
        } else if b[1] == 1.0 {
            Some(1)
        } else if b[2] == 1.0 {
            Some(2)
        } else {
            None
        };
        let edge = if b[2] == 0.0 {
            Some((0, b[1]))
        } else if b[0] == 0.0 {
            Some((1, b[2]))
        } else if b[1] == 0.0 {
            Some((2, b[0]))
        } else {
            None
        };
        if let Some(c) = corner {
            let o = h.corner_owner[c];
            g = owner_face(o) as usize;
            (u, v) = match owner_local(o) {
                0 => (0.0, 0.0),
                1 => (1.0, 0.0),
                _ => (0.0, 1.0),
            };
        } else if let Some((e, t)) = edge {
            let o = h.edge_owner[e];
            g = owner_face(o) as usize;
            let t = if g == face { t } else { 1.0 - t };
            (u, v) = match owner_local(o) {
                0 => (t, 0.0),
                1 => (1.0 - t, t),
                _ => (0.0, 1.0 - t),
            };
        }
        let grid = self.table.grid;
        let n = self.table.segments;
        let (ga, gb) = (u * grid as f32, v * grid as f32);
        let (ra, rb) = ((ga + 0.5).floor(), (gb + 0.5).floor());
        if (ga - ra).abs() < 0.02 && (gb - rb).abs() < 0.02 {
            let (row, flip) = self.row_of(g, ra as u32, rb as u32);
            if row != NO_ROW {
                let (p, q, r) = self.accumulate(g, row, flip, pos, nrm, geometric);
                return TessSample {
                    position: p,
                    normal: if geometric { cross(q, r) } else { q },
                    exact: true,
                };
            }
        }
        let (x, y) = (u * n as f32, v * n as f32);
        let i0 = x.floor().min(n as f32 - 1.0);
        let j0 = y.floor().min(n as f32 - 1.0 - i0);
        let (fx, fy) = (x - i0, y - j0);
        let (i0, j0) = (i0 as u32, j0 as u32);
        let (pts, w) = if fx + fy <= 1.0 {
            (
                [(i0, j0), (i0 + 1, j0), (i0, j0 + 1)],
                [1.0 - fx - fy, fx, fy],
            )
        } else {
            (
                [(i0 + 1, j0 + 1), (i0, j0 + 1), (i0 + 1, j0)],
                [fx + fy - 1.0, 1.0 - fx, 1.0 - fy],
            )
        };
        let mut acc = ([0f32; 3], [0f32; 3], [0f32; 3]);
        for (k, &(i, j)) in pts.iter().enumerate() {
            let (row, flip) = self.row_of(g, 3 * i, 3 * j);
            let (p, q, r) = self.accumulate(g, row, flip, pos, nrm, geometric);
            for c in 0..3 {
                let t = w[k] * p[c];
                acc.0[c] += t;
                let t = w[k] * q[c];
                acc.1[c] += t;
                let t = w[k] * r[c];
                acc.2[c] += t;
            }
        }
        TessSample {
            position: acc.0,
            normal: if geometric {
                cross(acc.1, acc.2)
            } else {
                acc.1
            },
            exact: false,
        }
    }

    /// Level-1 positions from base positions, as the stencil evaluator computes them
    /// ([`GpuStencils::row_point`]).
    pub fn subdivide(&self, base: &[[f32; 3]]) -> Vec<Level1Point> {
        (0..self.level1_vertices)
            .map(|v| {
                let [x, y, z] = self.stencils.row_point(v, |i| base[i as usize]);
                [x, y, z, 1.0]
            })
            .collect()
    }

    /// Level-1 limit normals, as `glsl/bft/normals.comp` computes them.
    pub fn normals(&self, level1: &[Level1Point]) -> Vec<Level1Point> {
        (0..self.level1_vertices as usize)
            .map(|v| {
                let (a, b) = (
                    self.tangent_offsets[v] as usize,
                    self.tangent_offsets[v + 1] as usize,
                );
                let (mut t1, mut t2) = ([0f32; 3], [0f32; 3]);
                for term in &self.tangent_terms[a..b] {
                    let q = level1[term.index as usize];
                    for c in 0..3 {
                        let t = term.weight_t1 * q[c];
                        t1[c] += t;
                        let t = term.weight_t2 * q[c];
                        t2[c] += t;
                    }
                }
                let n = cross(t1, t2);
                let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
                if l > 0.0 {
                    [n[0] / l, n[1] / l, n[2] / l, 0.0]
                } else {
                    [0.0; 4]
                }
            })
            .collect()
    }
}

fn cross(a: [f32; 3], b: [f32; 3]) -> [f32; 3] {
    [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ]
}
