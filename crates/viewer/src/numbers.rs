//! The value parsers of every numeric option: each names its option and the range it takes,
//! so `--segments -1`, `--size -1x5` or `--frames nan` are refused with what the option takes
//! (clap puts the value as written and the option before the message). Numeric options are
//! declared with `allow_hyphen_values`, so a negative number reaches its parser instead of
//! being taken for an option.
use std::fmt::Display;
use std::str::FromStr;

/// A number, any: NaN, infinities and values outside `lo..=hi` are left to the option's own
/// check after parsing (which names the value and the range); text that is no number is
/// refused here with the range the option takes.
pub fn float(s: &str, option: &str, lo: f32, hi: f32) -> Result<f32, String> {
    s.trim()
        .parse()
        .map_err(|_| format!("{option} takes a number from {lo} to {hi}"))
}

/// A whole number of the option's type, any: values outside `lo..=hi` are left to the option's
/// own check after parsing; text that is no such number (a negative one for an unsigned
/// option, a fraction, one beyond the type) is refused here with the range.
pub fn whole<T>(s: &str, option: &str, lo: T, hi: T) -> Result<T, String>
where
    T: FromStr + Display,
{
    s.trim()
        .parse()
        .map_err(|_| format!("{option} takes a whole number from {lo} to {hi}"))
}

/// An f32 option's value as a user would write it, for messages: shortest digits, exponent
/// form when very large or small (`1.8446744e19`, not 20 digits).
pub fn number32(x: f32) -> String {
    if x != 0.0 && x.is_finite() && !(1e-6..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// A finite number in `lo..=hi`.
pub fn float_in(s: &str, option: &str, lo: f32, hi: f32) -> Result<f32, String> {
    let x: Option<f32> = s.trim().parse().ok();
    match x {
        Some(x) if x.is_finite() && (lo..=hi).contains(&x) => Ok(x),
        _ => Err(format!("{option} takes a number from {lo} to {hi}")),
    }
}

/// [`float_in`] in f64.
pub fn float64_in(s: &str, option: &str, lo: f64, hi: f64) -> Result<f64, String> {
    let x: Option<f64> = s.trim().parse().ok();
    match x {
        Some(x) if x.is_finite() && (lo..=hi).contains(&x) => Ok(x),
        _ => Err(format!("{option} takes a number from {lo} to {hi}")),
    }
}

/// A whole number in `lo..=hi`.
pub fn whole_in<T>(s: &str, option: &str, lo: T, hi: T) -> Result<T, String>
where
    T: FromStr + PartialOrd + Display + Copy,
{
    let x: Option<T> = s.trim().parse().ok();
    match x {
        Some(x) if lo <= x && x <= hi => Ok(x),
        _ => Err(format!("{option} takes a whole number from {lo} to {hi}")),
    }
}

/// The most pixels a side of an image or window takes (`--size`).
pub const MAX_SIDE: u32 = 16384;

/// `WIDTHxHEIGHT`, each side 1 to [`MAX_SIDE`].
pub fn size(s: &str) -> Result<(u32, u32), String> {
    let bad = || format!("--size takes WIDTHxHEIGHT, each a whole number from 1 to {MAX_SIDE}");
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(bad)?;
    let side = |t: &str| whole_in(t, "", 1, MAX_SIDE).map_err(|_| bad());
    Ok((side(w)?, side(h)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ranges_are_named_and_bad_numbers_refused() {
        assert_eq!(float_in("0.5", "--x", 0.0, 1.0), Ok(0.5));
        for bad in ["-1", "nan", "inf", "2", "", "x", "1e39"] {
            assert_eq!(
                float_in(bad, "--x", 0.0, 1.0),
                Err("--x takes a number from 0 to 1".into()),
                "{bad}"
            );
        }
        assert_eq!(whole_in("7", "--n", 1u32, 8), Ok(7));
        for bad in ["-1", "0", "9", "1.5", "18446744073709551616", "nan"] {
            assert_eq!(
                whole_in(bad, "--n", 1u32, 8),
                Err("--n takes a whole number from 1 to 8".into()),
                "{bad}"
            );
        }
        assert_eq!(size("160x120"), Ok((160, 120)));
        for bad in ["-1x5", "0x5", "5x16385", "5", "x", "5x-1"] {
            assert!(
                size(bad)
                    .unwrap_err()
                    .starts_with("--size takes WIDTHxHEIGHT"),
                "{bad}"
            );
        }
    }
}
