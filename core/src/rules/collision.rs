//! Particle-particle collision (M5.2, eqs. 7-8).

use crate::rules::rng::Stream;
use crate::rules::vector::{div, dot_of, normalise, small_to_f32};

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

/// Per block occupancy mask, the pairs (by their index in `PAIRS_2D` or
/// `PAIRS_3D`) whose two cells both hold a particle: one look-up decides
/// whether the pair M5.2 drew collides.
static HOLDS_TWO_2D: [u32; 16] = holds_two::<6, 16>(&PAIRS_2D);
static HOLDS_TWO_3D: [u32; 256] = holds_two::<28, 256>(&PAIRS_3D);

const fn holds_two<const P: usize, const M: usize>(pairs: &[(u8, u8); P]) -> [u32; M] {
    let mut t = [0u32; M];
    let mut mask = 0;
    while mask < M {
        let mut p = 0;
        while p < P {
            let (a, b) = pairs[p];
            if mask >> a & mask >> b & 1 != 0 {
                t[mask] |= 1 << p;
            }
            p += 1;
        }
        mask += 1;
    }
    t
}

/// Whether both cells of pair `p` of a block with occupancy `occ` hold a
/// particle.
#[inline]
pub(crate) fn pair_holds_two<const D: usize>(occ: u8, p: u32) -> bool {
    let table: &[u32] = if D == 2 { &HOLDS_TWO_2D } else { &HOLDS_TWO_3D };
    table[usize::from(occ) & (table.len() - 1)] >> p & 1 != 0
}

/// The pairs of a block of dimension `D`.
#[inline]
pub(crate) fn block_pairs<const D: usize>() -> &'static [(u8, u8)] {
    if D == 2 { &PAIRS_2D } else { &PAIRS_3D }
}

/// M5.2's pair of a block with occupancy `occ`: one of the block's pairs,
/// uniformly (16 bits of the stream, drawn only where the block holds two
/// particles or more); its two cells where both hold a particle.
#[inline]
pub(crate) fn pick_pair<const D: usize>(occ: u8, rng: &mut Stream) -> Option<(usize, usize)> {
    if occ & occ.wrapping_sub(1) == 0 {
        return None;
    }
    let pairs = block_pairs::<D>();
    let p = rng.below(pairs.len() as u32);
    pair_holds_two::<D>(occ, p).then(|| {
        let (a, c) = pairs[p as usize];
        (usize::from(a), usize::from(c))
    })
}

/// A uniformly random unit vector (the `R` of eqs. 7-8): uniform on the
/// circle in 2D, on the sphere in 3D, the third component 0 in 2D.
///
/// Rejection sampling instead of `(cos t, sin t)`: a point uniform in the
/// square (cube) `[-1, 1]^D` on a grid of 2^-15, kept when it lies in the
/// shell `1/8 < r <= 1` (about 77 % of tries in 2D, 52 % in 3D), then
/// scaled to unit length. Its direction is uniform, and the inner bound
/// keeps the grid finer than 2.5e-4 rad in angle. One square root, no
/// `sincosf`; each try takes 32 bits (2D) or 48 (3D) of the stream.
#[inline]
pub(crate) fn random_unit<const D: usize>(rng: &mut Stream) -> [f32; 3] {
    // Bits to a coordinate in (-1, 1), symmetric about 0.
    let coord = |b: u32| (small_to_f32(b) - 32767.5) * (1.0 / 32768.0);
    loop {
        let xy = rng.bits(32);
        let z = if D == 3 { coord(rng.bits(16)) } else { 0.0 };
        let v = [coord(xy & 0xffff), coord(xy >> 16), z];
        let r2 = dot_of::<D>(v, v);
        if r2 > 1.0 / 64.0 && r2 <= 1.0 {
            let inv = div(1.0, crate::rules::vector::sqrt(r2));
            return v.map(|c| c * inv);
        }
    }
}

/// The mass shares `(ma / (ma + mb), mb / (ma + mb))` of eqs. 7-8,
/// computed as ratios so extreme masses (1e-30 with 1e30) neither overflow
/// nor turn into NaN: each share lies in `[0, 1]`. Equal masses give
/// `(0.5, 0.5)`, which a world of one mass uses without dividing.
#[inline]
pub(crate) fn shares(ma: f32, mb: f32) -> (f32, f32) {
    let total = ma + mb;
    if total.is_finite() && total > 0.0 {
        (div(ma, total), div(mb, total))
    } else {
        let ratio = div(mb, ma);
        (div(1.0, 1.0 + ratio), div(ratio, 1.0 + ratio))
    }
}

