//! Every technique, and the registry that builds one by name: the only place that lists
//! which techniques exist. Each technique declares itself in its own folder — its
//! [`TechniqueId`] constant and a [`TechniqueInfo`] (name, help, options it takes, the scheme
//! whose limit it draws, shader folder, C ABI value, patch-colour legend, constructor) — and
//! [`REGISTRY`] holds one line per technique. Callers (viewer, HUD, bench, export, C ABI,
//! tests) build through [`build`], check options against [`TechniqueInfo::features`] and
//! iterate [`registry`]; none of them matches on techniques.
pub mod acc;
pub mod adaptive;
pub mod bft;
pub mod cpu;
pub mod doo_sabin;
pub mod doo_sabin_limit;
pub mod face_patches;
pub mod flat;
pub mod gregory;
pub mod host_view;
pub mod phong;
pub mod planned_patches;
pub mod pn;
pub mod shared;
pub mod split;
pub mod vertex_patches;
pub mod windows;

use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{Features, FrameParams, PipelineChoice, Technique, TechniqueId};
use topology::ControlMesh;

/// Builds a technique for a mesh on a context's device.
pub type BuildFn = fn(&mut Context, &ControlMesh, &BuildOptions) -> Result<Built>;

/// Checks a frame's options against what a technique refuses before any device or mesh
/// exists (see [`check_options`]).
pub type CheckFn = fn(&BuildOptions, &FrameParams) -> Result<()>;

/// A patch-colour legend entry: colour and what it marks.
pub type LegendEntry = ([f32; 3], &'static str);

/// What the registry says of one technique: everything callers need, declared in the
/// technique's own folder.
#[derive(Clone, Copy, Debug)]
pub struct TechniqueInfo {
    pub id: TechniqueId,
    /// One line for `--help` and reports.
    pub help: &'static str,
    pub features: Features,
    /// The subdivision scheme whose limit surface it draws (None: not a subdivision surface).
    pub scheme: Option<topology::Scheme>,
    /// Drawn for its scheme when no technique is named (one per scheme).
    pub default_for_scheme: bool,
    /// Its shaders' folder under `glsl/` (a test checks every stage it names lies there or in
    /// `glsl/common/`).
    pub shader_folder: &'static str,
    /// Its `TESSERA_TECHNIQUE_*` value in the C ABI: stable, never reused.
    pub abi_code: u32,
    /// The patch-colour legend (empty without patch colours).
    pub legend: &'static [LegendEntry],
    pub build: BuildFn,
    pub check_options: CheckFn,
}

/// Every technique, one line each, in the order reports and the window's number keys list
/// them (flat first: ratios divide by it).
pub static REGISTRY: [&TechniqueInfo; 13] = [
    &flat::INFO,
    &phong::INFO,
    &pn::INFO,
    &bft::INFO,
    &adaptive::INFO,
    &gregory::INFO,
    &acc::INFO,
    &cpu::INFO,
    &cpu::CATMARK_INFO,
    &doo_sabin_limit::INFO,
    &doo_sabin::INFO,
    &cpu::DOO_SABIN_INFO,
    &vertex_patches::INFO,
];

/// Every technique, in the order reports list them (flat first: ratios divide by it).
pub fn registry() -> &'static [&'static TechniqueInfo] {
    &REGISTRY
}

/// The registry entry of `id`. Ids are made only inside this crate, each next to its
/// technique's registry entry (a test checks every entry's id finds it), so every id has one.
pub fn info(id: TechniqueId) -> &'static TechniqueInfo {
    REGISTRY
        .iter()
        .copied()
        .find(|i| i.id == id)
        .unwrap_or(REGISTRY[0])
}

/// The registry entry named `name` (`--method NAME`).
pub fn named(name: &str) -> Result<&'static TechniqueInfo> {
    REGISTRY
        .iter()
        .copied()
        .find(|i| i.id.name() == name)
        .ok_or_else(|| unknown(name))
}

/// The registry entry with C ABI value `code`.
pub fn by_abi_code(code: u32) -> Option<&'static TechniqueInfo> {
    REGISTRY.iter().copied().find(|i| i.abi_code == code)
}

/// The technique drawn for `scheme` when none is named.
pub fn default_for(scheme: topology::Scheme) -> Option<&'static TechniqueInfo> {
    REGISTRY
        .iter()
        .copied()
        .find(|i| i.default_for_scheme && i.scheme == Some(scheme))
}

fn unknown(name: &str) -> TessError {
    TessError::UnknownTechnique {
        name: name.to_string(),
        known: REGISTRY
            .iter()
            .map(|i| i.id.name())
            .collect::<Vec<_>>()
            .join(", "),
    }
}

/// The techniques that have a feature, by name, for messages ("needs --method bft").
pub fn names_with(feature: impl Fn(&Features) -> bool) -> Vec<&'static str> {
    REGISTRY
        .iter()
        .filter(|i| feature(&i.features))
        .map(|i| i.id.name())
        .collect()
}

impl std::str::FromStr for TechniqueId {
    type Err = TessError;
    fn from_str(s: &str) -> Result<Self> {
        named(s).map(|i| i.id)
    }
}

/// A [`CheckFn`] for techniques with nothing to refuse before they are built.
pub fn no_early_checks(_build: &BuildOptions, _params: &FrameParams) -> Result<()> {
    Ok(())
}

