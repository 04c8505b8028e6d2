//! Emitters (M6). Each step, before the blocks are processed, every emitter
//! places `floor(rate)` particles plus one more with probability
//! `rate - floor(rate)` (a Bernoulli sum: the mean is exactly `rate`, the
//! variance at most 1/4), in empty non-obstacle cells of its region chosen
//! uniformly (selection sampling over the region). What does not fit is
//! counted as shortfall. Draws come from the emitter's own stream
//! `(seed, step, emitter index)` (M8).

use crate::collision::random_unit;
use crate::desc::finite;
use crate::rng::{StepKey, Stream};
use crate::vector::clamp;
use crate::layout::{view_counted_ref, Plain};
use crate::world::World;
use crate::Error;

/// An emitter as the caller describes it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub struct Emitter {
    /// First cell of the region, inclusive.
    pub min: [u32; 3],
    /// Last cell of the region, exclusive (the third is 1 in 2D).
    pub max: [u32; 3],
    /// Mean particles per step, finite and not negative.
    pub rate: f32,
    /// Initial velocity.
    pub velocity: [f32; 3],
    /// Radius of a uniform random spread added to the velocity;
    /// `|velocity| + spread` must not exceed 1 (decided exactly).
    pub spread: f32,
    /// Mass of the emitted particles.
    pub mass: f32,
    /// Steps each particle lives, 0 for no limit; at most 65535, and only in
    /// worlds with `lifetimes`.
    pub lifetime: u32,
}

/// An emitter as the world stores it.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
#[repr(C)]
pub(crate) struct Slot {
    pub emitter: Emitter,
    pub mass_index: u32,
}

// SAFETY: u32 and f32 fields only, no padding, every bit pattern valid.
unsafe impl Plain for Slot {}

/// `e` as a world of `dim` dimensions, `n` cells per axis and, if
/// `lifetimes`, an age plane stores it (2D drops the third axis), or why
/// such a world refuses it. Shared by [`World::add_emitter`] and the
/// snapshot loader (M12), which holds a stored emitter to the same rules.
/// `e` is changed in place, refused or not (no copy of it in or out, each
/// a `memcpy` call on a small core): callers check a copy of their own.
pub(crate) fn checked(e: &mut Emitter, dim: usize, n: [usize; 3], lifetimes: bool) -> Result<(), Error> {
    // Every float is checked as given, before 2D drops the third axis.
    finite(&[e.rate, e.velocity[0], e.velocity[1], e.velocity[2], e.spread])?;
    if dim == 2 {
        e.min[2] = 0;
        e.max[2] = 1;
        e.velocity[2] = 0.0;
    }
    if e.rate < 0.0 || e.spread < 0.0 || (0..3).any(|k| e.min[k] >= e.max[k] || e.max[k] as usize > n[k]) {
        return Err(Error::BadEmitter);
    }
    if crate::speed::too_fast(e.velocity, e.spread) {
        return Err(Error::SpeedRange);
    }
    if e.lifetime > u32::from(u16::MAX) {
        return Err(Error::LifetimeRange);
    }
    if e.lifetime > 0 && !lifetimes {
        return Err(Error::NotEnabled);
    }
    Ok(())
}

impl World {
    /// Adds an emitter and returns its index.
    pub fn add_emitter(&mut self, mut e: Emitter) -> Result<usize, Error> {
        checked(&mut e, self.dim(), self.layout().n, self.head.desc.lifetimes)?;
        let used = self.head.emitters as usize;
        // The capacity the plane was sized for (`Layout::of`), without a
        // division by the slot's size.
        if used >= self.head.desc.emitter_capacity as usize {
            return Err(Error::EmitterTableFull);
        }
        let mass_index = u32::from(self.mass_index_of(e.mass)?);
        let (head, p) = self.planes::<u8>();
        p.emitters[used] = Slot { emitter: e, mass_index };
        head.emitters += 1;
        Ok(used)
    }

    /// Changes the rate of emitter `index`.
    pub fn set_emitter_rate(&mut self, index: usize, rate: f32) -> Result<(), Error> {
        finite(&[rate])?;
        if rate < 0.0 {
            return Err(Error::BadEmitter);
        }
        if index >= self.head.emitters as usize {
            return Err(Error::OutOfBounds);
        }
        self.planes::<u8>().1.emitters[index].emitter.rate = rate;
        Ok(())
    }

    /// The emitter table, as long as its capacity.
    fn slots(&self) -> &[Slot] {
        view_counted_ref(self.plane_bytes(self.layout().emitters()), self.head.desc.emitter_capacity as usize)
    }

