//! Order statistics of frame times: median and nearest-rank percentiles. Medians and p90 resist
//! the occasional slow frame (a page fault, another process) better than means.

/// The median: the middle value, or the mean of the two middle values for an even count.
/// `None` for an empty slice or when a value is NaN.
pub fn median(values: &[f64]) -> Option<f64> {
    let v = sorted(values)?;
    let n = v.len();
    Some(if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    })
}

/// The `p`-th percentile (0 < p ≤ 100) by the nearest-rank method: the smallest value with at
/// least p% of the values at or below it. Always one of the samples, never interpolated.
pub fn percentile(values: &[f64], p: f64) -> Option<f64> {
    if !(p > 0.0 && p <= 100.0) {
        return None;
    }
    let v = sorted(values)?;
    let rank = ((p / 100.0) * v.len() as f64).ceil() as usize;
    Some(v[rank.clamp(1, v.len()) - 1])
}

/// The 90th percentile (nearest rank).
pub fn p90(values: &[f64]) -> Option<f64> {
    percentile(values, 90.0)
}

fn sorted(values: &[f64]) -> Option<Vec<f64>> {
    if values.is_empty() || values.iter().any(|v| v.is_nan()) {
        return None;
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    Some(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn median_odd_even_and_unsorted() {
        assert_eq!(median(&[3.0, 1.0, 2.0]), Some(2.0));
        assert_eq!(median(&[4.0, 1.0, 3.0, 2.0]), Some(2.5));
        assert_eq!(median(&[7.0]), Some(7.0));
        assert_eq!(median(&[]), None);
        assert_eq!(median(&[1.0, f64::NAN]), None);
    }

    #[test]
    fn p90_is_nearest_rank() {
        let v: Vec<f64> = (1..=10).map(f64::from).collect();
        // 90% of 10 values: the 9th smallest.
        assert_eq!(p90(&v), Some(9.0));
        let v: Vec<f64> = (1..=30).rev().map(f64::from).collect();
        // ceil(0.9 · 30) = 27.
        assert_eq!(p90(&v), Some(27.0));
        // ceil(0.9 · 31) = 28.
        let v: Vec<f64> = (1..=31).map(f64::from).collect();
        assert_eq!(p90(&v), Some(28.0));
        assert_eq!(p90(&[5.0]), Some(5.0));
        assert_eq!(p90(&[2.0, 1.0]), Some(2.0));
        assert_eq!(p90(&[]), None);
        assert_eq!(percentile(&[1.0], 0.0), None);
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0], 100.0), Some(4.0));
        assert_eq!(percentile(&[1.0, 2.0, 3.0, 4.0], 50.0), Some(2.0));
    }
}
