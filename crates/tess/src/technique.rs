//! The one seam between Tessera's techniques and everything that uses them (viewer, bench,
//! capture/export, the C ABI).
//!
//! A technique turns a control mesh into **patch arrays** (OpenSubdiv's `PatchTable` arrays:
//! one patch type, a patch count, control points per patch) and records them. Callers never
//! see which technique they hold: they go through [`Technique`] and the [`crate::Context`]
//! that owns the pipelines, the frame uniforms and the recording of a frame.
//!
//! Design decisions:
//! - **Patch ids are frame-wide.** Arrays are numbered in order; patch `i` of array `a` has id
//!   `arrays[a].first_patch + i`, which is what the TES writes into a captured record and what
//!   [`Technique::face_point`] maps back to a base face.
//! - **Pipelines are described, not built, by techniques.** [`Technique::patch_pipeline`] names
//!   the stages of one patch type; the context builds and caches every (technique, patch type,
//!   spacing, pass) in one cache keyed by [`crate::context::PipelineKey`], and applies the pass
//!   style (shaded, wireframe overlay, attachment-less capture) the same way for all.
//! - **Recording borrows.** [`Technique::record_array`] takes `&'a self` with a
//!   [`vk_core::Encoder<'a>`], so every buffer and set bound stays alive as long as the
//!   encoder; a technique's mutable work (uploading animated base positions) happens before.
//! - **Capabilities are data.** What options a technique takes ([`Features`]) is declared in
//!   the [`crate::techniques::registry`], so callers check options generically and name the
//!   techniques that would accept a refused option.
use crate::camera::Camera;
use crate::capture::FacePoint;
use crate::error::{Result, TessError};
use crate::shaders::{Stage, Variant};
use crate::tessellator::{Domain, Spacing};
use vk_core::{DescriptorSet, Encoder};

/// A technique's name: keys pipelines and names techniques in messages. Each technique
/// declares its own constant in its folder (`TechniqueId::FLAT` in `techniques/flat/`), and
/// the registry ([`crate::techniques::registry`]) lists them; nothing else enumerates them.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct TechniqueId(&'static str);

impl TechniqueId {
    /// The id named `name` (the command line's `--method NAME`): made only next to a
    /// registry entry (outside this crate, ids come from the registry or by name).
    pub(crate) const fn new(name: &'static str) -> Self {
        Self(name)
    }

    /// The command-line name (`--method NAME`).
    pub fn name(self) -> &'static str {
        self.0
    }
}

impl std::fmt::Display for TechniqueId {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// The type of the patches of one array: decides the domain, the geometry path and the
/// pipeline (OpenSubdiv's `PatchDescriptor::Type`, whose non-patch types are drawn without
/// tessellation too).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchType {
    /// A base triangle (or fan triangle of a polygon), three control points.
    Triangle,
    /// A base quad, four control points.
    Quad,
    /// A level-1 Loop face evaluated from basis-function tables: one control point (the face).
    LoopBft,
    /// A regular bicubic B-spline patch of the feature-adaptive plan (16 control points,
    /// fetched by the TES; one control point carries the patch).
    BSpline,
    /// A Gregory end cap (20 control points, fetched by the TES).
    Gregory,
    /// A bilinear (Coons) end cap over its four canonical boundary curves.
    Bilinear,
    /// A Gregory triangle patch (15 control points fetched by the control stage).
    GregoryTriangle,
    /// Triangles of a mesh refined before the draw (no tessellation stage): the vertex stage
    /// reads each vertex as it is. A captured id names a vertex of the mesh.
    MeshTriangles,
    /// A base triangle drawn through a refinement pattern ([`crate::pattern`]): one instance
    /// of the pattern per patch, the vertex stage evaluating the patch at each pattern vertex.
    /// A captured id names the patch, its domain coordinate the pattern vertex's `(u, v)`.
    PatternTriangle,
    /// A base quad drawn through a refinement pattern.
    PatternQuad,
    /// A [`PatchType::BSpline`] patch drawn through refinement patterns, one per edge-level
    /// key: the vertex stage evaluates the patch the instance names (not the instance in
    /// order) at each pattern vertex. A captured id names the patch as on the tessellation
    /// path.
    PatternBSpline,
    /// A [`PatchType::Gregory`] end cap (or ACC-1 net) through refinement patterns.
    PatternGregory,
    /// A [`PatchType::Bilinear`] end cap through refinement patterns.
    PatternBilinear,
    /// A [`PatchType::GregoryTriangle`] through refinement patterns.
    PatternGregoryTriangle,
}

