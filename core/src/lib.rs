//! # mpca: particles on a Margolus-neighbourhood cellular automaton
//!
//! A `no_std` implementation of the particle model of Ecchu, Takai and Sato,
//! "Particle Motion Modeling by Cellular Automata and its Applications"
//! (1993), for 2D and 3D from one code path. The rules are numbered as in
//! `docs/model.md` (M1-M12) and cited where they are implemented.
//!
//! A world lives in memory the caller hands in; nothing is allocated.
//!
//! ```
//! use mpca::{Boundary, Description, World};
//!
//! // A 64 x 64 box with walls and gravity.
//! let mut desc = Description::new_2d(64, 64).with_boundary(Boundary::Wall);
//! desc.forces.uniform = true;
//! desc.gravity = [0.0, -0.01, 0.0];
//! desc.seed = 42;
//!
//! let mut memory = [0u8; 16 * 1024];
//! let world = World::init(&desc, &mut memory).unwrap();
//! for x in 0..64 {
//!     world.add_particle([x, 60, 0], [0.0, 0.0, 0.0]).unwrap();
//! }
//! world.step(100);
//! let stats = world.stats();
//! assert_eq!(stats.particles, 64);
//! assert!(stats.momentum[1] < 0.0); // falling
//! ```
//!
//! Where this crate resolves a point the paper leaves open or goes beyond
//! it, the item says so: boundaries (M4), the calibrated drift rule (M5.3),
//! the exact-fast assignment (M5.6), quantized storage (M1), emitters (M6).
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
mod speed;
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

/// The README's Rust example, compiled and run as a doctest so it stays true.
#[cfg(doctest)]
#[doc = include_str!("../../README.md")]
struct ReadmeExample;
