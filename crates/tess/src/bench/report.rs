//! The report as text: a console table, CSV (which parses back to the same rows) and Markdown
//! with a header saying what was measured, where and how.
use super::{BenchReport, BenchRow, TriangleSource};
use crate::error::{Result, TessError};
use std::fmt::Write as _;

/// The CSV columns, in order.
pub const CSV_HEADER: &str = "mesh,input_triangles,segments,method,triangles,triangles_expected,\
triangles_source,frames,warmup,gpu_median_ms,gpu_p90_ms,cpu_median_ms,cpu_p90_ms,\
total_median_ms,total_p90_ms,wall_median_ms,ratio_to_flat,level,triangle_ratio_to_flat,\
base_faces,device_bytes,note";

/// The columns before `level`, `triangle_ratio_to_flat`, `base_faces` and `device_bytes`
/// existed: [`parse_csv`] still reads such files (those fields then read S, none, 0, none).
pub const CSV_HEADER_V1: &str =
    "mesh,input_triangles,segments,method,triangles,triangles_expected,\
triangles_source,frames,warmup,gpu_median_ms,gpu_p90_ms,cpu_median_ms,cpu_p90_ms,\
total_median_ms,total_p90_ms,wall_median_ms,ratio_to_flat,note";

fn csv_field(s: &str) -> String {
    if s.contains([',', '"', '\n', '\r']) {
        format!("\"{}\"", s.replace('"', "\"\""))
    } else {
        s.to_owned()
    }
}

/// `{}` prints the shortest decimal that parses back to the same `f64`.
fn opt(v: Option<f64>) -> String {
    v.map(|v| v.to_string()).unwrap_or_default()
}

impl BenchReport {
    /// The rows as CSV (header first). Floats are written exactly, so [`parse_csv`] gives the
    /// same rows back.
    pub fn to_csv(&self) -> String {
        let mut out = String::from(CSV_HEADER);
        out.push('\n');
        for r in &self.rows {
            let fields = [
                csv_field(&r.mesh),
                r.input_triangles.to_string(),
                r.segments.to_string(),
                csv_field(&r.method),
                r.triangles.to_string(),
                r.triangles_expected.to_string(),
                r.triangles_source.as_str().to_owned(),
                r.frames.to_string(),
                r.warmup.to_string(),
                r.gpu_median_ms.to_string(),
                r.gpu_p90_ms.to_string(),
                opt(r.cpu_median_ms),
                opt(r.cpu_p90_ms),
                r.total_median_ms.to_string(),
                r.total_p90_ms.to_string(),
                r.wall_median_ms.to_string(),
                opt(r.ratio_to_flat),
                r.level.to_string(),
                opt(r.triangle_ratio_to_flat),
                r.base_faces.to_string(),
                r.device_bytes.map(|b| b.to_string()).unwrap_or_default(),
                csv_field(&r.note),
            ];
            out.push_str(&fields.join(","));
            out.push('\n');
        }
        out
    }

