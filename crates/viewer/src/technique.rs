//! The technique options shared by `render`, `view` and `export`, checked against what the
//! chosen technique declares it takes ([`tess::Features`] in [`tess::techniques::registry`]):
//! no per-technique code here, so a new technique needs no change in the viewer.
use crate::numbers::{float, float_in, number32, whole};
use anyhow::{bail, Result};
use clap::Args;
use std::path::Path;
use std::sync::Arc;
use tess::techniques::{
    self, adaptive::DEFAULT_ISOLATION, bft::DEFAULT_TABLE_LEVEL, BuildOptions, TechniqueInfo,
};
use tess::{FactorPolicy, Features, FrameParams, PipelineChoice, Spacing, TechniqueId};
use topology::patches::adaptive::EndCap;

/// The largest `--frame`: the wave's phase keeps f32 precision well past it (its period is 2).
const MAX_FRAME: f32 = 1e6;

// The range of these is checked with the technique after parsing (the message names the
// value); here a value that is no number is refused with the range.
pub fn parse_isolation(s: &str) -> Result<u32, String> {
    whole(s, "--isolation", 1, 8)
}

fn parse_sharpness_scale(s: &str) -> Result<f32, String> {
    float(s, "--sharpness-scale", 0.0, MAX_SHARPNESS_SCALE)
}

fn parse_weld(s: &str) -> Result<f64, String> {
    match s.trim().parse::<f64>() {
        Ok(x) if x.is_finite() && (0.0..=1e6).contains(&x) => Ok(x),
        _ => Err(
            "--weld takes a distance from 0 to 1e6 (model units), or nothing for \
                  identical positions"
                .into(),
        ),
    }
}

pub fn parse_pixels(s: &str) -> Result<f32, String> {
    float(s, "--pixels", 0.5, 16384.0)
}

pub fn parse_distance(s: &str) -> Result<f32, String> {
    float(s, "--distance", 0.0, 1e6)
}

fn parse_table_level(s: &str) -> Result<u32, String> {
    whole(s, "--table-level", 1, 6)
}

fn parse_frame(s: &str) -> Result<f32, String> {
    float(s, "--frame", -MAX_FRAME, MAX_FRAME)
}

pub fn parse_displace(s: &str) -> Result<f32, String> {
    float(s, "--displace", -1000.0, 1000.0)
}

/// `--displace-sine A,F`: amplitude and frequency.
pub fn parse_displace_sine(s: &str) -> Result<[f32; 2], String> {
    let Some((a, f)) = s.split_once(',') else {
        return Err("--displace-sine takes A,F: an amplitude and a frequency".into());
    };
    Ok([
        float_in(a, "--displace-sine's amplitude", -1000.0, 1000.0)?,
        float_in(f, "--displace-sine's frequency", 0.0, 1e6)?,
    ])
}

/// The largest `--sharpness-scale`.
const MAX_SHARPNESS_SCALE: f32 = 1000.0;

pub fn parse_pipeline(s: &str) -> Result<PipelineChoice, String> {
    s.parse()
}

pub fn parse_technique(s: &str) -> Result<TechniqueId, String> {
    s.parse::<TechniqueId>().map_err(|e| e.to_string())
}

/// `--method`'s long help: every technique of the registry with its one line, so the list is
/// never out of date.
pub fn method_long_help() -> String {
    let mut out = String::from(
        "The technique that draws the mesh; by default the limit surface of --scheme \
         (Catmull-Clark unless every face is a triangle, then Loop). One of:",
    );
    for info in techniques::registry() {
        out.push_str(&format!("\n  {:<12} {}", info.id.name(), info.help));
    }
    out
}

