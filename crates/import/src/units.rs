//! Unit conversion of the matrices and coordinates between two unit systems of the
//! product's grammar ([`fxbody::units::UnitSystem`]: `SI` or `LENGTH-MASS-TIME`, such as
//! `mm-t-s` (N, MPa) or `mm-kg-ms` (kN, GPa)).
//!
//! With `f_L`, `f_m`, `f_T` the factors that turn a FROM quantity into TO units,
//! `f_E = f_m f_L^2 / f_T^2` (energy), and `f_i = f_L` for a translation DOF, 1 for a
//! rotation or a scalar point: `K_ij *= f_E / (f_i f_j)`, `M_ij *= f_m f_L^2 / (f_i f_j)`,
//! coordinates `*= f_L`.

use fxbody::units::{UnitSystem, power_of_ten};

/// Conversion factors from the matrices' units to the body's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Units {
    /// Length factor f_L.
    pub length: f64,
    /// Mass factor f_m.
    pub mass: f64,
    /// Time factor f_T.
    pub time: f64,
}

impl Units {
    /// The factors from `from` to `to`: exact powers of ten (every unit of the grammar is
    /// a power of ten of the SI one), so `1e-3`, never `0.0010000000000000002`.
    pub fn between(from: UnitSystem, to: UnitSystem) -> Units {
        let f = |dims| power_of_ten(from.exponent(dims) - to.exponent(dims));
        Units {
            length: f([0, 1, 0]),
            mass: f([1, 0, 0]),
            time: f([0, 0, 1]),
        }
    }

    /// Energy factor `f_m f_L^2 / f_T^2`.
    pub fn energy(&self) -> f64 {
        self.mass * self.length * self.length / (self.time * self.time)
    }
}

#[cfg(test)]
mod tests {
    use super::{UnitSystem, Units};

    #[test]
    fn mm_t_s_to_mm_kg_ms_scales_k_by_1e_minus_3_and_m_by_1e3() {
        let sys = |s| UnitSystem::parse(s).unwrap();
        let u = Units::between(sys("mm-t-s"), sys("mm-kg-ms"));
        // K_tt: f_E / f_L^2 = f_m / f_T^2 = 1e3 / 1e6 = 1e-3 (N/mm -> kN/mm)
        assert_eq!(u.energy() / (u.length * u.length), 1e-3);
        // M_tt: f_m = 1e3 (t -> kg), exactly
        assert_eq!(u.mass, 1e3);
        assert_eq!(u.length, 1.0);
        assert_eq!(u.time, 1e3);
        // m -> mm: lengths times 1000
        assert_eq!(Units::between(UnitSystem::SI, sys("mm-kg-s")).length, 1e3);
    }
}
