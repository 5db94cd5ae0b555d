//! The FMI call sequence: the instance states and, per function, the set of states in
//! which it may be called (a bit mask), as the FMI 2.0 co-simulation state table
//! (section 4.2.4) and the Model Exchange one (section 3.2.3) give them. The two
//! interfaces' states are distinct bits (a co-simulation instance never enters Event or
//! Continuous-Time Mode, a Model Exchange one never Step Complete), so one mask per
//! function serves both: a co-simulation function called on a Model Exchange instance
//! is illegal in its state, and the other way round. In the Error state the table allows reading (Get of
//! variables, output derivatives, directional derivatives), saving and restoring FMU
//! states, SetDebugLogging, Reset and FreeInstance; not the status queries, not
//! Set, DoStep or Terminate. A read or a save in the Error state answers for the last
//! state before the error ([`crate::fmi::instance::Instance::before_error`]): the model
//! is kept at its last consistent state when a call fails.

/// Where an instance is in the FMI 2.0 co-simulation state machine, or in FMI 3.0's,
/// which names some of the same states otherwise (StepComplete is FMI 3.0's StepMode,
/// StepFailed its StepDiscarded; [`crate::fmi::version`] names them per version) and
/// adds Model Exchange's. The values are bits, so a set of states is a `u16` mask.
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
    /// Event Mode (Model Exchange, or FMI 3.0 co-simulation with event mode; never
    /// entered by a co-simulation instance of this FMU: hasEventMode="false").
    EventMode = 512,
    /// Continuous-Time Mode (Model Exchange only).
    ContinuousTimeMode = 1024,
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
            EventMode,
            ContinuousTimeMode,
        ]
        .into_iter()
        .find(|s| s.code() == c)
    }
}

use FmiState::*;

/// The mask of a set of states.
pub(crate) const fn m(states: &[FmiState]) -> u16 {
    let mut mask = 0;
    let mut k = 0;
    while k < states.len() {
        mask |= states[k] as u16;
        k += 1;
    }
    mask
}

/// States where a running or finished simulation can be read (in Error: if the state
/// before the error is one of the others).
pub const READABLE: u16 = m(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    EventMode,
    ContinuousTimeMode,
    Terminated,
]);
/// States whose full picture can be saved.
const SAVABLE: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    StepCanceled,
    EventMode,
    ContinuousTimeMode,
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
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
]);

/// fmi2SetDebugLogging.
pub const SET_DEBUG_LOGGING: u16 = SAVABLE | m(&[StepInProgress, Error]);
/// fmi2SetupExperiment.
pub const SETUP_EXPERIMENT: u16 = m(&[Instantiated]);
/// fmi2EnterInitializationMode.
pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
/// fmi2ExitInitializationMode.
pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
/// fmi2Terminate.
pub const TERMINATE: u16 = m(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
/// fmi2Reset.
pub const RESET: u16 = NOT_FATAL & !m(&[StepInProgress]);
/// fmi2Get{Real,Integer,Boolean,String} (in Error: the values of the last consistent
/// state).
pub const GET: u16 = READABLE | m(&[Error]);
/// fmi2Set{Real,Integer,Boolean,String} (which variables: checked by the model; in
/// Continuous-Time Mode only inputs, which the model's running phase allows alone).
pub const SET: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    EventMode,
    ContinuousTimeMode,
]);
/// fmi2GetFMUstate, fmi2SerializedFMUstateSize, fmi2SerializeFMUstate (in Error: the
/// saved state records the state before the error, so restoring it lands there).
pub const GET_FMU_STATE: u16 = SAVABLE | m(&[Error]);
/// fmi2SetFMUstate, fmi2DeSerializeFMUstate, fmi2FreeFMUstate (also from Error).
pub const SET_FMU_STATE: u16 = SAVABLE | m(&[Error]);
/// fmi2GetDirectionalDerivative.
pub const GET_DIRECTIONAL_DERIVATIVE: u16 = READABLE | m(&[Error]);
/// fmi2SetRealInputDerivatives.
pub const SET_REAL_INPUT_DERIVATIVES: u16 = m(&[Instantiated, InitializationMode, StepComplete]);
/// fmi2GetRealOutputDerivatives.
pub const GET_REAL_OUTPUT_DERIVATIVES: u16 =
    m(&[StepComplete, StepFailed, StepCanceled, Terminated, Error]);