impl PatchType {
    pub fn domain(self) -> Domain {
        match self {
            PatchType::Quad
            | PatchType::BSpline
            | PatchType::Gregory
            | PatchType::Bilinear
            | PatchType::PatternQuad
            | PatchType::PatternBSpline
            | PatchType::PatternGregory
            | PatchType::PatternBilinear => Domain::Quad,
            PatchType::Triangle
            | PatchType::LoopBft
            | PatchType::GregoryTriangle
            | PatchType::MeshTriangles
            | PatchType::PatternTriangle
            | PatchType::PatternGregoryTriangle => Domain::Triangle,
        }
    }

    /// The draw path its patches take.
    pub fn path(self) -> DrawPath {
        match self {
            PatchType::MeshTriangles => DrawPath::VertexStage,
            PatchType::PatternTriangle
            | PatchType::PatternQuad
            | PatchType::PatternBSpline
            | PatchType::PatternGregory
            | PatchType::PatternBilinear
            | PatchType::PatternGregoryTriangle => DrawPath::Pattern,
            _ => DrawPath::Tessellation,
        }
    }
}

/// One array of patches of one type.
///
/// A *patch* is the unit a captured id names: a tessellated patch, or on the vertex-stage
/// path whatever the technique numbers (a vertex of a refined mesh, a pattern instance).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchArray {
    pub patch: PatchType,
    pub patches: u32,
    /// Control points per tessellated patch; 0 on the vertex-stage path.
    pub control_points: u32,
    /// Frame-wide id of the array's first patch.
    pub first_patch: u32,
}

/// Numbers arrays frame-wide from `(type, patches, control points)`, leaving out empty ones.
pub fn number_arrays(arrays: &[(PatchType, u32, u32)]) -> Vec<PatchArray> {
    let mut first_patch = 0;
    let mut out = Vec::new();
    for &(patch, patches, control_points) in arrays {
        if patches > 0 {
            out.push(PatchArray {
                patch,
                patches,
                control_points,
                first_patch,
            });
            first_patch += patches;
        }
    }
    out
}

/// Which pass a pipeline draws.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Pass {
    /// Filled and shaded (pushed back slightly so the overlay wins the depth test).
    Shaded,
    /// Wireframe overlay (lines, no depth writes).
    Wireframe,
    /// No attachments, rasterizer discard; the `-DCAPTURE` build of the last stage before
    /// rasterization (the evaluation stage, or the vertex stage on the vertex-stage path)
    /// writes transform feedback records.
    Capture,
}

impl Pass {
    /// The `mode` the shaders read from their push constants.
    pub fn mode(self) -> u32 {
        match self {
            Pass::Wireframe => crate::gpu::bindings::DRAW_MODE_WIREFRAME,
            Pass::Shaded | Pass::Capture => crate::gpu::bindings::DRAW_MODE_SHADED,
        }
    }
}

/// How a draw chooses its tessellation factors. Every technique takes `Uniform`; the adaptive
/// ones are declared in [`Features::adaptive_factors`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum FactorPolicy {
    /// `segments` per base edge (the outer and inner level of a base-face patch).
    Uniform { segments: f32 },
    /// Edge factor = projected edge length / `pixels` per segment.
    Screen { pixels: f32 },
    /// An edge at `reference` distance from the eye gets the maximum level; the factor halves
    /// each time the distance doubles.
    Distance { reference: f32 },
}

impl Default for FactorPolicy {
    fn default() -> Self {
        FactorPolicy::Uniform { segments: 4.0 }
    }
}

