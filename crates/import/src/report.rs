//! What `import` built, dropped and checked: as text for the terminal and as JSON for
//! `--report`. The mass, centre of mass and inertia are printed always, so a user can
//! compare them with the FE code's own mass printout (Nastran's GPWG, for example): a
//! unit or WTMASS slip shows there first.

use std::fmt::Write;

use serde_json::{Value, json};

use super::rigid::MassProps;
use super::scale::Scale;

/// The import's findings; filled in as the pipeline runs.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// Free body (rigid modes written) or blocked.
    pub free: bool,
    /// DOFs (grid and scalar points) after dead-DOF removal.
    pub dofs: usize,
    /// DOFs with mass (the eigenproblem's size).
    pub dofs_with_mass: usize,
    /// Dead DOFs dropped (no stiffness, no mass), as `id.comp`.
    pub dead: Vec<String>,
    /// Massless DOFs condensed out, as `id.comp`.
    pub condensed: Vec<String>,
    /// Non-fatal findings.
    pub warnings: Vec<Warning>,
    /// `|K r| / (|K| |r|)` of the six rigid motions (when coordinates are known).
    pub rigid_residuals: Vec<f64>,
    /// Eigenmodes kept.
    pub kept_modes: usize,
    /// Static modes added for the cut.
    pub static_modes: usize,
    /// Frequencies of the eigenmodes dropped by `--fmax`.
    pub dropped_hz: Vec<f64>,
    /// Eigenfrequencies of the written (K_L, m_L), ascending.
    pub frequencies_hz: Vec<f64>,
    /// Freq written (the largest of `frequencies_hz`).
    pub freq: f64,
    /// Total mass, centre of mass, inertia about it (when coordinates are known).
    pub mass: Option<(f64, [f64; 3], [[f64; 3]; 3])>,
    /// Mean rotary inertia d given to rigid modes 13..15.
    pub rotary: Option<f64>,
    /// `|M_R,naive - M_R| / |M_R|` (Frobenius): how far OpenRadioss's `Phi_R^T M Phi_R`
    /// would be from the rotation-invariant M_R.
    pub naive_m_r_diff: Option<f64>,
    /// How far `Phi_L^T M Phi_L` and the dynamic block of `Phi_L^T K Phi_L` are from the
    /// diagonal m_L and K_L written (from the eigen relations), relative to that diagonal:
    /// round-off, estimated on a few probe vectors (`assemble`).
    pub offdiag: f64,
    /// Nodes written.
    pub nodes: usize,
    /// Irot flag.
    pub irot: bool,
    /// The whole-model route's findings (sparse reduction), when it ran.
    pub whole: Option<crate::whole::WholeReport>,
}

/// A non-fatal finding of the import. Where the advice would name what to give the
/// import, the finding is data and the command words it with its own options; `Display`
/// words it for a library user, naming no option.
#[derive(Debug, Clone, PartialEq)]
pub enum Warning {
    /// A finding that names nothing to give: worded here.
    Text(String),
    /// The lowest eigenvalue is determined only roughly ([`Resolution`]).
    Resolution(Resolution),
}

/// Double precision determines the lowest eigenvalue only to `accuracy` relative
/// ([`crate::modes::resolution_warning`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Resolution {
    /// The lowest eigenvalue over the largest, two digits.
    pub ratio: f64,
    /// `eps / ratio`, two digits: how far double precision guarantees the lowest.
    pub accuracy: f64,
    /// The body was imported as held without coordinates: its six lowest modes may be
    /// the rigid motions of a free body, left slightly stiff by the matrices' rounding.
    pub maybe_free: bool,
}

/// The start of [`Resolution`]'s advice when the body may be free; each wording ends it
/// with what to give.
pub const MAYBE_FREE: &str = "; if the body is free, its six lowest modes may be rigid motions \
                              the rounding left slightly stiff";

impl Resolution {
    /// The finding, without the advice for a body that may be free.
    pub fn finding(&self) -> String {
        format!(
            "the lowest eigenvalue is {} of the largest: double precision guarantees it only \
             to about {} relative (its frequency to half that), and matrices written with \
             fewer digits (a punch's 10) may not determine it at all",
            fxbody::num::num(self.ratio),
            fxbody::num::num(self.accuracy),
        )
    }
}

impl std::fmt::Display for Warning {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Warning::Text(t) => f.write_str(t),
            Warning::Resolution(r) => {
                f.write_str(&r.finding())?;
                if r.maybe_free {
                    write!(
                        f,
                        "{MAYBE_FREE}: give its coordinates and import it as free"
                    )?;
                }
                Ok(())
            }
        }
    }
}

impl Report {
    /// Record the mass properties, computed on M scaled by `scale` (back to the
    /// matrices' units here).
    pub fn mass_properties(&mut self, p: &MassProps, scale: Scale) {
        let i = p.inertia.map(|x| scale.mass_out(x));
        self.mass = Some((
            scale.mass_out(p.mass),
            p.com,
            [
                [i[(0, 0)], i[(0, 1)], i[(0, 2)]],
                [i[(1, 0)], i[(1, 1)], i[(1, 2)]],
                [i[(2, 0)], i[(2, 1)], i[(2, 2)]],
            ],
        ));
    }

    /// The stable step of the explicit reference scheme, `1 / (pi Freq)`.
    pub fn dt_fx(&self) -> f64 {
        1.0 / (std::f64::consts::PI * self.freq)
    }