/// How a surface is built (per-frame choices are [`crate::FrameParams`]).
#[derive(Clone, Debug)]
pub struct BuildOptions {
    /// Name for messages (the mesh's file).
    pub name: String,
    /// Basis-function table level (techniques with [`Features::table_level`]).
    pub table_level: u32,
    /// Build what geometric normals need (techniques with [`Features::geometric_normals`]).
    pub tangents: bool,
    /// Isolation level (techniques with [`Features::isolation`]).
    pub isolation: u32,
    /// End caps of faces still irregular at the isolation level.
    pub end_cap: topology::patches::adaptive::EndCap,
    /// Scales every crease and corner sharpness.
    pub sharpness_scale: f32,
    /// Follow semi-sharp creases past the isolation level until they decay (and the irregular
    /// vertices beside them `isolation` levels more).
    pub follow_semi_sharp: bool,
    /// Single-pass methods: split triangles into three quad patches instead of one Gregory
    /// triangle patch each.
    pub split_triangles: bool,
    /// Colour texture and height map (techniques with [`Features::surface`]).
    pub maps: crate::surface::SurfaceMaps,
    /// Meshes refined on the CPU refuse levels with more vertices than this (3 M vertices
    /// peak at about 1.6 GB of host memory).
    pub max_refined_vertices: u64,
    /// The draw path (`--pipeline`): resolved per technique and device by
    /// [`PipelineChoice::resolve`].
    pub pipeline: PipelineChoice,
}

impl Default for BuildOptions {
    fn default() -> Self {
        Self {
            name: "mesh".into(),
            table_level: bft::DEFAULT_TABLE_LEVEL,
            tangents: false,
            isolation: adaptive::DEFAULT_ISOLATION,
            end_cap: topology::patches::adaptive::EndCap::Gregory,
            sharpness_scale: 1.0,
            follow_semi_sharp: true,
            split_triangles: false,
            maps: Default::default(),
            max_refined_vertices: 4_000_000,
            pipeline: PipelineChoice::Auto,
        }
    }
}

/// A built technique and what the caller should tell the user about how it took the mesh.
pub struct Built {
    pub technique: Box<dyn Technique>,
    pub notes: Vec<String>,
}

/// Checks `params` against what technique `id` refuses before any device or mesh exists
/// (spacings, BFT's dyadic segments, adaptive's whole segments), so a bad option is reported
/// before the device is opened and the surface built. [`Technique::check`] repeats these checks
/// with what only the built surface and device know (tangent tables, the device's level).
pub fn check_options(id: TechniqueId, build: &BuildOptions, params: &FrameParams) -> Result<()> {
    (info(id).check_options)(build, params)
}

/// Builds technique `id` for `mesh` on `ctx`'s device, with one frame slot per slot of `ctx`,
/// for the draw path `options.pipeline` chooses (refused by name where the technique or the
/// device has no such path).
/// The subdivision techniques take a non-manifold mesh through its manifold split
/// ([`split::build_split`]); the others draw its faces as given.
pub fn build(
    ctx: &mut Context,
    id: TechniqueId,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let info = info(id);
    options
        .pipeline
        .resolve(id, info.features.paths, ctx.device())?;
    if info.scheme.is_some() {
        split::build_split(ctx, info, mesh, options)
    } else {
        (info.build)(ctx, mesh, options)
    }
}

/// A [`Built`] with no notes.
pub fn built(technique: impl Technique + 'static) -> Result<Built> {
    Ok(Built {
        technique: Box::new(technique),
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_registry_entry_is_found_by_name_id_and_abi_code() {
        for info in registry() {
            assert_eq!(named(info.id.name()).unwrap().id, info.id);
            assert_eq!(super::info(info.id).id, info.id);
            assert_eq!(by_abi_code(info.abi_code).unwrap().id, info.id);
            assert_eq!(info.id.name().parse::<TechniqueId>().unwrap(), info.id);
        }
        assert!("acc2".parse::<TechniqueId>().is_err());
        assert!(by_abi_code(0).is_none(), "0 is the C ABI's 'auto'");
    }

    #[test]
    fn names_and_abi_codes_are_unique_and_each_scheme_has_one_default() {
        let mut names: Vec<_> = registry().iter().map(|i| i.id.name()).collect();
        let mut codes: Vec<_> = registry().iter().map(|i| i.abi_code).collect();
        names.sort();
        names.dedup();
        codes.sort();
        codes.dedup();
        assert_eq!(names.len(), registry().len());
        assert_eq!(codes.len(), registry().len());
        for scheme in [
            topology::Scheme::Loop,
            topology::Scheme::CatmullClark,
            topology::Scheme::DooSabin,
        ] {
            let defaults = registry()
                .iter()
                .filter(|i| i.default_for_scheme && i.scheme == Some(scheme))
                .count();
            assert_eq!(defaults, 1, "{scheme}");
        }
    }

    #[test]
    fn every_shader_folder_holds_stages() {
        use crate::shaders::Stage;
        for info in registry() {
            let own = format!("{}/", info.shader_folder);
            let stages: Vec<Stage> = Stage::ALL
                .iter()
                .copied()
                .filter(|s| s.path().starts_with(&own))
                .collect();
            assert!(!stages.is_empty(), "{}: no stage in glsl/{own}", info.id);
        }
    }
}
