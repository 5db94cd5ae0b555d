//! What `pack` tells its user beyond the FMU: notes and warnings as data. The library
//! names no command-line option; the command words each note (crates/cli's pack.rs),
//! naming the options that set the values here.

use std::path::PathBuf;

/// One note of [`super::prepare`], in the order they arise.
#[derive(Debug, Clone, PartialEq)]
pub enum PackNote {
    /// A warning of the body file's reader ([`crate::body::Body::warnings`]).
    Body(String),
    /// No coordinate file: the node coordinates come from the rigid modes, frame origin
    /// L0 at (0, 0, 0).
    CoordsDerived,
    /// The coordinate file's node positions match the rigid modes with the frame origin
    /// L0 placed at `origin`.
    OriginPlaced {
        /// The coordinate file.
        coords: PathBuf,
        /// L0.
        origin: [f64; 3],
    },
    /// Mode truncation `Fmax::Auto` resolved to `hz` = 1/`step`.
    FmaxAuto {
        /// The frequency kept up to, Hz.
        hz: f64,
        /// The DefaultExperiment step it follows, s.
        step: f64,
    },
    /// Warning: the truncation frequency is below the first mode: no mode kept.
    FmaxBelowFirstMode {
        /// The truncation frequency, Hz.
        fmax: f64,
        /// The first mode's frequency, Hz.
        first: f64,
    },
    /// Every mode is below the truncation frequency: all kept, no residual correction.
    FmaxKeepsAll {
        /// The truncation frequency, Hz.
        fmax: f64,
        /// The modes kept (all).
        kept: usize,
    },
    /// `kept` of `total` modes kept, the rest by their static contribution.
    FmaxKeeps {
        /// The truncation frequency, Hz.
        fmax: f64,
        /// The modes kept.
        kept: usize,
        /// The body's modes.
        total: usize,
    },
    /// Warning: no mode moves exposed node `id` of the body file `body`.
    NodeBlocked {
        /// The node.
        id: i64,
        /// The body file.
        body: String,
    },
    /// Warning: the DefaultExperiment takes more than
    /// [`super::experiment::MAX_EXPERIMENT_STEPS`] steps.
    ExperimentTooLong {
        /// Stop time, s.
        stop: f64,
        /// Step, s.
        step: f64,
        /// Steps it takes.
        steps: f64,
        /// Whether the step was given (else derived).
        step_given: bool,
        /// Whether the stop time was given (else derived).
        stop_given: bool,
    },
    /// Warning: the step is below [`super::experiment::MIN_STEP_PER_PERIOD`] of the
    /// lowest mode's period.
    StepTooSmall {
        /// Step, s.
        step: f64,
        /// The lowest mode's frequency, Hz.
        lowest_hz: f64,
        /// Whether the step was given (else derived).
        step_given: bool,
    },
    /// Warning: every node is exposed (none chosen), making more than 1000 variables.
    AllNodesExposed {
        /// Nodes exposed.
        nodes: usize,
        /// Variables they make.
        variables: usize,
    },
}

impl PackNote {
    /// Whether the note is a warning (the user should act) rather than information.
    pub fn is_warning(&self) -> bool {
        matches!(
            self,
            PackNote::Body(_)
                | PackNote::FmaxBelowFirstMode { .. }
                | PackNote::NodeBlocked { .. }
                | PackNote::ExperimentTooLong { .. }
                | PackNote::StepTooSmall { .. }
                | PackNote::AllNodesExposed { .. }
        )
    }
}