impl std::fmt::Display for FactorPolicy {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            FactorPolicy::Uniform { segments } => write!(f, "{segments} segments per edge"),
            FactorPolicy::Screen { pixels } => write!(f, "screen-space, {pixels} px per segment"),
            FactorPolicy::Distance { reference } => {
                write!(f, "distance, maximum level at {reference}")
            }
        }
    }
}

/// Whether tessellated draws are split for drivers that need it. `Off` exists only so a test can
/// show the driver bug the split works around.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Default)]
pub enum DrawSplit {
    #[default]
    Auto,
    Off,
    /// One patch per draw: the slowest and surest reference.
    PerPatch,
}

/// Everything that decides what one frame shows, for every technique.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FrameParams {
    pub factors: FactorPolicy,
    pub spacing: Spacing,
    pub wireframe: bool,
    pub camera: Camera,
    /// Phong tessellation shape factor α (read by Phong only).
    pub phong_alpha: f32,
    /// Normals from the surface's parametric derivatives instead of its shading normals.
    pub geometric_normals: bool,
    /// Colour patches by type.
    pub patch_colours: bool,
    /// Texture coordinates at the reparameterized parameter on Gregory patches (seed 003).
    pub reparam: bool,
    /// Displacement along the normal per unit of height (0: none).
    pub displace: f32,
    /// The refinement-pattern seed's procedural displacement a·sin(f·‖P‖) along the normal:
    /// (amplitude a, frequency f); a = 0: none.
    pub displace_sine: [f32; 2],
    /// What the surface is coloured by (shading, or a view of the texture parameterization).
    pub show: crate::surface::SurfaceShow,
    pub split: DrawSplit,
    pub base_color: [f32; 3],
    pub clear_color: [f32; 4],
}

impl Default for FrameParams {
    fn default() -> Self {
        Self {
            factors: FactorPolicy::default(),
            spacing: Spacing::Equal,
            wireframe: false,
            camera: Camera::default(),
            phong_alpha: 0.75,
            geometric_normals: false,
            patch_colours: false,
            reparam: true,
            displace: 0.0,
            displace_sine: [0.0, 0.0],
            show: crate::surface::SurfaceShow::Shading,
            split: DrawSplit::Auto,
            base_color: [0.85, 0.72, 0.55],
            clear_color: [0.12, 0.13, 0.16, 1.0],
        }
    }
}

impl FrameParams {
    /// Uniform factors of `segments` per base edge.
    pub fn uniform(segments: f32) -> Self {
        Self {
            factors: FactorPolicy::Uniform { segments },
            ..Self::default()
        }
    }

    /// The uniform level, if the factors are uniform.
    pub fn uniform_segments(&self) -> Option<f32> {
        match self.factors {
            FactorPolicy::Uniform { segments } => Some(segments),
            _ => None,
        }
    }
}

/// What a technique accepts beyond uniform factors, declared once per technique.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Features {
    /// Screen-space and distance factor policies.
    pub adaptive_factors: bool,
    /// Which spacings: (equal, fractional even, fractional odd).
    pub spacings: [bool; 3],
    /// Base positions may change every frame ([`Technique::update_base`]).
    pub animation: bool,
    pub patch_colours: bool,
    pub geometric_normals: bool,
    /// The Phong shape factor.
    pub phong_alpha: bool,
    /// Basis-function table level.
    pub table_level: bool,
    /// Needs triangles (polygons are fan-triangulated first, with a note).
    pub triangles_only: bool,
    /// Feature-adaptive refinement: isolation level, end-cap type, sharpness scale.
    pub isolation: bool,
    /// Texture coordinates: colour texture, reparameterization, displacement.
    pub surface: bool,
    /// One patch per base face (gregory, acc): triangles as Gregory triangle patches or split.
    pub single_pass: bool,
    /// The procedural displacement a·sin(f·‖P‖) along the normal (`--displace-sine`).
    pub sine_displacement: bool,
    /// The draw paths it has (the conformance suite runs each).
    pub paths: &'static [DrawPath],
}

