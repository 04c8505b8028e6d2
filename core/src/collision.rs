//! Particle-particle collision (M5.2, eqs. 7-8) and the speed clamp (M5.5).

use rand_core::Rng;

use crate::rng::unit;

/// Cell pairs of a block, in a fixed order: `PAIRS_2D` has the C(4,2) = 6
/// pairs of a 2D block, `PAIRS_3D` the C(8,2) = 28 of a 3D one. M5.2 picks
/// one uniformly.
pub(crate) const PAIRS_2D: [(u8, u8); 6] = pairs::<6>(4);
pub(crate) const PAIRS_3D: [(u8, u8); 28] = pairs::<28>(8);

const fn pairs<const P: usize>(cells: u8) -> [(u8, u8); P] {
    let mut out = [(0u8, 0u8); P];
    let mut i = 0;
    let mut a = 0;
    while a < cells {
        let mut b = a + 1;
        while b < cells {
            out[i] = (a, b);
            i += 1;
            b += 1;
        }
        a += 1;
    }
    out
}

/// The pairs of a block of dimension `D`.
#[inline]
pub(crate) fn block_pairs<const D: usize>() -> &'static [(u8, u8)] {
    if D == 2 { &PAIRS_2D } else { &PAIRS_3D }
}

#[inline]
pub(crate) fn dot(a: [f32; 3], b: [f32; 3]) -> f32 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A uniformly random unit vector: `(cos t, sin t)` with `t` uniform in
/// `[0, 2 pi)` in 2D, uniform on the sphere in 3D (z uniform in `[-1, 1]`,
/// azimuth uniform: Archimedes' hat-box theorem).
#[inline]
pub(crate) fn random_unit<const D: usize, R: Rng + ?Sized>(rng: &mut R) -> [f32; 3] {
    let t = core::f32::consts::TAU * unit(rng);
    let (s, c) = libm::sincosf(t);
    if D == 2 {
        [c, s, 0.0]
    } else {
        let z = 2.0 * unit(rng) - 1.0;
        let r = libm::sqrtf((1.0 - z * z).max(0.0));
        [r * c, r * s, z]
    }
}

/// Eqs. 7-8: the velocities after a collision of masses `ma`, `mb` with
/// restitution `e` and random unit vector `r`. Momentum is conserved exactly
/// in real arithmetic, and the relative speed is scaled by `e`.
#[inline]
pub(crate) fn collide_pair(va: [f32; 3], vb: [f32; 3], ma: f32, mb: f32, e: f32, r: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let total = ma + mb;
    // Mass shares computed as ratios, so extreme masses (1e-30 with 1e30)
    // neither overflow nor turn into NaN: each share lies in [0, 1].
    let (sa, sb) = if total.is_finite() && total > 0.0 {
        (ma / total, mb / total)
    } else {
        let ratio = mb / ma;
        (1.0 / (1.0 + ratio), ratio / (1.0 + ratio))
    };
    let rel = [va[0] - vb[0], va[1] - vb[1], va[2] - vb[2]];
    let speed = libm::sqrtf(dot(rel, rel));
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    for k in 0..3 {
        let v0 = sa * va[k] + sb * vb[k]; // centre-of-mass velocity V0
        a[k] = v0 + e * sb * speed * r[k]; // eq. 7
        b[k] = v0 - e * sa * speed * r[k]; // eq. 8
    }
    (a, b)
}

