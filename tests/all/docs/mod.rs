//! The repository's documentation.

mod citations;
