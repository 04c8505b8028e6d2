//! External forces (M5.1, eqs. 4-6): `v <- v + dt F / m`, with `F` the sum of
//! the terms the description enables, in fine units (M1c). A uniform
//! acceleration is the same push for every mass; the other terms are
//! forces, each turned into a push by the exact product with its mass
//! class's `K = dt / m` and `W`, rounded. And the flow that drag relaxes
//! velocities towards (M5.1b).

use crate::api::desc::Vortex;
use crate::rules::fixed::{magnitude, quot, quotient16, sat, scaled, scaled_by, to_fine, SCALED_MAX};
use crate::rules::class::Class;
use crate::rules::turbulence::Eddies;

/// The force terms of one step, read-only, for the general force path.
pub(crate) struct ForceTerms<'a> {
    /// The uniform push, in fine units (M1c's `G`).
    pub gravity: [i64; 3],
    pub field: Option<&'a [f32]>,
    pub potential: Option<&'a [f32]>,
    pub vortex: Option<Swirl>,
    /// Fine units to a unit speed, `W = S 2^F`, as `(S, F)`.
    pub unit: (u32, i32),
    pub n: [usize; 3],
    pub periodic: [bool; 3],
    pub dim: usize,
}

impl ForceTerms<'_> {
    /// The push on a particle of class `class` at cell `pos` (dense index
    /// `cell`): the terms' sum in 64 bits, each saturated to `2^59` (twice
    /// that for the potential's differences), so the sum needs no test
    /// (the step fits it to the bound with its direction kept).
    #[inline]
    pub fn push(&self, pos: [usize; 3], cell: usize, class: &Class) -> [i64; 3] {
        let k = class.push;
        let mut p = self.gravity;
        // Without the feature `fields` a world has neither term
        // (`Description::check`), and the build no code for them.
        if cfg!(feature = "fields") {
            if let Some(field) = self.field {
                for a in 0..self.dim {
                    p[a] += scaled_by(field[cell * self.dim + a], k, self.unit.0, self.unit.1);
                }
            }
            if let Some(u) = self.potential {
                let g = self.descent(u, pos, cell, k);
                for a in 0..self.dim {
                    p[a] += g[a]; // eq. 6: F = -grad U
                }
            }
        }
        if let Some(v) = self.vortex {
            let t = v.at(pos, class.swirl);
            p[0] += t[0];
            p[1] += t[1];
        }
        p
    }

    /// `-grad U` as a push (eq. 6): central differences of the converted
    /// potential `P = U k` on the grid, `(P(x - 1) - P(x + 1)) >> 1`;
    /// one-sided at a face that is not periodic.
    fn descent(&self, u: &[f32], pos: [usize; 3], cell: usize, k: f32) -> [i64; 3] {
        let p = |i: usize| scaled_by(u[i], k, self.unit.0, self.unit.1);
        let mut g = [0i64; 3];
        let mut stride = 1usize;
        for a in 0..self.dim {
            let n = self.n[a];
            let x = pos[a];
            let lo_in = x > 0 || self.periodic[a];
            let hi_in = x + 1 < n || self.periodic[a];
            let lo = if x > 0 { cell - stride } else { cell + (n - 1) * stride };
            let hi = if x + 1 < n { cell + stride } else { cell - (n - 1) * stride };
            g[a] = match (lo_in, hi_in) {
                (true, true) => (p(lo) - p(hi)) >> 1,
                (false, true) => p(cell) - p(hi),
                (true, false) => p(lo) - p(cell),
                (false, false) => 0, // an axis of one cell has no gradient
            };
            stride *= n;
        }
        g
    }
}

/// The flow of M5.1b drag, read-only, for the general path: `u` at a cell
/// is the uniform wind, plus the wind plane's value there, plus the vortex
/// read as a velocity, plus the turbulence (M5.1c), in fine units (M1c).
pub(crate) struct Flow<'a> {
    /// The uniform wind (M1c's `U`).
    pub wind: [i32; 3],
    pub field: Option<&'a [f32]>,
    /// The vortex and its strength as a velocity (M1c's `Γ''`).
    pub vortex: Option<(Swirl, Strength)>,
    /// Fine units to a unit speed, `W = S 2^F`, as `(S, F)`.
    pub unit: (u32, i32),
    pub dim: usize,
    /// M1c's `C`: `2^16 / (1 + dt rate)`, the weight of the velocity.
    pub keep: i32,
    /// M5.1c's turbulence of this step.
    pub turbulence: Option<Eddies>,
}