/// A draw path of the seam: what geometry reaches the rasterizer.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum DrawPath {
    /// Patches through the tessellation stage ([`Geometry::Tessellated`]).
    Tessellation,
    /// Refinement patterns: a tessellated domain stored once and drawn instanced over the
    /// patches, each patch evaluated in the vertex stage ([`Geometry::Triangles`]).
    Pattern,
    /// Triangles of a mesh refined before the draw, from the vertex stage
    /// ([`Geometry::Triangles`]).
    VertexStage,
}

impl DrawPath {
    /// Whether `geometry` is this path's: tessellated patches on the tessellation path only.
    pub fn draws(self, geometry: Geometry) -> bool {
        geometry.is_tessellated() == (self == DrawPath::Tessellation)
    }

    /// The name `--pipeline` takes, where the path is a choice.
    pub fn name(self) -> &'static str {
        match self {
            DrawPath::Tessellation => "tessellation",
            DrawPath::Pattern => "pattern",
            DrawPath::VertexStage => "vertex-stage",
        }
    }
}

impl std::fmt::Display for DrawPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Which draw path a surface is built for (`--pipeline`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum PipelineChoice {
    /// Where a technique has both the tessellation and the pattern path, the one measured
    /// faster on the device's driver ([`prefers_patterns`]); the pattern path where the device
    /// has no tessellation shaders; techniques with only a vertex-stage path take that.
    #[default]
    Auto,
    Tessellation,
    Pattern,
}

impl std::str::FromStr for PipelineChoice {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "auto" => Ok(PipelineChoice::Auto),
            "tessellation" => Ok(PipelineChoice::Tessellation),
            "pattern" => Ok(PipelineChoice::Pattern),
            _ => Err(format!(
                "unknown pipeline '{s}' (tessellation, pattern, auto)"
            )),
        }
    }
}

/// Whether `--pipeline auto` draws through refinement patterns where a technique also has the
/// tessellation path, by the device's driver, as measured (docs/benchmarks.md, "Refinement
/// patterns against the tessellation stage"): on lavapipe the pattern path, its patterns the
/// tessellator's own ([`crate::pattern::from_tessellator`]: the same triangles as the
/// tessellation path), drew every measured row of flat, Phong and PN in 0.59–1.00 times the
/// tessellation path's time. Elsewhere the tessellation stage, until a device measures
/// otherwise.
pub fn prefers_patterns(device: &vk_core::Device) -> bool {
    device.info.is_lavapipe() && crate::pattern::from_tessellator(device)
}

impl PipelineChoice {
    /// The path a technique declaring `paths` draws on `device`; an error names `--pipeline`
    /// or the missing device feature.
    pub fn resolve(
        self,
        technique: TechniqueId,
        paths: &[DrawPath],
        device: &vk_core::Device,
    ) -> Result<DrawPath> {
        self.resolve_with(
            technique,
            paths,
            device.info.caps.tessellation_shader,
            prefers_patterns(device),
        )
    }

    /// [`Self::resolve`] on a device with (or without) tessellation shaders whose driver does
    /// (or does not) prefer patterns.
    pub fn resolve_with(
        self,
        technique: TechniqueId,
        paths: &[DrawPath],
        tessellation_shader: bool,
        prefer_patterns: bool,
    ) -> Result<DrawPath> {
        let has = |p: DrawPath| paths.contains(&p);
        match self {
            PipelineChoice::Tessellation if !has(DrawPath::Tessellation) => {
                Err(TessError::Unsupported {
                    technique,
                    what: "the tessellation path (--pipeline tessellation)",
                })
            }
            PipelineChoice::Tessellation if !tessellation_shader => {
                Err(TessError::NoTessellationShader { technique })
            }
            PipelineChoice::Tessellation => Ok(DrawPath::Tessellation),
            PipelineChoice::Pattern if has(DrawPath::Pattern) => Ok(DrawPath::Pattern),
            PipelineChoice::Pattern => Err(TessError::Unsupported {
                technique,
                what: "the refinement-pattern path (--pipeline pattern)",
            }),
            PipelineChoice::Auto if prefer_patterns && has(DrawPath::Pattern) => {
                Ok(DrawPath::Pattern)
            }
            PipelineChoice::Auto if has(DrawPath::Tessellation) && tessellation_shader => {
                Ok(DrawPath::Tessellation)
            }
            PipelineChoice::Auto if has(DrawPath::Pattern) => Ok(DrawPath::Pattern),
            PipelineChoice::Auto if has(DrawPath::VertexStage) => Ok(DrawPath::VertexStage),
            PipelineChoice::Auto => Err(TessError::NoTessellationShader { technique }),
        }
    }
}

