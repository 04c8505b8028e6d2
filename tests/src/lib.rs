//! Shared pieces of mpca's integration tests and benchmark: the paper's four
//! scenes (MODEL.md table, paper section 4) built through the public API.
#![deny(missing_docs)]

pub mod scenes;