/// fmi2DoStep.
pub const DO_STEP: u16 = m(&[StepComplete]);
/// fmi2CancelStep.
pub const CANCEL_STEP: u16 = m(&[StepInProgress]);
/// fmi2Get*Status. Also in Error, as issue 13 reads the FMI 2.0 table: the Reference
/// FMUs leave Error out of this mask, but a status query reads and changes nothing, and
/// after a refused step a master may ask fmi2LastSuccessfulTime (the time before the
/// refused step, where the instance still stands).
pub const GET_STATUS: u16 = m(&[
    StepComplete,
    StepInProgress,
    StepFailed,
    StepCanceled,
    Terminated,
    Error,
]);

/// fmi2EnterEventMode.
pub const ENTER_EVENT_MODE: u16 = m(&[EventMode, ContinuousTimeMode]);
/// fmi2NewDiscreteStates.
pub const NEW_DISCRETE_STATES: u16 = m(&[EventMode]);
/// fmi2EnterContinuousTimeMode.
pub const ENTER_CONTINUOUS_TIME_MODE: u16 = m(&[EventMode]);
/// fmi2CompletedIntegratorStep.
pub const COMPLETED_INTEGRATOR_STEP: u16 = m(&[ContinuousTimeMode]);
/// fmi2SetTime.
pub const SET_TIME: u16 = m(&[EventMode, ContinuousTimeMode]);
/// fmi2SetContinuousStates.
pub const SET_CONTINUOUS_STATES: u16 = m(&[ContinuousTimeMode]);
/// fmi2GetDerivatives, fmi2GetEventIndicators, fmi2GetContinuousStates (also in
/// initialisation mode: the derivatives are initial unknowns).
pub const GET_CONTINUOUS: u16 = m(&[
    InitializationMode,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
]);
/// fmi2GetNominalsOfContinuousStates (also right after instantiation).
pub const GET_NOMINALS: u16 = GET_CONTINUOUS | m(&[Instantiated]);

