//! The repository's documentation.

mod citations;
mod dependencies;
