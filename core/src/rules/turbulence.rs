//! M5.1c turbulence: the curl of a value-noise potential taken at the cell
//! corners, a part of M5.1b's flow. Every operation is on 32-bit integers
//! (a shader has no wider ones); the settings are converted once a world
//! ([`TurbulenceConstants`]), the time slices once a step ([`Eddies`]).

use crate::api::checks::positive;
use crate::api::desc::Description;
#[cfg(test)]
use crate::api::desc::Turbulence;
use crate::rules::fixed::{divr, scaled, scaled_by};
use crate::rules::rng::mix;

/// The seed's domain of the turbulence's keys: the bytes of "mpcatrb".
const DOMAIN: u64 = 0x6d70_6361_7472_6200;

/// A lattice point's index along x, y and z, and a component's, each
/// multiplied by its own odd constant before the hash.
const SPREAD: [u32; 4] = [0x9e37_79b9, 0xbf58_476d, 0x94d0_49bb, 0xa076_1d65];

/// The turbulence of one step (M5.1c's integers): the world's settings and
/// this step's time slices.
#[derive(Clone, Copy)]
pub(crate) struct Eddies {
    c: TurbulenceConstants,
    /// The two time slices' keys, `κ_0` and `κ_1`.
    keys: [u32; 2],
    /// The weight of the second slice, `w_t`, in Q15.
    time: u32,
    /// Per axis, its size in cells where it is periodic (the corner after
    /// its last cell is its first), or 0.
    wrap: [u32; 3],
    dim: usize,
}

/// M5.1c's `h32`: every bit of the word mixed into every other.
#[inline(always)]
const fn h32(mut x: u32) -> u32 {
    x = (x ^ (x >> 16)).wrapping_mul(0x1ce4_e5b9);
    x = (x ^ (x >> 15)).wrapping_mul(0x1331_11eb);
    x ^ (x >> 16)
}

/// `3 tau^2 - 2 tau^3` of `tau = x / 2^15`, in Q15, for `x < 2^15`.
#[inline(always)]
const fn smooth(x: u32) -> u32 {
    (((x * x) >> 15) * (3 * (1 << 15) - 2 * x)) >> 15
}

/// `a + (b - a) w / 2^15`, rounded down, for `a`, `b` in `[-2^15, 2^15)` and
/// `w` in `[0, 2^15]`: between `a` and `b`.
#[inline(always)]
const fn lerp(a: i32, b: i32, w: u32) -> i32 {
    a + (((b - a) * w as i32) >> 15)
}

/// M5.1c's settings as every step reads them (M1c), for the step here and
/// for a second implementation (`mpca::port`).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct TurbulenceConstants {
    /// `R = conv(rate, 1, 16)`: the slices' phase gained a step, in Q16.
    pub rate: u32,
    /// `β = mix(seed ⊕ "mpcatrb")`, from which each slice's key is mixed.
    pub base: u64,
    /// `T`'s top 12 bits, `t`.
    pub t: i32,
    /// `e - 30`: where `d t` is shifted left (or, below 0, right) to fine
    /// units.
    pub shift: i32,
    /// `log2(scale)`.
    pub lambda: u32,
}

impl TurbulenceConstants {
    /// The turbulence of a world of description `d`, for the unit speed
    /// `(s, fine)` (M1c); none where its amplitude is not above 0.
    /// [`Description::check`] has checked the settings.
    pub(crate) fn of(d: &Description, (s, fine): (u32, i32)) -> Option<TurbulenceConstants> {
        let t = &d.drag.turbulence;
        if !positive(t.amplitude) {
            return None;
        }
        // The scale of a unit `d`, `a W scale / (3 2^16 q)` in units of
        // 2^-30, and its top 12 bits.
        let q_bits = if d.dim == 3 { 2 } else { 0 };
        let big = divr(scaled_by(t.amplitude, t.scale as f32, s, fine + 14 - q_bits) as u64, 3);
        let bits = 64 - big.leading_zeros() as i32;
        Some(TurbulenceConstants {
            rate: scaled(t.rate, 1.0, 16) as u32,
            base: mix(d.seed ^ DOMAIN),
            t: if bits > 12 { big >> (bits - 12) } else { big << (12 - bits) } as i32,
            shift: bits - 12 - 30,
            lambda: t.scale.trailing_zeros(),
        })
    }
}