    /// Lines every rendering of the report starts with: device, date, build, setup, notes.
    fn header_lines(&self) -> Vec<String> {
        let d = &self.device;
        let c = &self.config;
        let mut lines = vec![
            format!(
                "Device: {} ({}), driver {} \"{}\", driver version {} (raw 0x{:08x})",
                d.name,
                d.device_type,
                d.driver_name,
                d.driver_info,
                d.driver_version,
                d.driver_version_raw
            ),
            format!("Date: {} UTC", self.date_utc),
            format!("Build profile: {}", self.profile),
            format!(
                "Setup: offscreen {}x{}, default camera (yaw {}°, pitch {}°, zoom {}), {}, \
                 {} timed frames after {} warm-up frames per row (unless a row says otherwise), the \
                 techniques' frames interleaved round robin at each mesh and S; GPU time = timestamps around the frame's work; ratio = total ms / Flat's total ms \
                 at the same mesh and S",
                c.extent.width,
                c.extent.height,
                c.camera.yaw,
                c.camera.pitch,
                c.camera.zoom,
                c.factors.describe(c.spacing),
                c.frames,
                c.warmup
            ),
            "Table memory: Flat, Phong and PN keep no tables (only the control mesh); the CPU \
             baseline keeps the refined mesh on the GPU (size in its rows' notes)"
                .to_owned(),
            "Memory per base face (B/face): bytes of every buffer and texture the method keeps \
             on the device for the mesh, as created (frame uniforms and pipelines excluded), \
             over the faces of the control mesh as loaded. Flat, Phong, PN: the render mesh's \
             vertex buffer (position + normal per render vertex) and patch index buffers; \
             adaptive, gregory, acc: base positions, vertex buffer (refined/local points), \
             stencils, patch records, control points, curves, patch surfaces, \
             reparameterization table, curve and corner owners, colour texture and height map \
             (1x1 each unless given); bft: base positions, tables, patch records, stencils, \
             level-1 vertices and normals; CPU baselines: the refined mesh's vertex and index \
             buffers at the row's level"
                .to_owned(),
        ];
        if c.equal_triangles {
            lines.push(
                "Equal triangles: at each mesh and S, Flat draws S segments per base edge and \
                 every other method the whole level (segments per patch edge for the patch \
                 techniques) whose CPU triangle count is nearest Flat's (lower level on a tie); \
                 column `level` is the level drawn, `tris × Flat` its counted triangles over \
                 Flat's, and × Flat is then a cost at (nearly) equal output triangles"
                    .to_owned(),
            );
        }
        if let Some(surface) = c.surface_note() {
            lines.push(format!(
                "Surface maps on the {} rows (their notes say so; the other methods draw as \
                 always): {surface}",
                crate::techniques::names_with(|f| f.surface).join(", ")
            ));
        }
        lines.extend(self.extra_notes.iter().cloned());
        lines.extend(self.mesh_notes.iter().cloned());
        lines
    }

    /// Loud warnings that belong above any table of this report.
    pub fn warnings(&self) -> Vec<String> {
        let mut w = Vec::new();
        if self.profile != "release" {
            w.push(format!(
                "WARNING: this is a {} build; its timings are not representative. Build with --release.",
                self.profile
            ));
        }
        if self.device.lavapipe {
            w.push(
                "WARNING: lavapipe (llvmpipe) is a CPU rasterizer: absolute times mean nothing \
                 for a GPU, and ratios hold on lavapipe only."
                    .to_owned(),
            );
        }
        w
    }

    fn cells(r: &BenchRow) -> Vec<String> {
        let f = |v: f64| format!("{v:.3}");
        vec![
            r.mesh.clone(),
            r.segments.to_string(),
            r.method.clone(),
            r.triangles.to_string(),
            f(r.gpu_median_ms),
            f(r.gpu_p90_ms),
            r.cpu_median_ms.map(f).unwrap_or_else(|| "—".into()),
            f(r.total_median_ms),
            r.ratio_to_flat
                .map(|x| format!("{x:.2}"))
                .unwrap_or_else(|| "—".into()),
            r.frames.to_string(),
            r.level.to_string(),
            r.triangle_ratio_to_flat
                .map(|x| format!("{x:.3}"))
                .unwrap_or_else(|| "—".into()),
            r.bytes_per_base_face()
                .map(|x| format!("{x:.0}"))
                .unwrap_or_else(|| "—".into()),
        ]
    }

    const COLUMNS: [&'static str; 13] = [
        "mesh",
        "S",
        "method",
        "out triangles",
        "GPU median ms",
        "GPU p90 ms",
        "CPU ms",
        "total ms",
        "× Flat",
        "frames",
        "level",
        "tris × Flat",
        "B/face",
    ];

