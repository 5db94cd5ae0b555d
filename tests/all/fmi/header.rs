//! The committed C header equals what cbindgen generates from the exports now, and it
//! declares all 34 FMI 2.0 co-simulation functions (FMI.md's list, typed out here).

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
