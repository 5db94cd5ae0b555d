//! Build script: generates the C header of the FMI ABI with cbindgen into `OUT_DIR`.
//! The committed `include/fxbody.h` must equal it (checked by `tests/all/fmi/header.rs`), so
//! C users always get a header that matches the library.

use std::path::PathBuf;

fn main() {
    println!("cargo:rerun-if-changed=build.rs");
    println!("cargo:rerun-if-changed=cbindgen.toml");
    println!("cargo:rerun-if-changed=src/fmi");
    let crate_dir =
        PathBuf::from(std::env::var("CARGO_MANIFEST_DIR").expect("cargo sets CARGO_MANIFEST_DIR"));
    let out_dir = PathBuf::from(std::env::var("OUT_DIR").expect("cargo sets OUT_DIR"));
    let config = cbindgen::Config::from_file(crate_dir.join("cbindgen.toml"))
        .expect("cbindgen.toml is readable and valid");
    let header = out_dir.join("fxbody.h");
    match cbindgen::Builder::new()
        // Only the ABI files: the rest of the crate has public constants that are not
        // part of the C interface.
        .with_src(crate_dir.join("src/fmi/types.rs"))
        .with_src(crate_dir.join("src/fmi/exports.rs"))
        .with_src(crate_dir.join("src/fmi/values.rs"))
        .with_src(crate_dir.join("src/fmi/fmu_state.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/types.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/exports.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/values.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/other_types.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/non_numeric.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/fmu_state.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/clocks.rs"))
        .with_src(crate_dir.join("src/fmi/fmi3/model_exchange.rs"))
        .with_config(config)
        .generate()
    {
        Ok(bindings) => {
            bindings.write_to_file(&header);
        }
        Err(e) => {
            // A header that cannot be generated must not break the library build; the
            // header test then fails with this message.
            println!("cargo:warning=cbindgen could not generate the header: {e}");
            let _ = std::fs::write(&header, format!("/* cbindgen failed: {e} */\n"));
        }
    }
}
