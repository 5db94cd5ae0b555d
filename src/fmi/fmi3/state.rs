//! The FMI 3.0 call sequence: per function, the states in which it may be called, as
//! masks of the shared [`FmiState`] bits. FMI 3.0 names StepComplete StepMode and
//! StepFailed StepDiscarded; an instance whose call returned fmi3Error is in Terminated
//! (FMI 3.0, "FMU State Setable"), which here is the shared Error state: its masks
//! allow what Terminated allows (reads, output derivatives, the FMU-state functions,
//! SetDebugLogging, Reset), and a read answers for the state before the error as in
//! FMI 2.0. EventMode and ContinuousTimeMode are Model Exchange's (and event-mode
//! co-simulation's); a co-simulation instance of this FMU never enters them, nor
//! StepDiscarded, nor the configuration, intermediate-update and clock-activation modes
//! (no structural parameters, no intermediate update, no clocks), so masks name no bit
//! for those.

use crate::fmi::state::FmiState::*;
use crate::fmi::state::m;

/// Every state but Fatal: FMI 3.0's super state "FMU State Setable".
const SETABLE: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    StepFailed,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
]);

/// fmi3SetDebugLogging.
pub const SET_DEBUG_LOGGING: u16 = SETABLE;
/// fmi3EnterInitializationMode.
pub const ENTER_INITIALIZATION_MODE: u16 = m(&[Instantiated]);
/// fmi3ExitInitializationMode.
pub const EXIT_INITIALIZATION_MODE: u16 = m(&[InitializationMode]);
/// fmi3EnterEventMode: from Step Mode (co-simulation with event mode) or
/// Continuous-Time Mode (Model Exchange).
pub const ENTER_EVENT_MODE: u16 = m(&[StepComplete, ContinuousTimeMode]);
/// fmi3Terminate: the super state "Initialized" (Step Mode, Step Discarded, Event
/// Mode, Continuous-Time Mode).
pub const TERMINATE: u16 = m(&[StepComplete, StepFailed, EventMode, ContinuousTimeMode]);
/// fmi3Reset.
pub const RESET: u16 = SETABLE;
/// fmi3Get{VariableType} (in the Error state: the values of the last consistent state).
pub const GET: u16 = m(&[
    InitializationMode,
    StepComplete,
    StepFailed,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
]);
/// fmi3Set{VariableType} (which variables: checked by the model).
pub const SET: u16 = m(&[
    Instantiated,
    InitializationMode,
    StepComplete,
    EventMode,
    ContinuousTimeMode,
]);
/// fmi3GetFMUState, fmi3SerializedFMUStateSize, fmi3SerializeFMUState (in Error: the
/// saved state records the state before the error).
pub const GET_FMU_STATE: u16 = SETABLE;
/// fmi3SetFMUState, fmi3FreeFMUState, fmi3DeserializeFMUState.
pub const SET_FMU_STATE: u16 = SETABLE;
/// fmi3GetDirectionalDerivative, fmi3GetAdjointDerivative.
pub const GET_DERIVATIVES: u16 = m(&[
    InitializationMode,
    StepComplete,
    EventMode,
    ContinuousTimeMode,
    Terminated,
    Error,
]);
/// fmi3GetNumberOfVariableDependencies, fmi3GetVariableDependencies: queries of the
/// model structure, in every state.
pub const DEPENDENCIES: u16 = SETABLE;
/// fmi3EnterConfigurationMode: from Instantiated (structural parameters), Step Mode or
/// Event Mode (tunable structural parameters).
pub const ENTER_CONFIGURATION_MODE: u16 = m(&[Instantiated, StepComplete, EventMode]);
/// fmi3ExitConfigurationMode: from Configuration or Reconfiguration Mode, never entered.
pub const EXIT_CONFIGURATION_MODE: u16 = 0;
/// The clock and interval functions (Event Mode, Clock Activation Mode, initialisation).
pub const CLOCKS: u16 = m(&[InitializationMode, EventMode]);
/// fmi3EvaluateDiscreteStates, fmi3UpdateDiscreteStates.
pub const DISCRETE_STATES: u16 = m(&[EventMode]);
/// fmi3EnterStepMode: from Event Mode (co-simulation with event mode).
pub const ENTER_STEP_MODE: u16 = m(&[EventMode]);
/// fmi3GetOutputDerivatives (in Error: if the state before allows it).
pub const GET_OUTPUT_DERIVATIVES: u16 = m(&[StepComplete, StepFailed, Terminated, Error]);
/// fmi3DoStep.
pub const DO_STEP: u16 = m(&[StepComplete]);
/// fmi3ActivateModelPartition: Clock Activation Mode (Scheduled Execution), never
/// entered.
pub const ACTIVATE_MODEL_PARTITION: u16 = 0;
/// fmi3EnterContinuousTimeMode, fmi3CompletedIntegratorStep, fmi3SetTime,
/// fmi3SetContinuousStates, and fmi3GetContinuousStateDerivatives,
/// fmi3GetEventIndicators, fmi3GetContinuousStates, fmi3GetNominalsOfContinuousStates
/// (GET_CONTINUOUS): FMI 3.0's Model Exchange states allow them where FMI 2.0's do, so
/// both versions read one set of masks (the test below checks them against FMI 3.0's
/// table).
pub use crate::fmi::state::{
    COMPLETED_INTEGRATOR_STEP, ENTER_CONTINUOUS_TIME_MODE, GET_CONTINUOUS, SET_CONTINUOUS_STATES,
    SET_TIME,
};
/// fmi3GetNumberOfContinuousStates, fmi3GetNumberOfEventIndicators.
pub const GET_NUMBER_OF: u16 = SETABLE;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fmi::state::{FmiState, assert_table};

    /// The FMI 3.0 table, per function, written from the standard's state descriptions
    /// (common states, co-simulation, Model Exchange) rather than from the masks above.
    /// Columns: Instantiated, InitializationMode, StepMode, StepDiscarded, EventMode,
    /// ContinuousTimeMode, Terminated, Terminated after an error, Fatal.
    #[test]
    fn masks_follow_the_standard() {
        const ORDER: [FmiState; 9] = [
            Instantiated,
            InitializationMode,
            StepComplete,
            StepFailed,
            EventMode,
            ContinuousTimeMode,
            Terminated,
            Error,
            Fatal,
        ];
        let table: [(&str, u16, &str); 21] = [
            ("fmi3SetDebugLogging", SET_DEBUG_LOGGING, "xxxxxxxx."),
            (
                "fmi3EnterInitializationMode",
                ENTER_INITIALIZATION_MODE,
                "x........",
            ),
            (
                "fmi3ExitInitializationMode",
                EXIT_INITIALIZATION_MODE,
                ".x.......",
            ),
            ("fmi3EnterEventMode", ENTER_EVENT_MODE, "..x..x..."),
            ("fmi3Terminate", TERMINATE, "..xxxx..."),
            ("fmi3Reset", RESET, "xxxxxxxx."),
            ("fmi3GetFloat64", GET, ".xxxxxxx."),
            ("fmi3SetFloat64", SET, "xxx.xx..."),
            ("fmi3GetFMUState", GET_FMU_STATE, "xxxxxxxx."),
            ("fmi3SetFMUState", SET_FMU_STATE, "xxxxxxxx."),
            ("fmi3GetDirectionalDerivative", GET_DERIVATIVES, ".xx.xxxx."),
            (
                "fmi3EnterConfigurationMode",
                ENTER_CONFIGURATION_MODE,
                "x.x.x....",
            ),
            ("fmi3EnterStepMode", ENTER_STEP_MODE, "....x...."),
            (
                "fmi3GetOutputDerivatives",
                GET_OUTPUT_DERIVATIVES,
                "..xx..xx.",
            ),
            ("fmi3DoStep", DO_STEP, "..x......"),
            (
                "fmi3EnterContinuousTimeMode",
                ENTER_CONTINUOUS_TIME_MODE,
                "....x....",
            ),
            (
                "fmi3CompletedIntegratorStep",
                COMPLETED_INTEGRATOR_STEP,
                ".....x...",
            ),
            ("fmi3SetTime", SET_TIME, "....xx..."),
            (
                "fmi3SetContinuousStates",
                SET_CONTINUOUS_STATES,
                ".....x...",
            ),
            ("fmi3GetContinuousStates", GET_CONTINUOUS, ".x..xxxx."),
            ("fmi3UpdateDiscreteStates", DISCRETE_STATES, "....x...."),
        ];
        assert_table(&ORDER, &table);
        // Nothing is allowed in Fatal, and no mask names a state FMI 3.0 does not have.
        let fmi2_only = m(&[StepInProgress, StepCanceled, Fatal]);
        for mask in [SETABLE, GET, SET, GET_DERIVATIVES, GET_CONTINUOUS, CLOCKS] {
            assert_eq!(mask & fmi2_only, 0);
        }
        assert_eq!(EXIT_CONFIGURATION_MODE | ACTIVATE_MODEL_PARTITION, 0);
    }
}