/// `bench --methods`'s long help: the registry's techniques, each with an `-animated` row when
/// it animates.
pub fn methods_long_help() -> String {
    let mut out = String::from(
        "Techniques to measure, comma-separated (each draws a row; those that animate also an \
         -animated row that moves the base every frame). Any of:",
    );
    for info in techniques::registry() {
        let animated = if info.features.animation {
            " (+ -animated row)"
        } else {
            ""
        };
        out.push_str(&format!("\n  {}{animated}", info.id.name()));
    }
    out.push_str(
        "\nA method may name its draw path: flat@pattern, pn@tessellation (rows of both paths \
         side by side). Without one it draws as the papers' methods do: through the \
         tessellation stage where the technique and the device have it.",
    );
    out
}

pub fn parse_end_cap(s: &str) -> Result<EndCap, String> {
    match s {
        "gregory" => Ok(EndCap::Gregory),
        "bilinear" => Ok(EndCap::Bilinear),
        _ => Err(format!("unknown end cap '{s}' (gregory, bilinear)")),
    }
}

/// The scheme a mesh is drawn with when `--scheme` is absent: the file's (a USD mesh's
/// `subdivisionScheme`), else Catmull-Clark unless every face is a triangle (then Loop).
pub fn default_scheme(mesh: &topology::ControlMesh) -> topology::Scheme {
    if let Some(scheme) = mesh.scheme {
        return scheme;
    }
    if mesh.faces().all(|f| f.len() == 3) {
        topology::Scheme::Loop
    } else {
        topology::Scheme::CatmullClark
    }
}

/// `--method`, or by default the technique that draws the limit surface of `--scheme` (or of
/// the mesh's default scheme); a scalar-tagged mesh (an ST-mesh) without either is drawn by
/// PN, the technique its tags shape. Any other technique for such a mesh is said on stderr.
pub fn resolve_method(
    method: Option<TechniqueId>,
    scheme: Option<&str>,
    mesh: &topology::ControlMesh,
) -> Result<TechniqueId> {
    let tagged = !mesh.scalar_tags.is_empty();
    let id = match (method, scheme) {
        (None, None) if tagged => TechniqueId::PN,
        _ => method_or_scheme_default(method, scheme, mesh)?,
    };
    if tagged && id != TechniqueId::PN {
        eprintln!("note: scalar tags shape curved PN triangles only (--method pn); {id} draws the mesh without them");
    }
    Ok(id)
}

fn method_or_scheme_default(
    method: Option<TechniqueId>,
    scheme: Option<&str>,
    mesh: &topology::ControlMesh,
) -> Result<TechniqueId> {
    let parsed = scheme
        .map(|s| {
            crate::topo_cmds::parse_scheme(s).map_err(|e| anyhow::anyhow!("--scheme {s}: {e}"))
        })
        .transpose()?;
    // `--scheme doo-sabin --method adaptive`: Doo-Sabin's feature-adaptive limit patches.
    if method == Some(TechniqueId::ADAPTIVE) && parsed == Some(topology::Scheme::DooSabin) {
        return Ok(TechniqueId::DOO_SABIN_LIMIT);
    }
    if let Some(m) = method {
        return Ok(m);
    }
    let scheme = match parsed {
        Some(s) => s,
        // A USD mesh whose scheme is bilinear or none: its faces, drawn flat (quads as
        // bilinear patches).
        None if mesh.scheme == Some(topology::Scheme::Bilinear) => return Ok(TechniqueId::FLAT),
        None => default_scheme(mesh),
    };
    techniques::default_for(scheme)
        .map(|i| i.id)
        .ok_or_else(|| {
            anyhow::anyhow!(
                "--scheme {}: no technique draws its limit surface yet (catmull-clark: --method adaptive, loop: --method bft)",
                scheme_name(scheme)
            )
        })
}

/// How edge factors are chosen (`--factors`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Factors {
    /// `--segments` per base edge.
    Uniform,
    /// Projected edge length over `--pixels`.
    Screen,
    /// Halving each time the eye's distance doubles past `--distance`.
    Distance,
}

