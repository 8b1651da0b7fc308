//! The techniques as the benchmark drives them: every row is a [`TechniqueRow`], one technique
//! of [`techniques::registry`] (plus an `-animated` row for those that animate), built by
//! name. The CPU baselines are techniques too (`cpu`, `cpu-catmark`: refined on the CPU, drawn
//! from the vertex stage), so a new technique needs no entry here.
use super::{BenchConfig, BenchMesh};
use crate::animation::Wave;
use crate::camera::Camera;
use crate::context::{statistics_query_safe, Context};
use crate::error::{Result, TessError};
use crate::technique::{DrawPath, FrameParams, PipelineChoice, Technique};
use crate::techniques::{self, BuildOptions, TechniqueInfo};
use std::time::Instant;
use vk_core::{vk, Device, Encoder};

/// What one frame of a row asks for.
#[derive(Clone, Copy, Debug)]
pub struct BenchFrame {
    /// Frame number within the row, warm-up frames included (0 is the first warm-up frame).
    pub index: u32,
    /// A warm-up frame (its times are not in the row).
    pub warmup: bool,
    /// The level this row draws at: segments per base edge S (the paper's 4×4, 16×16,
    /// 32×32 splits: S = 4, 16, 32), or under [`super::BenchConfig::equal_triangles`] the
    /// segments per patch edge chosen to match Flat's triangles at S.
    pub segments: u32,
    pub extent: vk::Extent2D,
    pub camera: Camera,
}

/// Everything a row needs to build its technique for one mesh.
#[derive(Clone, Copy)]
pub struct RowContext<'a> {
    pub device: &'a Device,
    pub mesh: &'a BenchMesh,
    pub config: &'a BenchConfig,
    pub color_format: vk::Format,
    pub depth_format: vk::Format,
}

/// The registry's names, for messages.
pub fn method_names() -> Vec<&'static str> {
    techniques::registry().iter().map(|i| i.id.name()).collect()
}

/// A bench method: a registry name, optionally with the draw path its rows take
/// (`flat@pattern`, `pn@tessellation`). Without one a row draws as the papers' methods do:
/// through the tessellation stage where the technique and the device have it (Table I's Flat
/// is the hardware tessellator's), else as `--pipeline auto` chooses.
pub fn parse_method(name: &str) -> Result<(&'static TechniqueInfo, Option<PipelineChoice>)> {
    let (technique, path) = match name.split_once('@') {
        Some((t, p)) => (t, Some(p)),
        None => (name, None),
    };
    let unknown = |reason: String| TessError::BenchConfig {
        option: "--methods".into(),
        reason,
    };
    let info = techniques::named(technique).map_err(|_| {
        unknown(format!(
            "unknown bench method '{name}' (known: {}; a draw path may follow as @tessellation or @pattern)",
            method_names().join(", ")
        ))
    })?;
    let choice = match path {
        None => None,
        Some(p) => match p.parse::<PipelineChoice>() {
            Ok(c @ (PipelineChoice::Tessellation | PipelineChoice::Pattern)) => Some(c),
            _ => {
                return Err(unknown(format!(
                    "'{name}': the draw path after @ is tessellation or pattern"
                )))
            }
        },
    };
    Ok((info, choice))
}

/// Builds the rows of the techniques named in `names` for one mesh, in registry order: each
/// technique's static row, and its `-animated` row when it animates.
pub fn build_rows(names: &[String], ctx: &RowContext<'_>) -> Result<Vec<TechniqueRow>> {
    let methods = names
        .iter()
        .map(|n| Ok((n.as_str(), parse_method(n)?)))
        .collect::<Result<Vec<_>>>()?;
    let mut out = Vec::new();
    for info in techniques::registry() {
        for &(name, (_, choice)) in methods.iter().filter(|m| m.1 .0.id == info.id) {
            out.push(TechniqueRow::new(ctx, info, (name, choice), false)?);
            if info.features.animation {
                out.push(TechniqueRow::new(ctx, info, (name, choice), true)?);
            }
        }
    }
    Ok(out)
}