    /// A console table, aligned, with the header lines and warnings above it.
    pub fn to_text(&self) -> String {
        let mut out = String::new();
        for w in self.warnings() {
            let _ = writeln!(out, "{w}");
        }
        for l in self.header_lines() {
            let _ = writeln!(out, "{l}");
        }
        let rows: Vec<Vec<String>> = self.rows.iter().map(Self::cells).collect();
        let mut width: Vec<usize> = Self::COLUMNS.iter().map(|c| c.chars().count()).collect();
        for r in &rows {
            for (w, c) in width.iter_mut().zip(r) {
                *w = (*w).max(c.chars().count());
            }
        }
        let line = |cells: &[String]| {
            cells
                .iter()
                .zip(&width)
                .enumerate()
                .map(|(i, (c, &w))| {
                    let pad = w - c.chars().count();
                    if i < 3 {
                        format!("{c}{}", " ".repeat(pad))
                    } else {
                        format!("{}{c}", " ".repeat(pad))
                    }
                })
                .collect::<Vec<_>>()
                .join("  ")
        };
        let head: Vec<String> = Self::COLUMNS.iter().map(|s| s.to_string()).collect();
        let _ = writeln!(out, "\n{}", line(&head));
        for (r, cells) in self.rows.iter().zip(&rows) {
            let _ = writeln!(out, "{}", line(cells));
            if !r.note.is_empty() {
                let _ = writeln!(out, "    note: {}", r.note);
            }
        }
        for s in &self.skipped {
            let _ = writeln!(
                out,
                "skipped {} S={} {}: {}",
                s.mesh, s.segments, s.method, s.reason
            );
        }
        out
    }

    /// A Markdown document: title, warnings, header list, the table, notes and skipped rows.
    pub fn to_markdown(&self) -> String {
        let mut out = String::from(
            "# Tessera benchmark: Table I of Holländer & Boubekeur\n\n\
             Generated by `tessera bench`.\n\n",
        );
        for w in self.warnings() {
            let _ = writeln!(out, "> **{w}**\n");
        }
        for l in self.header_lines() {
            let _ = writeln!(out, "- {l}");
        }
        let mut cols: Vec<&str> = Self::COLUMNS.to_vec();
        cols.push("wall ms");
        cols.push("notes");
        let _ = writeln!(out, "\n| {} |", cols.join(" | "));
        let align: Vec<&str> = cols
            .iter()
            .enumerate()
            .map(|(i, _)| {
                if i < 3 || i == cols.len() - 1 {
                    "---"
                } else {
                    "---:"
                }
            })
            .collect();
        let _ = writeln!(out, "| {} |", align.join(" | "));
        for r in &self.rows {
            let mut cells = Self::cells(r);
            cells.push(format!("{:.3}", r.wall_median_ms));
            cells.push(r.note.replace('|', "\\|"));
            let _ = writeln!(out, "| {} |", cells.join(" | "));
        }
        if !self.skipped.is_empty() {
            let _ = writeln!(out, "\nSkipped:\n");
            for s in &self.skipped {
                let _ = writeln!(
                    out,
                    "- {} S={} {}: {}",
                    s.mesh, s.segments, s.method, s.reason
                );
            }
        }
        out
    }
}

/// Splits one CSV line into fields (RFC 4180 quoting; no embedded newlines, which
/// [`BenchReport::to_csv`] never writes unquoted).
fn split_csv_line(line: &str) -> Vec<String> {
    let mut fields = Vec::new();
    let mut cur = String::new();
    let mut quoted = false;
    let mut chars = line.chars().peekable();
    while let Some(ch) = chars.next() {
        match (ch, quoted) {
            ('"', true) if chars.peek() == Some(&'"') => {
                cur.push('"');
                chars.next();
            }
            ('"', true) => quoted = false,
            ('"', false) if cur.is_empty() => quoted = true,
            (',', false) => fields.push(std::mem::take(&mut cur)),
            (c, _) => cur.push(c),
        }
    }
    fields.push(cur);
    fields
}

