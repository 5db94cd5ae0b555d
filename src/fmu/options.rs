//! The pack options an FMU carries in `resources/scene.txt`: the model name, the exposed
//! node IDs and the unit system. Written by `fxbody pack`, read back by the FMU at
//! instantiation, so the variables the library serves are the ones the description lists.
//!
//! Format: `key = value` lines, `#` comments, keys `format` (must be 1), `name`, `nodes`
//! (IDs separated by blanks), `units` (absent: no units declared), `fmax` (Hz; absent:
//! no mode truncation).

use std::fmt::Write;

/// A unit system for the declared units (`pack --units NAME`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum UnitSystem {
    /// Metre, kilogram, second: N, m, m/s, J.
    Si,
    /// Millimetre, tonne, second (a common Radioss system): N, mm, mm/s, mJ.
    MmTonneS,
}

impl UnitSystem {
    /// Parse a `--units` name: `SI` or `mm-t-s` (case-insensitive).
    pub fn parse(name: &str) -> Result<UnitSystem, String> {
        match name.to_ascii_lowercase().as_str() {
            "si" => Ok(UnitSystem::Si),
            "mm-t-s" | "mmts" => Ok(UnitSystem::MmTonneS),
            _ => Err(format!(
                "unknown unit system '{name}': expected SI (m, kg, s) or mm-t-s (mm, tonne, s)"
            )),
        }
    }

    /// The name written to scene.txt.
    pub fn name(self) -> &'static str {
        match self {
            UnitSystem::Si => "SI",
            UnitSystem::MmTonneS => "mm-t-s",
        }
    }
}

/// What `fxbody pack` was asked for, after defaults.
#[derive(Debug, Clone, PartialEq)]
pub struct SceneOptions {
    /// Model name (modelName; the modelIdentifier is its C-identifier form).
    pub name: String,
    /// Exposed node IDs, in the order the variables list them.
    pub nodes: Vec<i64>,
    /// Declared units, or none.
    pub units: Option<UnitSystem>,
    /// Keep the modes up to this frequency (Hz) with a static correction for the rest
    /// (`pack --fmax`, [`crate::reduce`]); `None`: all modes.
    pub fmax: Option<f64>,
}

impl SceneOptions {
    /// The modelIdentifier: `name` with every character outside `[A-Za-z0-9_]` replaced
    /// by `_`, prefixed with `_` when it would start with a digit or be empty.
    pub fn model_identifier(&self) -> String {
        let mut id: String = self
            .name
            .chars()
            .map(|c| {
                if c.is_ascii_alphanumeric() || c == '_' {
                    c
                } else {
                    '_'
                }
            })
            .collect();
        if id.is_empty() || id.starts_with(|c: char| c.is_ascii_digit()) {
            id.insert(0, '_');
        }
        id
    }

    /// The scene.txt text.
    pub fn to_text(&self) -> String {
        let mut s = String::from("# fxbody scene options (written by fxbody pack)\nformat = 1\n");
        let _ = writeln!(s, "name = {}", self.name.replace(['\n', '\r'], " "));
        let ids: Vec<String> = self.nodes.iter().map(|n| n.to_string()).collect();
        let _ = writeln!(s, "nodes = {}", ids.join(" "));
        if let Some(u) = self.units {
            let _ = writeln!(s, "units = {}", u.name());
        }
        if let Some(f) = self.fmax {
            let _ = writeln!(s, "fmax = {f:?}");
        }
        s
    }

    /// Read scene.txt text; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<SceneOptions, String> {
        let mut name = None;
        let mut nodes = None;
        let mut units = None;
        let mut format = None;
        let mut fmax = None;
        for (k, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let at = format!("{file}:{}", k + 1);
            let Some((key, value)) = line.split_once('=') else {
                return Err(format!("{at}: expected 'key = value', found '{line}'"));
            };
            let value = value.trim();
            match key.trim() {
                "format" => format = Some(value.to_string()),
                "name" => name = Some(value.to_string()),
                "nodes" => {
                    let ids: Result<Vec<i64>, _> =
                        value.split_whitespace().map(str::parse::<i64>).collect();
                    nodes = Some(ids.map_err(|e| {
                        format!("{at}: nodes: expected integer node IDs, found '{value}' ({e})")
                    })?);
                }
                "units" => {
                    units = Some(UnitSystem::parse(value).map_err(|e| format!("{at}: {e}"))?)
                }
                "fmax" => {
                    let f = value
                        .parse::<f64>()
                        .ok()
                        .filter(|f| f.is_finite() && *f > 0.0);
                    fmax = Some(f.ok_or_else(|| {
                        format!("{at}: fmax: expected a frequency > 0 (Hz), found '{value}'")
                    })?);
                }
                other => return Err(format!("{at}: unknown key '{other}'")),
            }
        }
        if format.as_deref() != Some("1") {
            return Err(format!(
                "{file}: expected 'format = 1', found {}",
                format.map_or("no format line".to_string(), |f| format!("'format = {f}'"))
            ));
        }
        Ok(SceneOptions {
            name: name.ok_or_else(|| format!("{file}: missing 'name = ...'"))?,
            nodes: nodes.ok_or_else(|| format!("{file}: missing 'nodes = ...'"))?,
            units,
            fmax,
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_round_trips_and_identifier_is_a_c_name() {
        let o = SceneOptions {
            name: "9 beam & co".into(),
            nodes: vec![12, -3, 7],
            units: Some(UnitSystem::Si),
            fmax: Some(13.5),
        };
        let back = SceneOptions::parse(&o.to_text(), "scene.txt").unwrap();
        assert_eq!(back, o);
        assert_eq!(o.model_identifier(), "_9_beam___co");
    }

    #[test]
    fn bad_text_is_refused_with_line() {
        let e = SceneOptions::parse("format = 1\nname = a\nnodes = 1 x\n", "s.txt").unwrap_err();
        assert!(e.starts_with("s.txt:3: nodes"), "{e}");
        let e = SceneOptions::parse("format = 2\nname = a\nnodes = 1\n", "s.txt").unwrap_err();
        assert!(e.contains("format = 2"), "{e}");
    }
}
