//! Numbers in messages, printed compactly: a user who passed `1e300` reads `1e300` back,
//! not 301 digits. One place, so every message of the product prints numbers alike.

/// `x` as short text: plain notation for moderate magnitudes (`0.25`, `1500`), scientific
/// notation (`1e300`, `6.8e-5`) for very large or very small ones, and the shortest
/// form that reads back to the same `f64` in both cases. NaN and infinities as Rust prints
/// them (`NaN`, `inf`, `-inf`).
pub fn num(x: f64) -> String {
    let a = x.abs();
    if !x.is_finite() || a == 0.0 || (1e-4..1e7).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

/// `n` and a noun with the plural it needs: `count(1, "node")` is `1 node`,
/// `count(2, "node")` is `2 nodes` (regular plurals only), so no message says
/// "1 exposed nodes".
pub fn count(n: usize, noun: &str) -> String {
    if n == 1 {
        format!("1 {noun}")
    } else {
        format!("{n} {noun}s")
    }
}

#[cfg(test)]
mod tests {
    use super::{count, num};

    #[test]
    fn counts_take_the_plural_they_need() {
        assert_eq!(count(1, "exposed node"), "1 exposed node");
        assert_eq!(count(0, "local mode"), "0 local modes");
        assert_eq!(count(21, "node"), "21 nodes");
    }

    #[test]
    fn large_and_small_numbers_are_short_and_read_back_exactly() {
        assert_eq!(num(1e300), "1e300");
        assert_eq!(num(-6.8e-5), "-6.8e-5");
        assert_eq!(num(0.25), "0.25");
        assert_eq!(num(68000.0), "68000");
        assert_eq!(num(0.0), "0");
        assert_eq!(num(f64::NAN), "NaN");
        assert_eq!(num(f64::INFINITY), "inf");
        for x in [1.7976931348623157e308, 4.9e-324, 1.0 / 3.0, 12345678.9] {
            assert_eq!(num(x).parse::<f64>().unwrap().to_bits(), x.to_bits());
            assert!(num(x).len() <= 24, "{}", num(x));
        }
    }
}
