//! Tessera's C ABI (`include/tessera.h`, generated from this crate by cbindgen; the C++ wrapper
//! `include/tessera.hpp` sits on top of it).
//!
//! # Handles
//! `TesseraContext*` (a device and how Tessera uses it), `TesseraSurface*` (one control mesh
//! built for one technique on one context) and `TesseraLimitEvaluator*` (a surface's or mesh's
//! exact limit surface on the CPU, [`limit`]) are opaque. They are numbers in a handle table
//! (the `handles` module), never pointers into Rust memory: a null, forged, destroyed or
//! twice-destroyed handle is answered with `TESSERA_STATUS_NULL_HANDLE`,
//! `TESSERA_STATUS_INVALID_HANDLE` or `TESSERA_STATUS_DESTROYED_HANDLE`, never undefined
//! behaviour. Destroying a context destroys the surfaces still created on it.
//!
//! # Status codes and messages
//! Every function that can fail returns a [`TesseraStatus`]: one value per class of the Rust
//! error types (`topology::TopologyError`, `tess::TessError`, `vk_core::VkError`) plus the
//! boundary's own (null/invalid/destroyed handle, null pointer, wrong size, index out of range,
//! wrong mode, panic). The message that names the face, edge, option or Vulkan call at fault
//! is kept twice: in the context the call was about (read with [`tessera_last_error`] and that
//! context), and in a thread-local string of the calling thread (read with a null context),
//! which is what a call that has no context yet (context creation) or whose context handle
//! was bad leaves its message in. A successful call leaves both untouched.
//!
//! No panic crosses the boundary: every exported function runs its body under
//! `std::panic::catch_unwind` and answers `TESSERA_STATUS_PANIC` with the panic's message.
//!
//! # Techniques through one seam
//! A technique is chosen by value (`TESSERA_TECHNIQUE_*`, or `_AUTO` to follow the scheme) and
//! built through `tess::build`; drawing, animation and capture go through `tess::Technique`
//! and `tess::Context`, so every technique the registry knows is reachable with the same
//! functions and no function names a technique.
//!
//! # Modes
//! - **Standalone** ([`tessera_context_create_standalone`]): Tessera loads Vulkan, chooses the
//!   device by the CLI's rules (`vk_core::device::choose_adapter`: best-scored, or by index or
//!   name substring) and renders into an RGBA8 buffer the host reads ([`tessera_render`]).
//! - **Host-owned** (see [`host`]): the host's Vulkan objects, never destroyed by Tessera;
//!   Tessera records into the host's dynamic-rendering scopes or a subpass of its render pass.
//!
//! Both capture what the GPU drew, with `tessera export`'s weld, crack report and OBJ
//! ([`capture`]), and both make limit evaluators ([`limit`]), which need no device at all when
//! made from a mesh.
//!
//! # Thread safety
//! Every function may be called from any thread. Calls on one context (and on its surfaces)
//! are serialized by a lock per context and per surface; calls on different contexts run
//! concurrently. A handle destroyed on one thread while another uses it makes the other's
//! call (or its next one) return `TESSERA_STATUS_DESTROYED_HANDLE`.
//!
//! # Enumerations and flags
//! Enumerations a host passes in are `uint32_t` with `#define`d values, and flags are
//! `uint32_t` (0 or 1): a value outside the enumeration is a `TESSERA_STATUS_INVALID_ARGUMENT`,
//! not a Rust enum holding an invalid discriminant.
//!
//! # Unsafe
//! vk-core is the crate that holds Tessera's `unsafe`; this crate is the one other place it is
//! unavoidable: the exported functions are `unsafe extern "C"` because they read the host's
//! raw pointers. Those reads are gathered in [`ffi`] (slices, strings, output writes), each
//! with its contract; everything past them is safe Rust.
pub mod ffi;
mod handles;
pub mod status;

pub use capture::{tessera_capture, tessera_capture_obj, TesseraCaptureReport};
pub use limit::{
    tessera_limit_evaluate, tessera_limit_evaluator_create, tessera_limit_evaluator_create_mesh,
    tessera_limit_evaluator_destroy, tessera_limit_evaluator_info, TesseraLimitEvaluator,
};
pub use status::TesseraStatus;

use ffi::{out_write, read_slice, read_str};
use handles::{lock, HandleTable};
use status::{Error, Result};
use std::cell::RefCell;
use std::ffi::c_char;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::sync::{Arc, Mutex, OnceLock};
use tess::surface::{SurfaceImage, SurfaceMaps, SurfaceShow};
use tess::{Camera, FactorPolicy, FrameParams, Spacing, Technique, TechniqueId};
use vk_core::{vk, Device, DeviceDesc, DeviceSelector, Instance, InstanceDesc, Validation};

/// An opaque context: a Vulkan device and how Tessera uses it.
// Not `repr(C)`: cbindgen then declares it opaque (`typedef struct TesseraContext TesseraContext;`).
pub struct TesseraContext {
    _opaque: (),
}

/// An opaque surface: one control mesh built for one technique on one context.
// Not `repr(C)`: cbindgen then declares it opaque (`typedef struct TesseraSurface TesseraSurface;`).
pub struct TesseraSurface {
    _opaque: (),
}

/// Which technique draws a surface (`TESSERA_TECHNIQUE_*`).
pub type TesseraTechnique = u32;
/// The technique of the scheme: `adaptive` for Catmull-Clark, `bft` for Loop.
pub const TESSERA_TECHNIQUE_AUTO: TesseraTechnique = 0;
pub const TESSERA_TECHNIQUE_FLAT: TesseraTechnique = 1;
pub const TESSERA_TECHNIQUE_PHONG: TesseraTechnique = 2;
pub const TESSERA_TECHNIQUE_PN: TesseraTechnique = 3;
pub const TESSERA_TECHNIQUE_BFT: TesseraTechnique = 4;
pub const TESSERA_TECHNIQUE_ADAPTIVE: TesseraTechnique = 5;
/// Catmull-Clark approximated in one pass: one Gregory patch per base face (`--method gregory`).
pub const TESSERA_TECHNIQUE_GREGORY: TesseraTechnique = 6;
/// Catmull-Clark approximated in one pass by ACC-1 patches, Gregory where ACC-1 does not apply
/// (`--method acc`).
pub const TESSERA_TECHNIQUE_ACC: TesseraTechnique = 7;
/// Loop subdivision on the CPU to level log2 S at the limit, drawn as a static mesh
/// (`--method cpu`; levels are powers of two up to 64 segments).
pub const TESSERA_TECHNIQUE_CPU: TesseraTechnique = 8;
/// Catmull-Clark subdivision on the CPU, drawn as a static mesh (`--method cpu-catmark`).
pub const TESSERA_TECHNIQUE_CPU_CATMARK: TesseraTechnique = 9;
/// Doo-Sabin subdivision refined on the GPU every frame to level log2 S, drawn from the vertex
/// stage (`--method doo-sabin`; levels are powers of two from 2 to 64 segments).
pub const TESSERA_TECHNIQUE_DOO_SABIN: TesseraTechnique = 10;
/// Doo-Sabin subdivision on the CPU to level log2 S, drawn as a static mesh
/// (`--method cpu-doo-sabin`: the CPU baseline of `TESSERA_TECHNIQUE_DOO_SABIN`).
pub const TESSERA_TECHNIQUE_CPU_DOO_SABIN: TesseraTechnique = 11;
/// The exact Doo-Sabin limit surface: biquadratic patches isolated feature-adaptively around the
/// centres of non-quad faces, bilinear end caps (`--method doo-sabin-limit`; the default for
/// `TESSERA_SCHEME_DOO_SABIN`).
pub const TESSERA_TECHNIQUE_DOO_SABIN_LIMIT: TesseraTechnique = 12;
/// Doo-Sabin subdivision as the seed paper's vertex patches: one array per control vertex,
/// refined in a compute kernel by index arithmetic to level log2 S, drawn from the vertex stage
/// (`--method vertex-patches`; levels are powers of two from 2 to 64 segments).
pub const TESSERA_TECHNIQUE_VERTEX_PATCHES: TesseraTechnique = 13;

/// The subdivision scheme (`TESSERA_SCHEME_*`).
pub type TesseraScheme = u32;
/// Catmull-Clark unless every face is a triangle (then Loop); a Loop technique fan-triangulates.
pub const TESSERA_SCHEME_AUTO: TesseraScheme = 0;
pub const TESSERA_SCHEME_CATMULL_CLARK: TesseraScheme = 1;
/// Loop, strictly: a mesh with a face that is not a triangle is refused (`TESSERA_STATUS_MESH`).
pub const TESSERA_SCHEME_LOOP: TesseraScheme = 2;
/// Doo-Sabin (drawn by `TESSERA_TECHNIQUE_DOO_SABIN_LIMIT`, `TESSERA_TECHNIQUE_DOO_SABIN`,
/// `TESSERA_TECHNIQUE_VERTEX_PATCHES` and `TESSERA_TECHNIQUE_CPU_DOO_SABIN`; its limit evaluator evaluates the exact Doo-Sabin limit).
pub const TESSERA_SCHEME_DOO_SABIN: TesseraScheme = 3;

