//! The committed C header equals what cbindgen generates from the exports now, and it
//! declares all 34 FMI 2.0 co-simulation functions (FMI.md's list, typed out here) and
//! all 75 functions of FMI 3.0's fmi3Functions.h (typed out here from the standard's
//! header, in its order).

const FMI2_CS_FUNCTIONS: [&str; 34] = [
    "fmi2GetTypesPlatform",
    "fmi2GetVersion",
    "fmi2SetDebugLogging",
    "fmi2Instantiate",
    "fmi2FreeInstance",
    "fmi2SetupExperiment",
    "fmi2EnterInitializationMode",
    "fmi2ExitInitializationMode",
    "fmi2Terminate",
    "fmi2Reset",
    "fmi2GetReal",
    "fmi2GetInteger",
    "fmi2GetBoolean",
    "fmi2GetString",
    "fmi2SetReal",
    "fmi2SetInteger",
    "fmi2SetBoolean",
    "fmi2SetString",
    "fmi2GetFMUstate",
    "fmi2SetFMUstate",
    "fmi2FreeFMUstate",
    "fmi2SerializedFMUstateSize",
    "fmi2SerializeFMUstate",
    "fmi2DeSerializeFMUstate",
    "fmi2GetDirectionalDerivative",
    "fmi2SetRealInputDerivatives",
    "fmi2GetRealOutputDerivatives",
    "fmi2DoStep",
    "fmi2CancelStep",
    "fmi2GetStatus",
    "fmi2GetRealStatus",
    "fmi2GetIntegerStatus",
    "fmi2GetBooleanStatus",
    "fmi2GetStringStatus",
];

const FMI3_FUNCTIONS: [&str; 75] = [
    "fmi3GetVersion",
    "fmi3SetDebugLogging",
    "fmi3InstantiateModelExchange",
    "fmi3InstantiateCoSimulation",
    "fmi3InstantiateScheduledExecution",
    "fmi3FreeInstance",
    "fmi3EnterInitializationMode",
    "fmi3ExitInitializationMode",
    "fmi3EnterEventMode",
    "fmi3Terminate",
    "fmi3Reset",
    "fmi3GetFloat32",
    "fmi3GetFloat64",
    "fmi3GetInt8",
    "fmi3GetUInt8",
    "fmi3GetInt16",
    "fmi3GetUInt16",
    "fmi3GetInt32",
    "fmi3GetUInt32",
    "fmi3GetInt64",
    "fmi3GetUInt64",
    "fmi3GetBoolean",
    "fmi3GetString",
    "fmi3GetBinary",
    "fmi3GetClock",
    "fmi3SetFloat32",
    "fmi3SetFloat64",
    "fmi3SetInt8",
    "fmi3SetUInt8",
    "fmi3SetInt16",
    "fmi3SetUInt16",
    "fmi3SetInt32",
    "fmi3SetUInt32",
    "fmi3SetInt64",
    "fmi3SetUInt64",
    "fmi3SetBoolean",
    "fmi3SetString",
    "fmi3SetBinary",
    "fmi3SetClock",
    "fmi3GetNumberOfVariableDependencies",
    "fmi3GetVariableDependencies",
    "fmi3GetFMUState",
    "fmi3SetFMUState",
    "fmi3FreeFMUState",
    "fmi3SerializedFMUStateSize",
    "fmi3SerializeFMUState",
    "fmi3DeserializeFMUState",
    "fmi3GetDirectionalDerivative",
    "fmi3GetAdjointDerivative",
    "fmi3EnterConfigurationMode",
    "fmi3ExitConfigurationMode",
    "fmi3GetIntervalDecimal",
    "fmi3GetIntervalFraction",
    "fmi3GetShiftDecimal",
    "fmi3GetShiftFraction",
    "fmi3SetIntervalDecimal",
    "fmi3SetIntervalFraction",
    "fmi3SetShiftDecimal",
    "fmi3SetShiftFraction",
    "fmi3EvaluateDiscreteStates",
    "fmi3UpdateDiscreteStates",
    "fmi3EnterContinuousTimeMode",
    "fmi3CompletedIntegratorStep",
    "fmi3SetTime",
    "fmi3SetContinuousStates",
    "fmi3GetContinuousStateDerivatives",
    "fmi3GetEventIndicators",
    "fmi3GetContinuousStates",
    "fmi3GetNominalsOfContinuousStates",
    "fmi3GetNumberOfEventIndicators",
    "fmi3GetNumberOfContinuousStates",
    "fmi3EnterStepMode",
    "fmi3GetOutputDerivatives",
    "fmi3DoStep",
    "fmi3ActivateModelPartition",
];

/// The names of the functions the header declares whose name starts with `prefix`:
/// declarations start in column 0, `<type> <name>(`.
fn declared(h: &str, prefix: &str) -> Vec<String> {
    h.lines()
        .filter(|l| !l.starts_with([' ', '/', '#', '}', 't']) && l.contains('('))
        .filter_map(|l| l.split('(').next()?.rsplit([' ', '*']).next())
        .filter(|n| n.starts_with(prefix))
        .map(str::to_string)
        .collect()
}

#[test]
fn header_declares_every_fmi3_function() {
    let mut got = declared(fxbody::fmi::GENERATED_HEADER, "fmi3");
    let mut want: Vec<String> = FMI3_FUNCTIONS.iter().map(|s| s.to_string()).collect();
    got.sort();
    want.sort();
    assert_eq!(
        got, want,
        "exactly fmi3Functions.h's 75 functions are declared"
    );
    // FMI 3.0's logger is not variadic: four fixed arguments.
    let h = fxbody::fmi::GENERATED_HEADER;
    let cb = h
        .split("typedef void (*fmi3LogMessageCallback)(")
        .nth(1)
        .and_then(|r| r.split(");").next())
        .expect("fmi3LogMessageCallback declared");
    assert!(!cb.contains("..."), "{cb}");
    assert_eq!(cb.matches(',').count(), 3, "{cb}");
}

#[test]
fn committed_header_is_fresh() {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/include/fxbody.h");
    let committed = std::fs::read_to_string(path).unwrap_or_default();
    let generated = fxbody::fmi::GENERATED_HEADER;
    if crate::common::blessing() {
        std::fs::write(path, generated).expect("write include/fxbody.h");
        return;
    }
    assert!(
        committed == generated,
        "include/fxbody.h is stale: regenerate it with `FXBODY_BLESS=1 cargo test --release --test all fmi::header`"
    );
}

#[test]
fn header_declares_every_fmi2_cosimulation_function() {
    let h = fxbody::fmi::GENERATED_HEADER;
    for f in FMI2_CS_FUNCTIONS {
        assert!(
            h.contains(&format!(" {f}(")) || h.contains(&format!("*{f}(")),
            "{f} not declared"
        );
    }
    // Declarations start in column 0: `<type> fmi2Name(`; nothing else is exported.
    let declared: Vec<&str> = h
        .lines()
        .filter(|l| {
            !l.starts_with([' ', '/', '#', '}', 't']) && l.contains("fmi2") && l.contains('(')
        })
        .filter_map(|l| l.split('(').next()?.rsplit([' ', '*']).next())
        .collect();
    assert_eq!(
        declared.len(),
        34,
        "exactly the 34 functions are declared: {declared:?}"
    );
}