impl Features {
    /// The first option of `params` a technique with these features does not take, as the
    /// [`TessError::Unsupported`] naming `technique` and the option; what every technique
    /// refuses alike, before its own [`Technique::check`].
    pub fn refuse(&self, technique: TechniqueId, params: &FrameParams) -> Result<()> {
        let refused = [
            (
                !self.adaptive_factors && params.uniform_segments().is_none(),
                "screen-space and distance factors",
            ),
            (!self.spacing(params.spacing), "this --spacing"),
            (
                !self.patch_colours && params.patch_colours,
                "patch colours (--patch-colours)",
            ),
            (
                !self.geometric_normals && params.geometric_normals,
                "geometric normals (--geometric-normals)",
            ),
            (
                !self.surface && params.displace != 0.0,
                "displacement (--displace)",
            ),
            (
                !self.sine_displacement && params.displace_sine[0] != 0.0,
                "sine displacement (--displace-sine)",
            ),
            (
                !self.surface && params.show != crate::surface::SurfaceShow::Shading,
                "parameter views (--show)",
            ),
            (
                !self.surface && !params.reparam,
                "texture reparameterization (--no-reparam)",
            ),
        ];
        match refused.iter().find(|(refuse, _)| *refuse) {
            Some(&(_, what)) => Err(TessError::Unsupported { technique, what }),
            None => Ok(()),
        }
    }

    pub fn spacing(&self, s: Spacing) -> bool {
        self.spacings[match s {
            Spacing::Equal => 0,
            Spacing::FractionalEven => 1,
            Spacing::FractionalOdd => 2,
        }]
    }
}

/// How an array's geometry reaches the rasterizer: the two draw paths behind the seam.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Geometry {
    /// Patches of `control_points` points through the tessellation stage; the evaluation stage
    /// is built per spacing (and as its `-DCAPTURE` build for captures).
    Tessellated {
        control: Stage,
        evaluation: Stage,
        control_points: u32,
    },
    /// Triangle lists from the vertex stage, which is then the last stage before rasterization
    /// (built as its `-DCAPTURE` build for captures). Indexed, instanced or indirect: the
    /// technique's [`Technique::record_array`] chooses the draw.
    Triangles,
}

impl Geometry {
    /// Whether the tessellation stage draws it (lavapipe's draw split applies only then).
    pub fn is_tessellated(self) -> bool {
        matches!(self, Geometry::Tessellated { .. })
    }
}

/// Vertex buffers a pipeline reads (`vk` descriptions, binding 0 upwards); per-instance
/// bindings carry per-instance data.
#[derive(Clone, Copy, Debug)]
pub struct VertexInput {
    pub bindings: &'static [vk_core::vk::VertexInputBindingDescription],
    pub attributes: &'static [vk_core::vk::VertexInputAttributeDescription],
}

impl VertexInput {
    /// No vertex buffers: the shaders fetch what they need from storage buffers.
    pub const NONE: VertexInput = VertexInput {
        bindings: &[],
        attributes: &[],
    };
    /// The interleaved [`crate::gpu::Vertex`] buffer at binding 0 (position, normal).
    pub const MESH: VertexInput = VertexInput {
        bindings: &[crate::gpu::Vertex::BINDING],
        attributes: &crate::gpu::Vertex::ATTRIBUTES,
    };

