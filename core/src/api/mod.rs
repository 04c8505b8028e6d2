//! The public API: descriptions and their checks, editing a world,
//! queries, snapshots and errors.

#[cfg(feature = "obstacles")]
pub(crate) mod bodies;
pub(crate) mod checks;
pub(crate) mod desc;
pub(crate) mod edit;
pub(crate) mod emitters;
pub(crate) mod error;
pub(crate) mod forces;
pub(crate) mod hash;
pub(crate) mod obstacles;
#[cfg(feature = "alloc")]
pub(crate) mod owned;
pub mod port;
pub(crate) mod query;
pub(crate) mod snapshot;
pub(crate) mod speed;
