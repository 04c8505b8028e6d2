//! A mass class as the rules read it during a step: the constants of one
//! mass, converted from it once a step (M1c).

use crate::rules::force::Strength;

/// A mass class as a step's blocks read it, converted from its mass once a
/// step (M1c). Laid out without padding: the classes of a world of masses
/// lie in its memory ([`mass_plane`](crate::storage::layout::mass_plane)).
#[derive(Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct Class {
    /// M1c's `K = quot(dt, m)`: the velocity, in unit speeds, a unit of
    /// force adds in a step. A force's push is its exact product with this
    /// and `W`, rounded.
    pub push: f32,
    /// M1c's `M`: the mass relative to the largest in use, `2^24` for that
    /// one (at least 1), from which a collision takes the shares.
    pub relative: u32,
    /// Units of the clamp's energy counter a fine unit squared of speed
    /// removed is worth: `m 2^31 / W^2` (M5.5, M10), by [`quot`](crate::rules::fixed::quot).
    pub energy: f32,
    /// Unused: keeps a class the size the mass table's plane gives it.
    pub spare: u32,
    /// The vortex's strength as a push for this class (M1c's `top(Γ')`),
    /// none without a vortex.
    pub swirl: Strength,
}