/// Eqs. 7-8: the velocities after a collision of particles with mass shares
/// `(sa, sb)` (see [`shares`]), restitution `e` and random unit vector `r`.
/// Momentum is conserved exactly in real arithmetic, and the relative speed
/// is scaled by `e`. Components from `D` on are 0 in and out.
#[inline]
pub(crate) fn collide_pair<const D: usize>(va: [f32; 3], vb: [f32; 3], (sa, sb): (f32, f32), e: f32, r: [f32; 3]) -> ([f32; 3], [f32; 3]) {
    let rel = [va[0] - vb[0], va[1] - vb[1], va[2] - vb[2]];
    let speed = e * crate::rules::vector::sqrt(dot_of::<D>(rel, rel));
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    for k in 0..D {
        let v0 = sa * va[k] + sb * vb[k]; // centre-of-mass velocity V0
        a[k] = v0 + sb * speed * r[k]; // eq. 7
        b[k] = v0 - sa * speed * r[k]; // eq. 8
    }
    (a, b)
}

/// M5.2b: eqs. 7-8 with `R` uniform among the directions for which both
/// outgoing speeds are at most `limit` (in the velocities' unit), by
/// drawing `R` again until they are. Such directions always exist: `R`
/// along `va - vb` gives each particle a weighted mean of the two incoming
/// velocities (`(sa + sb e) va + sb (1 - e) vb` for `a`), no faster than
/// the faster of them. After [`SPEED_LIMIT_TRIES`] refused draws (a set of
/// admissible directions too small to hit), that direction is taken.
#[inline]
pub(crate) fn collide_limited<const D: usize>(
    va: [f32; 3],
    vb: [f32; 3],
    s: (f32, f32),
    e: f32,
    limit: f32,
    rng: &mut Stream,
) -> ([f32; 3], [f32; 3]) {
    let fits = |v: [f32; 3]| dot_of::<D>(v, v) <= limit * limit;
    for _ in 0..SPEED_LIMIT_TRIES {
        let (a, b) = collide_pair::<D>(va, vb, s, e, random_unit::<D>(rng));
        if fits(a) && fits(b) {
            return (a, b);
        }
    }
    let rel = [va[0] - vb[0], va[1] - vb[1], va[2] - vb[2]];
    // rel = 0 leaves both at V0 whatever R is; an axis will do.
    collide_pair::<D>(va, vb, s, e, normalise(rel).unwrap_or([1.0, 0.0, 0.0]))
}

/// M1b: the pair `(a, b)`, just collided, with mass shares `(sa, sb)` and
/// velocities in quanta, with its relative velocity shrunk about the
/// centre of mass so that the kinetic energy it loses equals what the
/// stochastic rounding of both (M1) adds on average: rounding `x` adds
/// `f (1 - f)` quanta^2 per component, `f` its fraction, times `m / 2`. Both
/// sides are divided by the pair's mass, so only the shares appear:
/// `sa sb |a - b|^2 (1 - l^2) = sa Fa + sb Fb` with `F` the summed
/// `f (1 - f)`. Momentum is untouched; a pair with less relative energy
/// than that ends at its centre-of-mass velocity. Components from `D` on
/// are 0 in and out.
#[inline]
pub(crate) fn energy_neutral<const D: usize>(a: [f32; 3], b: [f32; 3], (sa, sb): (f32, f32)) -> ([f32; 3], [f32; 3]) {
    let gain = |x: [f32; 3]| {
        x[..D].iter().fold(0.0, |sum, &c| {
            let m = c.abs();
            let f = m - m as i32 as f32; // the fraction; f (1 - f) is even in c
            sum + f * (1.0 - f)
        })
    };
    let rel = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let kinetic = sa * sb * dot_of::<D>(rel, rel);
    let lost = sa * gain(a) + sb * gain(b);
    let l = if kinetic > lost { crate::rules::vector::sqrt(1.0 - div(lost, kinetic)) } else { 0.0 };
    let mut out = (a, b);
    for k in 0..D {
        let v0 = sa * a[k] + sb * b[k];
        out.0[k] = v0 + l * (a[k] - v0);
        out.1[k] = v0 + l * (b[k] - v0);
    }
    out
}

