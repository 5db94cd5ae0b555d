//! The `fxbody` command run end to end as a user runs it.

mod info;
mod inputs;
mod progress;
