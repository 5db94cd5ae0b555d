//! What differs between FMI 2.0 and FMI 3.0 at the boundary, in one place: the names of
//! states and functions in messages, and the text conventions of FMI 3.0's logger. The
//! instance, the gate (`super::instance::enter_as`: state mask, panic barrier, logging)
//! and the model are shared; an export tells the gate which version it belongs to, and
//! the instance knows which version made it (`super::instance::Instance::version`).
//!
//! Status values need no adapter: FMI 3.0's five are FMI 2.0's first five, the same
//! numbers (checked below), so the gate's status serves both.

use std::borrow::Cow;

use super::fmi3::types::*;
use super::state::FmiState;
use super::types::*;
pub use crate::fmu::fmi_version::FmiVersion;

const _: () = assert!(
    fmi3OK == fmi2OK
        && fmi3Warning == fmi2Warning
        && fmi3Discard == fmi2Discard
        && fmi3Error == fmi2Error
        && fmi3Fatal == fmi2Fatal
);

/// The interface an instance serves (FMI 2.0's fmuType, FMI 3.0's instantiation
/// function). Model Exchange's own states (Event and Continuous-Time Mode) are in
/// `FmiState`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interface {
    /// Co-simulation: fmi2Instantiate(fmi2CoSimulation), fmi3InstantiateCoSimulation.
    CoSimulation,
    /// Model Exchange: fmi2Instantiate(fmi2ModelExchange), fmi3InstantiateModelExchange.
    ModelExchange,
}

impl Interface {
    /// Its name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Interface::CoSimulation => "co-simulation",
            Interface::ModelExchange => "Model Exchange",
        }
    }
}

/// The name of state `s` in the terms of FMI `v`. FMI 3.0 sends an instance whose call
/// failed to Terminated, where reads, the FMU-state functions, Reset and FreeInstance
/// remain: the shared Error state, whose masks allow exactly those.
pub(crate) fn state_name(v: FmiVersion, s: FmiState) -> &'static str {
    use FmiState::*;
    match (v, s) {
        (FmiVersion::Fmi3, StepComplete) => "StepMode",
        (FmiVersion::Fmi3, StepFailed) => "StepDiscarded",
        (FmiVersion::Fmi3, Error) => "Terminated (after an error)",
        (_, Instantiated) => "Instantiated",
        (_, InitializationMode) => "InitializationMode",
        (_, StepComplete) => "StepComplete",
        (_, StepInProgress) => "StepInProgress",
        (_, StepFailed) => "StepFailed",
        (_, StepCanceled) => "StepCanceled",
        (_, Terminated) => "Terminated",
        (_, Error) => "Error",
        (_, Fatal) => "Fatal",
        (_, EventMode) => "EventMode",
        (_, ContinuousTimeMode) => "ContinuousTimeMode",
    }
}

/// FMI 2.0 names that messages of the shared layers use, with the FMI 3.0 name of the
/// same function or status. FMI 3.0 has no counterpart of fmi2SetRealInputDerivatives,
/// whose messages only its own calls raise.
const FMI3_NAMES: [(&str, &str); 20] = [
    ("fmi2DoStep", "fmi3DoStep"),
    ("fmi2EnterInitializationMode", "fmi3EnterInitializationMode"),
    ("fmi2Error", "fmi3Error"),
    ("fmi2ExitInitializationMode", "fmi3ExitInitializationMode"),
    ("fmi2FreeFMUstate", "fmi3FreeFMUState"),
    ("fmi2GetFMUstate", "fmi3GetFMUState"),
    ("fmi2GetInteger", "fmi3GetInt32"),
    ("fmi2GetReal", "fmi3GetFloat64"),
    ("fmi2GetRealOutputDerivatives", "fmi3GetOutputDerivatives"),
    ("fmi2OK", "fmi3OK"),
    ("fmi2Reset", "fmi3Reset"),
    ("fmi2SerializedFMUstateSize", "fmi3SerializedFMUStateSize"),
    ("fmi2SetDebugLogging", "fmi3SetDebugLogging"),
    ("fmi2SetFMUstate", "fmi3SetFMUState"),
    ("fmi2SetInteger", "fmi3SetInt32"),
    ("fmi2SetReal", "fmi3SetFloat64"),
    ("fmi2SetupExperiment", "fmi3EnterInitializationMode"),
    ("fmi2Terminate", "fmi3Terminate"),
    ("fmi2Warning", "fmi3Warning"),
    ("fmi2DeSerializeFMUstate", "fmi3DeserializeFMUState"),
];