/// Draws of `R` M5.2b makes before it takes the direction of the relative
/// velocity.
pub(crate) const SPEED_LIMIT_TRIES: u32 = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::rng::block_stream;
    use crate::rules::vector::dot;

    #[test]
    fn pair_tables_list_each_pair_once() {
        assert_eq!(PAIRS_2D, [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]);
        for (i, &(a, b)) in PAIRS_3D.iter().enumerate() {
            assert!(a < b && b < 8);
            assert!(!PAIRS_3D[..i].contains(&(a, b)));
        }
    }

    #[test]
    fn pair_look_up_matches_the_cells() {
        for occ in 0..16u8 {
            for (p, &(a, b)) in PAIRS_2D.iter().enumerate() {
                assert_eq!(pair_holds_two::<2>(occ, p as u32), occ >> a & occ >> b & 1 != 0);
            }
        }
        for occ in 0..=255u8 {
            for (p, &(a, b)) in PAIRS_3D.iter().enumerate() {
                assert_eq!(pair_holds_two::<3>(occ, p as u32), occ >> a & occ >> b & 1 != 0);
            }
        }
    }

    #[test]
    fn collision_conserves_momentum_and_scales_relative_speed() {
        let mut rng = block_stream(11, 0, 0);
        for _ in 0..crate::sized(1000, 100) {
            let r = random_unit::<3>(&mut rng);
            let va = [0.3, -0.2, 0.1];
            let vb = [-0.4, 0.5, 0.0];
            let (ma, mb, e) = (2.0, 0.5, 0.7);
            let (a, b) = collide_pair::<3>(va, vb, shares(ma, mb), e, r);
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
    fn speed_limited_collisions_stay_below_the_limit_and_keep_momentum() {
        // Expect: outgoing speeds <= 1 for any incoming pair at or below 1,
        // momentum as eqs. 7-8 keep it, the relative speed scaled by e; and
        // for a pair whose admissible directions are a sliver (both fast,
        // nearly parallel, e = 1) the fallback still fits.
        let mut rng = block_stream(12, 0, 0);
        let fits = |v: [f32; 3]| dot(v, v) <= 1.0;
        for i in 0..crate::sized(4000, 200) {
            let v = |rng: &mut Stream| random_unit::<3>(rng).map(|c| c * rng.unit());
            let (va, vb) = if i % 4 == 0 { ([0.99, 0.1, 0.0], [0.99, -0.12, 0.0]) } else { (v(&mut rng), v(&mut rng)) };
            let (ma, mb) = (1.0 + (i % 3) as f32, 1.0);
            let e = [1.0, 0.5, 0.9][i % 3];
            let (a, b) = collide_limited::<3>(va, vb, shares(ma, mb), e, 1.0, &mut rng);
            assert!(fits(a) && fits(b), "{va:?} {vb:?} -> {a:?} {b:?}");
            let (mut rel_before, mut rel_after) = (0.0, 0.0);
            for k in 0..3 {
                assert!((ma * va[k] + mb * vb[k] - ma * a[k] - mb * b[k]).abs() < 1e-5);
                rel_before += (va[k] - vb[k]) * (va[k] - vb[k]);
                rel_after += (a[k] - b[k]) * (a[k] - b[k]);
            }
            assert!((libm::sqrtf(rel_after) - e * libm::sqrtf(rel_before)).abs() < 1e-5);
        }
    }

    #[test]
    fn energy_neutral_pairs_keep_the_expected_energy_after_rounding() {
        // Expect: for pairs in quanta (8-bit scale), the kinetic energy after
        // compensation plus what rounding then adds on average (half the
        // mass times f (1 - f) per component) is the energy before. The
        // compensation is computed from the fractions before the pair is
        // scaled; f (1 - f) moves by at most as much as the fraction does,
        // so the two differ by at most half the mass times the distance
        // each component moved (plus f32 rounding). Momentum unchanged.
        let mut rng = block_stream(13, 0, 0);
        let energy = |x: [f32; 3], m: f32| 0.5 * m * dot(x, x);
        let gain = |x: [f32; 3], m: f32| x.iter().map(|c| { let f = c.abs() - c.abs().floor(); 0.5 * m * f * (1.0 - f) }).sum::<f32>();
        let (mut moves, mut gains) = (0.0, 0.0);
        for i in 0..crate::sized(2000, 200) {
            let a = random_unit::<3>(&mut rng).map(|c| c * 127.0 * rng.unit());
            let b = random_unit::<3>(&mut rng).map(|c| c * 127.0 * rng.unit());
            let (ma, mb) = (1.0 + (i % 4) as f32, 1.0);
            let (a2, b2) = energy_neutral::<3>(a, b, shares(ma, mb));
            let before = f64::from(energy(a, ma) + energy(b, mb));
            let after = f64::from(energy(a2, ma) + energy(b2, mb) + gain(a2, ma) + gain(b2, mb));
            let moved = |x: [f32; 3], y: [f32; 3], m: f32| 0.5 * m * (0..3).map(|k| (x[k] - y[k]).abs()).sum::<f32>();
            let bound = f64::from(moved(a, a2, ma) + moved(b, b2, mb)) + 1e-6 * before;
            assert!((after - before).abs() <= bound, "{i}: {before} -> {after} (bound {bound})");
            moves += f64::from(moved(a, a2, ma) + moved(b, b2, mb));
            gains += f64::from(gain(a, ma) + gain(b, mb));
            for k in 0..3 {
                assert!((ma * a[k] + mb * b[k] - ma * a2[k] - mb * b2[k]).abs() < 1e-3, "momentum");
            }
        }
        // The bound is small against what is compensated: typical pairs move
        // by far less than a quantum.
        assert!(moves < 0.1 * gains, "moved {moves} against gains {gains}");
    }

    #[test]
    fn extreme_masses_stay_finite() {
        let r = [1.0, 0.0, 0.0];
        for (ma, mb) in [(1e-30, 1e30), (1e30, 1e-30), (3e38, 3e38), (1e-45, 1e-45)] {
            let (a, b) = collide_pair::<3>([0.5, 0.0, 0.0], [-0.5, 0.0, 0.0], shares(ma, mb), 1.0, r);
            assert!(a.iter().chain(b.iter()).all(|c| c.is_finite()), "{ma} {mb}: {a:?} {b:?}");
        }
    }

    #[test]
    fn random_units_are_unit_and_uniform() {
        // Expect: unit length; in 2D the angle's 12 sectors and in 3D the
        // 8 octants and 6 bands of z each get their binomial share of
        // 120,000 draws (3,000 under Miri) within 5 sd.
        let mut rng = block_stream(6, 0, 0);
        let n = crate::sized(120_000, 3_000);
        let check = |counts: &[u32]| {
            let p = 1.0 / counts.len() as f64;
            let sd = (n as f64 * p * (1.0 - p)).sqrt();
            for &c in counts {
                assert!((f64::from(c) - n as f64 * p).abs() < 5.0 * sd, "{counts:?}");
            }
        };
        let mut sectors = [0u32; 12];
        let (mut octants, mut bands) = ([0u32; 8], [0u32; 6]);
        for _ in 0..n {
            let r = random_unit::<2>(&mut rng);
            let t = libm::atan2f(r[1], r[0]);
            let t = if t < 0.0 { t + core::f32::consts::TAU } else { t };
            sectors[((t / core::f32::consts::TAU * 12.0) as usize).min(11)] += 1;
            let r = random_unit::<3>(&mut rng);
            octants[usize::from(r[0] > 0.0) | usize::from(r[1] > 0.0) << 1 | usize::from(r[2] > 0.0) << 2] += 1;
            // Archimedes: z is uniform on [-1, 1] for a uniform direction.
            bands[(((r[2] + 1.0) * 3.0) as usize).min(5)] += 1;
        }
        check(&sectors);
        check(&octants);
        check(&bands);
    }

    #[test]
    fn random_units_are_unit() {
        let mut rng = block_stream(5, 0, 0);
        for _ in 0..crate::sized(1000, 100) {
            for r in [random_unit::<2>(&mut rng), random_unit::<3>(&mut rng)] {
                assert!((dot(r, r) - 1.0).abs() < 1e-5);
            }
        }
    }
}
