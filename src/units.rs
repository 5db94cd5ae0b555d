//! Unit systems, one grammar for every place that takes one (`pack --units`, `import
//! --units`, scene.txt): `SI` (= `m-kg-s`) or `LENGTH-MASS-TIME` with length
//! `m|cm|mm|um|km`, mass `kg|g|mg|t`, time `s|ms|us`, case-insensitive (`mm-t-s`,
//! `mm-kg-ms`, `MM-T-S`).
//!
//! Every unit of the grammar is a power of ten of the SI one, so a system is three
//! exponents and the value of any derived unit is an exact power of ten (`1e-3`, never
//! `0.0010000000000000002`).

use std::fmt;

/// Length units and their power of ten in metres.
const LENGTHS: [(&str, i32); 5] = [("m", 0), ("cm", -2), ("mm", -3), ("um", -6), ("km", 3)];
/// Mass units and their power of ten in kilograms.
const MASSES: [(&str, i32); 4] = [("kg", 0), ("g", -3), ("mg", -6), ("t", 3)];
/// Time units and their power of ten in seconds.
const TIMES: [(&str, i32); 3] = [("s", 0), ("ms", -3), ("us", -6)];

/// The expected form, for messages.
pub const FORM: &str = "SI, or LENGTH-MASS-TIME with length m|cm|mm|um|km, mass kg|g|mg|t, \
                        time s|ms|us (e.g. m-kg-s, mm-t-s, mm-kg-ms)";

/// A unit system: indices into the length, mass and time tables.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct UnitSystem {
    length: usize,
    mass: usize,
    time: usize,
}

/// A text that is not a unit system of the grammar (see [`FORM`]).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("unknown unit system '{0}': expected {FORM}")]
pub struct UnknownUnits(pub String);

impl UnitSystem {
    /// Metre, kilogram, second.
    pub const SI: UnitSystem = UnitSystem {
        length: 0,
        mass: 0,
        time: 0,
    };

    /// Parse one system: `SI` or `LENGTH-MASS-TIME` (case-insensitive).
    pub fn parse(text: &str) -> Result<UnitSystem, UnknownUnits> {
        let lower = text.trim().to_ascii_lowercase();
        if lower == "si" {
            return Ok(UnitSystem::SI);
        }
        let bad = || UnknownUnits(text.to_string());
        let parts: Vec<&str> = lower.split('-').collect();
        let [l, m, t] = parts[..] else {
            return Err(bad());
        };
        let find = |table: &[(&str, i32)], s: &str| table.iter().position(|u| u.0 == s);
        Ok(UnitSystem {
            length: find(&LENGTHS, l).ok_or_else(bad)?,
            mass: find(&MASSES, m).ok_or_else(bad)?,
            time: find(&TIMES, t).ok_or_else(bad)?,
        })
    }

    /// The name scene.txt and the documentation page show: `SI` for m-kg-s, else
    /// `LENGTH-MASS-TIME`; [`UnitSystem::parse`] reads it back.
    pub fn name(self) -> String {
        if self == UnitSystem::SI {
            "SI".into()
        } else {
            format!(
                "{}-{}-{}",
                self.length_name(),
                MASSES[self.mass].0,
                self.time_name()
            )
        }
    }