/// How tessellation factors are chosen (`TESSERA_FACTORS_*`).
pub type TesseraFactorPolicy = u32;
/// `factor` segments per base edge.
pub const TESSERA_FACTORS_UNIFORM: TesseraFactorPolicy = 0;
/// `factor` pixels per segment (techniques with adaptive factors).
pub const TESSERA_FACTORS_SCREEN: TesseraFactorPolicy = 1;
/// Maximum level at distance `factor` (world units), halving as the distance doubles.
pub const TESSERA_FACTORS_DISTANCE: TesseraFactorPolicy = 2;

/// Tessellation spacing (`TESSERA_SPACING_*`).
pub type TesseraSpacing = u32;
pub const TESSERA_SPACING_EQUAL: TesseraSpacing = 0;
pub const TESSERA_SPACING_FRACTIONAL_EVEN: TesseraSpacing = 1;
pub const TESSERA_SPACING_FRACTIONAL_ODD: TesseraSpacing = 2;

/// The draw path a surface is built for (`TESSERA_PIPELINE_*`, the CLI's `--pipeline`).
pub type TesseraPipeline = u32;
/// Where a technique has both paths, the one measured faster on the device's driver (patterns
/// on lavapipe, the tessellation stage elsewhere); refinement patterns without tessellation
/// shaders.
pub const TESSERA_PIPELINE_AUTO: TesseraPipeline = 0;
pub const TESSERA_PIPELINE_TESSELLATION: TesseraPipeline = 1;
/// Refinement patterns: a tessellated domain instanced over the patches, evaluated in the
/// vertex stage (flat, phong, pn).
pub const TESSERA_PIPELINE_PATTERN: TesseraPipeline = 2;

/// End caps of the adaptive technique (`TESSERA_END_CAP_*`).
pub type TesseraEndCap = u32;
pub const TESSERA_END_CAP_GREGORY: TesseraEndCap = 0;
pub const TESSERA_END_CAP_BILINEAR: TesseraEndCap = 1;

/// How texture coordinates are interpolated (`TESSERA_UV_INTERPOLATION_*`; adaptive, gregory,
/// acc): OpenSubdiv's face-varying linear-interpolation modes (docs/face-varying.md), or the
/// mesh's own (a file's `faceVaryingLinearInterpolation` or `t facevaryinginterpolateboundary`;
/// `all` for a `TesseraMeshDesc`, whose corners share a value where their uvs are bit-equal).
pub type TesseraUvInterpolation = u32;
pub const TESSERA_UV_INTERPOLATION_MESH: TesseraUvInterpolation = 0;
pub const TESSERA_UV_INTERPOLATION_NONE: TesseraUvInterpolation = 1;
pub const TESSERA_UV_INTERPOLATION_CORNERS_ONLY: TesseraUvInterpolation = 2;
pub const TESSERA_UV_INTERPOLATION_CORNERS_PLUS1: TesseraUvInterpolation = 3;
pub const TESSERA_UV_INTERPOLATION_CORNERS_PLUS2: TesseraUvInterpolation = 4;
pub const TESSERA_UV_INTERPOLATION_BOUNDARIES: TesseraUvInterpolation = 5;
/// Bilinear on each face.
pub const TESSERA_UV_INTERPOLATION_ALL: TesseraUvInterpolation = 6;

/// What a surface is coloured by (`TESSERA_SHOW_*`; adaptive, gregory, acc).
pub type TesseraShow = u32;
/// Lighting of the albedo (texture, patch colours or base colour).
pub const TESSERA_SHOW_SHADING: TesseraShow = 0;
/// How far the reparameterization moves the texture parameter (blue 0, red 0.05 of a patch).
pub const TESSERA_SHOW_PARAM_SHIFT: TesseraShow = 1;
/// The pointwise texture error (log scale); the surface must be built with `param_error` 1.
pub const TESSERA_SHOW_PARAM_ERROR: TesseraShow = 2;

/// The largest texture or height-map side the C ABI takes (the device's
/// `maxImageDimension2D` may lower it).
pub const TESSERA_MAX_IMAGE_SIDE: u32 = 16384;

/// The Khronos validation layer in standalone mode (`TESSERA_VALIDATION_*`).
pub type TesseraValidation = u32;
pub const TESSERA_VALIDATION_OFF: TesseraValidation = 0;
pub const TESSERA_VALIDATION_ON: TesseraValidation = 1;
/// Also synchronization validation (slower).
pub const TESSERA_VALIDATION_SYNCHRONIZATION: TesseraValidation = 2;

/// Whether Tessera keeps its Vulkan pipeline cache on disk between runs
/// (`TESSERA_PIPELINE_CACHE_*`).
pub type TesseraPipelineCache = u32;
/// On disk, in the descriptor's `pipeline_cache_dir`, or when that is NULL in the user's cache
/// directory (`$XDG_CACHE_HOME/tessera/pipelines`, else `~/.cache/tessera/pipelines`), one
/// file per device and driver build (its header is checked against the device before use);
/// the environment variable `TESSERA_PIPELINE_CACHE=off` turns it off for the process. The
/// value of a zero-filled descriptor.
pub const TESSERA_PIPELINE_CACHE_DEFAULT: TesseraPipelineCache = 0;
/// In memory only: every context compiles its pipelines afresh.
pub const TESSERA_PIPELINE_CACHE_OFF: TesseraPipelineCache = 1;

/// How a standalone context is made. A zero-filled descriptor is valid (best device, no
/// validation, the default pipeline cache).
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct TesseraStandaloneDesc {
    /// NUL-terminated device selector as the CLI's `--device`: NULL, "" or "auto" for the
    /// best-scored device, a number for an index, other text for a name substring.
    pub device: *const c_char,
    /// `TESSERA_VALIDATION_*`; the layer must be installed when not OFF.
    pub validation: TesseraValidation,
    /// `TESSERA_PIPELINE_CACHE_*`.
    pub pipeline_cache: TesseraPipelineCache,
    /// NULL (the user's cache directory) or a NUL-terminated directory for the pipeline cache
    /// (created when missing).
    pub pipeline_cache_dir: *const c_char,
}

impl Default for TesseraStandaloneDesc {
    /// What a zero-filled descriptor holds.
    fn default() -> Self {
        Self {
            device: std::ptr::null(),
            validation: TESSERA_VALIDATION_OFF,
            pipeline_cache: TESSERA_PIPELINE_CACHE_DEFAULT,
            pipeline_cache_dir: std::ptr::null(),
        }
    }
}

/// The directory of the pipeline cache a descriptor asks for; `None`: in memory only.
///
/// # Safety
/// `dir` is NULL or NUL-terminated.
pub(crate) unsafe fn pipeline_cache_dir(
    setting: TesseraPipelineCache,
    dir: *const c_char,
) -> Result<Option<std::path::PathBuf>> {
    // SAFETY: the caller's contract.
    let dir = unsafe { read_str(dir, "pipeline_cache_dir") }?;
    match setting {
        TESSERA_PIPELINE_CACHE_OFF => Ok(None),
        TESSERA_PIPELINE_CACHE_DEFAULT => match dir {
            Some(d) if d.is_empty() => Err(Error::new(
                TesseraStatus::InvalidArgument,
                "pipeline_cache_dir is empty (NULL means the user's cache directory)",
            )),
            Some(d) if vk_core::pipeline_cache::allowed_by_env() => Ok(Some(d.into())),
            Some(_) => Ok(None),
            None => Ok(vk_core::pipeline_cache::user_dir()),
        },
        v => Err(invalid(
            "pipeline_cache",
            v,
            "a TESSERA_PIPELINE_CACHE_* value",
        )),
    }
}

/// A control mesh. Arrays are read during the call only. Counts are of elements (vertices,
/// faces, creases), not of floats.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct TesseraMeshDesc {
    /// NUL-terminated name for messages; NULL: "mesh".
    pub name: *const c_char,
    /// `3 * vertex_count` floats (x, y, z).
    pub positions: *const f32,
    pub vertex_count: usize,
    /// `face_count` corner counts (3 or more each).
    pub face_sizes: *const u32,
    pub face_count: usize,
    /// `index_count` vertex indices, faces one after the other; `index_count` must equal the
    /// sum of `face_sizes`.
    pub face_indices: *const u32,
    pub index_count: usize,
    /// `2 * crease_count` vertex indices (each crease an edge of the mesh) and `crease_count`
    /// sharpness values (10 or more: infinitely sharp). NULL when `crease_count` is 0.
    pub crease_vertices: *const u32,
    pub crease_sharpness: *const f32,
    pub crease_count: usize,
    /// `corner_count` vertex indices and sharpness values. NULL when `corner_count` is 0.
    pub corner_vertices: *const u32,
    pub corner_sharpness: *const f32,
    pub corner_count: usize,
    /// NULL, or `2 * index_count` floats: one (u, v) per face corner.
    pub uvs: *const f32,
    /// Scalar tags of an ST-mesh (the PN technique's sharp creases; docs/scalar-tags.md):
    /// `scalar_tag_count` vertex indices and `6 * scalar_tag_count` floats, per tag its
    /// deviation vector (x, y, z), tension (0..=1), sharpness (0..=1) and bias (-1..=1). NULL
    /// when `scalar_tag_count` is 0.
    pub scalar_tag_vertices: *const u32,
    pub scalar_tag_values: *const f32,
    pub scalar_tag_count: usize,
}