/// Reads rows back from [`BenchReport::to_csv`]'s output.
pub fn parse_csv(text: &str) -> Result<Vec<BenchRow>> {
    let mut lines = text.lines();
    let header = lines.next().unwrap_or_default();
    let current = header.trim_end() == CSV_HEADER;
    if !current && header.trim_end() != CSV_HEADER_V1 {
        return Err(TessError::Csv {
            line: 1,
            column: "header".into(),
            value: header.to_string(),
        });
    }
    let mut rows = Vec::new();
    for (n, line) in lines.enumerate() {
        if line.trim().is_empty() {
            continue;
        }
        let line_no = n + 2;
        let mut f = split_csv_line(line);
        let fields = if current { 22 } else { 18 };
        if f.len() != fields {
            return Err(TessError::Csv {
                line: line_no,
                column: format!("field count (expected {fields})"),
                value: f.len().to_string(),
            });
        }
        if !current {
            // level (S), triangle ratio, base faces (unknown), device bytes before the note.
            let note = f.pop().unwrap_or_default();
            let s = f[2].clone();
            f.extend([s, String::new(), "0".into(), String::new(), note]);
        }
        let err = |col: &str, v: &str| TessError::Csv {
            line: line_no,
            column: col.into(),
            value: v.into(),
        };
        let int = |i: usize, col: &str| f[i].parse::<u64>().map_err(|_| err(col, &f[i]));
        let num = |i: usize, col: &str| {
            f[i].parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| err(col, &f[i]))
        };
        let opt_num = |i: usize, col: &str| {
            if f[i].is_empty() {
                Ok(None)
            } else {
                num(i, col).map(Some)
            }
        };
        rows.push(BenchRow {
            mesh: f[0].clone(),
            input_triangles: int(1, "input_triangles")?,
            segments: u32::try_from(int(2, "segments")?).map_err(|_| err("segments", &f[2]))?,
            method: f[3].clone(),
            triangles: int(4, "triangles")?,
            triangles_expected: int(5, "triangles_expected")?,
            triangles_source: f[6]
                .parse::<TriangleSource>()
                .map_err(|_| err("triangles_source", &f[6]))?,
            frames: u32::try_from(int(7, "frames")?).map_err(|_| err("frames", &f[7]))?,
            warmup: u32::try_from(int(8, "warmup")?).map_err(|_| err("warmup", &f[8]))?,
            gpu_median_ms: num(9, "gpu_median_ms")?,
            gpu_p90_ms: num(10, "gpu_p90_ms")?,
            cpu_median_ms: opt_num(11, "cpu_median_ms")?,
            cpu_p90_ms: opt_num(12, "cpu_p90_ms")?,
            total_median_ms: num(13, "total_median_ms")?,
            total_p90_ms: num(14, "total_p90_ms")?,
            wall_median_ms: num(15, "wall_median_ms")?,
            ratio_to_flat: opt_num(16, "ratio_to_flat")?,
            level: u32::try_from(int(17, "level")?).map_err(|_| err("level", &f[17]))?,
            triangle_ratio_to_flat: opt_num(18, "triangle_ratio_to_flat")?,
            base_faces: int(19, "base_faces")?,
            device_bytes: if f[20].is_empty() {
                None
            } else {
                Some(int(20, "device_bytes")?)
            },
            note: f[21].clone(),
        });
    }
    Ok(rows)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn csv_fields_with_commas_and_quotes_round_trip() {
        let line = format!(
            "{},{},{}",
            csv_field("a,b"),
            csv_field("say \"hi\""),
            csv_field("plain")
        );
        assert_eq!(split_csv_line(&line), vec!["a,b", "say \"hi\"", "plain"]);
        assert_eq!(split_csv_line("x,,y"), vec!["x", "", "y"]);
    }

    /// A CSV written before the level, triangle-ratio and memory columns still reads.
    #[test]
    fn first_format_csv_reads_with_defaults() {
        let text = format!(
            "{CSV_HEADER_V1}\nspot,372,16,flat,142848,142848,cpu,3,1,1.5,2,,,1.5,2,1.7,1,\"a, b\"\n"
        );
        let rows = parse_csv(&text).unwrap();
        assert_eq!(rows.len(), 1);
        let r = &rows[0];
        assert_eq!((r.segments, r.level, r.base_faces), (16, 16, 0));
        assert_eq!((r.triangle_ratio_to_flat, r.device_bytes), (None, None));
        assert_eq!(r.bytes_per_base_face(), None);
        assert_eq!(r.note, "a, b");
        // A short row is still refused, naming the count the header asks for.
        let e = parse_csv(&format!("{CSV_HEADER_V1}\na,b\n"))
            .unwrap_err()
            .to_string();
        assert!(e.contains("expected 18"), "{e}");
    }

    #[test]
    fn wrong_header_is_an_error() {
        assert!(parse_csv("a,b\n1,2\n").is_err());
        let bad_row = format!("{CSV_HEADER}\nonly,three,fields\n");
        let e = parse_csv(&bad_row).unwrap_err().to_string();
        assert!(e.contains("line 2"), "{e}");
    }
}
