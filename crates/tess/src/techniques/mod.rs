//! Every technique, and the registry that builds one by name: the only place that knows
//! which techniques exist. Callers (viewer, bench, export, C ABI) build through [`build`] and
//! check options against [`TechniqueInfo::features`].
pub mod adaptive;
pub mod bft;
pub mod face_patches;
pub mod flat;
pub mod gregory;
pub mod phong;
pub mod pn;
pub mod shared;
pub mod windows;

use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{Features, Technique, TechniqueId};
use topology::ControlMesh;

/// What the registry says of one technique.
#[derive(Clone, Copy, Debug)]
pub struct TechniqueInfo {
    pub id: TechniqueId,
    /// One line for `--help` and reports.
    pub help: &'static str,
    pub features: Features,
    /// The subdivision scheme whose limit surface it draws (None: not a subdivision surface).
    pub scheme: Option<topology::Scheme>,
}

const BASE_FACES: Features = Features {
    adaptive_factors: false,
    spacings: [true, true, true],
    animation: false,
    patch_colours: false,
    geometric_normals: false,
    phong_alpha: false,
    table_level: false,
    triangles_only: false,
    isolation: false,
    surface: false,
    single_pass: false,
};

static REGISTRY: [TechniqueInfo; 7] = [
    TechniqueInfo {
        id: TechniqueId::Flat,
        help: "flat tessellation of each base face (quads as quad patches)",
        features: BASE_FACES,
        scheme: None,
    },
    TechniqueInfo {
        id: TechniqueId::Phong,
        help: "Phong tessellation (Boubekeur & Alexa 2008) of the fan triangles",
        features: Features {
            phong_alpha: true,
            ..BASE_FACES
        },
        scheme: None,
    },
    TechniqueInfo {
        id: TechniqueId::Pn,
        help: "curved PN triangles with the corrected normal field",
        features: BASE_FACES,
        scheme: None,
    },
    TechniqueInfo {
        id: TechniqueId::Bft,
        help: "exact Loop limit surface from basis-function tables (Holländer & Boubekeur)",
        features: Features {
            adaptive_factors: true,
            spacings: [true, true, false],
            animation: true,
            patch_colours: true,
            geometric_normals: true,
            phong_alpha: false,
            table_level: true,
            triangles_only: true,
            isolation: false,
            surface: false,
            single_pass: false,
        },
        scheme: Some(topology::Scheme::Loop),
    },
    TechniqueInfo {
        id: TechniqueId::Adaptive,
        help: "exact Catmull-Clark limit surface by feature-adaptive refinement (Niessner et al.), Gregory or bilinear end caps",
        features: ADAPTIVE,
        scheme: Some(topology::Scheme::CatmullClark),
    },
    TechniqueInfo {
        id: TechniqueId::Gregory,
        help: "Catmull-Clark approximated by one Gregory patch per base face, B-spline where regular (Loop, Schaefer, Ni, Castano), Gregory triangle patches on triangles; other faces next to non-quads split once",
        features: SINGLE_PASS,
        scheme: Some(topology::Scheme::CatmullClark),
    },
    TechniqueInfo {
        id: TechniqueId::Acc,
        help: "Catmull-Clark approximated by ACC-1 bicubic patches (Loop & Schaefer), Gregory patches where ACC-1 does not apply",
        features: SINGLE_PASS,
        scheme: Some(topology::Scheme::CatmullClark),
    },
];

const ADAPTIVE: Features = Features {
    adaptive_factors: true,
    spacings: [true, true, false],
    animation: true,
    patch_colours: true,
    geometric_normals: false,
    phong_alpha: false,
    table_level: false,
    triangles_only: false,
    isolation: true,
    surface: true,
    single_pass: false,
};

/// The single-pass approximations: the adaptive machinery without isolation.
const SINGLE_PASS: Features = Features {
    isolation: false,
    single_pass: true,
    ..ADAPTIVE
};

/// Every technique, in the order reports list them (flat first: ratios divide by it).
pub fn registry() -> &'static [TechniqueInfo] {
    &REGISTRY
}

/// The registry entry of `id`.
pub fn info(id: TechniqueId) -> &'static TechniqueInfo {
    REGISTRY.iter().find(|i| i.id == id).unwrap_or(&REGISTRY[0])
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
        REGISTRY
            .iter()
            .find(|i| i.id.name() == s)
            .map(|i| i.id)
            .ok_or_else(|| TessError::UnknownTechnique {
                name: s.to_string(),
                known: REGISTRY
                    .iter()
                    .map(|i| i.id.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
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
pub fn check_options(
    id: TechniqueId,
    build: &BuildOptions,
    params: &crate::technique::FrameParams,
) -> Result<()> {
    match id {
        TechniqueId::Bft => bft::check_frame(build.table_level, params),
        TechniqueId::Adaptive | TechniqueId::Gregory | TechniqueId::Acc => {
            adaptive::check_frame(None, params)
        }
        TechniqueId::Flat | TechniqueId::Phong | TechniqueId::Pn => Ok(()),
    }
}

/// Builds technique `id` for `mesh` on `ctx`'s device, with one frame slot per slot of `ctx`.
pub fn build(
    ctx: &mut Context,
    id: TechniqueId,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let device = ctx.device().clone();
    let technique: Box<dyn Technique> = match id {
        TechniqueId::Flat => Box::new(flat::Flat::new(&device, mesh)?),
        TechniqueId::Phong => Box::new(phong::Phong::new(&device, mesh)?),
        TechniqueId::Pn => Box::new(pn::Pn::new(&device, mesh)?),
        TechniqueId::Bft => {
            let b = bft::Bft::new(
                ctx,
                mesh,
                &bft::BftOptions {
                    table_level: options.table_level,
                    tangents: options.tangents,
                    name: options.name.clone(),
                    patch_block: None,
                },
            )?;
            let notes = b.notes.clone();
            return Ok(Built {
                technique: Box::new(b),
                notes,
            });
        }
        TechniqueId::Adaptive | TechniqueId::Gregory | TechniqueId::Acc => {
            let surface = if id == TechniqueId::Adaptive {
                adaptive::Adaptive::new(
                    ctx,
                    mesh,
                    &adaptive::AdaptiveBuild {
                        isolation: options.isolation,
                        end_cap: options.end_cap,
                        sharpness_scale: options.sharpness_scale,
                        follow_semi_sharp: options.follow_semi_sharp,
                        name: options.name.clone(),
                        maps: options.maps.clone(),
                    },
                )?
            } else {
                gregory::build(
                    ctx,
                    mesh,
                    if id == TechniqueId::Acc {
                        topology::patches::adaptive::single_pass::SinglePassPatch::Acc1
                    } else {
                        topology::patches::adaptive::single_pass::SinglePassPatch::Gregory
                    },
                    options.sharpness_scale,
                    !options.split_triangles,
                    &options.name,
                    &options.maps,
                )?
            };
            let notes = surface.param_error_note().into_iter().collect();
            return Ok(Built {
                technique: Box::new(surface),
                notes,
            });
        }
    };
    Ok(Built {
        technique,
        notes: Vec::new(),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_technique_has_its_own_registry_entry() {
        for id in [
            TechniqueId::Flat,
            TechniqueId::Phong,
            TechniqueId::Pn,
            TechniqueId::Bft,
            TechniqueId::Adaptive,
            TechniqueId::Gregory,
            TechniqueId::Acc,
        ] {
            assert_eq!(info(id).id, id);
            assert_eq!(id.name().parse::<TechniqueId>().unwrap(), id);
        }
        assert!("acc2".parse::<TechniqueId>().is_err());
    }
}