pub fn parse_factors(s: &str) -> Result<Factors, String> {
    match s {
        "uniform" => Ok(Factors::Uniform),
        "screen" => Ok(Factors::Screen),
        "distance" => Ok(Factors::Distance),
        _ => Err(format!(
            "unknown factor policy '{s}' (uniform, screen, distance)"
        )),
    }
}

/// Options of the subdivision-surface techniques; techniques that do not take one refuse it.
#[derive(Args, Debug, Clone)]
pub struct SurfaceArgs {
    /// Subdivision scheme whose limit surface is drawn: catmull-clark (--method adaptive),
    /// loop (--method bft; polygons are fan-triangulated first) or doo-sabin (--method
    /// doo-sabin, refined to level log2 S). Defaults to catmull-clark unless every face is a
    /// triangle.
    #[arg(long)]
    pub scheme: Option<String>,
    /// Draw path: tessellation (the tessellation stage), pattern (refinement patterns: a
    /// tessellated domain stored once and instanced over the patches, evaluated in the vertex
    /// stage; every technique that evaluates a patch at a domain point) or auto (where a
    /// technique has both, the one measured faster on the device's driver: patterns on
    /// lavapipe, the tessellation stage elsewhere, and for bft and the planned surfaces, whose
    /// patterns measured slower, the tessellation stage wherever there is one; patterns
    /// without tessellation shaders).
    #[arg(long, default_value = "auto", value_parser = parse_pipeline)]
    pub pipeline: PipelineChoice,
    /// Merge coincident vertices before drawing: `--weld` alone merges vertices at identical
    /// positions, `--weld D` those within distance D (0 to 1e6, model units; chains of near
    /// vertices merge whole). What was merged is reported. Without it the mesh is drawn as
    /// given: a seam written as two rows of vertices stays open.
    #[arg(long, num_args = 0..=1, default_missing_value = "0", value_parser = parse_weld)]
    pub weld: Option<f64>,
    /// Isolation level of feature-adaptive refinement (adaptive): 1 to 8.
    #[arg(long, default_value_t = DEFAULT_ISOLATION, allow_hyphen_values = true, value_parser = parse_isolation)]
    pub isolation: u32,
    /// End caps of faces still irregular at the isolation level (adaptive): gregory or
    /// bilinear.
    #[arg(long, default_value = "gregory", value_parser = parse_end_cap)]
    pub end_cap: EndCap,
    /// Multiplies every crease and corner sharpness (adaptive), without reloading the mesh: 0
    /// to 1000. An infinitely sharp tag (sharpness 10 or more) counts as 10: it stays
    /// infinitely sharp at 1 and above, becomes semi-sharp below 1 (10 × the scale) and smooth
    /// at 0. Boundary edges stay infinitely sharp.
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = parse_sharpness_scale)]
    pub sharpness_scale: f32,
    /// Split each triangle into three quad patches (gregory, acc) instead of one Gregory
    /// triangle patch: closer to the limit, three times the patches.
    #[arg(long)]
    pub split_triangles: bool,
    /// Stop every feature at the isolation level: semi-sharp creases' leftover sharpness is
    /// treated as infinite there and every end cap sits there (adaptive; OpenSubdiv's
    /// behaviour). By default creases are followed until they decay, end caps beside them get
    /// the isolation level's smooth steps after that, and vertices whose caps converge slowly
    /// (cones, darts, valence 6 and up) are isolated deeper, so every cap is as close as the
    /// isolation level promises.
    #[arg(long)]
    pub creases_at_isolation: bool,
    /// Edge factors: uniform (--segments per edge, the default), screen (projected edge length
    /// / --pixels) or distance (halving each time the eye's distance doubles past --distance);
    /// screen and distance for the techniques that take them (bft, adaptive, gregory, acc).
    /// Powers of two, or any value with --fractional; computed from an edge's two endpoints
    /// only, so no cracks. (`--adaptive screen|distance` is the old spelling.)
    #[arg(long = "factors", alias = "adaptive", value_parser = parse_factors)]
    pub factors: Option<Factors>,
    /// --factors screen: target pixels per segment, 0.5 to 16384.
    #[arg(long, default_value_t = 8.0, allow_hyphen_values = true, value_parser = parse_pixels)]
    pub pixels: f32,
    /// --factors distance: eye distance, in bounding-box diagonals, at which an edge gets the
    /// tables' maximum level (above 0, at most 1000000).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true, value_parser = parse_distance)]
    pub distance: f32,
    /// Fractional factors (bft: linear geomorph between the two dyadic levels); the same as
    /// `--spacing fractional-even`.
    #[arg(long)]
    pub fractional: bool,
    /// Maximum table level L (bft): segments per base edge up to 2^(L+1); 1 to 6.
    #[arg(long, default_value_t = DEFAULT_TABLE_LEVEL, allow_hyphen_values = true, value_parser = parse_table_level)]
    pub table_level: u32,
    /// Normals from the surface's derivatives (bft: du × dv from the tangent tables) instead of
    /// its shading normals.
    #[arg(long)]
    pub geometric_normals: bool,
    /// Colour patches by type (bft: regular blue, extraordinary red, boundary green, private
    /// table violet; adaptive, gregory, acc: regular blue, Gregory red, bilinear yellow, Gregory
    /// triangle purple, lighter per level, transition patches darker, boundary and crease
    /// patches greener).
    #[arg(long, alias = "patch-colors")]
    pub patch_colours: bool,
    /// Time T of the --animate wave (base vertices moved along their normals), in seconds:
    /// -1000000 to 1000000.
    #[arg(long, allow_hyphen_values = true, value_parser = parse_frame)]
    pub frame: Option<f32>,
    /// Colour texture (PNG) shown at the mesh's `vt` coordinates (adaptive, gregory, acc).
    #[arg(long, value_name = "PNG")]
    pub texture: Option<std::path::PathBuf>,
    /// How texture coordinates are interpolated (OpenSubdiv's face-varying linear
    /// interpolation, USD's `faceVaryingLinearInterpolation`): none, cornersOnly,
    /// cornersPlus1, cornersPlus2, boundaries or all (bilinear on each face). Default: the
    /// file's (a USD mesh's attribute, cornersPlus1 when unauthored; an OBJ's `t
    /// facevaryinginterpolateboundary` tag, else all). See docs/face-varying.md.
    #[arg(long, value_name = "MODE")]
    pub uv_interpolation: Option<topology::rules::options::FVarLinearInterpolation>,
    /// Displace along the normal by S times the height (the --height map's, else a procedural
    /// bump pattern), seamlessly: shared edges stay bit-identical. -1000 to 1000.
    #[arg(long, value_name = "S", allow_hyphen_values = true, value_parser = parse_displace)]
    pub displace: Option<f32>,
    /// Height map (PNG, luminance in [0, 1]) for --displace.
    #[arg(long, value_name = "PNG")]
    pub height: Option<std::path::PathBuf>,
    /// The refinement-pattern seed's procedural displacement (flat, phong, pn, adaptive,
    /// gregory, acc): each point moves by A·sin(F·|P|) along its unit normal (on a patch edge,
    /// its canonical owner's), on both draw paths. A and F finite, |A| ≤ 1000, 0 ≤ F ≤ 1e6.
    /// Meshes whose OBJ normals differ across an edge open there (flat, phong, pn).
    #[arg(long, value_name = "A,F", allow_hyphen_values = true, value_parser = parse_displace_sine)]
    pub displace_sine: Option<[f32; 2]>,
    /// Texture coordinates at the Gregory patches' own parameter instead of the rational
    /// reparameterization of Schäfer et al. (seed 003, Eq. 3).
    #[arg(long)]
    pub no_reparam: bool,
    /// What to colour the surface by: `param-shift` shows how far the reparameterization moves
    /// the texture parameter (blue 0, red 0.05 of a patch and beyond); `param-error` the
    /// pointwise texture error of Eq. 1 (seed 003's Fig. 8) with or without `--no-reparam`,
    /// over the bbox diagonal on a log scale (blue 1e-5, green 3e-4, yellow 2e-3, red 1e-2),
    /// computed on the CPU for the rest pose when the surface is built.
    #[arg(long, value_name = "VIEW")]
    pub show: Option<String>,
}

