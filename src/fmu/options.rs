//! The pack options an FMU carries in `resources/scene.txt`: the model name, the exposed
//! node IDs and the unit system. Written by `fxbody pack`, read back by the FMU at
//! instantiation, so the variables the library serves are the ones the description lists.
//!
//! Format: `key = value` lines, `#` comments, keys `format` (must be 1), `name`, `nodes`
//! (IDs separated by blanks), `units` (absent: no units declared), `fmax` (Hz; absent:
//! no mode truncation), `step` and `stop` (s; the DefaultExperiment, absent: derived from
//! the body), `method` (`explicit`, `implicit` or `exact`: the `method` parameter's start
//! value; absent: the body's default), `platforms` (FMI platform names of libraries
//! added besides linux64, separated by blanks) and `interface` (`me` or `both`: the FMU
//! declares Model Exchange too, [`Interfaces`]; absent: co-simulation only).

use std::fmt::Write;

use super::interface::Interfaces;
use super::platforms::{UnknownPlatform, check_platform};
use super::vars::method_name;
use crate::scene::Scene;
use crate::solver::Method;

/// The unit systems of `units` ([`crate::units`]: one grammar for every command).
pub use crate::units::{UnitSystem, UnknownUnits};

/// Why scene.txt was refused; `at` is `file:line`, `file` the file's name.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum OptionsError {
    /// A line that is not `key = value`.
    #[error("{at}: expected 'key = value', found '{line}'")]
    NotKeyValue {
        /// File and line.
        at: String,
        /// The line's text.
        line: String,
    },
    /// `nodes` with something that is not an integer.
    #[error("{at}: nodes: expected integer node IDs, found '{value}' ({source})")]
    Nodes {
        /// File and line.
        at: String,
        /// The value text.
        value: String,
        /// The integer parser's complaint.
        source: std::num::ParseIntError,
    },
    /// `units` naming no known system.
    #[error("{at}: {source}")]
    Units {
        /// File and line.
        at: String,
        /// The unknown name.
        source: UnknownUnits,
    },
    /// `fmax` that is not a finite frequency > 0.
    #[error("{at}: fmax: expected a frequency > 0 (Hz), found '{value}'")]
    Fmax {
        /// File and line.
        at: String,
        /// The value text.
        value: String,
    },
    /// `step` or `stop` that is not a finite time > 0.
    #[error("{at}: {key}: expected a time > 0 (s), found '{value}'")]
    Time {
        /// File and line.
        at: String,
        /// `step` or `stop`.
        key: &'static str,
        /// The value text.
        value: String,
    },
    /// `method` naming no method.
    #[error("{at}: method: expected explicit, implicit, exact or split, found '{value}'")]
    Method {
        /// File and line.
        at: String,
        /// The value text.
        value: String,
    },
    /// `interface` naming no interface.
    #[error("{at}: interface: expected cs, me or both, found '{value}'")]
    Interface {
        /// File and line.
        at: String,
        /// The value text.
        value: String,
    },
    /// `platforms` naming no FMI 2.0 platform.
    #[error("{at}: {source}")]
    Platform {
        /// File and line.
        at: String,
        /// Why.
        source: UnknownPlatform,
    },
    /// A key this version does not know.
    #[error("{at}: unknown key '{key}'")]
    UnknownKey {
        /// File and line.
        at: String,
        /// The key.
        key: String,
    },
    /// No `format = 1` line (absent, or another version).
    #[error("{file}: expected 'format = 1', found {}", .found.as_ref().map_or("no format line".to_string(), |f| format!("'format = {f}'")))]
    Format {
        /// The file.
        file: String,
        /// The format value found, if any.
        found: Option<String>,
    },
    /// A required key is absent.
    #[error("{file}: missing '{key} = ...'")]
    Missing {
        /// The file.
        file: String,
        /// The key.
        key: &'static str,
    },
}

/// What `fxbody pack` was asked for, after defaults.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SceneOptions {
    /// Model name (modelName; the modelIdentifier is its C-identifier form).
    pub name: String,
    /// Exposed node IDs, in the order the variables list them.
    pub nodes: Vec<i64>,
    /// Declared units, or none.
    pub units: Option<UnitSystem>,
    /// Keep the modes up to this frequency (Hz) with a static correction for the rest
    /// (`pack --fmax`, [`crate::scene::reduce`]); `None`: all modes.
    pub fmax: Option<f64>,
    /// DefaultExperiment step size (`pack --step`), s; `None`: derived from the body
    /// ([`super::xml::default_experiment`]).
    pub step: Option<f64>,
    /// DefaultExperiment stop time (`pack --stop`), s; `None`: derived from the body.
    pub stop: Option<f64>,
    /// Start value of the `method` parameter (`pack --method`), for masters that cannot
    /// set parameters; `None`: the body's default ([`super::vars::default_method`]: exact
    /// blocked, split free).
    pub method: Option<Method>,
    /// FMI platforms of libraries added besides linux64 (`pack --binary`).
    pub platforms: Vec<String>,
    /// The interfaces the FMU declares (`pack --interface`).
    pub interface: Interfaces,
}

