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

mod api;
mod rules;
mod step;
mod storage;

pub use rules::{assign, rng};
pub use api::port;
pub use assign::Method;
pub use api::desc::{Boundary, Collisions, Description, Drag, Drift, Forces, Identity, Preset, Quantization, Turbulence, Vortex};
pub use api::error::{Error, ErrorKind};
#[cfg(feature = "alloc")]
pub use api::owned::WorldBox;
pub use api::query::{Cell, Particle, Particles, RegionStats, Stats};
pub use api::snapshot::{image_description, IMAGE_VERSION};
pub use rules::emitter::{Emitter, EmitterStats};
pub use rules::obstacle::{Shape, Surface};
#[cfg(feature = "obstacles")]
pub use api::bodies::BodyStats;
pub use step::Order;
#[cfg(target_has_atomic = "8")]
pub use step::tasks::{Host, MAX_TASKS};
pub use storage::world::{world_bytes, World, WORLD_ALIGN};

/// How many cases a test runs: `full` natively, `under_miri` under Miri,
/// which interprets every operation and runs a few thousand times slower.
/// The same checks either way, on fewer cases; statistical bands are
/// derived from the count, so they stay as strict.
#[cfg(test)]
pub(crate) const fn sized(full: usize, under_miri: usize) -> usize {
    if cfg!(miri) { under_miri } else { full }
}