impl Flow<'_> {
    /// The flow at cell `pos` (dense index `cell`), in fine units.
    #[inline]
    pub fn at(&self, pos: [usize; 3], cell: usize) -> [i32; 3] {
        let mut u = self.wind.map(i64::from);
        if let Some(field) = self.field {
            for a in 0..self.dim {
                u[a] += i64::from(to_fine(field[cell * self.dim + a], self.unit));
            }
        }
        if let Some((v, gamma)) = self.vortex {
            let t = v.at(pos, gamma);
            u[0] += t[0];
            u[1] += t[1];
        }
        if let Some(eddies) = &self.turbulence {
            let t = eddies.at(pos);
            for a in 0..self.dim {
                u[a] += t[a];
            }
        }
        u.map(sat)
    }
}

/// The static Rankine vortex in integers (M1c), converted once a step:
/// tangential, of magnitude `G/(2 pi) * r/R^2` inside the core and
/// `G/(2 pi r)` outside, which is `G/(2 pi) * (-dy, dx) / max(r^2, R^2)`:
/// no square root. Positions are in units of `2^-8` cells.
#[derive(Clone, Copy)]
pub(crate) struct Swirl {
    /// The centre, `round(c 2^8)`.
    centre: [i64; 2],
    /// `round(R 2^8)`, at most [`REACH`].
    core: u32,
    /// `G / (2 pi)` ([`quot`]), the one float the pushes are converted
    /// from.
    strength: f32,
}

/// The largest offset of a cell from the centre, in `2^-8` cells: `2^20`
/// cells, beyond which a cell's offset is cut.
const REACH: i64 = 1 << 28;

/// A vortex's strength as a push (M1c's `Γ'` or `Γ''`) kept as its top 16
/// bits and their place, `g 2^e` with `2^15 <= |g| < 2^16` (`g` 0 for no
/// strength), so that a particle's push needs only 32-bit products.
#[derive(Clone, Copy, Default)]
#[repr(C)]
pub(crate) struct Strength {
    /// The top 16 bits of the magnitude, with the strength's sign.
    pub(crate) g: i32,
    /// The place of `g`'s lowest bit.
    pub(crate) e: i32,
}

impl Strength {
    /// M1c's `top(x)`: the top 16 bits of `|x|`, rounded down.
    pub(crate) fn of(x: i64) -> Strength {
        let m = x.unsigned_abs();
        if m == 0 {
            return Strength::default();
        }
        let b = 64 - m.leading_zeros() as i32;
        let g = if b > 16 { m >> (b - 16) } else { m << (16 - b) } as i32;
        Strength { g: if x < 0 { -g } else { g }, e: b - 16 }
    }
}

impl Swirl {
    /// The vortex `v` converted.
    pub(crate) fn of(v: &Vortex) -> Swirl {
        let core = scaled(v.core_radius, 1.0, 8).clamp(0, REACH);
        Swirl {
            centre: [scaled(v.centre[0], 1.0, 8), scaled(v.centre[1], 1.0, 8)],
            core: core as u32,
            strength: {
                let q = quot(magnitude(v.circulation), magnitude(core::f32::consts::TAU), 0);
                if v.circulation.is_sign_negative() { -q } else { q }
            },
        }
    }

    /// The strength in fine units per `2^-8` cell for a factor `k` in a
    /// world whose unit speed is `(s, fine)` ([`unit_scale`](crate::rules::fixed::unit_scale)):
    /// M1c's `top(conv(G / (2 pi), k W, 8))`.
    /// The centre (`2^-8` cells) and the core radius (`2^-8` cells) as
    /// the step reads them, for a second implementation (`port`).
    pub(crate) fn integers(&self) -> ([i64; 2], u32) {
        (self.centre, self.core)
    }

    #[inline]
    pub(crate) fn gamma(&self, k: f32, (s, fine): (u32, i32)) -> Strength {
        Strength::of(scaled_by(self.strength, k, s, fine + 8))
    }

    /// The push at the centre of cell `pos` for strength `gamma`: each
    /// component `gamma d / max(|d|^2, R^2)`, its magnitude rounded down
    /// and the sign applied after, so that the field stays antisymmetric
    /// about the centre (M1c gives every rounding). The offsets are cut
    /// to 15 bits and the squared length to its top 16, so that every
    /// product and the one division fit 32 bits (a GPU has no wider
    /// integers, a small core no 64-bit divide).
    #[cfg_attr(feature = "small-step", inline)]
    #[cfg_attr(not(feature = "small-step"), inline(always))]
    pub(crate) fn at(&self, pos: [usize; 3], gamma: Strength) -> [i64; 2] {
        let d = |a: usize| (((pos[a] as i64) << 8) + 128 - self.centre[a]).clamp(-REACH, REACH);
        let (dx, dy) = (d(0), d(1));
        let (ax, ay) = (dx.unsigned_abs() as u32, dy.unsigned_abs() as u32);
        let big = ax.max(ay).max(self.core);
        if big == 0 || gamma.g == 0 {
            return [0, 0];
        }
        let cut = (32 - big.leading_zeros()).saturating_sub(15);
        let (ax, ay, core) = (ax >> cut, ay >> cut, self.core >> cut);
        let n = (ax * ax + ay * ay).max(core * core);
        let b = 32 - n.leading_zeros() as i32;
        let top = if b > 16 { n >> (b - 16) } else { n << (16 - b) };
        let f = quotient16(gamma.g.unsigned_abs() << 15, top);
        let e = gamma.e - cut as i32 - b + 1;
        let signed = |a: u32, negative: bool| {
            let y = u64::from(f * a);
            let m = if e < 0 { y >> -e } else if y > SCALED_MAX >> e { SCALED_MAX } else { y << e } as i64;
            if negative != (gamma.g < 0) { -m } else { m }
        };
        [signed(ay, dy > 0), signed(ax, dx < 0)]
    }
}

