//! `tessera export`: what the GPU's TES emitted, captured through transform feedback, welded by
//! position bits, checked for cracks and written as OBJ (format: `tess::capture`).
//!
//! A method only has to supply a [`Capture`]: its soup, how its patch ids map to base faces, and
//! its winding. Everything after (weld, edge report, classification, OBJ) is shared, so adding a
//! method is one [`ExportMethod`] variant and one arm in [`capture`].
use crate::cli::ExportArgs;
use crate::commands::{check_validation, load_mesh, open_device};
use anyhow::{bail, Context, Result};
use tess::capture::{
    classify_open_edges, CapturedSoup, Capturer, FacePoint, PatchFaceTable, Winding,
};
use tess::renderer::GpuMesh;
use tess::{DrawParams, Method, RenderMesh, Spacing};
use topology::ControlMesh;
use vk_core::Device;

/// How the surface is produced.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExportMethod {
    /// A triangle/quad technique of the renderer (flat, phong, pn).
    Tessellated(Method),
}

pub fn parse_export_method(s: &str) -> Result<ExportMethod, String> {
    match s.parse::<Method>() {
        Ok(m) => Ok(ExportMethod::Tessellated(m)),
        Err(_) => Err(format!("unknown method '{s}' (flat, phong, pn)")),
    }
}

/// Subdivision schemes export accepts; others are refused by name rather than ignored.
const SCHEMES: &[&str] = &["loop"];

/// What one method hands to the shared report.
pub struct Capture {
    pub soup: CapturedSoup,
    /// (captured patch id, domain coordinate) → base face and its (u, v).
    pub map: Box<dyn Fn(u32, [f32; 2]) -> Option<FacePoint>>,
    /// Corner order to write so faces wind like the base faces.
    pub winding: Winding,
    /// One line on how it was drawn (draws, patches, passes).
    pub summary: String,
}

struct Settings {
    segments: f32,
    spacing: Spacing,
    alpha: f32,
}

/// Captures `method` on `base`; the one place a new method plugs in.
fn capture(
    device: &Device,
    base: &ControlMesh,
    method: ExportMethod,
    s: &Settings,
) -> Result<Capture> {
    match method {
        ExportMethod::Tessellated(m) => {
            let rm = RenderMesh::from_control_mesh(base).context("preparing the mesh")?;
            let table = PatchFaceTable::new(rm.patch_origins(m));
            let mut capturer = Capturer::new(device)
                .context("tessera export captures through VK_EXT_transform_feedback")?;
            let gm = GpuMesh::upload(device, &rm)?;
            let params = DrawParams {
                method: m,
                spacing: s.spacing,
                level: s.segments,
                phong_alpha: s.alpha,
                ..DrawParams::default()
            };
            let (soup, stats) = capturer.capture_with_stats(&gm, &params)?;
            Ok(Capture {
                soup,
                map: Box::new(move |patch, domain| table.face_point(patch, domain)),
                // The TESs declare `ccw` in the upper-left domain: clockwise seen from outside.
                winding: Winding::Reversed,
                summary: format!(
                    "{} draws over {} patches, {} pass(es)",
                    stats.draws, stats.patches, stats.passes
                ),
            })
        }
    }
}

/// What the export found: printed, and what `--fail-on-cracks` decides on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExportReport {
    pub triangles: usize,
    pub corners: usize,
    pub welded_vertices: usize,
    pub open_edges: usize,
    pub on_base_boundary: usize,
    pub cracks: usize,
    pub unmapped: usize,
    pub non_manifold: usize,
    pub zero_area: usize,
}

pub fn run(a: ExportArgs) -> Result<()> {
    if let Some(scheme) = &a.scheme {
        if !SCHEMES.contains(&scheme.as_str()) {
            bail!(
                "--scheme {scheme}: export supports only {} for now",
                SCHEMES.join(", ")
            );
        }
    }
    if !(1.0..=64.0).contains(&a.segments) {
        bail!("--segments {} is outside 1..64", a.segments);
    }
    let base = load_mesh(Some(&a.input))?;
    let settings = Settings {
        segments: a.segments,
        spacing: a.spacing,
        alpha: a.alpha,
    };
    let (instance, device) = open_device(&a.gpu, vec![], &[])?;
    let captured = capture(&device, &base, a.method, &settings);
    drop(device);
    check_validation(&instance)?;
    let captured = captured?;

    let welded = captured.soup.weld()?;
    let edges = welded.open_edges();
    let classes = classify_open_edges(&captured.soup, &welded, &edges, &*captured.map, &base);
    let r = ExportReport {
        triangles: captured.soup.triangle_count(),
        corners: captured.soup.records.len(),
        welded_vertices: welded.positions.len(),
        open_edges: edges.open.len(),
        on_base_boundary: classes.on_base_boundary,
        cracks: classes.cracks,
        unmapped: classes.unmapped,
        non_manifold: edges.non_manifold.len(),
        zero_area: edges.zero_area.len(),
    };
    welded.write_obj(&a.output, &*captured.map, captured.winding)?;
    println!(
        "captured: {} triangles, {} vertices ({})",
        r.triangles, r.corners, captured.summary
    );
    println!(
        "welded: {} vertices (corners merged only when their position bits are identical)",
        r.welded_vertices
    );
    println!(
        "open edges: {} ({} on the base mesh's boundary, {} cracks{})",
        r.open_edges,
        r.on_base_boundary,
        r.cracks,
        if r.unmapped > 0 {
            format!(", {} of them on patches with no base face", r.unmapped)
        } else {
            String::new()
        }
    );
    println!("non-manifold edges: {}", r.non_manifold);
    println!("zero-area triangles: {}", r.zero_area);
    println!("wrote {}", a.output.display());
    if a.fail_on_cracks && r.cracks > 0 {
        bail!("{} cracks (--fail-on-cracks)", r.cracks);
    }
    Ok(())
}
