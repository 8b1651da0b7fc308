//! Driver workarounds: a documented list keyed by driver and version. Each entry names the bug,
//! how it was measured and what Tessera does about it. Never hide a bug by lowering quality
//! (e.g. tessellation factors): work around it.
use crate::device::AdapterInfo;
use ash::vk;

/// One known driver bug.
#[derive(Clone, Debug)]
pub struct Workaround {
    pub id: WorkaroundId,
    pub driver: vk::DriverId,
    pub summary: &'static str,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum WorkaroundId {
    /// lavapipe (Mesa llvmpipe's Vulkan driver), measured on Mesa 22.3: a tessellated draw is
    /// processed in chunks of min(patches, 4096 / control points per patch) patches, and a chunk
    /// emitting more than 65,536 vertices gets corrupt triangles (its vertex indices are 16-bit;
    /// the TES outputs themselves stay right) and slows down super-linearly. We split tessellated
    /// draws so that no chunk can exceed 65,536 vertices at the largest factor the draw can use.
    /// This is likely the cause of OpenSubdiv's holes on llvmpipe. The super-linear cost starts
    /// long before the corruption, so the split gives each draw a budget of
    /// [`LAVAPIPE_DRAW_VERTEX_BUDGET`] vertices, not the limit: measured on the catmark_car frame
    /// (6.9 M triangles), 4,096 vertices a draw is 1.2x faster than 65,536 for the adaptive
    /// surface and 1.3x for Flat (docs/benchmarks.md, "What lavapipe charges for: code size, varyings, draw size").
    LavapipeTessChunkVertexLimit,
    /// lavapipe, Mesa 22.3: a pipeline-statistics query around a draw of one-control-point
    /// patches with no vertex input (the BFT main pass) crashes a worker thread (SIGSEGV); the
    /// same draw without the query renders correctly. Tessera does not query statistics for
    /// such draws there and counts their output through transform feedback instead.
    LavapipeStatisticsQueryPointPatches,
    /// lavapipe, Mesa 22.3: in a tessellated draw of patches of more than one control point,
    /// `gl_PrimitiveID` restarts at 0 every ⌊1,024 / control points⌋ patches (measured: every
    /// 341 three-point and every 256 four-point patches; one-point patches count on correctly
    /// through hundreds of thousands). Patch ids written to captures, and any patch fetched by
    /// its id, would repeat (captures of flat, Phong and PN named later patches by earlier ones'
    /// ids at 1 or 2 segments: the teapot's 6,320 triangles showed 106 false cracks). Tessera
    /// draws at most that many such patches per draw.
    LavapipeTessPrimitiveIdRestart,
}

/// The list of every known workaround; `Workarounds::for_adapter` picks the active ones.
pub fn known() -> Vec<Workaround> {
    vec![
        Workaround {
            id: WorkaroundId::LavapipeTessChunkVertexLimit,
            driver: vk::DriverId::MESA_LLVMPIPE,
            summary: "lavapipe: tessellated draws split so no internal chunk emits > 65,536 vertices (16-bit chunk indices); 4,096 a draw, where its cost is still linear",
        },
        Workaround {
            id: WorkaroundId::LavapipeTessPrimitiveIdRestart,
            driver: vk::DriverId::MESA_LLVMPIPE,
            summary: "lavapipe: tessellated draws of multi-point patches split every 1,024 control points, where gl_PrimitiveID restarts",
        },
        Workaround {
            id: WorkaroundId::LavapipeStatisticsQueryPointPatches,
            driver: vk::DriverId::MESA_LLVMPIPE,
            summary: "lavapipe: no pipeline-statistics query around one-control-point patch draws (crashes)",
        },
    ]
}

/// The workarounds active on one device.
#[derive(Clone, Debug, Default)]
pub struct Workarounds {
    active: Vec<Workaround>,
}

/// Vertices a lavapipe chunk may emit before its 16-bit indices overflow.
pub const LAVAPIPE_CHUNK_VERTEX_LIMIT: u64 = 65_536;

/// Control points of multi-point patches after which lavapipe restarts `gl_PrimitiveID`.
pub const LAVAPIPE_PRIMITIVE_ID_CONTROL_POINTS: u32 = 1_024;

/// Vertices one tessellated draw may emit on lavapipe (at the draw's largest factors): within
/// the chunk limit, and small enough that a chunk's super-linear cost has not set in (each
/// draw is one chunk then). 16,384 and 8,192 measured in between, 2,048 no better.
pub const LAVAPIPE_DRAW_VERTEX_BUDGET: u64 = 4_096;
const _: () = assert!(LAVAPIPE_DRAW_VERTEX_BUDGET <= LAVAPIPE_CHUNK_VERTEX_LIMIT);

impl Workarounds {
    pub fn for_adapter(info: &AdapterInfo) -> Self {
        // No fixed Mesa version is known yet: every lavapipe gets the split.
        Self {
            active: known()
                .into_iter()
                .filter(|w| w.driver == info.driver_id)
                .collect(),
        }
    }

    pub fn active(&self) -> &[Workaround] {
        &self.active
    }

    pub fn has(&self, id: WorkaroundId) -> bool {
        self.active.iter().any(|w| w.id == id)
    }

    /// How many patches of `control_points` points one tessellated draw may hold, given the
    /// most vertices one patch can emit at the draw's largest factors. `u32::MAX` when no limit
    /// applies.
    pub fn max_patches_per_draw(&self, max_vertices_per_patch: u64, control_points: u32) -> u32 {
        let mut most = u32::MAX;
        if self.has(WorkaroundId::LavapipeTessChunkVertexLimit) {
            most = (LAVAPIPE_DRAW_VERTEX_BUDGET / max_vertices_per_patch.max(1)).max(1) as u32;
        }
        if self.has(WorkaroundId::LavapipeTessPrimitiveIdRestart) && control_points > 1 {
            most = most.min(LAVAPIPE_PRIMITIVE_ID_CONTROL_POINTS / control_points);
        }
        most.max(1)
    }
}