#[cfg(test)]
mod tests {
    extern crate std;

    use super::*;

    #[test]
    fn rankine_profile() {
        // Expect: with a push of 2^16 fine units per unit of force, the
        // force r / R^2 inside the core and 1 / r outside (G = 2 pi),
        // tangential and counter-clockwise, to a fine unit; none at the
        // centre.
        let v = Swirl::of(&Vortex { centre: [0.5, 0.5], core_radius: 2.0, circulation: core::f32::consts::TAU });
        let g = v.gamma(65536.0, (1, 0));
        // One cell to the right of the centre: 1/4 of 2^16.
        assert_eq!(v.at([1, 0, 0], g), [0, 16384]);
        // Four cells up: outside the core, 1/4 pointing -x.
        assert_eq!(v.at([0, 4, 0], g), [-16384, 0]);
        assert_eq!(v.at([0, 0, 0], g), [0, 0]);
    }

    #[test]
    fn the_push_is_the_quotient_to_its_bound() {
        // Expect: each component of the push within M1c's bound of
        // G d / max(|d|^2, R^2) computed exactly in 128 bits (G the
        // strength before its cut to 16 bits): 2^-11 of
        // |G| max(|dx|, |dy|, R) / max(|d|^2, R^2), plus a unit, with
        // saturation at 2^59. Offsets from 0 to 2^28 and strengths from 1
        // to 2^59, each of a random bit length.
        let mut rng = crate::rules::rng::block_stream(41, 0, 0);
        let mut worst = 0f64;
        for _ in 0..crate::sized(20_000, 500) {
            let mut length = |most: u32| {
                let word = u64::from(rng.bits(32)) << 32 | u64::from(rng.bits(32));
                let bits = rng.bits(8) % (most + 1);
                if bits == 0 { 0 } else { word >> (64 - bits) }
            };
            let strength = length(59) as i64 * if length(1) == 0 { 1 } else { -1 };
            let core = length(28) as i64;
            let centre = [length(28) as i64, length(28) as i64];
            let v = Swirl { centre, core: core as u32, strength: 0.0 };
            let pos = [length(20) as usize, length(20) as usize, 0];
            let got = v.at(pos, Strength::of(strength));
            let d = [0, 1].map(|a| (((pos[a] as i64) << 8) + 128 - centre[a]).clamp(-REACH, REACH) as i128);
            let r2 = (d[0] * d[0] + d[1] * d[1]).max(i128::from(core) * i128::from(core));
            if r2 == 0 {
                assert_eq!(got, [0, 0]);
                continue;
            }
            let g = i128::from(strength);
            let big = d[0].abs().max(d[1].abs()).max(i128::from(core));
            let bound = (g.abs() * big) as f64 / r2 as f64 / 2048.0 + 1.0;
            for (k, want) in [-g * d[1] / r2, g * d[0] / r2].into_iter().enumerate() {
                let want = want.clamp(-(1 << 59), 1 << 59);
                let off = (i128::from(got[k]) - want).abs() as f64;
                assert!(off <= bound, "{strength} {core} {centre:?} {pos:?}: {got:?}, want {want}");
                if want.abs() < 1 << 59 {
                    worst = worst.max((off - 1.0) / (bound - 1.0));
                }
            }
        }
        std::println!("worst error {worst:.3} of the bound");
    }

    #[test]
    fn a_core_too_small_to_store_gives_no_force_at_the_centre() {
        for circulation in [0.0, 1.0, -3e38] {
            let v = Swirl::of(&Vortex { centre: [4.5, 4.5], core_radius: 1e-30, circulation });
            let g = v.gamma(1e6, (1, 0));
            assert_eq!(v.at([4, 4, 0], g), [0, 0], "{circulation}");
            // On an axis through the centre: no component across it.
            assert_eq!(v.at([4, 5, 0], g)[1], 0, "{circulation}");
        }
    }
}