/// What a command asks of a technique: how to build it, what each frame shows, and the
/// animation.
#[derive(Clone, Debug)]
pub struct Setup {
    pub technique: TechniqueId,
    pub build: BuildOptions,
    /// Per frame; `--factors distance` is in diagonals here until [`Setup::world_params`].
    pub params: FrameParams,
    /// `--factors distance` in diagonals (turned into world units once the mesh is known).
    pub distance_diagonals: Option<f32>,
    pub animate: bool,
    pub frame: Option<f32>,
}

/// One command-line option a technique may refuse: its name, whether it was given, and which
/// feature takes it.
struct OptionUse {
    name: &'static str,
    given: bool,
    feature: fn(&Features) -> bool,
}

impl SurfaceArgs {
    /// Checks the options against `technique`'s features and builds the setup, in steps: the
    /// scheme, the options the technique refuses, the spacing and ranges, then the frame
    /// parameters. `segments` is the uniform segments per base edge, `spacing` the `--spacing`
    /// option, `params` the shared frame parameters (camera, wireframe, α) to complete.
    pub fn setup(
        &self,
        technique: TechniqueId,
        segments: f32,
        spacing: Spacing,
        animate: bool,
        mut params: FrameParams,
    ) -> Result<Setup> {
        let info = techniques::info(technique);
        let f = info.features;
        self.check_scheme(info)?;
        self.check_refused(&f, technique, animate)?;
        let spacing = if self.fractional {
            Spacing::FractionalEven
        } else {
            spacing
        };
        if !f.spacing(spacing) {
            bail!(
                "--spacing {}: --method {technique} does not take it (--fractional is \
                 fractional-even)",
                spacing_name(spacing)
            );
        }
        self.check_ranges(&f)?;
        check_displacement(self.displace, self.height.as_deref())?;
        params.show = self.show()?;
        params.reparam = !self.no_reparam;
        params.displace = self.displace.unwrap_or(0.0);
        params.displace_sine = self.displace_sine.unwrap_or([0.0, 0.0]);
        let maps = load_maps(
            self.texture.as_deref(),
            self.height.as_deref(),
            params.show == tess::surface::SurfaceShow::ParamError,
        )?;
        params.spacing = spacing;
        params.geometric_normals = self.geometric_normals;
        params.patch_colours = self.patch_colours;
        params.factors = self.factor_policy(segments)?;
        self.check_frame()?;
        Ok(Setup {
            technique,
            build: BuildOptions {
                name: String::new(),
                table_level: self.table_level,
                tangents: self.geometric_normals,
                isolation: self.isolation,
                end_cap: self.end_cap,
                sharpness_scale: self.sharpness_scale,
                follow_semi_sharp: !self.creases_at_isolation,
                split_triangles: self.split_triangles,
                maps,
                pipeline: self.pipeline,
                ..BuildOptions::default()
            },
            params,
            distance_diagonals: (self.factors == Some(Factors::Distance)).then_some(self.distance),
            animate,
            frame: self.frame,
        })
    }

