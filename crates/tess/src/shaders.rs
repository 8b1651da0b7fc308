//! SPIR-V of every shader in `glsl/`, compiled by the build script. TEMPORARY shim over the
//! old generated constants until the manifest lands.
#![allow(missing_docs)]
use crate::error::{Result, TessError};
use crate::tessellator::Spacing;

pub mod generated {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
use generated as g;
pub use generated::*;

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Stage {
    CommonMeshVert,
    CommonShadeFrag,
    CommonTriTesc,
    CommonQuadTesc,
    FlatTriTese,
    FlatQuadTese,
    PhongTriTese,
    PnTriTesc,
    PnTriTese,
    BftBftVert,
    BftBftTesc,
    BftBftTese,
    BftBftFrag,
    BftSubdivideComp,
    BftNormalsComp,
    PlainPlainVert,
}

#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct Variant {
    pub spacing: Option<Spacing>,
    pub capture: bool,
}

pub fn spirv(stage: Stage, variant: Variant) -> Result<&'static [u32]> {
    use Spacing::*;
    use Stage::*;
    let missing = || TessError::MissingShaderVariant { stage, variant };
    let sp = |v: [(&'static [u32], &'static [u32]); 3]| -> Result<&'static [u32]> {
        let (r, c) = match variant.spacing.ok_or_else(missing)? {
            Equal => v[0],
            FractionalEven => v[1],
            FractionalOdd => v[2],
        };
        Ok(if variant.capture { c } else { r })
    };
    let single = |w: &'static [u32]| -> Result<&'static [u32]> {
        if variant.spacing.is_some() || variant.capture {
            Err(missing())
        } else {
            Ok(w)
        }
    };
    match stage {
        CommonMeshVert => single(g::MESH_VERT),
        CommonShadeFrag => single(g::SHADE_FRAG),
        CommonTriTesc => single(g::TRI_TESC),
        CommonQuadTesc => single(g::QUAD_TESC),
        PnTriTesc => single(g::PN_TESC),
        BftBftVert => single(g::BFT_VERT),
        BftBftTesc => single(g::BFT_TESC),
        BftBftFrag => single(g::BFT_FRAG),
        BftSubdivideComp => single(g::BFT_SUBDIVIDE_COMP),
        BftNormalsComp => single(g::BFT_NORMALS_COMP),
        PlainPlainVert => single(g::PLAIN_VERT),
        FlatTriTese => sp([
            (g::FLAT_TRI_TESE_EQUAL, g::FLAT_TRI_TESE_EQUAL_CAPTURE),
            (g::FLAT_TRI_TESE_FRACTIONAL_EVEN, g::FLAT_TRI_TESE_FRACTIONAL_EVEN_CAPTURE),
            (g::FLAT_TRI_TESE_FRACTIONAL_ODD, g::FLAT_TRI_TESE_FRACTIONAL_ODD_CAPTURE),
        ]),
        FlatQuadTese => sp([
            (g::FLAT_QUAD_TESE_EQUAL, g::FLAT_QUAD_TESE_EQUAL_CAPTURE),
            (g::FLAT_QUAD_TESE_FRACTIONAL_EVEN, g::FLAT_QUAD_TESE_FRACTIONAL_EVEN_CAPTURE),
            (g::FLAT_QUAD_TESE_FRACTIONAL_ODD, g::FLAT_QUAD_TESE_FRACTIONAL_ODD_CAPTURE),
        ]),
        PhongTriTese => sp([
            (g::PHONG_TESE_EQUAL, g::PHONG_TESE_EQUAL_CAPTURE),
            (g::PHONG_TESE_FRACTIONAL_EVEN, g::PHONG_TESE_FRACTIONAL_EVEN_CAPTURE),
            (g::PHONG_TESE_FRACTIONAL_ODD, g::PHONG_TESE_FRACTIONAL_ODD_CAPTURE),
        ]),
        PnTriTese => sp([
            (g::PN_TESE_EQUAL, g::PN_TESE_EQUAL_CAPTURE),
            (g::PN_TESE_FRACTIONAL_EVEN, g::PN_TESE_FRACTIONAL_EVEN_CAPTURE),
            (g::PN_TESE_FRACTIONAL_ODD, g::PN_TESE_FRACTIONAL_ODD_CAPTURE),
        ]),
        BftBftTese => sp([
            (g::BFT_TESE_EQUAL, g::BFT_TESE_EQUAL_CAPTURE),
            (g::BFT_TESE_FRACTIONAL_EVEN, g::BFT_TESE_FRACTIONAL_EVEN_CAPTURE),
            (g::BFT_TESE_FRACTIONAL_ODD, g::BFT_TESE_FRACTIONAL_ODD_CAPTURE),
        ]),
    }
}