/// How a surface is built. [`tessera_surface_desc_default`] fills the defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct TesseraSurfaceDesc {
    pub technique: TesseraTechnique,
    pub scheme: TesseraScheme,
    /// Basis-function table level (bft), 1..=6.
    pub table_level: u32,
    /// Build tangent tables so frames may ask for geometric normals (bft); 0 or 1.
    pub tangents: u32,
    /// Isolation level (adaptive).
    pub isolation: u32,
    /// `TESSERA_END_CAP_*` (adaptive).
    pub end_cap: TesseraEndCap,
    /// Scales every crease and corner sharpness (adaptive, gregory, acc).
    pub sharpness_scale: f32,
    /// Colour texture sampled at the mesh's `uvs` (adaptive, gregory, acc): NULL (none, and
    /// both sizes 0) or `texture_width * texture_height * 4` bytes of RGBA8 sRGB, rows top to
    /// bottom, copied during the call. Sides 1..=`TESSERA_MAX_IMAGE_SIDE` (and the device's
    /// `maxImageDimension2D`).
    pub texture: *const u8,
    pub texture_width: u32,
    pub texture_height: u32,
    /// Height map for the frame's `displace` (adaptive, gregory, acc): NULL (none: a procedural
    /// height) or `height_map_width * height_map_height` finite floats (typically 0..1), rows
    /// top to bottom, copied during the call; sides as the texture's.
    pub height_map: *const f32,
    pub height_map_width: u32,
    pub height_map_height: u32,
    /// Compute the texture-error lattice `TESSERA_SHOW_PARAM_ERROR` draws (CPU work at build
    /// time); 0 or 1 (adaptive, gregory, acc).
    pub param_error: u32,
    /// Split each triangle into three quad patches instead of one Gregory triangle patch; 0 or
    /// 1 (gregory, acc).
    pub split_triangles: u32,
    /// `TESSERA_PIPELINE_*`: the draw path.
    pub pipeline: TesseraPipeline,
    /// `TESSERA_UV_INTERPOLATION_*`: how texture coordinates are interpolated
    /// (`TESSERA_UV_INTERPOLATION_MESH`: the mesh's own mode).
    pub uv_interpolation: TesseraUvInterpolation,
}

/// What one frame shows. [`tessera_frame_desc_default`] fills the defaults.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct TesseraFrameDesc {
    /// Target size in pixels: the standalone image's, or the host's viewport (screen-space
    /// factors and the wireframe width depend on it).
    pub width: u32,
    pub height: u32,
    /// `TESSERA_FACTORS_*` and its value (segments, pixels per segment, or distance).
    pub factor_policy: TesseraFactorPolicy,
    pub factor: f32,
    pub spacing: TesseraSpacing,
    /// Wireframe overlay; 0 or 1.
    pub wireframe: u32,
    /// Standalone orbit camera, in degrees (zoom > 1 moves closer); ignored where the host
    /// gives view and projection.
    pub yaw: f32,
    pub pitch: f32,
    pub zoom: f32,
    /// Phong shape factor (phong).
    pub phong_alpha: f32,
    /// Colour patches by type (bft, adaptive); 0 or 1.
    pub patch_colours: u32,
    /// Normals from the parametric derivatives (bft built with tangents); 0 or 1.
    pub geometric_normals: u32,
    pub base_color: [f32; 3],
    /// Clear colour of the standalone image (RGBA, 0..1).
    pub clear_color: [f32; 4],
    /// 1: texture coordinates at the base parameter, without the reparameterization of
    /// Gregory patches (seed 003); 0 or 1 (default 0, so a zero-filled descriptor keeps it on;
    /// 1 only on adaptive, gregory, acc).
    pub no_reparam: u32,
    /// Displacement along the normal by this times the height (the surface's height map, else
    /// a procedural one); finite, at most 1000 in magnitude; nonzero only on adaptive, gregory,
    /// acc.
    pub displace: f32,
    /// `TESSERA_SHOW_*`; other than SHADING only on adaptive, gregory, acc.
    pub show: TesseraShow,
}

type Contexts =
    HandleTable<ContextState, SurfaceState, topology::limit::face_domain::LimitEvaluator>;

fn handles() -> &'static Mutex<Contexts> {
    static HANDLES: OnceLock<Mutex<Contexts>> = OnceLock::new();
    HANDLES.get_or_init(|| Mutex::new(HandleTable::default()))
}

thread_local! {
    static LAST_ERROR: RefCell<String> = const { RefCell::new(String::new()) };
}

/// What a context is. Drop order (field order): surfaces waiting for their last frame, the
/// device handle, then the instance.
pub(crate) struct ContextState {
    /// Host-owned mode: surfaces destroyed by the host while frames that drew them may still
    /// run, each with the frame that was current at its destruction ([`host`]).
    graveyard: Vec<(u64, Arc<Mutex<SurfaceState>>)>,
    device: Device,
    /// The validation-message counter of a standalone context's own instance.
    instance: Arc<Instance>,
    mode: Mode,
    last_error: String,
}

pub(crate) enum Mode {
    Standalone,
    /// The host's device; `frame` is what [`tessera_begin_frame`] last said.
    Host {
        frames_in_flight: usize,
        frame: u64,
        formats: [vk::Format; 2],
        /// The host's render pass subpass; `None`: dynamic rendering.
        subpass: Option<vk_core::pipeline::Subpass>,
        /// `dynamicRendering` is enabled on the host's device (captures need it).
        dynamic_rendering: bool,
    },
}

impl ContextState {
    /// The frame slot the current frame writes (its uniforms, its animated positions).
    fn slot(&self) -> usize {
        match self.mode {
            Mode::Standalone => 0,
            Mode::Host {
                frames_in_flight,
                frame,
                ..
            } => (frame % frames_in_flight as u64) as usize,
        }
    }
}

/// One surface. Drop order (field order): the technique (its buffers and sets), then the
/// `tess::Context` (pipelines, layouts, frame uniforms) it was built on.
pub(crate) struct SurfaceState {
    technique: Box<dyn Technique>,
    tess: tess::Context,
    vertex_count: usize,
    /// Base positions at creation ([`tessera_surface_positions`] before any update).
    rest: Vec<[f32; 3]>,
    /// The control mesh as built (positions at creation): what captures classify open edges
    /// against and limit evaluators evaluate.
    mesh: topology::ControlMesh,
    /// The subdivision scheme of its limit surface ([`limit`]).
    scheme: topology::Scheme,
    /// The sharpness scale its technique applied (1 where the technique does not scale).
    sharpness_scale: f32,
    /// What host-owned frames draw ([`tessera_surface_set_frame`]).
    frame: (FrameParams, vk::Extent2D),
    /// The newest animated positions and their version; each slot records the version it
    /// holds, so a slot reused by a later frame catches up before it is drawn.
    positions: Option<(u64, Vec<[f32; 3]>)>,
    slot_versions: Vec<u64>,
}

impl SurfaceState {
    /// The control mesh whose limit surface the surface stands for: its newest positions,
    /// its creases and corners scaled as its technique scaled them.
    fn limit_mesh(&self) -> topology::ControlMesh {
        let mut mesh = self.mesh.clone();
        if let Some((_, p)) = &self.positions {
            mesh.positions = p.iter().map(|q| q.map(f64::from)).collect();
        }
        let scale = |s: &mut f32| {
            if !topology::rules::is_infinite(*s) {
                *s *= self.sharpness_scale;
            }
        };
        mesh.creases
            .iter_mut()
            .for_each(|c| scale(&mut c.sharpness));
        mesh.corners
            .iter_mut()
            .for_each(|c| scale(&mut c.sharpness));
        mesh
    }

    /// Brings frame slot `slot`'s animated positions up to the newest ones.
    fn sync_positions(&mut self, slot: usize) -> Result<()> {
        if let Some((version, p)) = &self.positions {
            if self.slot_versions.get(slot) != Some(version) {
                self.technique.update_base(slot, p)?;
                if let Some(v) = self.slot_versions.get_mut(slot) {
                    *v = *version;
                }
            }
        }
        Ok(())
    }
}

fn handle_id<T>(p: *const T) -> u64 {
    p as usize as u64
}

fn context_ptr(id: u64) -> *mut TesseraContext {
    id as usize as *mut TesseraContext
}

fn surface_ptr(id: u64) -> *mut TesseraSurface {
    id as usize as *mut TesseraSurface
}

fn panic_message(payload: Box<dyn std::any::Any + Send>) -> String {
    let what = payload
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| payload.downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic without a message".into());
    format!("panic inside Tessera (a bug; please report it): {what}")
}

/// Runs `body` under `catch_unwind`; a failure's message goes to the thread's last error.
fn guard(body: impl FnOnce() -> Result<()>) -> TesseraStatus {
    let e = match catch_unwind(AssertUnwindSafe(body)) {
        Ok(Ok(())) => return TesseraStatus::Ok,
        Ok(Err(e)) => e,
        Err(payload) => Error::new(TesseraStatus::Panic, panic_message(payload)),
    };
    LAST_ERROR.with(|l| *l.borrow_mut() = e.message.clone());
    e.status
}

/// [`guard`] for a call about context `ctx`: its message also goes to the context.
fn with_context(
    ctx: *const TesseraContext,
    body: impl FnOnce(&mut ContextState) -> Result<()>,
) -> TesseraStatus {
    let id = handle_id(ctx);
    let mut state = None;
    let status = guard(|| {
        let c = lock(handles())?.context(id)?;
        state = Some(c.clone());
        let mut s = lock(&c)?;
        body(&mut s)
    });
    if status != TesseraStatus::Ok {
        if let Some(c) = state {
            let message = LAST_ERROR.with(|l| l.borrow().clone());
            if let Ok(mut s) = c.lock() {
                s.last_error = message;
            }
        }
    }
    status
}