    /// `--scheme`: a technique without a scheme of its own (the base faces as patches) takes
    /// any scheme some technique draws; one with a scheme takes only its own.
    fn check_scheme(&self, info: &TechniqueInfo) -> Result<()> {
        let Some(scheme) = &self.scheme else {
            return Ok(());
        };
        let technique = info.id;
        let wanted = crate::topo_cmds::parse_scheme(scheme)
            .map_err(|e| anyhow::anyhow!("--scheme {scheme}: {e}"))?;
        // A technique without a scheme of its own (the base faces as patches) takes any
        // scheme some technique draws; one with a scheme takes only its own.
        let drawn_by_any = techniques::registry()
            .iter()
            .any(|i| i.scheme == Some(wanted));
        if info.scheme.map_or(!drawn_by_any, |s| s != wanted) {
            let drawn: Vec<String> = techniques::registry()
                .iter()
                .filter_map(|i| {
                    i.scheme
                        .map(|s| format!("{} (--method {})", scheme_name(s), i.id))
                })
                .collect();
            bail!(
                "--scheme {scheme}: --method {technique} does not draw it; limit surfaces \
                 drawn so far: {}",
                drawn.join(", ")
            );
        }
        Ok(())
    }

    /// Each option a technique may refuse: its name, whether it was given, which feature takes
    /// it.
    fn option_uses(&self, animate: bool) -> [OptionUse; 17] {
        [
            OptionUse {
                name: "--factors",
                given: matches!(self.factors, Some(Factors::Screen | Factors::Distance)),
                feature: |f| f.adaptive_factors,
            },
            OptionUse {
                name: "--geometric-normals",
                given: self.geometric_normals,
                feature: |f| f.geometric_normals,
            },
            OptionUse {
                name: "--patch-colours",
                given: self.patch_colours,
                feature: |f| f.patch_colours,
            },
            OptionUse {
                name: "--frame",
                given: self.frame.is_some(),
                feature: |f| f.animation,
            },
            OptionUse {
                name: "--animate",
                given: animate,
                feature: |f| f.animation,
            },
            OptionUse {
                name: "--isolation",
                given: self.isolation != DEFAULT_ISOLATION,
                feature: |f| f.isolation,
            },
            OptionUse {
                name: "--end-cap",
                given: self.end_cap != EndCap::Gregory,
                feature: |f| f.isolation,
            },
            OptionUse {
                name: "--sharpness-scale",
                given: self.sharpness_scale != 1.0,
                feature: |f| f.isolation,
            },
            OptionUse {
                name: "--split-triangles",
                given: self.split_triangles,
                feature: |f| f.single_pass,
            },
            OptionUse {
                name: "--creases-at-isolation",
                given: self.creases_at_isolation,
                feature: |f| f.isolation,
            },
            OptionUse {
                name: "--texture",
                given: self.texture.is_some(),
                feature: |f| f.surface,
            },
            OptionUse {
                name: "--displace",
                given: self.displace.is_some(),
                feature: |f| f.surface,
            },
            OptionUse {
                name: "--displace-sine",
                given: self.displace_sine.is_some(),
                feature: |f| f.sine_displacement,
            },
            OptionUse {
                name: "--height",
                given: self.height.is_some(),
                feature: |f| f.surface,
            },
            OptionUse {
                name: "--no-reparam",
                given: self.no_reparam,
                feature: |f| f.surface,
            },
            OptionUse {
                name: "--show",
                given: self.show.is_some(),
                feature: |f| f.surface,
            },
            OptionUse {
                name: "--table-level",
                given: self.table_level != DEFAULT_TABLE_LEVEL,
                feature: |f| f.table_level,
            },
        ]
    }