/// A method by its name (`explicit`, `implicit`, `exact`, `split`: the names of
/// [`super::vars::METHODS`]), as `pack --method` and scene.txt spell it.
pub fn method_by_name(name: &str) -> Option<Method> {
    super::vars::METHODS
        .iter()
        .find(|i| i.name == name)
        .map(|i| i.method)
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

    /// The DefaultExperiment `(stop time, step size)`: `--stop` and `--step` where given,
    /// else derived from the body ([`super::xml::default_experiment`]).
    pub fn experiment(&self, scene: &Scene) -> (f64, f64) {
        let (stop, step) = super::xml::default_experiment(scene);
        (self.stop.unwrap_or(stop), self.step.unwrap_or(step))
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
        if let Some(h) = self.step {
            let _ = writeln!(s, "step = {h:?}");
        }
        if let Some(t) = self.stop {
            let _ = writeln!(s, "stop = {t:?}");
        }
        if let Some(m) = self.method {
            let _ = writeln!(s, "method = {}", method_name(m));
        }
        if !self.platforms.is_empty() {
            let _ = writeln!(s, "platforms = {}", self.platforms.join(" "));
        }
        // Written only when not the default, so that a co-simulation FMU's options (and
        // GUID) are what they were before Model Exchange existed.
        if self.interface != Interfaces::CoSimulation {
            let _ = writeln!(s, "interface = {}", self.interface.name());
        }
        s
    }

    /// Read scene.txt text; `file` names it in messages.
    pub fn parse(text: &str, file: &str) -> Result<SceneOptions, OptionsError> {
        let mut name = None;
        let mut nodes = None;
        let mut units = None;
        let mut format = None;
        let mut fmax = None;
        let (mut step, mut stop, mut method) = (None, None, None);
        let mut platforms = Vec::new();
        let mut interface = Interfaces::CoSimulation;
        for (k, line) in text.lines().enumerate() {
            let line = line.trim();
            if line.is_empty() || line.starts_with('#') {
                continue;
            }
            let at = format!("{file}:{}", k + 1);
            let Some((key, value)) = line.split_once('=') else {
                return Err(OptionsError::NotKeyValue {
                    at,
                    line: line.to_string(),
                });
            };
            let value = value.trim();
            match key.trim() {
                "format" => format = Some(value.to_string()),
                "name" => name = Some(value.to_string()),
                "nodes" => {
                    let ids: Result<Vec<i64>, _> =
                        value.split_whitespace().map(str::parse::<i64>).collect();
                    nodes = Some(ids.map_err(|source| OptionsError::Nodes {
                        at: at.clone(),
                        value: value.to_string(),
                        source,
                    })?);
                }
                "units" => {
                    units = Some(
                        UnitSystem::parse(value)
                            .map_err(|source| OptionsError::Units { at, source })?,
                    )
                }
                "fmax" => {
                    let f = value
                        .parse::<f64>()
                        .ok()
                        .filter(|f| f.is_finite() && *f > 0.0);
                    fmax = Some(f.ok_or_else(|| OptionsError::Fmax {
                        at,
                        value: value.to_string(),
                    })?);
                }
                key @ ("step" | "stop") => {
                    let key = if key == "step" { "step" } else { "stop" };
                    let t = value
                        .parse::<f64>()
                        .ok()
                        .filter(|t| t.is_finite() && *t > 0.0)
                        .ok_or_else(|| OptionsError::Time {
                            at,
                            key,
                            value: value.to_string(),
                        })?;
                    if key == "step" {
                        step = Some(t);
                    } else {
                        stop = Some(t);
                    }
                }
                "method" => {
                    method = Some(method_by_name(value).ok_or_else(|| OptionsError::Method {
                        at,
                        value: value.to_string(),
                    })?);
                }
                "interface" => {
                    interface =
                        Interfaces::parse(value).ok_or_else(|| OptionsError::Interface {
                            at,
                            value: value.to_string(),
                        })?;
                }
                "platforms" => {
                    for p in value.split_whitespace() {
                        check_platform(p).map_err(|source| OptionsError::Platform {
                            at: at.clone(),
                            source,
                        })?;
                        platforms.push(p.to_string());
                    }
                }
                other => {
                    return Err(OptionsError::UnknownKey {
                        at,
                        key: other.to_string(),
                    });
                }
            }
        }
        if format.as_deref() != Some("1") {
            return Err(OptionsError::Format {
                file: file.to_string(),
                found: format,
            });
        }
        Ok(SceneOptions {
            name: name.ok_or_else(|| OptionsError::Missing {
                file: file.to_string(),
                key: "name",
            })?,
            nodes: nodes.ok_or_else(|| OptionsError::Missing {
                file: file.to_string(),
                key: "nodes",
            })?,
            units,
            fmax,
            step,
            stop,
            method,
            platforms,
            interface,
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
            units: Some(UnitSystem::SI),
            fmax: Some(13.5),
            step: Some(5e-4),
            stop: Some(2.0),
            method: Some(Method::Explicit),
            platforms: vec!["win64".into(), "darwin64".into()],
            interface: Interfaces::Both,
        };
        let back = SceneOptions::parse(&o.to_text(), "scene.txt").unwrap();
        assert_eq!(back, o);
        assert_eq!(o.model_identifier(), "_9_beam___co");
    }

    #[test]
    fn bad_text_is_refused_with_line() {
        let e = SceneOptions::parse("format = 1\nname = a\nnodes = 1 x\n", "s.txt")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("s.txt:3: nodes"), "{e}");
        let e = SceneOptions::parse("format = 2\nname = a\nnodes = 1\n", "s.txt")
            .unwrap_err()
            .to_string();
        assert!(e.contains("format = 2"), "{e}");
        for (line, what) in [
            (
                "step = -1",
                "s.txt:4: step: expected a time > 0 (s), found '-1'",
            ),
            (
                "method = fast",
                "s.txt:4: method: expected explicit, implicit, exact or split",
            ),
            (
                "platforms = win64 amiga",
                "s.txt:4: unknown FMI 2.0 platform 'amiga'",
            ),
        ] {
            let e = SceneOptions::parse(
                &format!("format = 1\nname = a\nnodes = 1\n{line}\n"),
                "s.txt",
            )
            .unwrap_err()
            .to_string();
            assert!(e.starts_with(what), "{e}");
        }
    }
}
