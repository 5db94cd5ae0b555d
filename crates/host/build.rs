//! Build script: compiles the C logger shim (`src/logger.c`). FMI 2.0's logger is a
//! C-variadic function (`printf`-style), which stable Rust cannot define; the shim
//! formats the message with `vsnprintf` and hands plain text to Rust.

fn main() {
    println!("cargo:rerun-if-changed=src/logger.c");
    cc::Build::new()
        .file("src/logger.c")
        .warnings(true)
        .compile("fxbody_host_logger");
}