    /// The length unit's symbol (`mm`).
    pub fn length_name(self) -> &'static str {
        LENGTHS[self.length].0
    }

    /// The time unit's symbol (`ms`).
    pub fn time_name(self) -> &'static str {
        TIMES[self.time].0
    }

    /// The power of ten, in SI, of this system's unit of dimension
    /// `kg^dims[0] m^dims[1] s^dims[2]`.
    pub fn exponent(self, dims: [i32; 3]) -> i32 {
        dims[0] * MASSES[self.mass].1
            + dims[1] * LENGTHS[self.length].1
            + dims[2] * TIMES[self.time].1
    }

    /// The value in SI of this system's unit of dimension `dims` (see
    /// [`UnitSystem::exponent`]), correctly rounded.
    pub fn factor(self, dims: [i32; 3]) -> f64 {
        power_of_ten(self.exponent(dims))
    }

    /// The force unit: N with an SI prefix when the system's force unit is one (mm-t-s:
    /// N, mm-kg-ms: kN), else the product of the base units (cm-g-s: `g.cm/s2`).
    pub fn force_name(self) -> String {
        self.prefixed([1, 1, -2], "N")
    }

    /// The energy unit: J with an SI prefix when it is one (mm-t-s: mJ), else the
    /// product of the base units (cm-g-s: `g.cm2/s2`).
    pub fn energy_name(self) -> String {
        self.prefixed([1, 2, -2], "J")
    }

    /// `symbol` with the SI prefix of this system's unit of `dims` (a force or an
    /// energy), else that unit spelt in base units.
    fn prefixed(self, dims: [i32; 3], symbol: &str) -> String {
        match prefix(self.exponent(dims)) {
            Some(p) => format!("{p}{symbol}"),
            None => {
                let l = if dims[1] == 1 { "" } else { "2" };
                format!(
                    "{}.{}{l}/{}2",
                    MASSES[self.mass].0,
                    self.length_name(),
                    self.time_name()
                )
            }
        }
    }
}

impl fmt::Display for UnitSystem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.name())
    }
}

/// The SI prefix of `10^e`, if it has one of those this grammar can reach.
fn prefix(e: i32) -> Option<&'static str> {
    Some(match e {
        -9 => "n",
        -6 => "u",
        -3 => "m",
        0 => "",
        3 => "k",
        6 => "M",
        9 => "G",
        _ => return None,
    })
}

/// `10^e`, correctly rounded (the decimal parser rounds once; `powi` may not).
pub fn power_of_ten(e: i32) -> f64 {
    format!("1e{e}").parse().unwrap_or(f64::NAN)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_grammar_accepts_si_and_every_combination_and_reads_its_own_names() {
        for (l, _) in LENGTHS {
            for (m, _) in MASSES {
                for (t, _) in TIMES {
                    let u = UnitSystem::parse(&format!("{l}-{m}-{t}")).unwrap();
                    assert_eq!(UnitSystem::parse(&u.name()), Ok(u));
                }
            }
        }
        assert_eq!(UnitSystem::parse("si"), Ok(UnitSystem::SI));
        assert_eq!(UnitSystem::parse("m-kg-s"), Ok(UnitSystem::SI));
        assert_eq!(UnitSystem::parse("MM-T-S").unwrap().name(), "mm-t-s");
        for bad in ["", "mm-t", "mm-lb-s", "mm-t-s-x", "mm t s", "SI:mm-t-s"] {
            assert_eq!(
                UnitSystem::parse(bad),
                Err(UnknownUnits(bad.into())),
                "{bad}"
            );
        }
    }

    #[test]
    fn derived_units_are_the_textbook_ones() {
        let mmts = UnitSystem::parse("mm-t-s").unwrap();
        let mmkgms = UnitSystem::parse("mm-kg-ms").unwrap();
        let cgs = UnitSystem::parse("cm-g-s").unwrap();
        // mm-t-s: N, mJ (N mm), 1 N = 1 t mm/s^2.
        assert_eq!(
            (mmts.force_name(), mmts.energy_name()),
            ("N".into(), "mJ".into())
        );
        assert_eq!(mmts.factor([1, 1, -2]), 1.0);
        assert_eq!(mmts.factor([1, 2, -2]), 1e-3);
        // mm-kg-ms: kN and J; a stress unit kN/mm^2 = GPa.
        assert_eq!(
            (mmkgms.force_name(), mmkgms.energy_name()),
            ("kN".into(), "J".into())
        );
        assert_eq!(mmkgms.factor([1, -1, -2]), 1e9);
        // cm-g-s: the dyne (1e-5 N) has no prefix of N: named from the base units.
        assert_eq!(cgs.force_name(), "g.cm/s2");
        assert_eq!(cgs.factor([1, 1, -2]), 1e-5);
        assert_eq!(cgs.energy_name(), "g.cm2/s2");
    }
}
