//! Quantized velocity storage (M1). A component `v` in `[-1, 1]` is stored as
//! the integer nearest `v * SCALE`, rounded stochastically when it comes from
//! the step, so the stored value is right on average: an acceleration below
//! one quantum per step still acts, by raising the chance of rounding up.

use rand_core::Rng;

/// A stored velocity component type.
pub(crate) trait Quant: Copy + Default + crate::world::Plain + 'static {
    /// Stored steps per unit speed.
    const SCALE: f32;
    fn from_int(q: i32) -> Self;
    fn to_int(self) -> i32;

    #[inline]
    fn get(self) -> f32 {
        self.to_int() as f32 * (1.0 / Self::SCALE)
    }

    /// Round to nearest, halves away from zero so that `v` and `-v` store
    /// opposite values: for velocities a caller sets, which need no stream.
    #[inline]
    fn nearest(v: f32) -> Self {
        Self::from_int(libm::roundf(v.clamp(-1.0, 1.0) * Self::SCALE) as i32)
    }

    /// Unbiased stochastic rounding of `x`, a velocity component in quanta
    /// (`v * SCALE`): `E[result] = x` to within 2^-24 of a quantum. The step
    /// works in quanta, so a velocity nothing changed is an exact integer and
    /// is stored back unchanged without a draw.
    #[inline]
    fn stochastic<R: Rng + ?Sized>(x: f32, rng: &mut R) -> Self {
        let x = x.clamp(-Self::SCALE, Self::SCALE);
        let lo = libm::floorf(x);
        let frac = x - lo;
        let up = frac > 0.0 && crate::rng::chance(rng, frac);
        Self::from_int(lo as i32 + i32::from(up))
    }
}

impl Quant for i8 {
    const SCALE: f32 = 127.0;
    #[inline]
    fn from_int(q: i32) -> Self {
        q.clamp(-127, 127) as i8
    }
    #[inline]
    fn to_int(self) -> i32 {
        i32::from(self)
    }
}

#[cfg(feature = "q16")]
impl Quant for i16 {
    const SCALE: f32 = 32767.0;
    #[inline]
    fn from_int(q: i32) -> Self {
        q.clamp(-32767, 32767) as i16
    }
    #[inline]
    fn to_int(self) -> i32 {
        i32::from(self)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::block_stream;

    fn mean_of<Q: Quant>(v: f32, n: u32) -> f64 {
        let mut rng = block_stream(3, 0, 0);
        (0..n).map(|_| f64::from(Q::stochastic(v, &mut rng).get())).sum::<f64>() / f64::from(n)
    }

    #[test]
    fn stochastic_rounding_is_unbiased() {
        // v sits 0.3 quanta above a grid point; each draw is the lower point
        // plus a Bernoulli(0.3) quantum, sd of the mean = q*sqrt(.21/n).
        let mean = mean_of::<i8>(10.3, 100_000);
        let q = 1.0 / 127.0;
        let want = 10.3 * q;
        let sd = q * (0.21f64 / 100_000.0).sqrt();
        assert!((mean - want).abs() < 5.0 * sd, "{mean} vs {want}");
    }

    #[test]
    fn integers_in_quanta_draw_nothing() {
        let mut rng = block_stream(0, 0, 0);
        let mut twin = rng.clone();
        for q in -127..=127 {
            assert_eq!(i8::stochastic(q as f32, &mut rng).to_int(), q);
        }
        assert_eq!(rng.next_u32(), twin.next_u32());
    }

    #[test]
    fn nearest_round_trips_every_stored_value() {
        for q in -127..=127 {
            assert_eq!(i8::nearest(i8::from_int(q).get()).to_int(), q);
        }
    }
}