    /// Refuses, in one message, every given option `technique`'s features decline, naming the
    /// techniques that take them.
    fn check_refused(&self, f: &Features, technique: TechniqueId, animate: bool) -> Result<()> {
        let uses = self.option_uses(animate);
        let refused: Vec<&OptionUse> = uses.iter().filter(|u| u.given && !(u.feature)(f)).collect();
        if !refused.is_empty() {
            let mut takers: Vec<&str> = Vec::new();
            for u in &refused {
                for n in techniques::names_with(u.feature) {
                    if !takers.contains(&n) {
                        takers.push(n);
                    }
                }
            }
            let names: Vec<&str> = refused.iter().map(|u| u.name).collect();
            bail!(
                "{} only {} to --method {} (not to --method {technique})",
                names.join(", "),
                if names.len() == 1 { "applies" } else { "apply" },
                takers.join(" or --method ")
            );
        }
        Ok(())
    }

    /// The ranges of the options `f` takes: isolation, sharpness scale, table level.
    fn check_ranges(&self, f: &Features) -> Result<()> {
        if f.isolation && !(1..=8).contains(&self.isolation) {
            bail!("--isolation {} is outside 1..8", self.isolation);
        }
        if f.isolation
            && !(self.sharpness_scale.is_finite()
                && (0.0..=MAX_SHARPNESS_SCALE).contains(&self.sharpness_scale))
        {
            bail!(
                "--sharpness-scale {}: give a factor from 0 to {MAX_SHARPNESS_SCALE}",
                number32(self.sharpness_scale)
            );
        }
        if f.table_level && !(1..=6).contains(&self.table_level) {
            bail!("--table-level {} is outside 1..6", self.table_level);
        }
        Ok(())
    }

