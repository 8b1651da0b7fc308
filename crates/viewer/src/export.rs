//! `tessera export`: what the GPU's TES emitted, captured through transform feedback, welded by
//! position bits, checked for cracks and written as OBJ (format: `tess::capture`).
//!
//! A method only has to supply a [`Capture`]: its soup, how its patch ids map to base faces, and
//! its winding. Everything after (weld, edge report, classification, OBJ) is shared, so adding a
//! method is one [`Technique`] variant and one arm in [`capture`].
use crate::cli::ExportArgs;
use crate::commands::{camera, check_validation, load_mesh, mesh_name, open_device};
use crate::technique::{loop_control_mesh, BftSetup, Technique, Wave};
use anyhow::{bail, Context, Result};
use tess::bft::{patch_uv, BftSurface};
use tess::capture::{
    classify_open_edges, face_corner_uv, CapturedSoup, Capturer, FacePoint, PatchFaceTable, Winding,
};
use tess::renderer::GpuMesh;
use tess::{Camera, DrawParams, RenderMesh, Renderer, Spacing};
use topology::ControlMesh;
use vk_core::{vk, Device};

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
    name: String,
    segments: f32,
    spacing: Spacing,
    alpha: f32,
    camera: Camera,
    extent: vk::Extent2D,
    bft: Option<BftSetup>,
}

/// Captures `method` on `base`; the one place a new method plugs in.
fn capture(
    device: &Device,
    base: &ControlMesh,
    method: Technique,
    s: &Settings,
) -> Result<Capture> {
    match (method, &s.bft) {
        (Technique::Tessellated(m), _) => {
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
        (Technique::Bft, Some(setup)) => capture_bft(device, base, s, setup),
        (Technique::Bft, None) => bail!("internal: bft without its setup"),
    }
}

/// The BFT surface of `base` (fan-triangulated for Loop when it has polygons), its base moved
/// by the wave at `--frame T`, captured from the TES. Captured points map back to the input's
/// faces: a fan triangle's barycentrics go linearly into its polygon's domain, as for the other
/// methods ([`face_corner_uv`]).
fn capture_bft(
    device: &Device,
    base: &ControlMesh,
    s: &Settings,
    setup: &BftSetup,
) -> Result<Capture> {
    let (loop_mesh, origin, note) = loop_control_mesh(base, &s.name);
    if let Some(n) = note {
        eprintln!("{n}");
    }
    let mut renderer = Renderer::offscreen(device)?;
    let mut surface = BftSurface::new(
        &renderer,
        &loop_mesh,
        &s.name,
        setup.table_level,
        setup.params.geometric_normals,
        1,
    )
    .context("tessera export --method bft")?;
    if let Some(t) = setup.frame {
        surface.update_base(0, &Wave::new(&loop_mesh).at(t))?;
    }
    let params = setup.world_params((surface.bbox_min, surface.bbox_max));
    let draw = DrawParams {
        camera: s.camera,
        ..DrawParams::default()
    };
    let soup = surface
        .capture(&mut renderer, &draw, &params, s.extent)
        .context("tessera export captures through VK_EXT_transform_feedback")?;
    let fans = FanDomains::new(base, &origin);
    let bft = surface.bft.clone();
    let patches = surface.patch_count();
    Ok(Capture {
        summary: format!(
            "{patches} level-1 patches, {:?}{}",
            params.factors,
            if params.fractional { " fractional" } else { "" }
        ),
        soup,
        map: Box::new(move |patch, domain| {
            if patch >= patches {
                return None;
            }
            let (u, v) = patch_uv(domain);
            let (t, bu, bv) = bft.base_domain(patch as usize, u, v);
            // (bu, bv) weigh the triangle's corners 1 and 2.
            fans.face_point(t, [1.0 - bu - bv, bu, bv])
        }),
        // bft.tese declares `ccw` in the upper-left domain, like the other TESs.
        winding: Winding::Reversed,
    })
}

/// Where each triangle of a fan triangulation lies in its polygon's (u, v) domain.
struct FanDomains {
    /// Per triangle: origin face, its side count, fan index j (corners 0, j + 1, j + 2).
    fans: Vec<(u32, u32, u32)>,
}

impl FanDomains {
    fn new(base: &ControlMesh, origin: &[u32]) -> Self {
        let mut fans = Vec::with_capacity(origin.len());
        for (t, &o) in origin.iter().enumerate() {
            let j = match fans.last() {
                Some(&(prev, _, j)) if t > 0 && prev == o => j + 1,
                _ => 0,
            };
            fans.push((o, base.face(o as usize).len() as u32, j));
        }
        Self { fans }
    }

    /// The point with barycentric weights `w` of triangle `t`'s corners, in its polygon.
    fn face_point(&self, t: usize, w: [f64; 3]) -> Option<FacePoint> {
        let &(face, n, j) = self.fans.get(t)?;
        let mut uv = [0.0f64; 2];
        for (k, corner) in [0, j + 1, j + 2].into_iter().enumerate() {
            let c = face_corner_uv(n, corner);
            uv[0] += w[k] * c[0];
            uv[1] += w[k] * c[1];
        }
        Some(FacePoint {
            face,
            u: uv[0] as f32,
            v: uv[1] as f32,
        })
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
    let bft = a.surface.setup(a.method, a.segments, a.spacing, false)?;
    if bft.is_none() && !(1.0..=64.0).contains(&a.segments) {
        bail!("--segments {} is outside 1..64", a.segments);
    }
    let base = load_mesh(Some(&a.input))?;
    let settings = Settings {
        name: mesh_name(Some(&a.input)),
        segments: a.segments,
        spacing: a.spacing,
        alpha: a.alpha,
        camera: camera(&a.camera),
        extent: vk::Extent2D {
            width: a.size.0,
            height: a.size.1,
        },
        bft,
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