/// `text` as an FMI 3.0 logger receives it: with `rename`, FMI 2.0 function and status
/// names of the shared messages replaced by their FMI 3.0 names (whole identifiers
/// only); in any case every
/// `#` doubled, since FMI 3.0 reads `#<valueReference>#` in a message as a variable
/// reference and `##` as one `#`.
pub(crate) fn fmi3_text(text: &str, rename: bool) -> Cow<'_, str> {
    if !(text.contains('#') || (rename && text.contains("fmi2"))) {
        return Cow::Borrowed(text);
    }
    let ident = |c: char| c.is_ascii_alphanumeric() || c == '_';
    let mut out = String::with_capacity(text.len() + 8);
    let mut rest = text;
    while let Some(at) = rest.find(['#', 'f']) {
        out.push_str(&rest[..at]);
        rest = &rest[at..];
        if let Some(after) = rest.strip_prefix('#') {
            out.push_str("##");
            rest = after;
            continue;
        }
        let len = rest.find(|c: char| !ident(c)).unwrap_or(rest.len());
        let word = &rest[..len.max(1)];
        let starts_word = !out.chars().next_back().is_some_and(ident);
        match FMI3_NAMES.iter().find(|(two, _)| *two == word) {
            Some((_, three)) if starts_word && rename => out.push_str(three),
            _ => out.push_str(word),
        }
        rest = &rest[word.len()..];
    }
    out.push_str(rest);
    Cow::Owned(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fmi3_messages_name_fmi3_functions_and_escape_hashes() {
        assert_eq!(
            fmi3_text("method is an Integer: set it with fmi2SetInteger", true),
            "method is an Integer: set it with fmi3SetInt32"
        );
        assert_eq!(
            fmi3_text(
                "rho_inf is a fixed parameter: set it before fmi2ExitInitializationMode",
                true
            ),
            "rho_inf is a fixed parameter: set it before fmi3ExitInitializationMode"
        );
        // Whole identifiers only: a longer 2.0 name without a 3.0 counterpart stays.
        assert_eq!(
            fmi3_text("fmi2SetRealInputDerivatives, fmi2SetReal.", true),
            "fmi2SetRealInputDerivatives, fmi3SetFloat64."
        );
        assert_eq!(fmi3_text("xfmi2SetReal", true), "xfmi2SetReal");
        assert_eq!(
            fmi3_text("instance #1 of 100%s, node ##", true),
            "instance ##1 of 100%s, node ####"
        );
        assert!(matches!(fmi3_text("plain text", true), Cow::Borrowed(_)));
        // Left as written on request, '#' still escaped.
        assert_eq!(fmi3_text("fmi2DoStep on #2", false), "fmi2DoStep on ##2");
        assert!(matches!(fmi3_text("fmi2DoStep", false), Cow::Borrowed(_)));
        // Every entry is an FMI 2.0 name with an FMI 3.0 name.
        for (two, three) in FMI3_NAMES {
            assert!(
                two.starts_with("fmi2") && three.starts_with("fmi3"),
                "{two}"
            );
            assert_eq!(fmi3_text(two, true), three);
        }
    }

    #[test]
    fn state_names_per_version() {
        use FmiState::*;
        assert_eq!(state_name(FmiVersion::Fmi2, StepComplete), "StepComplete");
        assert_eq!(state_name(FmiVersion::Fmi3, StepComplete), "StepMode");
        assert_eq!(state_name(FmiVersion::Fmi3, StepFailed), "StepDiscarded");
        assert_eq!(state_name(FmiVersion::Fmi2, Error), "Error");
        // FMI 2.0's names are the enumeration's own.
        for s in [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepInProgress,
            StepFailed,
            StepCanceled,
            Terminated,
            Error,
            Fatal,
            EventMode,
            ContinuousTimeMode,
        ] {
            assert_eq!(state_name(FmiVersion::Fmi2, s), format!("{s:?}"));
        }
    }
}
