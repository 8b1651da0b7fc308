//! SPIR-V of every shader stage declared in `glsl/manifest.toml`, compiled by the build script
//! in every declared variant, and looked up by a typed key:
//!
//! ```
//! use tess::shaders::{spirv, Stage, Variant};
//! use tess::Spacing;
//! let capture = Variant { spacing: Some(Spacing::FractionalOdd), capture: true, ..Variant::default() };
//! let words = spirv(Stage::PnTriTese, capture).unwrap();
//! assert_eq!(words[0], 0x0723_0203); // the SPIR-V magic number
//! // A stage ignores the axes it does not vary along: the TCS has one build.
//! assert_eq!(spirv(Stage::PnTriTesc, capture).unwrap(), spirv(Stage::PnTriTesc, Variant::default()).unwrap());
//! // A variant the manifest does not declare is an error: every TES needs a spacing.
//! assert!(spirv(Stage::PnTriTese, Variant::default()).is_err());
//! ```
use vk_core::vk;
include!(concat!(env!("OUT_DIR"), "/shaders.rs"));

/// The SPIR-V of `stage` built as `variant` (on the axes the stage varies along; the others
/// are ignored, see [`Stage::project`]); [`crate::TessError::ShaderVariant`] when the
/// manifest does not declare that build.
pub fn spirv(stage: Stage, variant: Variant) -> crate::Result<&'static [u32]> {
    let key = stage.project(variant);
    stage
        .compiled()
        .iter()
        .find(|(v, _)| *v == key)
        .map(|&(_, words)| words)
        .ok_or(crate::TessError::ShaderVariant { stage, variant })
}

/// The pipeline stage of `stage` (from its file extension).
pub fn vk_stage(stage: Stage) -> vk::ShaderStageFlags {
    stage.vk_stage()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn manifest_defaults_are_the_variant_default() {
        assert_eq!(DEFAULT_VARIANT, Variant::default());
    }

    #[test]
    fn every_stage_is_built_and_named_after_its_file() {
        for stage in Stage::ALL {
            assert!(!stage.compiled().is_empty(), "{stage:?}");
            let camel: String = stage
                .path()
                .split(['/', '.', '_'])
                .map(|w| w[..1].to_uppercase() + &w[1..])
                .collect();
            assert_eq!(format!("{stage:?}"), camel);
            // Every declared build is reachable through the lookup, as itself.
            for &(v, words) in stage.compiled() {
                assert_eq!(stage.project(v), v);
                assert_eq!(spirv(stage, v).expect("declared"), words);
            }
        }
        let tese = Stage::ALL
            .iter()
            .filter(|s| vk_stage(**s) == vk::ShaderStageFlags::TESSELLATION_EVALUATION)
            .count();
        assert_eq!(tese, 9);
    }

    #[test]
    fn an_undeclared_variant_is_a_typed_error() {
        let e = spirv(Stage::FlatTriTese, Variant::default()).expect_err("no spacing");
        assert!(matches!(
            e,
            crate::TessError::ShaderVariant {
                stage: Stage::FlatTriTese,
                ..
            }
        ));
        assert!(e.to_string().contains("flat/tri.tese"), "{e}");
    }
}