    /// Runs every emitter once (M6), at the start of a step.
    pub(crate) fn emit(&mut self) {
        let (seed, step, dim) = (self.head.desc.seed, self.head.step, self.dim());
        let key = StepKey::emitters(seed, step);
        for i in 0..self.head.emitters as usize {
            let slot: Slot = self.slots()[i];
            let e = slot.emitter;
            let mut rng = key.stream(i as u64);
            let whole = floor_rate(e.rate);
            // Casting saturates, so an absurd rate asks for u64::MAX.
            let wanted = crate::vector::saturating_u64(whole).saturating_add(u64::from(rng.chance(e.rate - whole)));
            if wanted == 0 {
                continue;
            }
            let grid = self.layout().grid();
            // Cells, counted in machine words (not u64: small cores add
            // those in pairs of instructions).
            let mut free = 0usize;
            each_site(grid, &e, |s| free += usize::from(!self.occupied(s) && !self.is_obstacle(s)));
            let placing = wanted.min(free as u64) as usize;
            self.head.counters.shortfall = self.head.counters.shortfall.saturating_add(wanted - placing as u64);
            let mut need = placing;
            let mut left = free;
            let mut chosen = |w: &mut World, s| {
                if need == 0 || w.occupied(s) || w.is_obstacle(s) {
                    return;
                }
                // Selection sampling: take this cell with chance need/left,
                // which picks a uniform subset of `placing` free cells.
                // `left` counts cells, so it fits the u32 of `below`.
                let take = (rng.below(left as u32) as usize) < need;
                left -= 1;
                if take {
                    need -= 1;
                    let v = spread_velocity(&e, dim, &mut rng);
                    w.place_emitted(s, v, slot.mass_index as u8, e.lifetime as u16, &mut rng);
                }
            };
            each_site(grid, &e, |s| chosen(self, s));
            // Saturating: an image (M12) may carry any count.
            self.head.counters.emitted = self.head.counters.emitted.saturating_add(placing as u64);
            self.head.counters.particles += placing as u64;
        }
    }
}

/// `floor(x)` for an `x` that is not negative (a rate: `checked`), by
/// clearing the bits of its fraction: a few instructions where `floorf`
/// is a library routine of some 100 bytes.
fn floor_rate(x: f32) -> f32 {
    let bits = x.to_bits();
    let exponent = (bits >> 23 & 0xff) as i32 - 127;
    if exponent < 0 {
        // Below 1: no whole part (the sign kept, as floor keeps -0).
        return f32::from_bits(bits & 0x8000_0000);
    }
    // 23 fraction bits, of which `exponent` lie above the point.
    let fraction = 0x7f_ffffu32.checked_shr(exponent as u32).unwrap_or(0);
    f32::from_bits(bits & !fraction)
}

/// Calls `f` with every site of the emitter's region.
fn each_site(l: crate::layout::Grid, e: &Emitter, mut f: impl FnMut(crate::layout::Site)) {
    for z in e.min[2] as usize..e.max[2] as usize {
        for y in e.min[1] as usize..e.max[1] as usize {
            for x in e.min[0] as usize..e.max[0] as usize {
                f(l.site(x, y, z));
            }
        }
    }
}

/// The emitter's velocity plus a uniform point of the disc or ball of radius
/// `spread`.
fn spread_velocity(e: &Emitter, dim: usize, rng: &mut Stream) -> [f32; 3] {
    let mut v = e.velocity;
    if e.spread > 0.0 {
        // A build without 3D has only 2D worlds: the 3D branch (and cbrtf)
        // is not linked into it.
        let (dir, radius) = if dim == 2 || !cfg!(feature = "dim3") {
            (random_unit::<2>(rng), crate::vector::sqrt(rng.unit()))
        } else {
            (random_unit::<3>(rng), libm::cbrtf(rng.unit()))
        };
        for k in 0..3 {
            v[k] += e.spread * radius * dir[k];
        }
    }
    // |velocity| + spread <= 1 was checked; rounding may still leave a hair
    // over 1, which is no clamp of the model's, so it is not counted.
    let _ = clamp(&mut v, 1.0);
    v
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;
    use crate::rng::block_stream;

    #[test]
    fn floor_rate_is_floor_for_rates() {
        // Expect: floorf's value, bit for bit, for 0, -0, every power of
        // two's neighbours, infinity and random values of every size.
        let mut rng = block_stream(9, 9, 9);
        let check = |x: f32| assert_eq!(floor_rate(x).to_bits(), libm::floorf(x).to_bits(), "{x:e}");
        check(0.0);
        check(-0.0);
        check(f32::INFINITY);
        for e in 0..255u32 {
            let x = f32::from_bits(e << 23);
            for k in 0..3 {
                check(f32::from_bits(x.to_bits() + k));
                check(f32::from_bits((x.to_bits() + k).saturating_sub(3)));
            }
        }
        for _ in 0..crate::sized(100_000, 1_000) {
            check(f32::from_bits(rng.bits(31)));
        }
    }
}