    /// `--show`.
    fn show(&self) -> Result<tess::surface::SurfaceShow> {
        Ok(match self.show.as_deref() {
            None => tess::surface::SurfaceShow::Shading,
            Some(name) => match tess::surface::SurfaceShow::parse(name) {
                Some(show) => show,
                None => bail!(
                    "--show {name}: expected one of {}",
                    tess::surface::SurfaceShow::NAMES
                ),
            },
        })
    }

    /// `--factors` with `--pixels` or `--distance` (distance in diagonals until
    /// [`Setup::world_params`]), checked.
    fn factor_policy(&self, segments: f32) -> Result<FactorPolicy> {
        let factors = match self.factors {
            None | Some(Factors::Uniform) => FactorPolicy::Uniform { segments },
            Some(Factors::Screen) => FactorPolicy::Screen {
                pixels: self.pixels,
            },
            // Set in world units by `world_params` once the mesh is loaded.
            Some(Factors::Distance) => FactorPolicy::Distance {
                reference: self.distance,
            },
        };
        if let FactorPolicy::Screen { pixels } = factors {
            if !(pixels.is_finite() && (0.5..=16384.0).contains(&pixels)) {
                bail!(
                    "--pixels {}: give 0.5 to 16384 pixels per segment",
                    number32(pixels)
                );
            }
        }
        if let FactorPolicy::Distance { reference } = factors {
            if !(reference.is_finite() && reference > 0.0 && reference <= 1e6) {
                bail!(
                    "--distance {}: give a number of diagonals above 0, at most 1000000",
                    number32(reference)
                );
            }
        }
        Ok(factors)
    }

    /// `--frame`: a finite time within ±MAX_FRAME seconds.
    fn check_frame(&self) -> Result<()> {
        if let Some(t) = self.frame {
            if !(t.is_finite() && t.abs() <= MAX_FRAME) {
                bail!(
                    "--frame {}: give a finite time from -{MAX_FRAME} to {MAX_FRAME} seconds",
                    number32(t)
                );
            }
        }
        Ok(())
    }
}

/// `--displace S` and `--height PNG` as every command that takes them checks them (render,
/// view, export, bench): a finite scale, and a height map only with a scale.
pub fn check_displacement(displace: Option<f32>, height: Option<&Path>) -> Result<()> {
    if let Some(s) = displace {
        if !(s.is_finite() && s.abs() <= 1e3) {
            bail!(
                "--displace {}: give a finite scale from -1000 to 1000",
                number32(s)
            );
        }
    }
    if height.is_some() && displace.is_none() {
        bail!("--height needs --displace S (the scale of the height)");
    }
    Ok(())
}