impl Eddies {
    /// The turbulence of step `step` in a world of `dim` axes of `n` cells
    /// (`periodic` where they wrap) whose settings are `c`: the two time
    /// slices' keys and the weight between them.
    pub(crate) fn of(c: TurbulenceConstants, step: u64, dim: usize, n: [usize; 3], periodic: [bool; 3]) -> Eddies {
        let phase = step.wrapping_mul(u64::from(c.rate));
        let slice = phase >> 16;
        Eddies {
            c,
            keys: [0, 1].map(|j| mix(c.base ^ slice.wrapping_add(j)) as u32),
            time: smooth((phase & 0xffff) as u32 >> 1),
            wrap: [0, 1, 2].map(|k| if periodic[k] { n[k] as u32 } else { 0 }),
            dim,
        }
    }

    /// The turbulent flow at the cell `pos`, in fine units: `d` from the
    /// potential at the cell's corners, scaled by `T`. Out of line: one
    /// copy serves every width and dimension, and its hashes outweigh a
    /// call.
    #[inline(never)]
    pub(crate) fn at(&self, pos: [usize; 3]) -> [i64; 3] {
        let dim = self.dim;
        let mut d = [0i32; 3];
        for m in 0..1usize << dim {
            let mut corner = [0u32; 3];
            // The corner's side on each axis; 0 on an axis 2D has not.
            let mut sign = [0i32; 3];
            for k in 0..dim {
                let upper = m >> k & 1 != 0;
                let p = pos[k] as u32 + u32::from(upper);
                // The corner after the last cell of a periodic axis is
                // its first.
                corner[k] = if upper && p == self.wrap[k] { 0 } else { p };
                sign[k] = if upper { 1 } else { -1 };
            }
            // d += sign x A, with A = (0, 0, psi) in 2D: one formula for
            // both.
            let mut a = [0i32; 3];
            for (c, value) in a.iter_mut().enumerate().skip(if dim == 2 { 2 } else { 0 }) {
                *value = self.potential(corner, c as u32);
            }
            for k in 0..3 {
                let (i, j) = ((k + 1) % 3, (k + 2) % 3);
                d[k] += sign[i] * a[j] - sign[j] * a[i];
            }
        }
        let mut u = [0i64; 3];
        for k in 0..dim {
            let (y, shift) = (d[k] * self.c.t, self.c.shift);
            u[k] = i64::from(if shift >= 0 { y << shift } else { y >> (-shift).min(31) });
        }
        u
    }

    /// Component `c` of the potential at `corner`: the lattice values
    /// round it blended along x, then y, then z for each time slice, then
    /// the two slices blended. Out of line: called from one loop.
    #[inline(never)]
    fn potential(&self, corner: [u32; 3], c: u32) -> i32 {
        let (dim, lambda) = (self.dim, self.c.lambda);
        let mut points = [[0u32; 2]; 3];
        let mut w = [0u32; 3];
        for k in 0..dim {
            let i = corner[k] >> lambda;
            // The lattice's last point on a periodic axis is its first.
            points[k] = [i, if i + 1 == self.wrap[k] >> lambda { 0 } else { i + 1 }];
            w[k] = smooth((corner[k] & ((1 << lambda) - 1)) << (15 - lambda));
        }
        let mut slices = [0i32; 2];
        for (slice, &key) in slices.iter_mut().zip(&self.keys) {
            // The lattice points in the order x fastest; each value is
            // blended, as soon as its partner is known, with the one kept
            // for its axis (the pairs of a binary counter's carries), so
            // the blends are those of x first, then y, then z.
            let mut kept = [0i32; 3];
            for m in 0..1usize << dim {
                let mut x = c.wrapping_mul(SPREAD[3]);
                for k in 0..dim {
                    x = x.wrapping_add(points[k][m >> k & 1].wrapping_mul(SPREAD[k]));
                }
                let mut value = h32(key ^ x) as i32 >> 16;
                let mut k = 0;
                while k < dim && m >> k & 1 != 0 {
                    value = lerp(kept[k], value, w[k]);
                    k += 1;
                }
                if k < dim {
                    kept[k] = value;
                } else {
                    *slice = value;
                }
            }
        }
        lerp(slices[0], slices[1], self.time)
    }

