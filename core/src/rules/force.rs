//! External forces (M5.1, eqs. 4-6): `v <- v + dt F / m`, with `F` the sum of
//! the terms the description enables, in fine units (M1c). A uniform
//! acceleration is the same push for every mass; the other terms are
//! forces, each turned into a push by the exact product with its mass
//! class's `K = dt / m` and `W`, rounded. And the flow that drag relaxes
//! velocities towards (M5.1b).

use crate::api::desc::Vortex;
use crate::rules::fixed::{magnitude, quot, sat, scaled, scaled_by, to_fine, udiv, SCALED_MAX};
use crate::rules::class::Class;

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
        // (`Layout::of`), and the build no code for them.
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
/// read as a velocity, in fine units (M1c).
pub(crate) struct Flow<'a> {
    /// The uniform wind (M1c's `U`).
    pub wind: [i32; 3],
    pub field: Option<&'a [f32]>,
    /// The vortex and its strength as a velocity (M1c's `Γ''`).
    pub vortex: Option<(Swirl, i64)>,
    /// Fine units to a unit speed, `W = S 2^F`, as `(S, F)`.
    pub unit: (u32, i32),
    pub dim: usize,
    /// M1c's `C`: `2^16 / (1 + dt rate)`, the weight of the velocity.
    pub keep: i32,
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
    /// `round(R 2^8)^2`.
    core2: i64,
    /// `G / (2 pi)` ([`quot`]), the one float the pushes are converted
    /// from.
    strength: f32,
}

/// The largest offset of a cell from the centre, in `2^-8` cells: `2^20`
/// cells, beyond which a cell's offset is cut.
const REACH: i64 = 1 << 28;

impl Swirl {
    /// The vortex `v` converted.
    pub(crate) fn of(v: &Vortex) -> Swirl {
        let core = scaled(v.core_radius, 1.0, 8).clamp(0, REACH);
        Swirl {
            centre: [scaled(v.centre[0], 1.0, 8), scaled(v.centre[1], 1.0, 8)],
            core2: core * core,
            strength: {
                let q = quot(magnitude(v.circulation), magnitude(core::f32::consts::TAU), 0);
                if v.circulation.is_sign_negative() { -q } else { q }
            },
        }
    }

    /// The strength in fine units per `2^-8` cell for a factor `k` in a
    /// world whose unit speed is `(s, fine)` ([`unit_scale`](crate::rules::fixed::unit_scale)):
    /// M1c's `Γ' = conv(G / (2 pi), k W, 8)`, saturated at `2^59`.
    #[inline]
    pub(crate) fn gamma(&self, k: f32, (s, fine): (u32, i32)) -> i64 {
        scaled_by(self.strength, k, s, fine + 8)
    }

    /// The push at the centre of cell `pos` for strength `gamma`, each
    /// component `gamma d / max(|d|^2, R^2)` rounded toward zero, so that
    /// the field stays antisymmetric about the centre ([`ratio`]). Zero at
    /// the centre, for any core.
    #[inline]
    pub(crate) fn at(&self, pos: [usize; 3], gamma: i64) -> [i64; 2] {
        let d = |a: usize| (((pos[a] as i64) << 8) + 128 - self.centre[a]).clamp(-REACH, REACH);
        let (dx, dy) = (d(0), d(1));
        let r2 = ((dx * dx + dy * dy) as u64).max(self.core2 as u64);
        if r2 == 0 {
            return [0, 0];
        }
        let g = gamma.unsigned_abs();
        let signed = |d: i64, negative: bool| {
            let m = ratio(g, d.unsigned_abs(), r2) as i64;
            if negative != (gamma < 0) { -m } else { m }
        };
        [signed(dy, dy > 0), signed(dx, dx < 0)]
    }
}

/// `g a / r2` rounded down, for `g` up to `2^59`, `a` up to `2^28` and
/// `r2` from 1 to `2^57`, without a product wider than 64 bits: the whole
/// part of `g / r2` times `a`, saturating, plus the remainder's share
/// (exact while `r2` is below `2^35`: cells within 724 of the centre),
/// with the remainder and `r2` cut to 35 bits first, which may move the
/// result by a unit. The result saturates at `2^59`.
fn ratio(g: u64, a: u64, r2: u64) -> u64 {
    let whole = udiv(g, r2);
    let rest = g - whole * r2;
    let cut = (64 - r2.leading_zeros()).saturating_sub(35);
    let part = udiv((rest >> cut) * a, r2 >> cut);
    whole.saturating_mul(a).saturating_add(part).min(SCALED_MAX)
}

#[cfg(test)]
mod tests {
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
    fn the_ratio_is_the_quotient() {
        // Expect: floor(g a / r2) computed in 128 bits, to a unit (the
        // cut remainder), saturated at 2^59.
        let mut rng = crate::rules::rng::block_stream(41, 0, 0);
        for _ in 0..crate::sized(20_000, 500) {
            let g = rng.next_u64() >> (3 + rng.bits(6) % 60);
            let a = u64::from(rng.bits(28));
            let r2 = (rng.next_u64() >> (7 + rng.bits(6) % 57)).max(1);
            let want = (u128::from(g) * u128::from(a) / u128::from(r2)).min(1 << 59) as u64;
            let got = ratio(g, a, r2);
            assert!(got.abs_diff(want) <= 1, "{g} {a} {r2}: {got} vs {want}");
        }
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
