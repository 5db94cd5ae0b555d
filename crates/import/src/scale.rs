//! K and M brought to unit size by exact powers of two before anything is computed, and
//! the refusal of an entry no double-precision eigen-solve can take.
//!
//! Why: every test of the import is relative (a pivot of the unit-diagonal matrix, an
//! eigenvalue against the largest, a residual against `|K| |r|`), but sums of squares
//! and products of a matrix scaled by 1e-300 underflow, and of one scaled by 1e300
//! overflow, long before the ratios do. Multiplying by a power of two is exact, so the
//! import of a model and of the same model scaled by any power of two is the same body
//! bit for bit (scaled back), and by 10^(+-100) the same to round-off. The body is
//! written in the matrices' own units: every output is scaled back.
//!
//! What scaling cannot fix: a model whose diagonal ratios `K_ii / M_ii` (each DOF's own
//! frequency squared, near enough) span more than [`SPREAD_LIMIT`]. Real models span
//! about 1e10 (a 500-element frame: 1e4; a Craig-Bampton model's modal coordinates
//! against its grid DOFs, in mm-t-s: 1e11); an entry 1e300 times too large or too small
//! (a typo, a lost exponent) spans far more, and the eigen-solve then loses every digit
//! of the other modes. It is refused, naming the entry.

use nalgebra::DMatrix;

use super::ImportError;
use super::dofs::Reduced;
use fxbody::num::num;

/// Largest spread of `K_ii / M_ii` over the DOFs with stiffness and mass that an import
/// takes (module text).
pub const SPREAD_LIMIT: f64 = 1e30;

/// The powers of two K and M were multiplied by: internal = 2^exponent x true.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Scale {
    /// Exponent of K's factor.
    pub k: i32,
    /// Exponent of M's factor.
    pub m: i32,
}

/// `x 2^e`, in two steps so that neither factor overflows (exact while the result is a
/// normal number).
pub fn times_pow2(x: f64, e: i32) -> f64 {
    let half = e / 2;
    x * 2f64.powi(half) * 2f64.powi(e - half)
}

impl Scale {
    /// No scaling.
    pub const ONE: Scale = Scale { k: 0, m: 0 };

    /// A true eigenvalue of `K phi = lambda M phi` in internal units.
    pub fn eigenvalue_in(&self, lambda: f64) -> f64 {
        times_pow2(lambda, self.k - self.m)
    }

    /// An internal eigenvalue in true units.
    pub fn eigenvalue_out(&self, lambda: f64) -> f64 {
        times_pow2(lambda, self.m - self.k)
    }

    /// An internal frequency (Hz) in true units.
    pub fn hz_out(&self, f: f64) -> f64 {
        let e = self.m - self.k;
        if e % 2 == 0 {
            times_pow2(f, e / 2)
        } else {
            times_pow2(f, (e - 1) / 2) * std::f64::consts::SQRT_2
        }
    }

    /// An internal mass-type value (m_L, M_R, M_C, inertia) in true units.
    pub fn mass_out(&self, x: f64) -> f64 {
        times_pow2(x, -self.m)
    }

    /// An internal stiffness-type value (K_L, K_C) in true units.
    pub fn stiffness_out(&self, x: f64) -> f64 {
        times_pow2(x, -self.k)
    }
}

/// The exponent e that brings `max_abs 2^e` into [0.5, 1) (0 for zero or non-finite),
/// read from the number's bits (a logarithm rounds near the largest numbers).
fn unit_exponent(max_abs: f64) -> i32 {
    if !(max_abs.is_finite() && max_abs > 0.0) {
        return 0;
    }
    let (x, shift) = if max_abs < f64::MIN_POSITIVE {
        (max_abs * 2f64.powi(64), 64)
    } else {
        (max_abs, 0)
    };
    let biased = ((x.to_bits() >> 52) & 0x7ff) as i32;
    // x = 1.f 2^(biased - 1023) = 0.1f 2^(biased - 1022)
    -(biased - 1022) + shift
}

fn amax(a: &DMatrix<f64>) -> f64 {
    a.iter().fold(0.0f64, |m, v| m.max(v.abs()))
}

/// Scale K and M of `model` to a largest entry in [0.5, 1) by powers of two; returns
/// the exponents (also kept in `model.scale`).
pub fn normalise(model: &mut Reduced) -> Scale {
    let s = Scale {
        k: unit_exponent(amax(&model.k)),
        m: unit_exponent(amax(&model.m)),
    };
    model.k.apply(|x| *x = times_pow2(*x, s.k));
    model.m.apply(|x| *x = times_pow2(*x, s.m));
    model.scale = s;
    s
}

/// Refuse a model whose diagonal ratios `K_ii / M_ii` span more than [`SPREAD_LIMIT`],
/// naming the entry farthest from the others (module text). `k_name`, `m_name` name the
/// matrices. Call before [`normalise`] (the entries are reported as read).
pub fn check_spread(model: &Reduced, k_name: &str, m_name: &str) -> Result<(), ImportError> {
    // log2 of each ratio: no overflow for 1e308 / 1e-320
    let mut ratios: Vec<(f64, usize)> = (0..model.a.len())
        .filter(|&i| model.k[(i, i)] > 0.0 && model.m[(i, i)] > 0.0)
        .map(|i| (model.k[(i, i)].log2() - model.m[(i, i)].log2(), i))
        .collect();
    if ratios.len() < 2 {
        return Ok(());
    }
    ratios.sort_by(|a, b| a.0.total_cmp(&b.0));
    let (lo, hi) = (ratios[0], ratios[ratios.len() - 1]);
    let spread = hi.0 - lo.0;
    if spread <= SPREAD_LIMIT.log2() {
        return Ok(());
    }
    let median = ratios[ratios.len() / 2].0;
    let (outlier, other) = if median - lo.0 > hi.0 - median {
        (lo, hi)
    } else {
        (hi, lo)
    };
    let dof = |i: usize| model.all[model.a[i]];
    let i = outlier.1;
    Err(ImportError::Spread {
        dof: dof(i),
        other: dof(other.1),
        entries: format!(
            "K({d}, {d}) = {} and M({d}, {d}) = {} ({k_name}, {m_name})",
            num(model.k[(i, i)]),
            num(model.m[(i, i)]),
            d = dof(i)
        ),
        spread: format!("1e{}", (spread * std::f64::consts::LOG10_2).round()),
    })
}

#[cfg(test)]
mod tests {
    use super::{times_pow2, unit_exponent};

    /// The factor is an exact power of two that brings the largest entry into [0.5, 1),
    /// from the smallest subnormal to the largest finite number.
    #[test]
    fn unit_exponent_is_exact_and_in_range() {
        for x in [
            1.0,
            3.0,
            1e-300,
            5e-324,
            1e308,
            f64::MAX,
            0.75,
            2.0f64.powi(-1070),
        ] {
            let y = times_pow2(x, unit_exponent(x));
            assert!((0.5..1.0).contains(&y), "{x:e}: {y}");
            assert_eq!(times_pow2(y, -unit_exponent(x)), x, "{x:e}: not exact");
        }
        assert_eq!(unit_exponent(0.0), 0);
        assert_eq!(unit_exponent(f64::INFINITY), 0);
    }
}