/// [`with_context`] for a call about `surface` of `ctx`.
fn with_surface(
    ctx: *const TesseraContext,
    surface: *const TesseraSurface,
    body: impl FnOnce(&mut ContextState, &mut SurfaceState) -> Result<()>,
) -> TesseraStatus {
    let ctx_id = handle_id(ctx);
    with_context(ctx, |c| {
        let (owner, s) = lock(handles())?.surface(handle_id(surface))?;
        if owner != ctx_id {
            return Err(Error::new(
                TesseraStatus::WrongContext,
                format!(
                    "surface {:#x} belongs to context {owner:#x}, not {ctx_id:#x}",
                    handle_id(surface)
                ),
            ));
        }
        let mut s = lock(&s)?;
        body(c, &mut s)
    })
}

/// The static name of a status code ("ok", "destroyed handle", ...); "unknown status" for a
/// value that is none. Thread-safe; the string is never freed.
#[no_mangle]
pub extern "C" fn tessera_status_name(status: u32) -> *const c_char {
    use TesseraStatus as S;
    let all = [
        S::Ok,
        S::NullHandle,
        S::InvalidHandle,
        S::DestroyedHandle,
        S::NullPointer,
        S::InvalidArgument,
        S::WrongSize,
        S::IndexOutOfRange,
        S::WrongMode,
        S::WrongContext,
        S::Parse,
        S::Mesh,
        S::NonFinite,
        S::Unsupported,
        S::NoLoader,
        S::NoDevice,
        S::MissingFeatures,
        S::Vulkan,
        S::OutOfMemory,
        S::Recording,
        S::Capture,
        S::Io,
        S::Panic,
        S::Internal,
    ];
    all.iter()
        .find(|s| **s as u32 == status)
        .map(|s| s.name().as_ptr())
        .unwrap_or(c"unknown status".as_ptr())
}

/// Copies the last error message into `buffer` (NUL-terminated, truncated to `capacity - 1`
/// bytes) and returns its full length in bytes (without the NUL), so a host can size a buffer
/// with a first call of capacity 0. With a context: the last failure of a call about that
/// context (on any thread); with NULL: the last failure on the calling thread (any call). A
/// context handle that is not live reads as NULL. Empty when nothing failed.
///
/// # Safety
/// `buffer` is NULL (then `capacity` is ignored) or points to `capacity` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn tessera_last_error(
    ctx: *const TesseraContext,
    buffer: *mut c_char,
    capacity: usize,
) -> usize {
    let read = || -> String {
        let from_context = handles()
            .lock()
            .ok()
            .and_then(|r| r.context(handle_id(ctx)).ok())
            .and_then(|c| c.lock().ok().map(|s| s.last_error.clone()));
        from_context.unwrap_or_else(|| LAST_ERROR.with(|l| l.borrow().clone()))
    };
    let message = catch_unwind(read).unwrap_or_default();
    // SAFETY: the caller's contract for `buffer` and `capacity`.
    unsafe { ffi::write_c_string(&message, buffer, capacity) };
    message.len()
}

/// Fills `desc` with the CLI's defaults: technique AUTO, scheme AUTO, bft's default table
/// level, no tangents, adaptive's default isolation, Gregory end caps, sharpness scale 1, no
/// texture, no height map, no texture-error lattice.
///
/// # Safety
/// `desc` is NULL (answered with NULL_POINTER) or points to a writable `TesseraSurfaceDesc`.
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_desc_default(
    desc: *mut TesseraSurfaceDesc,
) -> TesseraStatus {
    guard(|| {
        let b = tess::BuildOptions::default();
        let d = TesseraSurfaceDesc {
            technique: TESSERA_TECHNIQUE_AUTO,
            scheme: TESSERA_SCHEME_AUTO,
            table_level: b.table_level,
            tangents: 0,
            isolation: b.isolation,
            end_cap: TESSERA_END_CAP_GREGORY,
            sharpness_scale: b.sharpness_scale,
            texture: std::ptr::null(),
            texture_width: 0,
            texture_height: 0,
            height_map: std::ptr::null(),
            height_map_width: 0,
            height_map_height: 0,
            param_error: 0,
            split_triangles: 0,
            pipeline: TESSERA_PIPELINE_AUTO,
            uv_interpolation: TESSERA_UV_INTERPOLATION_MESH,
        };
        // SAFETY: the caller's contract.
        unsafe { out_write(desc, d, "desc") }
    })
}

/// Fills `desc` with the defaults of `tessera render`: 640x480, 4 uniform segments, equal
/// spacing, no wireframe, the CLI's camera, colours and Phong factor, reparameterization on,
/// no displacement, shading.
///
/// # Safety
/// `desc` is NULL (answered with NULL_POINTER) or points to a writable `TesseraFrameDesc`.
#[no_mangle]
pub unsafe extern "C" fn tessera_frame_desc_default(desc: *mut TesseraFrameDesc) -> TesseraStatus {
    guard(|| {
        let p = FrameParams::default();
        let d = TesseraFrameDesc {
            width: 640,
            height: 480,
            factor_policy: TESSERA_FACTORS_UNIFORM,
            factor: p.uniform_segments().unwrap_or(4.0),
            spacing: TESSERA_SPACING_EQUAL,
            wireframe: 0,
            yaw: p.camera.yaw,
            pitch: p.camera.pitch,
            zoom: p.camera.zoom,
            phong_alpha: p.phong_alpha,
            patch_colours: 0,
            geometric_normals: 0,
            base_color: p.base_color,
            clear_color: p.clear_color,
            no_reparam: u32::from(!p.reparam),
            displace: p.displace,
            show: TESSERA_SHOW_SHADING,
        };
        // SAFETY: the caller's contract.
        unsafe { out_write(desc, d, "desc") }
    })
}

fn flag(value: u32, what: &str) -> Result<bool> {
    match value {
        0 => Ok(false),
        1 => Ok(true),
        v => Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} {v}: expected 0 or 1"),
        )),
    }
}

fn invalid(what: &str, value: u32, expected: &str) -> Error {
    Error::new(
        TesseraStatus::InvalidArgument,
        format!("{what} {value}: expected {expected}"),
    )
}

/// The frame parameters of `d`, checked where the boundary can tell (the technique checks the
/// rest when it draws).
fn frame_params(d: &TesseraFrameDesc) -> Result<(FrameParams, vk::Extent2D)> {
    if d.width == 0 || d.height == 0 {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!(
                "frame size {}x{}: both must be at least 1",
                d.width, d.height
            ),
        ));
    }
    let factors = match d.factor_policy {
        TESSERA_FACTORS_UNIFORM => FactorPolicy::Uniform { segments: d.factor },
        TESSERA_FACTORS_SCREEN => FactorPolicy::Screen { pixels: d.factor },
        TESSERA_FACTORS_DISTANCE => FactorPolicy::Distance {
            reference: d.factor,
        },
        v => return Err(invalid("factor_policy", v, "a TESSERA_FACTORS_* value")),
    };
    if !(d.factor.is_finite() && d.factor > 0.0) {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("factor {}: expected a finite number above 0", d.factor),
        ));
    }
    let spacing = match d.spacing {
        TESSERA_SPACING_EQUAL => Spacing::Equal,
        TESSERA_SPACING_FRACTIONAL_EVEN => Spacing::FractionalEven,
        TESSERA_SPACING_FRACTIONAL_ODD => Spacing::FractionalOdd,
        v => return Err(invalid("spacing", v, "a TESSERA_SPACING_* value")),
    };
    let numbers = [d.yaw, d.pitch, d.zoom, d.phong_alpha, d.displace]
        .into_iter()
        .chain(d.base_color)
        .chain(d.clear_color);
    if let Some(bad) = numbers.into_iter().find(|x| !x.is_finite()) {
        return Err(Error::new(
            TesseraStatus::NonFinite,
            format!("frame description holds a non-finite number ({bad})"),
        ));
    }
    if d.displace.abs() > 1e3 {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!(
                "displace {}: expected a finite scale of at most 1000 in magnitude",
                d.displace
            ),
        ));
    }
    let show = match d.show {
        TESSERA_SHOW_SHADING => SurfaceShow::Shading,
        TESSERA_SHOW_PARAM_SHIFT => SurfaceShow::ParamShift,
        TESSERA_SHOW_PARAM_ERROR => SurfaceShow::ParamError,
        v => return Err(invalid("show", v, "a TESSERA_SHOW_* value")),
    };
    let params = FrameParams {
        factors,
        spacing,
        wireframe: flag(d.wireframe, "wireframe")?,
        camera: Camera {
            yaw: d.yaw,
            pitch: d.pitch,
            zoom: d.zoom,
            ..Camera::default()
        },
        phong_alpha: d.phong_alpha,
        geometric_normals: flag(d.geometric_normals, "geometric_normals")?,
        patch_colours: flag(d.patch_colours, "patch_colours")?,
        base_color: d.base_color,
        clear_color: d.clear_color,
        reparam: !flag(d.no_reparam, "no_reparam")?,
        displace: d.displace,
        show,
        ..FrameParams::default()
    };
    Ok((
        params,
        vk::Extent2D {
            width: d.width,
            height: d.height,
        },
    ))
}

