//! Shared pieces of mpca's integration tests and benchmark: the paper's four
//! scenes (docs/model.md, paper section 4) built through the public API.
#![deny(missing_docs)]

pub mod measure;
pub mod plot;
pub mod scenes;
pub mod setup;
pub mod table;
