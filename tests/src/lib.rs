//! Shared pieces of mpca's integration tests and benchmark: the paper's four
//! scenes (docs/model.md, paper section 4) built through the public API.
#![deny(missing_docs)]

pub mod measure;
pub mod plot;
pub mod scenes;
pub mod setup;
pub mod table;

/// The workspace README's Rust examples, each a whole `main.rs`
/// (tests/readme.rs holds them to that), compiled and run as doctests so
/// they stay true.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
struct ReadmeExamples;