/// One row: a technique through a [`Context`] of its own, uniform factors of S segments per
/// base edge, the pre-pass (if any) inside the timed span; the `-animated` row moves the base
/// by the `--animate` wave every frame ([`Technique::update_base`]: an upload of base
/// positions, or for a mesh refined on the CPU a refinement and an upload), its CPU time
/// reported.
///
/// Per frame the runner calls [`Self::begin_frame`] (host work), then records one command
/// buffer: timestamp, [`Self::record_pre_pass`] (outside any rendering scope: compute), the
/// rendering scope with [`Self::record`] (draws), timestamp; it submits and waits. The GPU time
/// is the span between the two timestamps, so a compute pre-pass counts.
pub struct TechniqueRow {
    label: String,
    mesh_name: String,
    animated: bool,
    technique: Box<dyn Technique>,
    wave: Option<Wave>,
    context: Context,
    /// Faces of the control mesh as loaded (the memory note's denominator).
    base_faces: usize,
    /// Displacement scale and reparameterization of every frame: the config's for techniques
    /// that take surface maps, else none and the default.
    displace: f32,
    reparam: bool,
    /// The config's edge factors, and the mesh's bounding-box diagonal they are measured in.
    factors: (super::BenchFactors, f32),
    /// The config's spacing where the technique takes it, else equal.
    spacing: crate::tessellator::Spacing,
    /// What the row draws beyond plain shading ([`BenchConfig::surface_note`]), for its note.
    surface_note: Option<String>,
}

/// The config's factors for a row of `info` on `mesh`: screen-space and distance factors
/// where the technique takes them (uniform elsewhere, so Flat stays the baseline at S).
fn row_factors(
    config: &super::BenchConfig,
    info: &TechniqueInfo,
    mesh: &topology::ControlMesh,
) -> (super::BenchFactors, f32) {
    match info.features.adaptive_factors {
        true => (config.factors, mesh.bbox_diagonal() as f32),
        false => (super::BenchFactors::Uniform, 1.0),
    }
}

impl TechniqueRow {
    /// The row of `info` named `name` (its registry name, or with the draw path `choice`:
    /// `flat@pattern`; see [`parse_method`] for a name without one), animated or not.
    pub fn new(
        ctx: &RowContext<'_>,
        info: &TechniqueInfo,
        (name, choice): (&str, Option<PipelineChoice>),
        animated: bool,
    ) -> Result<Self> {
        let tessellation = ctx.device.info.caps.tessellation_shader
            && info.features.paths.contains(&DrawPath::Tessellation);
        let choice = match choice {
            Some(c) => c,
            None if tessellation => PipelineChoice::Tessellation,
            None => PipelineChoice::Auto,
        };
        let mut context = Context::new(ctx.device, ctx.color_format, ctx.depth_format, 1)?;
        // Catmull-Clark and Doo-Sabin techniques take the mesh as loaded (a fan triangulation
        // is another surface for them); the others its fan triangulation (the paper's Table I).
        let as_loaded = [topology::Scheme::CatmullClark, topology::Scheme::DooSabin];
        let mesh = if info.scheme.is_some_and(|s| as_loaded.contains(&s)) {
            &ctx.mesh.input
        } else {
            &ctx.mesh.mesh
        };
        // Textures, displacement and the reparameterization apply to the techniques that take
        // them (`Features::surface`); the others draw as always.
        let surface = info.features.surface;
        let built = techniques::build(
            &mut context,
            info.id,
            mesh,
            &BuildOptions {
                name: ctx.mesh.name.clone(),
                isolation: ctx.config.isolation,
                follow_semi_sharp: ctx.config.follow_semi_sharp,
                maps: if surface {
                    ctx.config.maps.clone()
                } else {
                    Default::default()
                },
                max_refined_vertices: ctx.config.cpu_max_vertices,
                pipeline: choice,
                ..BuildOptions::default()
            },
        )?;
        let wave = match (animated, built.technique.base_mesh()) {
            (true, Some(m)) => Some(Wave::new(m)),
            _ => None,
        };
        Ok(Self {
            label: if animated {
                format!("{name}-animated")
            } else {
                name.to_string()
            },
            mesh_name: ctx.mesh.name.clone(),
            animated,
            technique: built.technique,
            wave,
            context,
            base_faces: ctx.mesh.input.num_faces(),
            displace: if surface { ctx.config.displace } else { 0.0 },
            reparam: !surface || ctx.config.reparam,
            factors: row_factors(ctx.config, info, mesh),
            spacing: if info.features.spacing(ctx.config.spacing) {
                ctx.config.spacing
            } else {
                crate::tessellator::Spacing::Equal
            },
            surface_note: if surface {
                ctx.config.surface_note()
            } else {
                None
            },
        })
    }

