//! Build script. The FMI helper adds header generation (cbindgen) here.
fn main() {
    println!("cargo:rerun-if-changed=build.rs");
}
