//! The FMI call sequence: the instance states and, per function, the set of states in
//! which it may be called (a bit mask). FMI 2.0 co-simulation state machine, with one
//! project rule on top: after an error only Reset, SetFMUstate and FreeInstance.

/// Where an instance is in the FMI 2.0 co-simulation state machine. The values are bits,
/// so a set of states is a `u16` mask.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[repr(u16)]
pub enum FmiState {
    /// After fmi2Instantiate or fmi2Reset.
    Instantiated = 1,
    /// Between Enter- and ExitInitializationMode.
    InitializationMode = 2,
    /// Ready for a step.
    StepComplete = 4,
    /// An asynchronous step is running (never entered: steps are synchronous).
    StepInProgress = 8,
    /// A step failed with Discard (never entered here).
    StepFailed = 16,
    /// A step was cancelled (never entered here).
    StepCanceled = 32,
    /// After fmi2Terminate.
    Terminated = 64,
    /// After a call returned fmi2Error.
    Error = 128,
    /// After a call returned fmi2Fatal.
    Fatal = 256,
}

impl FmiState {
    /// The bit of this state.
    pub fn bit(self) -> u16 {
        self as u16
    }

    /// A code for saved states (fits a byte).
    pub fn code(self) -> u8 {
        (self as u16).trailing_zeros() as u8
    }

    /// The state with [`FmiState::code`] `c`, if it is one a saved state may hold.
    pub fn from_code(c: u8) -> Option<FmiState> {
        use FmiState::*;
        [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepFailed,
            StepCanceled,
            Terminated,
        ]
        .into_iter()
        .find(|s| s.code() == c)
    }
}

use FmiState::*;

const fn m(states: &[FmiState]) -> u16 {
    let mut mask = 0;
    let mut k = 0;
    while k < states.len() {
        mask |= states[k] as u16;
        k += 1;
    }
    mask
}

/// States where a running or finished simulation can be read.
const READABLE: u16 = m(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
]);
/// States whose full picture can be saved.
const SAVABLE: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    Terminated,
]);
/// Every state but fatal.
const NOT_FATAL: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepInProgress,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
]);

/// fmi2SetDebugLogging.
pub const SET_DEBUG_LOGGING: u16 = SAVABLE;
/// fmi2SetupExperiment.
pub const SETUP_EXPERIMENT: u16 = m(&[Instantiated]);
/// fmi2EnterInitializationMode.
pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
/// fmi2ExitInitializationMode.
pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
/// fmi2Terminate.
pub const TERMINATE: u16 = m(&[StepComplete, StepFailed]);
/// fmi2Reset.
pub const RESET: u16 = NOT_FATAL & !m(&[StepInProgress]);
/// fmi2Get{Real,Integer,Boolean,String}.
pub const GET: u16 = READABLE;
/// fmi2Set{Real,Integer,Boolean,String} (which variables: checked by the model).
pub const SET: u16 = m(&[Instantiated, InitializationMode, StepComplete]);
/// fmi2GetFMUstate, fmi2SerializedFMUstateSize, fmi2SerializeFMUstate.
pub const GET_FMU_STATE: u16 = SAVABLE;
/// fmi2SetFMUstate, fmi2DeSerializeFMUstate, fmi2FreeFMUstate (also from Error).
pub const SET_FMU_STATE: u16 = SAVABLE | m(&[Error]);
/// fmi2GetDirectionalDerivative.
pub const GET_DIRECTIONAL_DERIVATIVE: u16 = READABLE;
/// fmi2SetRealInputDerivatives.
pub const SET_REAL_INPUT_DERIVATIVES: u16 = m(&[Instantiated, InitializationMode, StepComplete]);
/// fmi2GetRealOutputDerivatives.
pub const GET_REAL_OUTPUT_DERIVATIVES: u16 =
    m(&[StepComplete, StepFailed, StepCanceled, Terminated]);
/// fmi2DoStep.
pub const DO_STEP: u16 = m(&[StepComplete]);
/// fmi2CancelStep.
pub const CANCEL_STEP: u16 = m(&[StepInProgress]);
/// fmi2Get*Status.
pub const GET_STATUS: u16 = m(&[
    StepComplete,
    StepInProgress,
    StepFailed,
    StepCanceled,
    Terminated,
]);

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn masks_follow_the_standard_table() {
        let allowed = |mask: u16| -> Vec<FmiState> {
            [
                Instantiated,
                InitializationMode,
                StepComplete,
                StepInProgress,
                StepFailed,
                StepCanceled,
                Terminated,
                Error,
                Fatal,
            ]
            .into_iter()
            .filter(|s| mask & s.bit() != 0)
            .collect()
        };
        assert_eq!(allowed(DO_STEP), vec![StepComplete]);
        assert_eq!(allowed(EXIT_INITIALIZATION_MODE), vec![InitializationMode]);
        assert_eq!(allowed(TERMINATE), vec![StepComplete, StepFailed]);
        // After an error: Reset, SetFMUstate, FreeInstance (free is not masked) only.
        let after_error: Vec<u16> = [
            SET_DEBUG_LOGGING,
            SETUP_EXPERIMENT,
            ENTER_INITIALIZATION_MODE,
            EXIT_INITIALIZATION_MODE,
            TERMINATE,
            GET,
            SET,
            GET_FMU_STATE,
            GET_DIRECTIONAL_DERIVATIVE,
            SET_REAL_INPUT_DERIVATIVES,
            GET_REAL_OUTPUT_DERIVATIVES,
            DO_STEP,
            CANCEL_STEP,
            GET_STATUS,
        ]
        .into_iter()
        .filter(|mask| mask & Error.bit() != 0)
        .collect();
        assert!(after_error.is_empty());
        assert!(RESET & Error.bit() != 0 && SET_FMU_STATE & Error.bit() != 0);
        assert!(RESET & Fatal.bit() == 0);
        for s in [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepFailed,
            StepCanceled,
            Terminated,
        ] {
            assert_eq!(FmiState::from_code(s.code()), Some(s));
        }
        assert_eq!(FmiState::from_code(Error.code()), None);
    }
}
