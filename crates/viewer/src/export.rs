//! `tessera export`: what the GPU's TES emitted, captured through transform feedback, welded by
//! position bits, checked for cracks and written as OBJ (format: `tess::capture`).
//!
//! Works for every technique through `tess::Technique`: the capture, the patch-to-face map
//! (`Technique::face_point`) and everything after (weld, edge report, classification, OBJ) are
//! shared, so a new technique needs nothing here.
use crate::cli::ExportArgs;
use crate::commands::{
    build_technique, camera, check_drawable, check_validation, load_mesh_welded, mesh_name,
    open_device,
};
use crate::technique::describe;
use anyhow::{bail, Context as _, Result};
use tess::capture::{classify_open_edges, Capturer, Winding};
use tess::{Context, FrameParams};
use vk_core::vk;

/// What the export found: printed, and what `--fail-on-cracks` decides on.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct ExportReport {
    pub triangles: usize,
    pub corners: usize,
    pub welded_vertices: usize,
    pub open_edges: usize,
    pub on_base_boundary: usize,
    /// Open edges along the base mesh's non-manifold edges (sheets meeting there without
    /// sharing vertices): not cracks.
    pub on_non_manifold_edge: usize,
    /// Open edges inside a base face of no area (`tess::capture::OpenEdgeClasses`): not cracks.
    pub in_face_of_no_area: usize,
    pub cracks: usize,
    pub unmapped: usize,
    pub non_manifold: usize,
    pub zero_area: usize,
}

/// Refuses to write a capture with a NaN or infinite position or normal: validated input
/// (coordinates within `topology::mesh::MAX_COORDINATE`) never makes one, so one is a bug to report,
/// not a file to write.
fn check_finite(welded: &tess::WeldedMesh) -> Result<()> {
    for (what, values) in [("position", &welded.positions), ("normal", &welded.normals)] {
        if let Some(i) = values.iter().position(|p| !p.iter().all(|c| c.is_finite())) {
            let [x, y, z] = values[i];
            bail!(
                "the GPU emitted a non-finite {what} ({x}, {y}, {z}) at captured vertex {}; \
                 nothing written",
                i + 1
            );
        }
    }
    Ok(())
}

/// (patch id, domain bits) → base-face point of each welded vertex.
type FaceMap = std::collections::HashMap<(u32, [u32; 2]), tess::capture::FacePoint>;

pub fn run(a: ExportArgs) -> Result<()> {
    let params = FrameParams {
        camera: camera(&a.camera),
        phong_alpha: a.alpha,
        ..FrameParams::default()
    };
    let (base, lines) = load_mesh_welded(
        a.input.as_deref(),
        a.surface.weld,
        a.surface.uv_interpolation,
    )?;
    check_drawable(&base, &lines, &mesh_name(a.input.as_deref()), false)?;
    let method = crate::technique::resolve_method(a.method, a.surface.scheme.as_deref(), &base)?;
    let mut setup = a.surface.setup(
        method,
        crate::cli::segments_or_depth(a.segments, a.depth),
        a.spacing,
        false,
        params,
    )?;
    crate::technique::check_segments(&setup)?;
    setup.build.name = mesh_name(a.input.as_deref());
    tess::surface::check_texcoords(&base, &setup.build.maps, &setup.build.name)?;
    let extent = vk::Extent2D {
        width: a.size.0,
        height: a.size.1,
    };
    let (instance, device) = open_device(&a.gpu, vec![], &[])?;
    // Everything that holds GPU objects (the technique maps patch ids to base faces) lives in
    // this closure, so the validation check below sees the device destroyed.
    type Captured = (
        ExportReport,
        String,
        tess::WeldedMesh,
        FaceMap,
        Option<Vec<[f64; 2]>>,
    );
    let result = (|| -> Result<Captured> {
        let mut ctx = Context::offscreen(&device)?;
        let capturer = Capturer::new(&ctx)
            .context("tessera export captures through VK_EXT_transform_feedback")?;
        let mut technique = build_technique(&mut ctx, &base, &lines, &setup)?;
        let params = setup.world_params(technique.bbox());
        let (soup, stats) = crate::progress::during("capturing the tessellated triangles", || {
            capturer.capture(&mut ctx, technique.as_mut(), &params, extent)
        })?;
        let summary = format!(
            "{}; {} draws over {} patches, {} pass(es)",
            describe(setup.technique, &params),
            stats.draws,
            stats.patches,
            stats.passes
        );
        let map = |patch: u32, domain: [f32; 2]| technique.face_point(patch, domain);
        let (welded, edges, classes) = crate::progress::during(
            format!("welding {} triangles", soup.triangle_count()),
            || -> Result<_> {
                let welded = soup.weld()?;
                let edges = welded.open_edges();
                let classes = classify_open_edges(&soup, &welded, &edges, &map, &base);
                Ok((welded, edges, classes))
            },
        )?;
        let r = ExportReport {
            triangles: soup.triangle_count(),
            corners: soup.records.len(),
            welded_vertices: welded.positions.len(),
            open_edges: edges.open.len(),
            on_base_boundary: classes.on_base_boundary,
            on_non_manifold_edge: classes.on_non_manifold_edge,
            in_face_of_no_area: classes.in_face_of_no_area,
            cracks: classes.cracks,
            unmapped: classes.unmapped,
            non_manifold: edges.non_manifold.len(),
            zero_area: edges.zero_area.len(),
        };
        // The welded vertices' base-face points, kept as plain data so the OBJ is written only
        // after the validation check.
        let faces: FaceMap = welded
            .patch
            .iter()
            .zip(&welded.domain)
            .filter_map(|(&p, &d)| Some(((p, d.map(f32::to_bits)), map(p, d)?)))
            .collect();
        // Each corner's texture coordinate as the technique's shaders compute it (on the
        // host, from the same tables); none where the technique draws none.
        let texcoords = welded.corner_texcoords(|p, d| technique.texcoord(p, d, params.reparam));
        Ok((r, summary, welded, faces, texcoords))
    })();
    drop(device);
    check_validation(&instance)?;
    let (r, summary, welded, faces, texcoords) = result?;
    check_finite(&welded)?;
    let map = |patch: u32, domain: [f32; 2]| faces.get(&(patch, domain.map(f32::to_bits))).copied();
    // Every TES declares `ccw` in the upper-left domain: clockwise seen from outside.
    welded.write_obj(&a.output, &map, texcoords.as_deref(), Winding::Reversed)?;
    out!(
        "captured: {} triangles, {} vertices ({})",
        r.triangles,
        r.corners,
        summary
    );
    out!(
        "welded: {} vertices (corners merged only when their position bits are identical)",
        r.welded_vertices
    );
    out!(
        "open edges: {} ({} on the base mesh's boundary, {} cracks{}, {} along its non-manifold \
         edges, {} inside its faces of no area)",
        r.open_edges,
        r.on_base_boundary,
        r.cracks,
        if r.unmapped > 0 {
            format!(", {} of them on patches with no base face", r.unmapped)
        } else {
            String::new()
        },
        r.on_non_manifold_edge,
        r.in_face_of_no_area,
    );
    out!(
        "edges of three or more triangles: {} (where sheets of a non-manifold edge share \
         their vertices)",
        r.non_manifold
    );
    out!("zero-area triangles: {}", r.zero_area);
    out!("wrote {}", a.output.display());
    if a.fail_on_cracks && r.cracks > 0 {
        bail!("{} cracks (--fail-on-cracks)", r.cracks);
    }
    Ok(())
}