    pub fn is_empty(&self) -> bool {
        self.bindings.is_empty()
    }
}

/// The stages and fixed state of one patch type's pipelines. On the tessellated path the
/// evaluation stage is picked per spacing; the last stage before rasterization comes as its
/// `-DCAPTURE` build for captures, which drop the fragment stage.
#[derive(Clone, Copy, Debug)]
pub struct PatchPipeline {
    pub vertex: Stage,
    pub geometry: Geometry,
    pub fragment: Stage,
    pub vertex_input: VertexInput,
    /// Bytes of the push-constant block every stage shares.
    pub push_constant_bytes: u32,
    /// The technique's own shader axes (the `Variant` fields beyond spacing, capture and
    /// surface, which the frame sets), for its control and evaluation stages.
    pub axes: Variant,
}

impl PatchPipeline {
    /// A tessellated pipeline of `control_points`-point patches.
    pub fn tessellated(
        vertex: Stage,
        control: Stage,
        evaluation: Stage,
        fragment: Stage,
        control_points: u32,
    ) -> Self {
        Self {
            vertex,
            geometry: Geometry::Tessellated {
                control,
                evaluation,
                control_points,
            },
            fragment,
            vertex_input: VertexInput::NONE,
            push_constant_bytes: std::mem::size_of::<crate::gpu::DrawPush>() as u32,
            axes: Variant::default(),
        }
    }

    /// A vertex-stage pipeline drawing triangle lists.
    pub fn triangles(vertex: Stage, fragment: Stage) -> Self {
        Self {
            vertex,
            geometry: Geometry::Triangles,
            fragment,
            vertex_input: VertexInput::NONE,
            push_constant_bytes: std::mem::size_of::<crate::gpu::DrawPush>() as u32,
            axes: Variant::default(),
        }
    }

    /// Control points per patch (0 on the vertex-stage path).
    pub fn control_points(&self) -> u32 {
        match self.geometry {
            Geometry::Tessellated { control_points, .. } => control_points,
            Geometry::Triangles => 0,
        }
    }
}

/// How many draws and patches one recorded pass issued (for tests of the draw split).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct DrawCounts {
    pub draws: u32,
    pub patches: u32,
}

impl std::ops::AddAssign for DrawCounts {
    fn add_assign(&mut self, o: Self) {
        self.draws += o.draws;
        self.patches += o.patches;
    }
}

/// A technique, as every caller sees it. Object safe: callers hold `Box<dyn Technique>`.
/// `Send`, so a surface built on one thread may be drawn from another (the C ABI's handles
/// are usable from any host thread).
pub trait Technique: Send {
    fn id(&self) -> TechniqueId;

    /// Axis-aligned bounds of the base mesh at rest (frames the camera; an animated base does
    /// not move it).
    fn bbox(&self) -> ([f32; 3], [f32; 3]);

    /// The patch arrays, frame-wide numbered (see [`number_arrays`]).
    fn patch_arrays(&self) -> &[PatchArray];

    /// The draw path its arrays take (one per surface).
    fn draw_path(&self) -> DrawPath {
        self.patch_arrays()
            .first()
            .map_or(DrawPath::Tessellation, |a| a.patch.path())
    }

    /// Checks `params` against what this technique and this surface can draw; errors name the
    /// option at fault. Called before anything is recorded.
    fn check(&self, params: &FrameParams) -> Result<()>;

    /// Stages of one of its patch types.
    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline;

    /// Whether a frame with `params` needs the surface build of the evaluation and fragment
    /// stages (the manifest's `surface` axis: texture coordinates, displacement, owners' normals,
    /// parameter views, the patch-colour albedo varying); the plain build is smaller and hands
    /// the rasterizer fewer varyings, and lavapipe pays for both on every vertex.
    fn surface_build(&self, _params: &FrameParams) -> bool {
        false
    }

