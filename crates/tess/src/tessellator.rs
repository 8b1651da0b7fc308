//! The fixed-function tessellator's arithmetic, computed independently on the CPU: how levels
//! are rounded for each spacing and how many vertices a patch emits (Vulkan spec, "Tessellation":
//! triangle and quad tessellation). Used to size draws (driver workaround) and as the oracle of
//! the pipeline-statistics test.

/// Tessellation spacing (the TES's `equal_spacing` / `fractional_*_spacing`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, Default)]
pub enum Spacing {
    #[default]
    Equal,
    FractionalEven,
    FractionalOdd,
}

impl std::str::FromStr for Spacing {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "equal" => Ok(Spacing::Equal),
            "fractional-even" | "fractional_even" => Ok(Spacing::FractionalEven),
            "fractional-odd" | "fractional_odd" => Ok(Spacing::FractionalOdd),
            _ => Err(format!(
                "unknown spacing '{s}' (equal, fractional-even, fractional-odd)"
            )),
        }
    }
}

/// The name `FromStr` reads: `equal`, `fractional-even`, `fractional-odd`.
impl std::fmt::Display for Spacing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Spacing::Equal => "equal",
            Spacing::FractionalEven => "fractional-even",
            Spacing::FractionalOdd => "fractional-odd",
        })
    }
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Domain {
    Triangle,
    Quad,
}

/// The maximum tessellation level the project relies on (the Vulkan minimum of
/// maxTessellationGenerationLevel).
pub const MAX_LEVEL: f32 = 64.0;

impl Spacing {
    /// The integer segment count an edge with `level` gets (the spec's rounding): equal → ceil in
    /// [1, 64]; fractional even → next even in [2, 64]; fractional odd → next odd in [1, 63].
    pub fn segments(self, level: f32) -> u32 {
        let level = if level.is_nan() { 1.0 } else { level };
        match self {
            Spacing::Equal => level.clamp(1.0, MAX_LEVEL).ceil() as u32,
            Spacing::FractionalEven => {
                let n = level.clamp(2.0, MAX_LEVEL).ceil() as u32;
                n + (n % 2)
            }
            Spacing::FractionalOdd => {
                let n = level.clamp(1.0, MAX_LEVEL - 1.0).ceil() as u32;
                n + (1 - n % 2)
            }
        }
    }

    /// Segments of an inner level of 1 that must still split because an outer level exceeds 1.
    fn split_inner_one(self) -> u32 {
        match self {
            Spacing::Equal | Spacing::FractionalEven => 2,
            Spacing::FractionalOdd => 3,
        }
    }
}

/// Vertices one triangle patch emits with outer levels `outer` and inner level `inner`.
pub fn triangle_vertex_count(spacing: Spacing, outer: [f32; 3], inner: f32) -> u64 {
    let e: Vec<u64> = outer.iter().map(|&l| spacing.segments(l) as u64).collect();
    let mut n = spacing.segments(inner);
    if n == 1 {
        if e.iter().all(|&s| s == 1) {
            return 3;
        }
        n = spacing.split_inner_one();
    }
    let mut count: u64 = e.iter().sum();
    let mut s = n as i64 - 2;
    while s > 0 {
        count += 3 * s as u64;
        s -= 2;
    }
    if s == 0 {
        count += 1;
    }
    count
}

/// Vertices one quad patch emits with outer levels `outer` and inner levels `inner`.
pub fn quad_vertex_count(spacing: Spacing, outer: [f32; 4], inner: [f32; 2]) -> u64 {
    let e: Vec<u64> = outer.iter().map(|&l| spacing.segments(l) as u64).collect();
    let mut n0 = spacing.segments(inner[0]);
    let mut n1 = spacing.segments(inner[1]);
    if n0 == 1 && n1 == 1 && e.iter().all(|&s| s == 1) {
        return 4;
    }
    if n0 == 1 {
        n0 = spacing.split_inner_one();
    }
    if n1 == 1 {
        n1 = spacing.split_inner_one();
    }
    let mut count: u64 = e.iter().sum();
    let (mut m0, mut m1) = (n0 as i64 - 2, n1 as i64 - 2);
    while m0 > 0 && m1 > 0 {
        count += 2 * (m0 + m1) as u64;
        m0 -= 2;
        m1 -= 2;
    }
    if m0 == 0 && m1 == 0 {
        count += 1;
    } else if m0 == 0 && m1 > 0 {
        count += m1 as u64 + 1;
    } else if m1 == 0 && m0 > 0 {
        count += m0 as u64 + 1;
    }
    count
}

/// Vertices one patch emits with every level equal to `level`.
pub fn uniform_vertex_count(domain: Domain, spacing: Spacing, level: f32) -> u64 {
    match domain {
        Domain::Triangle => triangle_vertex_count(spacing, [level; 3], level),
        Domain::Quad => quad_vertex_count(spacing, [level; 4], [level; 2]),
    }
}