    /// `d` unscaled at `pos`, for the tests of its divergence.
    #[cfg(test)]
    fn unscaled(&self, pos: [usize; 3]) -> [i32; 3] {
        let scaled = Eddies { c: TurbulenceConstants { t: 1, shift: 0, ..self.c }, ..*self };
        scaled.at(pos).map(|x| x as i32)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn eddies(dim: usize, scale: u32, n: [usize; 3], periodic: [bool; 3], step: u64) -> Eddies {
        let mut d = Description::new_3d(1, 1, 1);
        (d.dim, d.seed) = (dim as u32, 7);
        d.drag.turbulence = Turbulence { amplitude: 0.3, scale, rate: 0.05 };
        Eddies::of(TurbulenceConstants::of(&d, (127, 16)).unwrap(), step, dim, n, periodic)
    }

    /// M5.1c: over the cells round every corner inside the grid (and, on
    /// a periodic axis, the corner between its last cell and its first),
    /// the unscaled flow out of the upper side less that into the lower
    /// side, summed over the axes, is 0 exactly; and the flow is not 0.
    /// Under Miri, which interprets every operation, smaller grids and two
    /// scales: the same identity on fewer corners.
    #[test]
    fn the_flow_has_no_divergence_on_the_grid() {
        let grids = [(2, [24, 16, 1], [false; 3]), (2, [32, 16, 1], [true, false, true]), (3, [8, 8, 8], [false, true, false])];
        let small = [(2, [6, 4, 1], [false; 3]), (2, [4, 4, 1], [true, false, true]), (3, [4, 2, 2], [false, true, false])];
        let scales: &[u32] = if cfg!(miri) { &[1, 2] } else { &[1, 2, 4, 8] };
        for (dim, n, periodic) in if cfg!(miri) { small } else { grids } {
            for &scale in scales {
                let e = eddies(dim, scale, n, periodic, 123);
                let mut moving = 0;
                let corners = |k: usize| match (k < dim, periodic[k]) {
                    (false, _) => 0..1,
                    (true, true) => 0..n[k],
                    (true, false) => 1..n[k],
                };
                for z in corners(2) {
                    for y in corners(1) {
                        for x in corners(0) {
                            let corner = [x, y, z];
                            let mut div = 0i64;
                            for m in 0..1usize << dim {
                                let mut cell = [0usize; 3];
                                for k in 0..dim {
                                    cell[k] = (corner[k] + n[k] - 1 + (m >> k & 1)) % n[k];
                                }
                                let d = e.unscaled(cell);
                                for k in 0..dim {
                                    let side = if m >> k & 1 != 0 { 1 } else { -1 };
                                    div += side * i64::from(d[k]);
                                }
                                moving += usize::from(d != [0; 3]);
                            }
                            assert_eq!(div, 0, "dim {dim} scale {scale} corner {corner:?}");
                        }
                    }
                }
                assert!(moving > 0, "dim {dim} scale {scale}: no flow");
            }
        }
    }

    /// No component is above the amplitude but for rounding, and the
    /// flow changes with the step at the rate's pace.
    /// Under Miri on smaller grids, as above.
    #[test]
    fn the_flow_is_bounded_by_the_amplitude_and_changes_in_time() {
        let w = 127i64 << 16;
        let grids = if cfg!(miri) { [(2, [8, 8, 1]), (3, [4, 4, 2])] } else { [(2, [64, 64, 1]), (3, [16, 16, 16])] };
        for (dim, n) in grids {
            let scales: &[u32] = if cfg!(miri) { &[1, 4] } else { &[1, 4, 16] };
            for &scale in scales {
                let e = eddies(dim, scale, n, [false; 3], 10);
                let later = eddies(dim, scale, n, [false; 3], 50);
                let (mut top, mut changed) = (0i64, 0);
                for z in 0..n[2] {
                    for y in 0..n[1] {
                        for x in 0..n[0] {
                            let u = e.at([x, y, z]);
                            top = top.max(u.iter().map(|c| c.abs()).max().unwrap());
                            changed += usize::from(u != later.at([x, y, z]));
                        }
                    }
                }
                let bound = (w as f64 * 0.3 * 1.001) as i64;
                assert!(top <= bound && top > bound / 8, "dim {dim} scale {scale}: {top} against {bound}");
                assert!(changed > n[0] * n[1] * n[2] / 2, "dim {dim} scale {scale}: {changed} cells changed");
            }
        }
    }
}