    /// Descriptor-set layout of its set 1, if its pipelines have one (set 0 is the frame's).
    /// One layout per technique type, made by the context ([`crate::Context::set_layout`]).
    fn set_layout_bindings(&self) -> &'static [vk_core::descriptor::BindingDesc] {
        &[]
    }

    /// Its set 1 for frame slot `slot`, when it has one.
    fn descriptor_set(&self, slot: usize) -> Option<&DescriptorSet> {
        let _ = slot;
        None
    }

    /// Vertices one patch of `array` emits at most under `params` (sizes draw splits).
    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64;

    /// Triangles `array` emits under `params` when the CPU knows it exactly (uniform factors),
    /// else `None` (a capture then measures first).
    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64>;

    /// The control mesh whose positions [`Technique::update_base`] replaces (in its vertex
    /// order), for techniques with [`Features::animation`].
    fn base_mesh(&self) -> Option<&topology::ControlMesh> {
        None
    }

    /// Host work a frame of `params` needs before it is recorded, such as refining a mesh to the
    /// level the frame asks for or taking the frame's refinement patterns from `ctx`. Called by
    /// [`crate::Context::prepare`] after [`Self::check`].
    fn prepare_frame(&mut self, ctx: &mut crate::Context, params: &FrameParams) -> Result<()> {
        let _ = (ctx, params);
        Ok(())
    }

    /// Uploads new base positions for frame slot `slot` (animation). Techniques without
    /// [`Features::animation`] refuse.
    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        let _ = (slot, positions);
        Err(TessError::Unsupported {
            technique: self.id(),
            what: "animated base positions",
        })
    }

    /// Commands before the rendering scope (compute kernels) for frame slot `slot`, with the
    /// barriers that order them after the previous frame's reads and before this frame's
    /// tessellation stages.
    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let _ = (enc, frame_set, slot);
        Ok(())
    }

    /// Records the draws of `array` for frame slot `slot` with its pipeline and sets already
    /// bound by the context,
    /// `per_draw` patches at most per draw (tessellated arrays), each draw's first patch id in
    /// its push constants.
    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        slot: usize,
        params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts>;

    /// Maps a captured (patch id, domain coordinate) — the tessellator's `gl_TessCoord.xy`, or
    /// what a vertex-stage capture records — to a point of a base face, in
    /// [`crate::capture::face_corner_uv`]'s convention; `None` for an id it never drew.
    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint>;

    /// The texture coordinate the surface shows at a captured (patch id, domain coordinate),
    /// as its shaders compute it, in `f64` on the host (`reparam`: with the texture
    /// reparameterization, [`FrameParams::reparam`]); `None` for a technique that draws no
    /// texture coordinates, a mesh without them, or an id it never drew.
    fn texcoord(&self, _patch: u32, _domain: [f32; 2], _reparam: bool) -> Option<[f64; 2]> {
        None
    }

    /// Lines for reports (e.g. the memory of its tables).
    fn report_notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// Every buffer and texture this surface keeps on the device, as created (its debug name
    /// and size in bytes): what the bench reports as the technique's memory. The frame's
    /// uniforms, descriptor sets and pipelines (the [`crate::Context`]'s) are not in it.
    fn device_memory(&self) -> Vec<DeviceAllocation>;
}

/// One buffer or texture a technique keeps on the device ([`Technique::device_memory`]).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct DeviceAllocation {
    /// The debug name it was created with ("adaptive stencil terms", "mesh vertices", ...).
    pub name: String,
    pub bytes: u64,
}

impl DeviceAllocation {
    /// `allocations` with those of one name as one entry, its bytes summed and its name given
    /// the count (a family of refinement patterns: "refinement pattern Triangle points (×14)"),
    /// in the order each name first appears.
    pub fn merged(allocations: impl IntoIterator<Item = Self>) -> Vec<Self> {
        let mut out: Vec<(Self, usize)> = Vec::new();
        for a in allocations {
            match out.iter_mut().find(|(b, _)| b.name == a.name) {
                Some((b, n)) => {
                    b.bytes += a.bytes;
                    *n += 1;
                }
                None => out.push((a, 1)),
            }
        }
        out.into_iter()
            .map(|(a, n)| match n {
                1 => a,
                n => Self {
                    name: format!("{} (×{n})", a.name),
                    bytes: a.bytes,
                },
            })
            .collect()
    }