/// M5.5: scales `v` back to `|v| = 1` if it is longer, returning the kinetic
/// energy that removed for mass `m` (`None` if nothing changed).
///
/// A velocity that overflowed `f32` (a force of 1e30 over a mass of 1e-30)
/// keeps its direction: infinite components become unit ones and finite
/// ones vanish beside them; a component left undefined (`inf - inf`) counts
/// as zero. The energy removed is then reported as infinite.
#[inline]
pub(crate) fn clamp(v: &mut [f32; 3], m: f32) -> Option<f64> {
    let s2 = dot(*v, *v);
    if s2 <= 1.0 {
        return None;
    }
    if !s2.is_finite() {
        let big = v.iter().filter(|c| !c.is_nan()).fold(0.0f32, |b, c| b.max(c.abs()));
        for c in v.iter_mut() {
            *c = if c.is_nan() || big == 0.0 {
                0.0
            } else if big.is_infinite() {
                if c.is_infinite() { c.signum() } else { 0.0 }
            } else if big > 1.0 {
                *c / big
            } else {
                // Only a NaN made the length undefined; what is left is
                // already short enough and keeps its size.
                *c
            };
        }
        let _ = clamp(v, m);
        return Some(f64::INFINITY);
    }
    let inv = 1.0 / libm::sqrtf(s2);
    for c in v.iter_mut() {
        *c *= inv;
    }
    Some(0.5 * f64::from(m) * (f64::from(s2) - 1.0))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rng::block_stream;

    #[test]
    fn pair_tables_list_each_pair_once() {
        assert_eq!(PAIRS_2D, [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]);
        for (i, &(a, b)) in PAIRS_3D.iter().enumerate() {
            assert!(a < b && b < 8);
            assert!(!PAIRS_3D[..i].contains(&(a, b)));
        }
    }

    #[test]
    fn collision_conserves_momentum_and_scales_relative_speed() {
        let mut rng = block_stream(11, 0, 0);
        for _ in 0..1000 {
            let r = random_unit::<3, _>(&mut rng);
            let va = [0.3, -0.2, 0.1];
            let vb = [-0.4, 0.5, 0.0];
            let (ma, mb, e) = (2.0, 0.5, 0.7);
            let (a, b) = collide_pair(va, vb, ma, mb, e, r);
            let mut rel_before = 0.0;
            let mut rel_after = 0.0;
            for k in 0..3 {
                let p0 = ma * va[k] + mb * vb[k];
                let p1 = ma * a[k] + mb * b[k];
                assert!((p0 - p1).abs() < 1e-6, "momentum {p0} {p1}");
                rel_before += (va[k] - vb[k]) * (va[k] - vb[k]);
                rel_after += (a[k] - b[k]) * (a[k] - b[k]);
            }
            assert!((libm::sqrtf(rel_after) - e * libm::sqrtf(rel_before)).abs() < 1e-5);
        }
    }

    #[test]
    fn extreme_masses_stay_finite() {
        let r = [1.0, 0.0, 0.0];
        for (ma, mb) in [(1e-30, 1e30), (1e30, 1e-30), (3e38, 3e38), (1e-45, 1e-45)] {
            let (a, b) = collide_pair([0.5, 0.0, 0.0], [-0.5, 0.0, 0.0], ma, mb, 1.0, r);
            assert!(a.iter().chain(b.iter()).all(|c| c.is_finite()), "{ma} {mb}: {a:?} {b:?}");
        }
    }

    #[test]
    fn random_units_are_unit() {
        let mut rng = block_stream(5, 0, 0);
        for _ in 0..1000 {
            for r in [random_unit::<2, _>(&mut rng), random_unit::<3, _>(&mut rng)] {
                assert!((dot(r, r) - 1.0).abs() < 1e-5);
            }
        }
    }

    #[test]
    fn clamp_survives_overflow() {
        // Expectation: a finite unit vector along the overflowing direction,
        // zero where the direction is undefined, and infinite energy removed.
        for (v, want) in [
            ([f32::INFINITY, 1.0, 0.0], [1.0, 0.0, 0.0]),
            ([f32::NEG_INFINITY, f32::INFINITY, 0.0], [-core::f32::consts::FRAC_1_SQRT_2, core::f32::consts::FRAC_1_SQRT_2, 0.0]),
            ([3e38, 3e38, 0.0], [core::f32::consts::FRAC_1_SQRT_2, core::f32::consts::FRAC_1_SQRT_2, 0.0]),
            ([f32::NAN, 0.0, 2.0], [0.0, 0.0, 1.0]),
            ([f32::NAN, 0.25, 0.0], [0.0, 0.25, 0.0]),
            ([f32::NAN, f32::NAN, f32::NAN], [0.0, 0.0, 0.0]),
        ] {
            let mut u = v;
            assert_eq!(clamp(&mut u, 1.0), Some(f64::INFINITY), "{v:?}");
            for k in 0..3 {
                assert!((u[k] - want[k]).abs() < 1e-6, "{v:?} -> {u:?}");
            }
        }
    }

    #[test]
    fn clamp_reports_removed_energy() {
        let mut v = [0.6, 0.8, 0.0];
        assert_eq!(clamp(&mut v, 1.0), None);
        let mut v = [2.0, 0.0, 0.0];
        assert_eq!(clamp(&mut v, 2.0), Some(3.0));
        assert_eq!(v, [1.0, 0.0, 0.0]);
    }
}