/// Test support: each function's mask against its row of a state table written out from
/// the standard (`x`: allowed in the state of that column of `order`, `.`: not), so the
/// FMI 2.0 co-simulation, 2.0 Model Exchange and 3.0 tables are checked the one way.
#[cfg(test)]
pub(crate) fn assert_table(order: &[FmiState], table: &[(&str, u16, &str)]) {
    for &(name, mask, row) in table {
        assert_eq!(row.len(), order.len(), "{name}: one column per state");
        let want: Vec<bool> = row.chars().map(|c| c == 'x').collect();
        let got: Vec<bool> = order.iter().map(|s| mask & s.bit() != 0).collect();
        assert_eq!(got, want, "{name}");
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FMI 2.0 co-simulation state table (section 4.2.4), written out per function
    /// from the standard rather than from the masks above. Columns, in order:
    /// instantiated, initializationMode, stepComplete, stepInProgress, stepFailed,
    /// stepCanceled, terminated, error, fatal.
    #[test]
    fn masks_follow_the_standard_table() {
        const ORDER: [FmiState; 9] = [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepInProgress,
            StepFailed,
            StepCanceled,
            Terminated,
            Error,
            Fatal,
        ];
        let table: [(&str, u16, &str); 14] = [
            ("fmi2SetDebugLogging", SET_DEBUG_LOGGING, "xxxxxxxx."),
            ("fmi2SetupExperiment", SETUP_EXPERIMENT, "x........"),
            (
                "fmi2EnterInitializationMode",
                ENTER_INITIALIZATION_MODE,
                "x........",
            ),
            (
                "fmi2ExitInitializationMode",
                EXIT_INITIALIZATION_MODE,
                ".x.......",
            ),
            ("fmi2Terminate", TERMINATE, "..x.x...."),
            ("fmi2Reset", RESET, "xxx.xxxx."),
            ("fmi2GetReal", GET, ".xx.xxxx."),
            ("fmi2SetReal", SET, "xxx......"),
            ("fmi2GetFMUstate", GET_FMU_STATE, "xxx.xxxx."),
            (
                "fmi2GetDirectionalDerivative",
                GET_DIRECTIONAL_DERIVATIVE,
                ".xx.xxxx.",
            ),
            (
                "fmi2SetRealInputDerivatives",
                SET_REAL_INPUT_DERIVATIVES,
                "xxx......",
            ),
            (
                "fmi2GetRealOutputDerivatives",
                GET_REAL_OUTPUT_DERIVATIVES,
                "..x.xxxx.",
            ),
            ("fmi2DoStep", DO_STEP, "..x......"),
            ("fmi2CancelStep", CANCEL_STEP, "...x....."),
        ];
        assert_table(&ORDER, &table);
        // fmi2Get*Status: stepComplete, stepInProgress, stepFailed, stepCanceled (never
        // entered here), terminated, and error (see GET_STATUS).
        assert_eq!(
            GET_STATUS,
            m(&[
                StepComplete,
                StepInProgress,
                StepFailed,
                StepCanceled,
                Terminated,
                Error
            ])
        );
        // Restoring is allowed wherever saving is.
        assert_eq!(SET_FMU_STATE, GET_FMU_STATE);
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

    /// The FMI 2.0 Model Exchange state table (section 3.2.3), per function, written
    /// out from the standard. Columns: instantiated, initializationMode, eventMode,
    /// continuousTimeMode, terminated, error, fatal.
    #[test]
    fn model_exchange_masks_follow_the_standard_table() {
        const ORDER: [FmiState; 7] = [
            Instantiated,
            InitializationMode,
            EventMode,
            ContinuousTimeMode,
            Terminated,
            Error,
            Fatal,
        ];
        let table: [(&str, u16, &str); 17] = [
            ("fmi2SetDebugLogging", SET_DEBUG_LOGGING, "xxxxxx."),
            ("fmi2SetupExperiment", SETUP_EXPERIMENT, "x......"),
            (
                "fmi2ExitInitializationMode",
                EXIT_INITIALIZATION_MODE,
                ".x.....",
            ),
            ("fmi2Terminate", TERMINATE, "..xx..."),
            ("fmi2Reset", RESET, "xxxxxx."),
            ("fmi2GetReal", GET, ".xxxxx."),
            ("fmi2SetReal", SET, "xxxx..."),
            ("fmi2GetFMUstate", GET_FMU_STATE, "xxxxxx."),
            (
                "fmi2GetDirectionalDerivative",
                GET_DIRECTIONAL_DERIVATIVE,
                ".xxxxx.",
            ),
            ("fmi2EnterEventMode", ENTER_EVENT_MODE, "..xx..."),
            ("fmi2NewDiscreteStates", NEW_DISCRETE_STATES, "..x...."),
            (
                "fmi2EnterContinuousTimeMode",
                ENTER_CONTINUOUS_TIME_MODE,
                "..x....",
            ),
            (
                "fmi2CompletedIntegratorStep",
                COMPLETED_INTEGRATOR_STEP,
                "...x...",
            ),
            ("fmi2SetTime", SET_TIME, "..xx..."),
            ("fmi2SetContinuousStates", SET_CONTINUOUS_STATES, "...x..."),
            ("fmi2GetDerivatives", GET_CONTINUOUS, ".xxxxx."),
            ("fmi2GetNominalsOfContinuousStates", GET_NOMINALS, "xxxxxx."),
        ];
        assert_table(&ORDER, &table);
        // The co-simulation-only functions are illegal in every Model Exchange state.
        for mask in [DO_STEP, CANCEL_STEP, GET_STATUS & !Error.bit()] {
            assert_eq!(mask & m(&[EventMode, ContinuousTimeMode]), 0);
        }
        for s in [EventMode, ContinuousTimeMode] {
            assert_eq!(FmiState::from_code(s.code()), Some(s));
        }
    }
}
