//! The `fxbody` command: a thin layer over the library.

fn main() {
    eprintln!("fxbody: no commands yet");
    std::process::exit(2);
}