/// "adaptive, gregory or acc": the techniques with the surface feature (textures,
/// displacement, reparameterization).
fn surface_techniques() -> String {
    let names = tess::techniques::names_with(|f| f.surface);
    match names.split_last() {
        Some((last, rest)) if !rest.is_empty() => format!("{} or {last}", rest.join(", ")),
        _ => names.join(""),
    }
}

/// Refuses what `technique` cannot draw among the options `given` (their names and whether
/// each is set), as the CLI refuses them (`OptionUse`): one message naming every field.
fn refuse_surface_options(technique: TechniqueId, given: &[(&str, bool)]) -> Result<()> {
    if tess::techniques::info(technique).features.surface {
        return Ok(());
    }
    let names: Vec<&str> = given.iter().filter(|g| g.1).map(|g| g.0).collect();
    if names.is_empty() {
        return Ok(());
    }
    Err(Error::new(
        TesseraStatus::Unsupported,
        format!(
            "{} only {} to technique {} (this surface's technique is {technique})",
            names.join(", "),
            if names.len() == 1 { "applies" } else { "apply" },
            surface_techniques()
        ),
    ))
}

/// [`frame_params`] for `s`, refusing the surface options (`no_reparam`, `displace`, `show`)
/// on techniques without them.
fn surface_frame_params(
    s: &SurfaceState,
    d: &TesseraFrameDesc,
) -> Result<(FrameParams, vk::Extent2D)> {
    let (params, extent) = frame_params(d)?;
    refuse_surface_options(
        s.technique.id(),
        &[
            ("no_reparam", !params.reparam),
            ("displace", params.displace != 0.0),
            ("show", params.show != SurfaceShow::Shading),
        ],
    )?;
    Ok((params, extent))
}

/// Creates a standalone context: Tessera's own Vulkan instance and device, chosen as the CLI
/// chooses. Thread-safe.
///
/// # Safety
/// `desc` is NULL (defaults: best device, validation off, the default pipeline cache) or
/// points to a readable `TesseraStandaloneDesc` whose `device` and `pipeline_cache_dir` are
/// NULL or NUL-terminated strings; `out` points to a writable `TesseraContext*` (set to NULL
/// on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_context_create_standalone(
    desc: *const TesseraStandaloneDesc,
    out: *mut *mut TesseraContext,
) -> TesseraStatus {
    guard(|| {
        // SAFETY: the caller's contract for `out`.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract for `desc`.
        let desc = unsafe { ffi::read_opt(desc) }.unwrap_or_default();
        // SAFETY: the caller's contract for `desc.pipeline_cache_dir`.
        let cache = unsafe { pipeline_cache_dir(desc.pipeline_cache, desc.pipeline_cache_dir) }?;
        // SAFETY: the caller's contract for `desc.device`.
        let selector: DeviceSelector = unsafe { read_str(desc.device, "device") }?
            .unwrap_or_default()
            .parse()
            .unwrap_or_default();
        let validation = match desc.validation {
            TESSERA_VALIDATION_OFF => Validation::Off,
            TESSERA_VALIDATION_ON => Validation::On,
            TESSERA_VALIDATION_SYNCHRONIZATION => Validation::Synchronization,
            v => return Err(invalid("validation", v, "a TESSERA_VALIDATION_* value")),
        };
        let instance = Instance::new(&InstanceDesc {
            app_name: "tessera (C ABI)".into(),
            validation,
            surface_extensions: Vec::new(),
        })?;
        if validation != Validation::Off && instance.validation() == Validation::Off {
            return Err(Error::new(
                TesseraStatus::Unsupported,
                "validation was asked for but VK_LAYER_KHRONOS_validation is not installed \
                 (package vulkan-validationlayers)",
            ));
        }
        let device = Device::new(
            &instance,
            &DeviceDesc {
                selector,
                pipeline_cache_dir: cache,
                ..DeviceDesc::default()
            },
            &[],
        )?;
        let id = lock(handles())?.add_context(ContextState {
            graveyard: Vec::new(),
            device,
            instance,
            mode: Mode::Standalone,
            last_error: String::new(),
        });
        // SAFETY: as above.
        unsafe { out_write(out, context_ptr(id), "out") }
    })
}

/// Destroys a context and every surface still created on it. Standalone: waits for Tessera's
/// own submissions, then destroys its device and instance. Thread-safe; a second destroy
/// returns DESTROYED_HANDLE.
///
/// # Safety
/// None beyond the handle, which may be anything (it is looked up, never dereferenced).
#[no_mangle]
pub unsafe extern "C" fn tessera_context_destroy(ctx: *mut TesseraContext) -> TesseraStatus {
    guard(|| {
        let id = handle_id(ctx);
        let (context, surfaces) = {
            let mut r = lock(handles())?;
            let c = r.remove_context(id)?;
            (c, r.remove_surfaces_of(id))
        };
        // Surfaces go first: they hold the device their buffers and pipelines belong to.
        drop(surfaces);
        drop(context);
        Ok(())
    })
}

/// Error-severity messages the validation layer reported on a standalone context so far (0
/// when validation is off). Thread-safe.
///
/// # Safety
/// `count` points to a writable `uint32_t`.
#[no_mangle]
pub unsafe extern "C" fn tessera_context_validation_errors(
    ctx: *const TesseraContext,
    count: *mut u32,
) -> TesseraStatus {
    with_context(ctx, |c| {
        let n = c.instance.messages().error_count();
        // SAFETY: the caller's contract.
        unsafe { out_write(count, n, "count") }
    })
}

/// `TESSERA_SCHEME_*` as a scheme, `None` for AUTO.
fn given_scheme(scheme: TesseraScheme) -> Result<Option<topology::Scheme>> {
    use topology::Scheme;
    match scheme {
        TESSERA_SCHEME_AUTO => Ok(None),
        TESSERA_SCHEME_CATMULL_CLARK => Ok(Some(Scheme::CatmullClark)),
        TESSERA_SCHEME_LOOP => Ok(Some(Scheme::Loop)),
        TESSERA_SCHEME_DOO_SABIN => Ok(Some(Scheme::DooSabin)),
        v => Err(invalid("scheme", v, "a TESSERA_SCHEME_* value")),
    }
}

/// The scheme of a surface's limit surface: the one given, else its technique's, else Loop
/// when every face is a triangle and Catmull-Clark otherwise.
fn surface_scheme(
    scheme: TesseraScheme,
    technique: Option<TechniqueId>,
    mesh: &topology::ControlMesh,
) -> Result<topology::Scheme> {
    use topology::Scheme;
    let drawn = technique.and_then(|t| tess::techniques::info(t).scheme);
    Ok(given_scheme(scheme)?.or(drawn).unwrap_or_else(|| {
        if mesh.faces().all(|f| f.len() == 3) {
            Scheme::Loop
        } else {
            Scheme::CatmullClark
        }
    }))
}

/// The technique `d` asks for on `mesh`, and the mesh it is built from (a strict Loop scheme
/// refuses non-triangles, naming the face).
fn choose_technique(d: &TesseraSurfaceDesc, mesh: &topology::ControlMesh) -> Result<TechniqueId> {
    use topology::Scheme;
    let scheme = given_scheme(d.scheme)?;
    if scheme == Some(Scheme::Loop) {
        if let Some((face, f)) = mesh.faces().enumerate().find(|(_, f)| f.len() != 3) {
            return Err(topology::TopologyError::LoopRequiresTriangles {
                face,
                size: f.len(),
            }
            .into());
        }
    }
    let technique = match d.technique {
        TESSERA_TECHNIQUE_AUTO => {
            let scheme = scheme.unwrap_or(if mesh.faces().all(|f| f.len() == 3) {
                Scheme::Loop
            } else {
                Scheme::CatmullClark
            });
            tess::techniques::default_for(scheme)
                .map(|i| i.id)
                .ok_or_else(|| {
                    Error::new(
                        TesseraStatus::Unsupported,
                        format!("scheme {scheme:?}: no technique draws its limit surface"),
                    )
                })?
        }
        // Every other value is a registry entry's stable C ABI value.
        v => match tess::techniques::by_abi_code(v) {
            Some(info) => info.id,
            None => return Err(invalid("technique", v, "a TESSERA_TECHNIQUE_* value")),
        },
    };
    let info = tess::techniques::info(technique);
    if let (Some(want), Some(draws)) = (scheme, info.scheme) {
        if want != draws {
            return Err(Error::new(
                TesseraStatus::Unsupported,
                format!("technique {technique} draws the {draws:?} limit surface, not {want:?}"),
            ));
        }
    }
    Ok(technique)
}

/// One image of a surface description: `(pointer, width, height)` checked against each
/// other and against `max_side`; `None` when absent (NULL and both sides 0).
fn image_shape<T>(
    what: &str,
    ptr: *const T,
    width: u32,
    height: u32,
    max_side: u32,
    limit: &str,
) -> Result<Option<(u32, u32)>> {
    match (ptr.is_null(), width, height) {
        (true, 0, 0) => Ok(None),
        (true, w, h) => Err(Error::new(
            TesseraStatus::NullPointer,
            format!("{what} is NULL but its size is {w}x{h} (NULL needs both sides 0)"),
        )),
        (false, w, h) if w == 0 || h == 0 => Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} size {w}x{h}: both sides must be at least 1 when {what} is given"),
        )),
        (false, w, h) if w > max_side || h > max_side => Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{what} size {w}x{h}: each side must be at most {max_side} ({limit})"),
        )),
        (false, w, h) => Ok(Some((w, h))),
    }
}

