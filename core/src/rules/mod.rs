//! The model's rules, each in a file named after it: what happens to the
//! particles of a block, independent of where a world keeps them.

pub mod assign;
#[cfg(feature = "obstacles")]
pub(crate) mod body;
pub(crate) mod class;
pub(crate) mod collision;
pub(crate) mod emitter;
pub(crate) mod faces;
pub(crate) mod fixed;
pub(crate) mod force;
pub(crate) mod obstacle;
pub(crate) mod quant;
pub(crate) mod turbulence;
pub mod rng;
pub(crate) mod vector;