    /// A row of a technique built elsewhere (the benchmark's own comparisons, such as the
    /// seed's Fig. 7), drawn through its own context.
    pub fn from_technique(
        label: &str,
        technique: Box<dyn Technique>,
        context: Context,
        mesh: &BenchMesh,
    ) -> Self {
        Self {
            label: label.to_owned(),
            mesh_name: mesh.name.clone(),
            animated: false,
            technique,
            wave: None,
            context,
            base_faces: mesh.input.num_faces(),
            displace: 0.0,
            reparam: true,
            factors: (super::BenchFactors::Uniform, 1.0),
            spacing: crate::tessellator::Spacing::Equal,
            surface_note: None,
        }
    }

    fn params(&self, segments: u32, camera: Camera) -> FrameParams {
        let (factors, diagonal) = self.factors;
        FrameParams {
            camera,
            displace: self.displace,
            reparam: self.reparam,
            factors: factors.policy(segments as f32, diagonal),
            spacing: self.spacing,
            ..FrameParams::default()
        }
    }

    pub fn label(&self) -> &str {
        &self.label
    }

    pub fn skip_reason(&self, segments: u32) -> Option<String> {
        self.technique
            .check(&self.params(segments, Camera::default()))
            .err()
            .map(|e| e.to_string())
    }

    pub fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let params = self.params(frame.segments, frame.camera);
        let cpu = match (&self.wave, self.animated) {
            (Some(wave), true) => {
                // The viewer's --animate: deform on the CPU, upload only the base positions.
                let start = Instant::now();
                let moved = wave.at(frame.index as f32 / 30.0);
                self.technique.update_base(0, &moved)?;
                Some(start.elapsed().as_secs_f64() * 1e3)
            }
            _ => None,
        };
        self.context
            .write_frame(0, self.technique.bbox(), &params, frame.extent)?;
        self.context
            .prepare(self.technique.as_mut(), &params, &[crate::Pass::Shaded])?;
        Ok(cpu)
    }

    pub fn record_pre_pass<'a>(&'a self, enc: &mut Encoder<'a>, _frame: &BenchFrame) -> Result<()> {
        self.context
            .record_pre_pass(enc, self.technique.as_ref(), 0)
    }

    pub fn record<'a>(&'a self, enc: &mut Encoder<'a>, frame: &BenchFrame) -> Result<u64> {
        let params = self.params(frame.segments, frame.camera);
        let t = self.technique.as_ref();
        self.context
            .record_pass(enc, t, 0, &params, crate::Pass::Shaded)?;
        Ok((0..t.patch_arrays().len())
            .map(|i| t.triangles(&params, i).unwrap_or(0))
            .sum())
    }

    pub fn row_notes(&mut self) -> Vec<String> {
        self.surface_note.iter().cloned().collect()
    }

    pub fn report_notes(&self) -> Vec<String> {
        if self.animated {
            return Vec::new();
        }
        let memory = self.technique.device_memory();
        let parts: Vec<String> = memory
            .iter()
            .map(|a| format!("{} {}", a.name, a.bytes))
            .collect();
        self.technique
            .report_notes()
            .into_iter()
            .chain(std::iter::once(format!(
                "{} device memory {} bytes for {} base faces: {}",
                self.technique.id(),
                memory.iter().map(|a| a.bytes).sum::<u64>(),
                self.base_faces,
                parts.join(", ")
            )))
            .map(|n| format!("{}: {n}", self.mesh_name))
            .collect()
    }

    pub fn statistics_query_safe(&self) -> bool {
        statistics_query_safe(self.context.device(), self.technique.as_ref())
    }

    pub fn triangles_at(&self, segments: u32) -> Option<u64> {
        let params = self.params(segments, Camera::default());
        let t = self.technique.as_ref();
        t.check(&params).ok()?;
        (0..t.patch_arrays().len())
            .map(|i| t.triangles(&params, i))
            .sum()
    }

    pub fn device_bytes(&self) -> Option<u64> {
        Some(self.technique.device_memory().iter().map(|a| a.bytes).sum())
    }
}