/// The texture, height map and lattice request of `d` for `technique`, copied and checked.
///
/// # Safety
/// `d.texture` is NULL or addresses `texture_width * texture_height * 4` readable bytes;
/// `d.height_map` is NULL or addresses `height_map_width * height_map_height` readable floats.
unsafe fn read_maps(
    d: &TesseraSurfaceDesc,
    technique: TechniqueId,
    device: &Device,
    name: &str,
) -> Result<SurfaceMaps> {
    let device_max = device.info.caps.max_image_dimension_2d;
    let (max_side, limit) = if device_max < TESSERA_MAX_IMAGE_SIDE {
        (device_max, "the device's maxImageDimension2D")
    } else {
        (TESSERA_MAX_IMAGE_SIDE, "TESSERA_MAX_IMAGE_SIDE")
    };
    let texture = image_shape(
        "texture",
        d.texture,
        d.texture_width,
        d.texture_height,
        max_side,
        limit,
    )?;
    let height = image_shape(
        "height_map",
        d.height_map,
        d.height_map_width,
        d.height_map_height,
        max_side,
        limit,
    )?;
    let param_error = flag(d.param_error, "param_error")?;
    refuse_surface_options(
        technique,
        &[
            ("texture", texture.is_some()),
            ("height_map", height.is_some()),
            ("param_error", param_error),
        ],
    )?;
    let texture = match texture {
        None => None,
        Some((w, h)) => {
            let texels = w as usize * h as usize;
            // SAFETY: the caller's contract: `w * h * 4` readable bytes.
            let bytes = unsafe { read_slice(d.texture, texels, 4, "texture") }?;
            Some(Arc::new(SurfaceImage {
                name: format!("{name}: texture"),
                width: w,
                height: h,
                format: vk_core::texture::TextureFormat::Rgba8Srgb,
                texels: bytes.to_vec(),
            }))
        }
    };
    let height = match height {
        None => None,
        Some((w, h)) => {
            // SAFETY: the caller's contract: `w * h` readable floats.
            let values =
                unsafe { read_slice(d.height_map, w as usize * h as usize, 1, "height_map") }?;
            if let Some(i) = values.iter().position(|x| !x.is_finite()) {
                return Err(Error::new(
                    TesseraStatus::NonFinite,
                    format!(
                        "height_map texel ({}, {}) is {}: heights must be finite",
                        i % w as usize,
                        i / w as usize,
                        values[i]
                    ),
                ));
            }
            Some(Arc::new(SurfaceImage {
                name: format!("{name}: height map"),
                width: w,
                height: h,
                format: vk_core::texture::TextureFormat::R32Float,
                texels: values.iter().flat_map(|x| x.to_le_bytes()).collect(),
            }))
        }
    };
    Ok(SurfaceMaps {
        texture,
        height,
        param_error,
    })
}

/// Builds a surface on `c` (the shared tail of the two creation functions).
///
/// # Safety
/// The images `d` points to are as [`read_maps`] needs.
unsafe fn create_surface(
    ctx_id: u64,
    c: &mut ContextState,
    mut mesh: topology::ControlMesh,
    d: &TesseraSurfaceDesc,
    name: String,
) -> Result<u64> {
    use topology::rules::options::FVarLinearInterpolation as Fvar;
    match d.uv_interpolation {
        TESSERA_UV_INTERPOLATION_MESH => {}
        v @ TESSERA_UV_INTERPOLATION_NONE..=TESSERA_UV_INTERPOLATION_ALL => {
            mesh.options.fvar_interpolation = Fvar::ALL_MODES[(v - 1) as usize];
        }
        v => {
            return Err(invalid(
                "uv_interpolation",
                v,
                "a TESSERA_UV_INTERPOLATION_* value",
            ))
        }
    }
    topology::mesh::check_positions(&mesh.positions)?;
    mesh.validate()?;
    mesh.apply_boundary_none();
    let technique = choose_technique(d, &mesh)?;
    let end_cap = match d.end_cap {
        TESSERA_END_CAP_GREGORY => topology::patches::adaptive::EndCap::Gregory,
        TESSERA_END_CAP_BILINEAR => topology::patches::adaptive::EndCap::Bilinear,
        v => return Err(invalid("end_cap", v, "a TESSERA_END_CAP_* value")),
    };
    let split_triangles = flag(d.split_triangles, "split_triangles")?;
    if split_triangles && !tess::techniques::info(technique).features.single_pass {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!(
                "split_triangles: {technique} draws no Gregory triangle patches (gregory, acc do)"
            ),
        ));
    }
    // SAFETY: the caller's contract.
    let maps = unsafe { read_maps(d, technique, &c.device, &name) }?;
    let options = tess::BuildOptions {
        name,
        table_level: d.table_level,
        tangents: flag(d.tangents, "tangents")?,
        isolation: d.isolation,
        end_cap,
        sharpness_scale: d.sharpness_scale,
        split_triangles,
        maps,
        pipeline: match d.pipeline {
            TESSERA_PIPELINE_AUTO => tess::PipelineChoice::Auto,
            TESSERA_PIPELINE_TESSELLATION => tess::PipelineChoice::Tessellation,
            TESSERA_PIPELINE_PATTERN => tess::PipelineChoice::Pattern,
            v => return Err(invalid("pipeline", v, "a TESSERA_PIPELINE_* value")),
        },
        ..tess::BuildOptions::default()
    };
    let mut t = match &c.mode {
        Mode::Standalone => tess::Context::offscreen(&c.device)?,
        Mode::Host {
            frames_in_flight,
            formats,
            subpass: None,
            ..
        } => tess::Context::new(&c.device, formats[0], formats[1], *frames_in_flight)?,
        Mode::Host {
            frames_in_flight,
            formats,
            subpass: Some(subpass),
            ..
        } => tess::Context::for_subpass(
            &c.device,
            *subpass,
            formats[0],
            formats[1],
            *frames_in_flight,
        )?,
    };
    let built = tess::build(&mut t, technique, &mesh, &options)?;
    let slots = t.frames_in_flight();
    let info = tess::techniques::info(technique);
    let state = SurfaceState {
        scheme: surface_scheme(d.scheme, Some(technique), &mesh)?,
        sharpness_scale: if info.scheme == Some(topology::Scheme::CatmullClark) {
            d.sharpness_scale
        } else {
            1.0
        },
        technique: built.technique,
        tess: t,
        vertex_count: mesh.positions.len(),
        rest: mesh
            .positions
            .iter()
            .map(|p| [p[0] as f32, p[1] as f32, p[2] as f32])
            .collect(),
        frame: (
            FrameParams::default(),
            vk::Extent2D {
                width: 640,
                height: 480,
            },
        ),
        positions: None,
        slot_versions: vec![0; slots],
        mesh,
    };
    Ok(lock(handles())?.add_surface(ctx_id, state))
}

