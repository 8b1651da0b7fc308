//! Which technique draws the surface, and the options of the Loop basis-function-table one
//! (`--method bft`), shared by `render`, `view` and `export`.
use anyhow::{bail, Result};
use clap::Args;
use tess::bft::{base_normals, base_positions, wave, BftParams, FactorPolicy, DEFAULT_TABLE_LEVEL};
use tess::{Method, Spacing};
use topology::ControlMesh;

/// A technique of the renderer (flat, phong, pn: the base faces as patches) or the Loop limit
/// surface from basis-function tables (Holländer & Boubekeur).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Technique {
    Tessellated(Method),
    Bft,
}

pub fn parse_technique(s: &str) -> Result<Technique, String> {
    match s {
        "bft" => Ok(Technique::Bft),
        _ => s
            .parse::<Method>()
            .map(Technique::Tessellated)
            .map_err(|_| format!("unknown method '{s}' (flat, phong, pn, bft)")),
    }
}

/// Adaptive factor policies of `--method bft`.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Adaptive {
    Screen,
    Distance,
}

fn parse_adaptive(s: &str) -> Result<Adaptive, String> {
    match s {
        "screen" => Ok(Adaptive::Screen),
        "distance" => Ok(Adaptive::Distance),
        _ => Err(format!("unknown adaptive policy '{s}' (screen, distance)")),
    }
}

/// Options of the subdivision-surface techniques (`--method bft`); the others refuse them.
#[derive(Args, Debug, Clone)]
pub struct SurfaceArgs {
    /// Subdivision scheme of `--method bft`: loop (its only scheme, the default). Polygons of
    /// more than three sides are fan-triangulated first.
    #[arg(long)]
    pub scheme: Option<String>,
    /// Adaptive edge factors (bft): screen (projected edge length / --pixels) or distance
    /// (halving each time the eye's distance doubles past --distance). Powers of two, or any
    /// value with --fractional; computed from an edge's two endpoints only, so no cracks.
    #[arg(long, value_parser = parse_adaptive)]
    pub adaptive: Option<Adaptive>,
    /// --adaptive screen: target pixels per segment.
    #[arg(long, default_value_t = 8.0)]
    pub pixels: f32,
    /// --adaptive distance: eye distance, in bounding-box diagonals, at which an edge gets the
    /// tables' maximum level.
    #[arg(long, default_value_t = 1.0)]
    pub distance: f32,
    /// Fractional factors (bft): linear geomorph between the two dyadic levels (same as
    /// `--spacing fractional-even`).
    #[arg(long)]
    pub fractional: bool,
    /// Maximum table level L (bft): segments per base edge up to 2^(L+1).
    #[arg(long, default_value_t = DEFAULT_TABLE_LEVEL)]
    pub table_level: u32,
    /// Normals from the tangent tables (du × dv) instead of subdivision shading (bft).
    #[arg(long)]
    pub geometric_normals: bool,
    /// Colour patches by kind (bft): regular blue, extraordinary red, boundary green, private
    /// table violet.
    #[arg(long, alias = "patch-colors")]
    pub patch_colours: bool,
    /// Time T of the --animate wave (base vertices moved along their normals), in seconds;
    /// needs --method bft.
    #[arg(long, allow_hyphen_values = true)]
    pub frame: Option<f32>,
}

/// Everything `--method bft` needs beyond the shared draw parameters.
#[derive(Clone, Debug)]
pub struct BftSetup {
    pub params: BftParams,
    pub table_level: u32,
    /// `--adaptive distance` in diagonals (turned into world units once the mesh is known).
    pub distance_diagonals: Option<f32>,
    pub frame: Option<f32>,
}