/// The images of `--texture` and `--height`, read before any device is opened: a file that
/// is missing, not a regular file, too large or not an image is an error naming the option
/// and the file (`--height FILE: 20000x20000 pixels, outside 1..16384 per side`).
pub fn load_maps(
    texture: Option<&Path>,
    height: Option<&Path>,
    param_error: bool,
) -> Result<tess::surface::SurfaceMaps> {
    let load = |option: &str, p: &Path, load: fn(&Path) -> tess::Result<_>| {
        load(p)
            .map(Arc::new)
            .map_err(|e| anyhow::anyhow!("{option} {e}"))
    };
    Ok(tess::surface::SurfaceMaps {
        texture: match texture {
            Some(p) => Some(load("--texture", p, |p| tess::surface::load_texture(p))?),
            None => None,
        },
        height: match height {
            Some(p) => Some(load("--height", p, |p| tess::surface::load_height(p))?),
            None => None,
        },
        param_error,
    })
}

fn scheme_name(s: topology::Scheme) -> &'static str {
    match s {
        topology::Scheme::Loop => "loop",
        topology::Scheme::CatmullClark => "catmull-clark",
        topology::Scheme::DooSabin => "doo-sabin",
        topology::Scheme::Bilinear => "bilinear",
    }
}

fn spacing_name(s: Spacing) -> &'static str {
    match s {
        Spacing::Equal => "equal",
        Spacing::FractionalEven => "fractional-even",
        Spacing::FractionalOdd => "fractional-odd",
    }
}

impl Setup {
    /// The frame parameters with `--distance` in world units of a mesh whose box is `bbox`.
    pub fn world_params(&self, bbox: ([f32; 3], [f32; 3])) -> FrameParams {
        let mut p = self.params;
        if let Some(d) = self.distance_diagonals {
            let diag = glam::Vec3::from(bbox.1).distance(glam::Vec3::from(bbox.0));
            p.factors = FactorPolicy::Distance {
                reference: d * diag.max(1e-6),
            };
        }
        p
    }

    /// Whether the base moves: `--animate`, or a `--frame` of the wave.
    pub fn moved(&self) -> bool {
        self.animate || self.frame.is_some()
    }
}

/// The most uniform segments per base edge any technique takes: flat, Phong and PN on the
/// refinement-pattern path, whose generated patterns reach 256 (BFT at table level 6 draws
/// level-1 faces at tessellation level 64, i.e. 2^(6+1) = 128 per base edge).
pub const MAX_SEGMENTS: f32 = tess::pattern::MAX_GENERATED_SEGMENTS as f32;

/// `--segments` (every command's name for the uniform segments per edge; `--level` is a hidden
/// alias), checked before any device is opened: a finite number of segments from 1 to
/// [`MAX_SEGMENTS`], then what the technique refuses without a device or a mesh (BFT's powers
/// of two up to its table level, adaptive's whole numbers, spacings). What needs the device
/// (flat, phong and pn up to its level, adaptive up to half of it) is checked by the built
/// technique, which names `--segments` too.
pub fn check_segments(setup: &Setup) -> Result<()> {
    if let FactorPolicy::Uniform { segments } = setup.params.factors {
        if !(segments.is_finite() && (1.0..=MAX_SEGMENTS).contains(&segments)) {
            bail!(
                "--segments {}: give a number of segments per edge (the tessellation \
                 level) from 1 to 64 (--method bft: up to 2^(--table-level + 1); flat, phong \
                 and pn on the pattern path: up to 256)",
                number32(segments)
            );
        }
    }
    tess::techniques::check_options(setup.technique, &setup.build, &setup.params)?;
    Ok(())
}

/// A one-line summary of what a frame shows, for messages and the window title.
pub fn describe(technique: TechniqueId, p: &FrameParams) -> String {
    let mut s = format!("{technique}, {}", p.factors);
    if p.spacing != Spacing::Equal {
        s.push_str(&format!(", {} spacing", spacing_name(p.spacing)));
    }
    for (on, what) in [
        (p.geometric_normals, "geometric normals"),
        (p.patch_colours, "patch colours"),
        (p.wireframe, "wireframe"),
    ] {
        if on {
            s.push_str(", ");
            s.push_str(what);
        }
    }
    s
}