    pub fn of_buffer(b: &vk_core::Buffer) -> Self {
        Self {
            name: b.name().to_owned(),
            bytes: b.size(),
        }
    }

    /// Every mip level, tightly packed (the driver may pad; this is what the texels need).
    pub fn of_texture(t: &vk_core::Texture) -> Self {
        let texel = t.format().bytes_per_texel() as u64;
        Self {
            name: t.name().to_owned(),
            bytes: (0..t.levels())
                .map(|l| {
                    let e = t.level_extent(l);
                    e.width as u64 * e.height as u64 * texel
                })
                .sum(),
        }
    }
}

/// Splits patches `0..patches` of an array into draws of at most `per_draw`, calling
/// `draw(first, count)` for each: the loop every technique's `record_array` shares.
pub fn for_each_draw(
    patches: u32,
    per_draw: u32,
    mut draw: impl FnMut(u32, u32) -> Result<()>,
) -> Result<DrawCounts> {
    let per_draw = per_draw.max(1);
    let mut counts = DrawCounts::default();
    let mut first = 0;
    while first < patches {
        let n = per_draw.min(patches - first);
        draw(first, n)?;
        counts.draws += 1;
        counts.patches += n;
        first += n;
    }
    Ok(counts)
}

#[cfg(test)]
mod tests {
    /// Allocations of one name merge into one entry with their count and summed bytes; the
    /// others keep their names and order.
    #[test]
    fn allocations_of_one_name_merge() {
        let a = |name: &str, bytes| DeviceAllocation {
            name: name.into(),
            bytes,
        };
        let merged = DeviceAllocation::merged([a("p", 3), a("q", 5), a("p", 4), a("p", 1)]);
        assert_eq!(merged, vec![a("p (×3)", 8), a("q", 5)]);
    }

    use super::*;

    const BOTH: &[DrawPath] = &[DrawPath::Tessellation, DrawPath::Pattern];
    const TESSELLATION: &[DrawPath] = &[DrawPath::Tessellation];
    const VERTEX: &[DrawPath] = &[DrawPath::VertexStage];
    const ID: TechniqueId = TechniqueId::new("probe");

    fn auto(paths: &[DrawPath], tessellation: bool, prefer: bool) -> Result<DrawPath> {
        PipelineChoice::Auto.resolve_with(ID, paths, tessellation, prefer)
    }

    #[test]
    fn auto_follows_the_device_and_the_measured_preference() {
        assert_eq!(auto(BOTH, true, false).unwrap(), DrawPath::Tessellation);
        assert_eq!(auto(BOTH, true, true).unwrap(), DrawPath::Pattern);
        assert_eq!(auto(BOTH, false, false).unwrap(), DrawPath::Pattern);
        assert_eq!(
            auto(TESSELLATION, true, true).unwrap(),
            DrawPath::Tessellation
        );
        assert_eq!(auto(VERTEX, false, true).unwrap(), DrawPath::VertexStage);
        assert!(matches!(
            auto(TESSELLATION, false, false),
            Err(TessError::NoTessellationShader { .. })
        ));
    }

    #[test]
    fn an_explicit_path_is_drawn_or_refused_by_name() {
        let pattern = |paths| PipelineChoice::Pattern.resolve_with(ID, paths, true, false);
        let tessellation =
            |paths, device| PipelineChoice::Tessellation.resolve_with(ID, paths, device, true);
        assert_eq!(pattern(BOTH).unwrap(), DrawPath::Pattern);
        assert_eq!(tessellation(BOTH, true).unwrap(), DrawPath::Tessellation);
        for e in [pattern(TESSELLATION), tessellation(VERTEX, true)] {
            let e = e.unwrap_err();
            assert!(e.to_string().contains("--pipeline"), "{e}");
        }
        assert!(matches!(
            tessellation(BOTH, false),
            Err(TessError::NoTessellationShader { .. })
        ));
    }
}