impl SurfaceArgs {
    /// Checks the options against `technique` and builds the BFT setup (None for the other
    /// techniques, which refuse BFT-only options rather than ignore them). `segments` is the
    /// uniform segments per base edge, `spacing` the `--spacing` option.
    pub fn setup(
        &self,
        technique: Technique,
        segments: f32,
        spacing: Spacing,
        animate: bool,
    ) -> Result<Option<BftSetup>> {
        if let Some(scheme) = &self.scheme {
            if scheme != "loop" {
                bail!("--scheme {scheme}: only loop is supported (the bft method evaluates Loop limit surfaces)");
            }
        }
        if technique != Technique::Bft {
            let used: Vec<&str> = [
                (self.adaptive.is_some(), "--adaptive"),
                (self.fractional, "--fractional"),
                (self.geometric_normals, "--geometric-normals"),
                (self.patch_colours, "--patch-colours"),
                (self.frame.is_some(), "--frame"),
                (animate, "--animate"),
                (self.table_level != DEFAULT_TABLE_LEVEL, "--table-level"),
            ]
            .iter()
            .filter(|(on, _)| *on)
            .map(|(_, name)| *name)
            .collect();
            if !used.is_empty() {
                bail!("{} only apply to --method bft", used.join(", "));
            }
            return Ok(None);
        }
        if spacing == Spacing::FractionalOdd {
            bail!("--spacing fractional-odd: bft morphs between dyadic levels, use --fractional (fractional-even)");
        }
        if !(1..=6).contains(&self.table_level) {
            bail!("--table-level {} is outside 1..6", self.table_level);
        }
        let fractional = self.fractional || spacing == Spacing::FractionalEven;
        let factors = match self.adaptive {
            None => {
                if segments.fract() != 0.0 || segments < 1.0 {
                    bail!("--segments {segments}: bft takes whole segments per base edge");
                }
                FactorPolicy::Uniform {
                    segments: segments as u32,
                }
            }
            Some(Adaptive::Screen) => {
                if !(self.pixels.is_finite() && self.pixels >= 0.5) {
                    bail!(
                        "--pixels {}: give at least 0.5 pixels per segment",
                        self.pixels
                    );
                }
                FactorPolicy::Screen {
                    pixels: self.pixels,
                }
            }
            Some(Adaptive::Distance) => {
                if !(self.distance.is_finite() && self.distance > 0.0) {
                    bail!(
                        "--distance {}: give a positive number of diagonals",
                        self.distance
                    );
                }
                // Set in world units by `world_factors` once the mesh is loaded.
                FactorPolicy::Distance {
                    reference: self.distance,
                }
            }
        };
        if let Some(t) = self.frame {
            if !t.is_finite() {
                bail!("--frame {t}: give a finite time");
            }
        }
        Ok(Some(BftSetup {
            params: BftParams {
                factors,
                fractional,
                geometric_normals: self.geometric_normals,
                patch_colours: self.patch_colours,
            },
            table_level: self.table_level,
            distance_diagonals: (self.adaptive == Some(Adaptive::Distance))
                .then_some(self.distance),
            frame: self.frame,
        }))
    }
}

impl BftSetup {
    /// The factors with `--distance` in world units of a mesh whose box is `bbox`.
    pub fn world_params(&self, bbox: ([f32; 3], [f32; 3])) -> BftParams {
        let mut p = self.params;
        if let Some(d) = self.distance_diagonals {
            let diag = glam::Vec3::from(bbox.1).distance(glam::Vec3::from(bbox.0));
            p.factors = FactorPolicy::Distance {
                reference: d * diag.max(1e-6),
            };
        }
        p
    }
}

/// The control mesh Loop subdivides: `mesh` itself when it is all triangles, else its fan
/// triangulation, plus per triangle the face it came from and, when triangulated, a note saying
/// so (for stderr).
pub fn loop_control_mesh(
    mesh: &ControlMesh,
    name: &str,
) -> (ControlMesh, Vec<u32>, Option<String>) {
    let polygons = mesh.faces().filter(|f| f.len() != 3).count();
    if polygons == 0 {
        return (mesh.clone(), (0..mesh.num_faces() as u32).collect(), None);
    }
    let (tri, origin) = mesh.triangulated();
    let note = format!(
        "note: {name}: {polygons} of {} faces are not triangles; Loop subdivides their fan \
         triangulation ({} triangles)",
        mesh.num_faces(),
        tri.num_faces()
    );
    (tri, origin, Some(note))
}

/// The `--animate` wave at time `t` applied to the rest pose of `mesh`: what is uploaded.
pub struct Wave {
    rest: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    bbox: ([f32; 3], [f32; 3]),
}

impl Wave {
    pub fn new(mesh: &ControlMesh) -> Self {
        let rest = base_positions(mesh);
        let bbox = tess::bft::bbox(&rest);
        Self {
            normals: base_normals(mesh),
            rest,
            bbox,
        }
    }

    pub fn at(&self, t: f32) -> Vec<[f32; 3]> {
        wave(&self.rest, &self.normals, self.bbox.0, self.bbox.1, t)
    }
}