/// The control mesh `d` describes, every count and index checked.
///
/// # Safety
/// Every pointer in `d` is NULL or addresses as many elements as its count says
/// ([`TesseraMeshDesc`]), and `d.name` is NULL or NUL-terminated.
unsafe fn read_mesh(d: &TesseraMeshDesc) -> Result<(topology::ControlMesh, String)> {
    // SAFETY: the caller's contract (see this function's `# Safety`).
    let name = unsafe { read_str(d.name, "name") }?.unwrap_or_else(|| "mesh".into());
    // SAFETY: the caller's contract (see this function's `# Safety`).
    let positions = unsafe { read_slice(d.positions, d.vertex_count, 3, "positions") }?;
    // SAFETY: the caller's contract (see this function's `# Safety`).
    let sizes = unsafe { read_slice(d.face_sizes, d.face_count, 1, "face_sizes") }?;
    // SAFETY: the caller's contract (see this function's `# Safety`).
    let indices = unsafe { read_slice(d.face_indices, d.index_count, 1, "face_indices") }?;
    let total: u64 = sizes.iter().map(|&s| s as u64).sum();
    if total != d.index_count as u64 {
        return Err(Error::new(
            TesseraStatus::WrongSize,
            format!(
                "{name}: face_sizes add up to {total} corners, index_count is {}",
                d.index_count
            ),
        ));
    }
    let mut face_offsets = Vec::with_capacity(sizes.len() + 1);
    face_offsets.push(0u32);
    for &s in sizes {
        let last = face_offsets.last().copied().unwrap_or(0);
        face_offsets.push(last + s);
    }
    for (corner, &v) in indices.iter().enumerate() {
        if v as usize >= d.vertex_count {
            let face = face_offsets.partition_point(|&o| o as usize <= corner) - 1;
            return Err(Error::new(
                TesseraStatus::IndexOutOfRange,
                format!(
                    "{name}: face {face}: vertex index {v} out of range (mesh has {} vertices)",
                    d.vertex_count
                ),
            ));
        }
    }
    let crease_vertices =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.crease_vertices, d.crease_count, 2, "crease_vertices") }?;
    let crease_sharpness =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.crease_sharpness, d.crease_count, 1, "crease_sharpness") }?;
    let corner_vertices =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.corner_vertices, d.corner_count, 1, "corner_vertices") }?;
    let corner_sharpness =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.corner_sharpness, d.corner_count, 1, "corner_sharpness") }?;
    // Tags are checked here, not only by the techniques that read them: a flat surface
    // ignores creases, but a bad index is the host's bug wherever it is drawn.
    for (i, &v) in crease_vertices.iter().enumerate() {
        if v as usize >= d.vertex_count {
            return Err(Error::new(
                TesseraStatus::IndexOutOfRange,
                format!(
                    "{name}: crease {}: vertex index {v} out of range (mesh has {} vertices)",
                    i / 2,
                    d.vertex_count
                ),
            ));
        }
    }
    for (i, &v) in corner_vertices.iter().enumerate() {
        if v as usize >= d.vertex_count {
            return Err(Error::new(
                TesseraStatus::IndexOutOfRange,
                format!(
                    "{name}: corner {i}: vertex index {v} out of range (mesh has {} vertices)",
                    d.vertex_count
                ),
            ));
        }
    }
    if let Some((i, x)) = crease_sharpness
        .iter()
        .chain(corner_sharpness)
        .enumerate()
        .find(|(_, x)| !(x.is_finite() && **x >= 0.0))
    {
        let what = if i < crease_sharpness.len() {
            format!("crease {i}")
        } else {
            format!("corner {}", i - crease_sharpness.len())
        };
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!("{name}: {what}: sharpness {x}: expected a finite number of at least 0"),
        ));
    }
    // SAFETY: the caller's contract (see this function's `# Safety`).
    let scalar_tags = unsafe { scalar_tags(d, &name) }?;
    let uvs = if d.uvs.is_null() {
        None
    } else {
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let uv = unsafe { read_slice(d.uvs, d.index_count, 2, "uvs") }?;
        Some(
            uv.chunks_exact(2)
                .map(|c| [c[0] as f64, c[1] as f64])
                .collect(),
        )
    };
    let creases = crease_vertices
        .chunks_exact(2)
        .zip(crease_sharpness)
        .map(|(v, &sharpness)| topology::mesh::EdgeCrease {
            vertices: [v[0], v[1]],
            sharpness,
        })
        .collect();
    let corners = corner_vertices
        .iter()
        .zip(corner_sharpness)
        .map(|(&vertex, &sharpness)| topology::mesh::VertexCorner { vertex, sharpness })
        .collect();
    let mesh = topology::ControlMesh {
        positions: positions
            .chunks_exact(3)
            .map(|p| [p[0] as f64, p[1] as f64, p[2] as f64])
            .collect(),
        face_offsets,
        face_vertices: indices.to_vec(),
        uvs,
        uv_indices: None,
        normals: None,
        creases,
        corners,
        holes: Vec::new(),
        scalar_tags,
        options: Default::default(),
        scheme: None,
    };
    Ok((mesh, name))
}

/// The mesh's scalar tags; an index out of range is the host's bug (values are checked with
/// the mesh, `topology::mesh::scalar_tags::check`).
///
/// # Safety
/// As [`tessera_surface_create`]'s `mesh`.
unsafe fn scalar_tags(
    d: &TesseraMeshDesc,
    name: &str,
) -> Result<Vec<topology::mesh::scalar_tags::ScalarTag>> {
    let vertices =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.scalar_tag_vertices, d.scalar_tag_count, 1, "scalar_tag_vertices") }?;
    let values =
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { read_slice(d.scalar_tag_values, d.scalar_tag_count, 6, "scalar_tag_values") }?;
    if let Some((i, &v)) = vertices
        .iter()
        .enumerate()
        .find(|(_, &v)| v as usize >= d.vertex_count)
    {
        return Err(Error::new(
            TesseraStatus::IndexOutOfRange,
            format!(
                "{name}: scalar tag {i}: vertex index {v} out of range (mesh has {} vertices)",
                d.vertex_count
            ),
        ));
    }
    Ok(vertices
        .iter()
        .zip(values.chunks_exact(6))
        .map(|(&vertex, t)| topology::mesh::scalar_tags::ScalarTag {
            vertex,
            deviation: [t[0], t[1], t[2]],
            tension: t[3],
            sharpness: t[4],
            bias: t[5],
        })
        .collect())
}

/// Builds a surface from a mesh given as arrays. Thread-safe (serialized per context).
///
/// # Safety
/// `mesh` and `desc` are NULL (answered with NULL_POINTER; `desc` NULL means defaults) or
/// readable, every array in `mesh` NULL or as long as its count says, `desc`'s `texture` and
/// `height_map` NULL or as long as their sizes say; `out` points to a
/// writable `TesseraSurface*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_create(
    ctx: *mut TesseraContext,
    mesh: *const TesseraMeshDesc,
    desc: *const TesseraSurfaceDesc,
    out: *mut *mut TesseraSurface,
) -> TesseraStatus {
    let ctx_id = handle_id(ctx);
    with_context(ctx, |c| {
        // SAFETY: the caller's contract for `out`, `mesh` and `desc`.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let m = unsafe { ffi::read_required(mesh, "mesh") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let d = unsafe { surface_desc(desc) }?;
        // SAFETY: the caller's contract for the arrays `mesh` points to.
        let (mesh, name) = unsafe { read_mesh(&m) }?;
        // SAFETY: the caller's contract for the images `desc` points to.
        let id = unsafe { create_surface(ctx_id, c, mesh, &d, name) }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { out_write(out, surface_ptr(id), "out") }
    })
}

/// `desc`, or the defaults when NULL.
///
/// # Safety
/// `desc` is NULL or readable.
unsafe fn surface_desc(desc: *const TesseraSurfaceDesc) -> Result<TesseraSurfaceDesc> {
    // SAFETY: the caller's contract.
    match unsafe { ffi::read_opt(desc) } {
        Some(d) => Ok(d),
        None => {
            let mut d = std::mem::MaybeUninit::<TesseraSurfaceDesc>::uninit();
            // SAFETY: `d` is writable; the call fills every field.
            let status = unsafe { tessera_surface_desc_default(d.as_mut_ptr()) };
            if status != TesseraStatus::Ok {
                return Err(Error::new(status, "default surface description"));
            }
            // SAFETY: initialized by the successful call above.
            Ok(unsafe { d.assume_init() })
        }
    }
}

/// The spot control mesh (Keenan Crane, public domain), embedded as the CLI embeds it.
const SPOT: &str = include_str!("../../../assets/spot_control_mesh.obj");

/// Builds a surface from OBJ text (with OpenSubdiv's `t crease`/`t corner` tags); NULL text
/// builds the embedded spot mesh `tessera render` draws by default. Thread-safe (serialized per
/// context).
///
/// # Safety
/// `obj_text` is NULL or points to `obj_len` readable bytes (UTF-8, no NUL needed); `name` is
/// NULL or NUL-terminated; `desc` is NULL (defaults) or readable, its `texture` and
/// `height_map` NULL or as long as their sizes say; `out` points to a writable
/// `TesseraSurface*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_create_obj(
    ctx: *mut TesseraContext,
    obj_text: *const c_char,
    obj_len: usize,
    name: *const c_char,
    desc: *const TesseraSurfaceDesc,
    out: *mut *mut TesseraSurface,
) -> TesseraStatus {
    let ctx_id = handle_id(ctx);
    with_context(ctx, |c| {
        // SAFETY: the caller's contract for every pointer.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let d = unsafe { surface_desc(desc) }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let given = unsafe { read_str(name, "name") }?;
        let (text, name) = if obj_text.is_null() {
            (
                SPOT.to_owned(),
                given.unwrap_or_else(|| "spot_control_mesh.obj (embedded)".into()),
            )
        } else {
            // SAFETY: the caller's contract (see this function's `# Safety`).
            let bytes = unsafe { read_slice(obj_text.cast::<u8>(), obj_len, 1, "obj_text") }?;
            let text = String::from_utf8(bytes.to_vec()).map_err(|e| {
                Error::new(
                    TesseraStatus::Parse,
                    format!(
                        "obj_text is not UTF-8 at byte {}",
                        e.utf8_error().valid_up_to()
                    ),
                )
            })?;
            (text, given.unwrap_or_else(|| "mesh".into()))
        };
        let mesh = topology::mesh::obj::parse_obj(&text, &name)?;
        // SAFETY: the caller's contract for the images `desc` points to.
        let id = unsafe { create_surface(ctx_id, c, mesh, &d, name) }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { out_write(out, surface_ptr(id), "out") }
    })
}

/// Builds a surface from a mesh file: `.usda`, `.usdc`, `.usdz` or `.usd` read as USD (every
/// drawn Mesh prim, merged: `topology::mesh::usd`), any other name as OBJ with OpenSubdiv's
/// tags. The surface is named by the file's stem. Errors name the file (and for USD the prim
/// and the attribute; for OBJ the line). Thread-safe (serialized per context).
///
/// # Safety
/// `path` is NULL (refused) or NUL-terminated; `desc` is NULL (defaults) or readable, its
/// `texture` and `height_map` NULL or as long as their sizes say; `out` points to a writable
/// `TesseraSurface*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_create_file(
    ctx: *mut TesseraContext,
    path: *const c_char,
    desc: *const TesseraSurfaceDesc,
    out: *mut *mut TesseraSurface,
) -> TesseraStatus {
    let ctx_id = handle_id(ctx);
    with_context(ctx, |c| {
        // SAFETY: the caller's contract for every pointer.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let d = unsafe { surface_desc(desc) }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let path = unsafe { read_str(path, "path") }?
            .ok_or_else(|| Error::new(TesseraStatus::InvalidArgument, "path is NULL"))?;
        let path = std::path::Path::new(&path);
        let (mesh, _) = topology::mesh::usd::load_mesh_file(path)?;
        let name = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| path.display().to_string());
        // SAFETY: the caller's contract for the images `desc` points to.
        let id = unsafe { create_surface(ctx_id, c, mesh, &d, name) }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        unsafe { out_write(out, surface_ptr(id), "out") }
    })
}

