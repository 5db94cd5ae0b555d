//! Unit conversion between Radioss-style unit systems `LENGTH-MASS-TIME`, such as
//! `mm-t-s` (N, MPa) or `mm-kg-ms` (kN, GPa): `--units FROM:TO`.
//!
//! With `f_L`, `f_m`, `f_T` the factors that turn a FROM quantity into TO units,
//! `f_E = f_m f_L^2 / f_T^2` (energy), and `f_i = f_L` for a translation DOF, 1 for a
//! rotation or a scalar point: `K_ij *= f_E / (f_i f_j)`, `M_ij *= f_m f_L^2 / (f_i f_j)`,
//! coordinates `*= f_L`.

use super::ImportError;

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

fn length(s: &str) -> Option<f64> {
    Some(match s {
        "m" => 1.0,
        "cm" => 1e-2,
        "mm" => 1e-3,
        "um" => 1e-6,
        "km" => 1e3,
        _ => return None,
    })
}

fn mass(s: &str) -> Option<f64> {
    Some(match s {
        "kg" => 1.0,
        "g" => 1e-3,
        "mg" => 1e-6,
        "t" => 1e3,
        _ => return None,
    })
}

fn time(s: &str) -> Option<f64> {
    Some(match s {
        "s" => 1.0,
        "ms" => 1e-3,
        "us" => 1e-6,
        _ => return None,
    })
}

/// One system `L-M-T` in SI: (metres, kilograms, seconds) per unit.
fn system(s: &str) -> Result<[f64; 3], ImportError> {
    let parts: Vec<&str> = s.split('-').collect();
    let bad = || ImportError::BadUnits {
        text: s.to_string(),
        expected: "LENGTH-MASS-TIME with length m|cm|mm|um|km, mass kg|g|mg|t, time \
                   s|ms|us (e.g. mm-t-s)",
    };
    if parts.len() != 3 {
        return Err(bad());
    }
    Ok([
        length(parts[0]).ok_or_else(bad)?,
        mass(parts[1]).ok_or_else(bad)?,
        time(parts[2]).ok_or_else(bad)?,
    ])
}

impl Units {
    /// Parse `FROM:TO`, e.g. `mm-t-s:mm-kg-ms`.
    pub fn parse(s: &str) -> Result<Units, ImportError> {
        let (from, to) = s.split_once(':').ok_or_else(|| ImportError::BadUnits {
            text: s.to_string(),
            expected: "FROM:TO (e.g. mm-t-s:m-kg-s)",
        })?;
        let (a, b) = (system(from)?, system(to)?);
        Ok(Units {
            length: a[0] / b[0],
            mass: a[1] / b[1],
            time: a[2] / b[2],
        })
    }

    /// Energy factor `f_m f_L^2 / f_T^2`.
    pub fn energy(&self) -> f64 {
        self.mass * self.length * self.length / (self.time * self.time)
    }
}

#[cfg(test)]
mod tests {
    use super::Units;

    #[test]
    fn mm_t_s_to_mm_kg_ms_scales_k_by_1e_minus_3_and_m_by_1e3() {
        let u = Units::parse("mm-t-s:mm-kg-ms").unwrap();
        // K_tt: f_E / f_L^2 = f_m / f_T^2 = 1e3 / 1e6 = 1e-3 (N/mm -> kN/mm)
        assert!((u.energy() / (u.length * u.length) - 1e-3).abs() < 1e-15);
        // M_tt: f_m = 1e3 (t -> kg)
        assert!((u.mass - 1e3).abs() < 1e-12);
        assert!(Units::parse("mm-t").is_err());
        assert!(Units::parse("mm-lb-s:m-kg-s").is_err());
    }

    /// The library's error carries the text and what was expected, and names no
    /// command-line option (the `fxbody import` command words it with `--units`).
    #[test]
    fn a_bad_unit_system_is_data_not_an_option_name() {
        let e = Units::parse("mm-lb-s:m-kg-s").unwrap_err();
        assert!(
            matches!(&e, super::ImportError::BadUnits { text, .. } if text == "mm-lb-s"),
            "{e:?}"
        );
        let e = Units::parse("mm-t-s").unwrap_err().to_string();
        assert!(
            e.contains("'mm-t-s'") && e.contains("FROM:TO") && !e.contains("--"),
            "{e}"
        );
    }
}
