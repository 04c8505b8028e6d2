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
use crate::layout::Plain;
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
    /// `|velocity| + spread` must not exceed 1 (summed in `f64`).
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
pub(crate) fn checked(e: Emitter, dim: usize, n: [usize; 3], lifetimes: bool) -> Result<Emitter, Error> {
    // Every float is checked as given, before 2D drops the third axis.
    finite(&[e.rate, e.velocity[0], e.velocity[1], e.velocity[2], e.spread])?;
    let mut e = e;
    if dim == 2 {
        e.min[2] = 0;
        e.max[2] = 1;
        e.velocity[2] = 0.0;
    }
    if e.rate < 0.0 || e.spread < 0.0 || (0..3).any(|k| e.min[k] >= e.max[k] || e.max[k] as usize > n[k]) {
        return Err(Error::BadEmitter);
    }
    // In f64: an f32 sum rounds 0.5 + 0.50000006 down to 1. The squares
    // are exact in f64 and the rest errs by about 1e-16, far below the
    // spacing of f32 values at 1 (6e-8 below, 1.2e-7 above).
    let speed = libm::sqrt(e.velocity.iter().map(|&c| f64::from(c) * f64::from(c)).sum::<f64>());
    if speed + f64::from(e.spread) > 1.0 {
        return Err(Error::SpeedRange);
    }
    if e.lifetime > u32::from(u16::MAX) {
        return Err(Error::LifetimeRange);
    }
    if e.lifetime > 0 && !lifetimes {
        return Err(Error::NotEnabled);
    }
    Ok(e)
}

impl World {
    /// Adds an emitter and returns its index.
    pub fn add_emitter(&mut self, e: Emitter) -> Result<usize, Error> {
        let e = checked(e, self.dim(), self.layout().n, self.head.desc.lifetimes)?;
        let used = self.head.emitters as usize;
        if used >= self.layout().emitters.len / core::mem::size_of::<Slot>() {
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

    /// Runs every emitter once (M6), at the start of a step.
    pub(crate) fn emit(&mut self) {
        let (seed, step, dim) = (self.head.desc.seed, self.head.step, self.dim());
        let key = StepKey::emitters(seed, step);
        for i in 0..self.head.emitters as usize {
            let slot: Slot = self.plane::<Slot>(self.layout().emitters)[i];
            let e = slot.emitter;
            let mut rng = key.stream(i as u64);
            let whole = libm::floorf(e.rate);
            // Casting saturates, so an absurd rate asks for u64::MAX.
            let wanted = (whole as u64).saturating_add(u64::from(rng.chance(e.rate - whole)));
            if wanted == 0 {
                continue;
            }
            let l = *self.layout();
            let mut free = 0u64;
            each_site(&l, &e, |s| free += u64::from(!self.occupied(s) && !self.is_obstacle(s)));
            let placing = wanted.min(free);
            self.head.counters.shortfall = self.head.counters.shortfall.saturating_add(wanted - placing);
            let mut need = placing;
            let mut left = free;
            let mut chosen = |w: &mut World, s| {
                if need == 0 || w.occupied(s) || w.is_obstacle(s) {
                    return;
                }
                // Selection sampling: take this cell with chance need/left,
                // which picks a uniform subset of `placing` free cells.
                // `left` counts cells, so it fits the u32 of `below`.
                let take = u64::from(rng.below(left as u32)) < need;
                left -= 1;
                if take {
                    need -= 1;
                    let v = spread_velocity(&e, dim, &mut rng);
                    w.place(s, v, slot.mass_index as u8, e.lifetime as u16, Some(&mut rng));
                }
            };
            each_site(&l, &e, |s| chosen(self, s));
            // Saturating: an image (M12) may carry any count.
            self.head.counters.emitted = self.head.counters.emitted.saturating_add(placing);
            self.head.counters.particles += placing;
        }
    }
}

/// Calls `f` with every site of the emitter's region.
fn each_site(l: &crate::layout::Layout, e: &Emitter, mut f: impl FnMut(crate::layout::Site)) {
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
            (random_unit::<2>(rng), libm::sqrtf(rng.unit()))
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