/// Destroys a surface: its handle is invalid at once. Standalone: its objects are freed at
/// once (Tessera's own submissions are waited for). Host-owned: they are freed by the first
/// [`host::tessera_begin_frame`] whose frame is `frames_in_flight` past the frame current at
/// the destruction (the host then guarantees the frames that could draw it finished), or with
/// the context. Thread-safe; a second destroy returns DESTROYED_HANDLE.
///
/// # Safety
/// None beyond the handles, which may be anything (they are looked up, never dereferenced).
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_destroy(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
) -> TesseraStatus {
    let ctx_id = handle_id(ctx);
    with_context(ctx, |c| {
        let mut r = lock(handles())?;
        let (owner, _) = r.surface(handle_id(surface))?;
        if owner != ctx_id {
            return Err(Error::new(
                TesseraStatus::WrongContext,
                format!(
                    "surface {:#x} belongs to context {owner:#x}, not {ctx_id:#x}",
                    handle_id(surface)
                ),
            ));
        }
        let s = r.remove_surface(handle_id(surface))?;
        drop(r);
        if let Mode::Host { frame, .. } = c.mode {
            // Frames up to `frame` may still draw it; tessera_begin_frame frees it once the
            // host says they finished.
            c.graveyard.push((frame, s));
        }
        Ok(())
    })
}

/// The number of control vertices (what [`tessera_surface_update_positions`] takes) and the
/// axis-aligned bounds of the base mesh at rest. Any output may be NULL. Thread-safe.
///
/// # Safety
/// Each output is NULL or writable (`bbox_min`/`bbox_max`: 3 floats).
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_info(
    ctx: *const TesseraContext,
    surface: *const TesseraSurface,
    vertex_count: *mut usize,
    bbox_min: *mut f32,
    bbox_max: *mut f32,
) -> TesseraStatus {
    with_surface(ctx, surface, |_, s| {
        let (lo, hi) = s.technique.bbox();
        // SAFETY: the caller's contract; NULL outputs are skipped.
        unsafe {
            ffi::out_write_opt(vertex_count, s.vertex_count);
            ffi::out_write_opt(bbox_min.cast::<[f32; 3]>(), lo);
            ffi::out_write_opt(bbox_max.cast::<[f32; 3]>(), hi);
        }
        Ok(())
    })
}

/// Replaces the base positions (animation): `3 * vertex_count` floats, `vertex_count` the
/// surface's. Techniques without animated bases (flat, phong, pn) return UNSUPPORTED.
/// Thread-safe (serialized per context).
///
/// # Safety
/// `positions` is NULL or points to `3 * vertex_count` readable floats.
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_update_positions(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    positions: *const f32,
    vertex_count: usize,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        // SAFETY: the caller's contract.
        let p = unsafe { read_slice(positions, vertex_count, 3, "positions") }?;
        if vertex_count != s.vertex_count {
            return Err(Error::new(
                TesseraStatus::WrongSize,
                format!(
                    "{vertex_count} positions given, the surface has {} vertices",
                    s.vertex_count
                ),
            ));
        }
        if let Some(i) = p.iter().position(|x| !x.is_finite()) {
            return Err(Error::new(
                TesseraStatus::NonFinite,
                format!("vertex {} has a NaN or infinite coordinate", i / 3),
            ));
        }
        let p: Vec<[f32; 3]> = p.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
        if s.technique.base_mesh().is_none() {
            // Refused by the technique itself, with its own message.
            s.technique.update_base(0, &p)?;
        }
        let version = s.positions.as_ref().map_or(1, |(v, _)| v + 1);
        s.positions = Some((version, p));
        match c.mode {
            Mode::Standalone => s.sync_positions(0),
            Mode::Host { .. } => s.sync_positions(c.slot()),
        }
    })
}

/// Copies the surface's base positions (the newest given to
/// [`tessera_surface_update_positions`], else those it was created with) into `positions`:
/// `3 * vertex_count` floats, `vertex_count` the surface's. Thread-safe.
///
/// # Safety
/// `positions` is NULL or points to `3 * vertex_count` writable floats.
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_positions(
    ctx: *const TesseraContext,
    surface: *const TesseraSurface,
    positions: *mut f32,
    vertex_count: usize,
) -> TesseraStatus {
    with_surface(ctx, surface, |_, s| {
        if vertex_count != s.vertex_count {
            return Err(Error::new(
                TesseraStatus::WrongSize,
                format!(
                    "room for {vertex_count} positions given, the surface has {} vertices",
                    s.vertex_count
                ),
            ));
        }
        let current = s.positions.as_ref().map_or(&s.rest, |(_, p)| p);
        let bytes = vertex_count * 3 * std::mem::size_of::<f32>();
        // SAFETY: the caller's contract: `3 * vertex_count` writable floats.
        let out = unsafe { ffi::write_slice(positions.cast::<u8>(), bytes, "positions") }?;
        for (dst, src) in out.chunks_exact_mut(4).zip(current.iter().flatten()) {
            dst.copy_from_slice(&src.to_ne_bytes());
        }
        Ok(())
    })
}

/// The view and projection (column-major 4x4) Tessera's standalone camera uses for `frame`
/// on this surface, so a host can draw exactly the view [`tessera_render`] draws.
/// Thread-safe.
///
/// # Safety
/// `frame` is readable; `view` and `proj` point to 16 writable floats each.
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_camera(
    ctx: *const TesseraContext,
    surface: *const TesseraSurface,
    frame: *const TesseraFrameDesc,
    view: *mut f32,
    proj: *mut f32,
) -> TesseraStatus {
    with_surface(ctx, surface, |_, s| {
        // SAFETY: the caller's contract.
        let f = unsafe { ffi::read_required(frame, "frame") }?;
        let (params, extent) = frame_params(&f)?;
        let (lo, hi) = s.technique.bbox();
        let m = params
            .camera
            .matrices(lo, hi, extent.width as f32 / extent.height as f32);
        // SAFETY: the caller's contract.
        unsafe {
            out_write(view.cast::<[f32; 16]>(), m.view.to_cols_array(), "view")?;
            out_write(proj.cast::<[f32; 16]>(), m.proj.to_cols_array(), "proj")
        }
    })
}

/// Standalone: renders one frame of the surface offscreen and copies it into `pixels`:
/// `width * height * 4` bytes of RGBA8, rows top to bottom. Waits for the GPU (Tessera's own
/// queue). Thread-safe (serialized per context).
///
/// # Safety
/// `frame` is readable; `pixels` is NULL or points to `pixels_len` writable bytes.
#[no_mangle]
pub unsafe extern "C" fn tessera_render(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    frame: *const TesseraFrameDesc,
    pixels: *mut u8,
    pixels_len: usize,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        standalone_only(c, "tessera_render")?;
        // SAFETY: the caller's contract.
        let f = unsafe { ffi::read_required(frame, "frame") }?;
        let (params, extent) = surface_frame_params(s, &f)?;
        let needed = extent.width as usize * extent.height as usize * 4;
        if pixels_len != needed {
            return Err(Error::new(
                TesseraStatus::WrongSize,
                format!(
                    "pixels_len {pixels_len}: a {}x{} RGBA8 image needs {needed} bytes",
                    extent.width, extent.height
                ),
            ));
        }
        // SAFETY: the caller's contract.
        let out = unsafe { ffi::write_slice(pixels, pixels_len, "pixels") }?;
        let image = s
            .tess
            .render_offscreen(s.technique.as_mut(), &params, extent)?;
        out.copy_from_slice(&image.pixels);
        Ok(())
    })
}

fn standalone_only(c: &ContextState, call: &str) -> Result<()> {
    match c.mode {
        Mode::Standalone => Ok(()),
        Mode::Host { .. } => Err(Error::new(
            TesseraStatus::WrongMode,
            format!("{call} needs a standalone context (this one draws into the host's device)"),
        )),
    }
}

pub mod capture;
pub mod host;
pub mod limit;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_panic_inside_becomes_a_status_and_a_message() {
        let status = guard(|| panic!("an invariant broke"));
        assert_eq!(status, TesseraStatus::Panic);
        let message = LAST_ERROR.with(|l| l.borrow().clone());
        assert!(
            message.contains("an invariant broke") && message.contains("panic"),
            "{message}"
        );
        let status = guard(|| std::panic::panic_any(7u32));
        assert_eq!(status, TesseraStatus::Panic);
    }

    #[test]
    fn every_status_has_a_name() {
        for v in 0..=TesseraStatus::Internal as u32 {
            // SAFETY: tessera_status_name returns a static NUL-terminated string.
            let name = unsafe { std::ffi::CStr::from_ptr(tessera_status_name(v)) };
            assert_ne!(name.to_str().unwrap(), "unknown status", "status {v}");
        }
    }
}
