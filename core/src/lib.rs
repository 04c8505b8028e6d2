// The crate's documentation is its README (core/README.md): what crates.io
// and docs.rs show open on the same runnable example, and it runs as a
// doctest.
#![doc = include_str!("../README.md")]
#![no_std]
#![deny(missing_docs)]
#![warn(clippy::std_instead_of_core, clippy::alloc_instead_of_core)]
// Loops over axes `for k in 0..D` index several arrays at once, as the
// equations do; iterator chains would hide that.
#![allow(clippy::needless_range_loop)]

#[cfg(feature = "std")]
extern crate std;

pub mod assign;
mod cells;
mod collision;
mod desc;
mod edit;
mod emitter;
mod error;
mod force;
mod hash;
mod kernel;
mod layout;
mod obstacle;
#[cfg(feature = "alloc")]
mod owned;
mod partition;
mod quant;
mod query;
pub mod rng;
mod snapshot;
mod step;
#[cfg(target_has_atomic = "8")]
mod tasks;
mod vector;
mod world;

pub use assign::Method;
pub use desc::{Boundary, Collisions, Description, Drag, Drift, Forces, Quantization, Vortex};
pub use emitter::Emitter;
pub use error::Error;
pub use obstacle::{Shape, Surface};
#[cfg(feature = "alloc")]
pub use owned::WorldBox;
pub use step::Order;
#[cfg(target_has_atomic = "8")]
pub use tasks::{Host, MAX_TASKS};
pub use query::{Cell, Particle, Particles, RegionStats, Stats};
pub use snapshot::{image_description, IMAGE_VERSION};
pub use world::{world_bytes, World, WORLD_ALIGN};

/// How many cases a test runs: `full` natively, `under_miri` under Miri,
/// which interprets every operation and runs a few thousand times slower.
/// The same checks either way, on fewer cases; statistical bands are
/// derived from the count, so they stay as strict.
#[cfg(test)]
pub(crate) const fn sized(full: usize, under_miri: usize) -> usize {
    if cfg!(miri) { under_miri } else { full }
}