    /// Human-readable summary, each warning as `worded` words it (the command names its
    /// options; `ToString::to_string` for the library's wording).
    pub fn text(&self, worded: &dyn Fn(&Warning) -> String) -> String {
        let mut o = String::new();
        if let Some(w) = &self.whole {
            let _ = writeln!(
                o,
                "model: {} equations, {} stored terms of K; rigid motions |K r|/(|K||r|) = {:.1e}",
                w.equations, w.nnz, w.rigid_residual
            );
            for c in &w.connections {
                let _ = writeln!(o, "connection: {c}");
            }
            if w.craig_bampton {
                let _ = writeln!(
                    o,
                    "Craig-Bampton: {} fixed-interface modes below {:.6e} Hz and {} \
                     constraint modes (the body's frequencies are the Craig-Bampton model's)",
                    w.model_hz.len(),
                    w.fmax,
                    w.static_modes
                );
                let _ = writeln!(
                    o,
                    "estimated frequency error against the full model, per elastic mode: {}",
                    w.cb_error_estimates
                        .iter()
                        .map(|e| format!("{e:.2e}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                );
            } else {
                let _ = writeln!(
                    o,
                    "kept every mode of the model below {:.6e} Hz: {} (by inertia count; {} \
                 Lanczos block steps), with {} static modes; the body's frequencies below \
                 it equal the model's to {:.1e}{}",
                    w.fmax,
                    w.model_hz.len(),
                    w.lanczos_steps,
                    w.static_modes,
                    w.freq_match,
                    if w.dropped > 0 {
                        format!("; {} dependent basis directions dropped", w.dropped)
                    } else {
                        String::new()
                    }
                );
            }
        }
        let _ = writeln!(
            o,
            "body: {}, {} nodes, Irot {}, {} DOFs ({} with mass)",
            if self.free { "free" } else { "blocked" },
            self.nodes,
            u8::from(self.irot),
            self.dofs,
            self.dofs_with_mass
        );
        if let Some((m, c, i)) = &self.mass {
            let _ = writeln!(o, "mass: {m:.9e}");
            let _ = writeln!(o, "centre of mass: {:.9e} {:.9e} {:.9e}", c[0], c[1], c[2]);
            let _ = writeln!(o, "inertia about the centre of mass:");
            for row in i {
                let _ = writeln!(o, "  {:.9e} {:.9e} {:.9e}", row[0], row[1], row[2]);
            }
        }
        let _ = writeln!(
            o,
            "local modes: {} ({} static, {} eigenmodes){}",
            self.static_modes + self.kept_modes,
            self.static_modes,
            self.kept_modes,
            if self.dropped_hz.is_empty() {
                String::new()
            } else {
                format!(
                    "; {} eigenmodes dropped ({:.6e} to {:.6e} Hz)",
                    self.dropped_hz.len(),
                    self.dropped_hz[0],
                    self.dropped_hz[self.dropped_hz.len() - 1]
                )
            }
        );
        let shown: Vec<String> = self
            .frequencies_hz
            .iter()
            .take(10)
            .map(|f| format!("{f:.6e}"))
            .collect();
        let _ = writeln!(
            o,
            "frequencies (Hz): {}{}",
            shown.join(" "),
            if self.frequencies_hz.len() > 10 {
                " ..."
            } else {
                ""
            }
        );
        let _ = writeln!(
            o,
            "Freq {:.9e} Hz, explicit step dt_fx = 1/(pi Freq) = {:.3e}",
            self.freq,
            self.dt_fx()
        );
        if !self.dead.is_empty() {
            let _ = writeln!(o, "dropped dead DOFs: {}", self.dead.join(" "));
        }
        if !self.condensed.is_empty() {
            let _ = writeln!(
                o,
                "condensed massless DOFs ({}): {}",
                self.condensed.len(),
                self.condensed.join(" ")
            );
        }
        if let Some(d) = self.naive_m_r_diff {
            let _ = writeln!(
                o,
                "M_R from the exact mass properties; the naive Phi_R^T M Phi_R differs by {d:.3e}"
            );
        }
        for w in &self.warnings {
            let _ = writeln!(o, "warning: {}", worded(w));
        }
        o
    }

    /// The JSON report, each warning as `worded` words it (as in [`Report::text`]).
    pub fn json(&self, worded: &dyn Fn(&Warning) -> String) -> Value {
        let warnings: Vec<String> = self.warnings.iter().map(worded).collect();
        let mass = self
            .mass
            .as_ref()
            .map(|(m, c, i)| json!({"total_mass": m, "center_of_mass": c, "inertia": i}));
        json!({
            "free": self.free,
            "irot": self.irot,
            "nodes": self.nodes,
            "dofs": self.dofs,
            "dofs_with_mass": self.dofs_with_mass,
            "mass": mass,
            "rotary_inertia_modes_13_15": self.rotary,
            "local_modes": self.static_modes + self.kept_modes,
            "static_modes": self.static_modes,
            "eigenmodes": self.kept_modes,
            "dropped_hz": self.dropped_hz,
            "frequencies_hz": self.frequencies_hz,
            "freq_hz": self.freq,
            "dt_fx": self.dt_fx(),
            "dead_dofs": self.dead,
            "condensed_dofs": self.condensed,
            "rigid_residuals": self.rigid_residuals,
            "naive_m_r_rel_diff": self.naive_m_r_diff,
            "offdiag_dropped": self.offdiag,
            "warnings": warnings,
            "whole_model": self.whole.as_ref().map(|w| json!({
                "equations": w.equations,
                "nnz_k": w.nnz,
                "fmax_hz": w.fmax,
                "model_hz": w.model_hz,
                "freq_match": w.freq_match,
                "static_modes": w.static_modes,
                "rigid_residual": w.rigid_residual,
                "connections": w.connections,
                "dropped_basis": w.dropped,
                "lanczos_steps": w.lanczos_steps,
                "reduction": if w.craig_bampton { "craig-bampton" } else { "modes" },
                "cb_error_estimates": w.cb_error_estimates,
            })),
        })
    }
}
