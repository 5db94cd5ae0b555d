//! The `fxbody` command run end to end as a user runs it.

mod first_use;
mod info;
mod input_kinds;
mod inputs;
mod pack_extras;
mod progress;
