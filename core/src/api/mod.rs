//! The public API: descriptions and their checks, editing a world,
//! queries, snapshots and errors.

pub(crate) mod desc;
pub(crate) mod edit;
pub(crate) mod error;
pub(crate) mod hash;
#[cfg(feature = "alloc")]
pub(crate) mod owned;
pub(crate) mod query;
pub(crate) mod snapshot;