/// Triangles a tessellated patch emits, from its vertex count `vertices` and the segments on its
/// outer edges `boundary`: the tessellation is a triangulated disc, so Euler's formula gives
/// T = 2V − B − 2. (It holds for every spacing: fractional levels move vertices, not topology.)
fn disc_triangles(vertices: u64, boundary: u64) -> u64 {
    (2 * vertices).saturating_sub(boundary + 2)
}

/// Triangles one triangle patch emits (what transform feedback captures, ÷ 3 corners).
pub fn triangle_triangle_count(spacing: Spacing, outer: [f32; 3], inner: f32) -> u64 {
    let boundary = outer.iter().map(|&l| spacing.segments(l) as u64).sum();
    disc_triangles(triangle_vertex_count(spacing, outer, inner), boundary)
}

/// Triangles one quad patch emits.
pub fn quad_triangle_count(spacing: Spacing, outer: [f32; 4], inner: [f32; 2]) -> u64 {
    let boundary = outer.iter().map(|&l| spacing.segments(l) as u64).sum();
    disc_triangles(quad_vertex_count(spacing, outer, inner), boundary)
}

/// Triangles one patch emits with every level equal to `level`.
pub fn uniform_triangle_count(domain: Domain, spacing: Spacing, level: f32) -> u64 {
    match domain {
        Domain::Triangle => triangle_triangle_count(spacing, [level; 3], level),
        Domain::Quad => quad_triangle_count(spacing, [level; 4], [level; 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A spacing's name reads back as the same spacing.
    #[test]
    fn spacing_names_read_back() {
        for s in [
            Spacing::Equal,
            Spacing::FractionalEven,
            Spacing::FractionalOdd,
        ] {
            assert_eq!(s.to_string().parse::<Spacing>(), Ok(s));
        }
    }

    #[test]
    fn known_counts() {
        assert_eq!(
            uniform_vertex_count(Domain::Triangle, Spacing::Equal, 1.0),
            3
        );
        assert_eq!(
            uniform_vertex_count(Domain::Triangle, Spacing::Equal, 2.0),
            7
        );
        assert_eq!(
            uniform_vertex_count(Domain::Triangle, Spacing::Equal, 3.0),
            12
        );
        assert_eq!(uniform_vertex_count(Domain::Quad, Spacing::Equal, 1.0), 4);
        assert_eq!(uniform_vertex_count(Domain::Quad, Spacing::Equal, 2.0), 9);
        assert_eq!(uniform_vertex_count(Domain::Quad, Spacing::Equal, 4.0), 25);
        // Quads with uniform level n form an (n+1)^2 grid.
        for n in 1..=64u32 {
            assert_eq!(
                uniform_vertex_count(Domain::Quad, Spacing::Equal, n as f32),
                ((n + 1) * (n + 1)) as u64
            );
        }
        // Triangles are concentric rings of 3n, 3(n-2), ... vertices (not a barycentric grid:
        // level 2 has 7 vertices, as the GPU's TES invocation count confirms), closing with a
        // centre point for even n: 3(n/2)(n/2+1)+1 for even n, 3 ceil(n/2)^2 for odd n.
        for n in 1..=64u64 {
            let expected = if n % 2 == 0 {
                3 * (n / 2) * (n / 2 + 1) + 1
            } else {
                3 * n.div_ceil(2).pow(2)
            };
            assert_eq!(
                uniform_vertex_count(Domain::Triangle, Spacing::Equal, n as f32),
                expected,
                "level {n}"
            );
        }
    }

    #[test]
    fn triangle_counts() {
        // Quads: an n × n grid of split squares.
        for n in 1..=64u64 {
            assert_eq!(
                uniform_triangle_count(Domain::Quad, Spacing::Equal, n as f32),
                2 * n * n
            );
        }
        // Triangles: one at level 1; level 2 fans six triangles around the centre; level 3 is
        // a ring of 9 + 3 around one inner triangle.
        let tri = |n: f32| uniform_triangle_count(Domain::Triangle, Spacing::Equal, n);
        assert_eq!((tri(1.0), tri(2.0), tri(3.0)), (1, 6, 13));
        // Each ring of an n-segment triangle holds 3(2n − 2) triangles: 3n outer + 3(n − 2) inner
        // segments, each the base of one triangle.
        for n in 3..=64u64 {
            assert_eq!(
                tri(n as f32),
                tri((n - 2) as f32) + 6 * (n - 1),
                "level {n}"
            );
        }
    }

    #[test]
    fn spacing_rounding() {
        assert_eq!(Spacing::FractionalEven.segments(1.0), 2);
        assert_eq!(Spacing::FractionalEven.segments(2.5), 4);
        assert_eq!(Spacing::FractionalOdd.segments(1.0), 1);
        assert_eq!(Spacing::FractionalOdd.segments(1.5), 3);
        assert_eq!(Spacing::FractionalOdd.segments(64.0), 63);
        assert_eq!(Spacing::Equal.segments(0.2), 1);
        assert_eq!(Spacing::Equal.segments(f32::NAN), 1);
    }
}
