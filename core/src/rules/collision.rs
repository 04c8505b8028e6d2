//! Particle-particle collision (M5.2, eqs. 7-8).

use crate::rules::rng::Stream;
use crate::rules::fixed::{divr, isqrt, mulq, rsqrt, sq, turn, udiv, TURNS};

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

/// `|d| R` for the `R` of eqs. 7-8, uniform on the circle (2D) or the
/// sphere (3D), with `d` in fine units (M1c).
///
/// In 2D, `d` turned by one of [`TURNS`] angles, uniformly (10 bits of the
/// stream): the turn keeps the length, so no square root. In 3D, a point
/// uniform in the cube of side `2^16` around 0 (three 16-bit draws, 48
/// bits a try) kept when it lies in the shell `2^13 < |p| <= 2^15` (about
/// 52 % of tries; the inner bound keeps the grid of directions fine),
/// scaled to the length of `d`: both lengths rounded to nearest, and the
/// quotient too, so that no step of it shortens the result on average.
#[inline]
pub(crate) fn turned<const D: usize>(d: [i32; 3], rng: &mut Stream) -> [i32; 3] {
    if D == 2 {
        let (c, s) = turn(rng.bits(TURNS.trailing_zeros()));
        return [mulq(d[0], c, 30) - mulq(d[1], s, 30), mulq(d[0], s, 30) + mulq(d[1], c, 30), 0];
    }
    turned_3d(d, rng)
}

/// [`turned`] in 3D, out of line: a rejection loop and two square roots,
/// which every routine that collides in 3D would otherwise copy.
#[inline(never)]
fn turned_3d(d: [i32; 3], rng: &mut Stream) -> [i32; 3] {
    let p = loop {
        let xy = rng.bits(32);
        let p = [(xy & 0xffff) as i32 - (1 << 15), (xy >> 16) as i32 - (1 << 15), rng.bits(16) as i32 - (1 << 15)];
        let r2 = sq::<3>(p);
        if r2 > 1 << 26 && r2 <= 1 << 30 {
            break p;
        }
    };
    let (length, radius) = (rsqrt(sq::<3>(d)), rsqrt(sq::<3>(p)));
    p.map(|c| {
        let m = divr(u64::from(c.unsigned_abs()) * length, radius) as i32;
        if c < 0 { -m } else { m }
    })
}

/// M1c's mass shares of eqs. 7-8 in Q16, `(A, 2^16 - A)` with `A` the
/// share of the particle of relative mass `ma` rounded to nearest: each in
/// `[0, 2^16]`, whatever the masses.
#[inline]
pub(crate) fn shares(ma: u32, mb: u32) -> (i32, i32) {
    let total = (u64::from(ma) + u64::from(mb)).max(1);
    let a = udiv((u64::from(ma) << 16) + total / 2, total);
    (a as i32, (1 << 16) - a as i32)
}

/// The shares of a pair of one mass.
pub(crate) const HALVES: (i32, i32) = (1 << 15, 1 << 15);

/// The masses of a colliding pair as M1c reads them: `None` for one mass,
/// else the relative masses `(M_a, M_b)`.
pub(crate) type Masses = Option<(u32, u32)>;

/// The velocity of the heavier particle of a pair after a stage changed
/// the lighter one from `light` to `light2` (M1c): what keeps the pair's
/// momentum, `heavy + M_l (light - light2) / M_h`, rounded to nearest. The
/// change is at most the lighter one's, so the rounding costs the heavier
/// particle half a fine unit at most.
#[inline]
fn balance(heavy: i32, light: i32, light2: i32, (m_heavy, m_light): (u32, u32)) -> i32 {
    let n = i64::from(m_light) * i64::from(light - light2);
    let m = i64::from(m_heavy.max(1));
    heavy + (2 * n + m).div_euclid(2 * m) as i32
}

/// A pair's two velocities after a stage gave them `a` and `b` from `va`
/// and `vb`: with one mass, `b` is the momentum less `a`, exactly; with
/// two, the heavier one is [`balance`]d against the lighter, so momentum
/// is kept to the rounding of a fine unit.
#[inline(always)]
fn conserve(va: i32, vb: i32, a: i32, b: i32, masses: Masses) -> (i32, i32) {
    match masses {
        None => (a, va + vb - a),
        // Equal masses take the second arm, which is then the one-mass
        // rule exactly: a world of classes of one mass is the world of one
        // mass (M9).
        Some((ma, mb)) if ma > mb => (balance(va, vb, b, (ma, mb)), b),
        Some((ma, mb)) => (a, balance(vb, va, a, (mb, ma))),
    }
}

/// Eqs. 7-8 in fine units (M1c): the velocities after a collision of
/// particles with velocities `va`, `vb`, mass shares `(A, B)` in Q16,
/// restitution `e` in Q16 and `t = |va - vb| R`. The lighter particle's
/// velocity comes from its equation; the other keeps the momentum
/// ([`conserve`]). Components from `D` on are 0 in and out.
///
/// Every input is within a unit speed (the clamp, M5.5, comes before):
/// `t` is at most twice that long, and no sum here leaves an `i32`.
#[inline(always)]
pub(crate) fn collide_pair<const D: usize>(va: [i32; 3], vb: [i32; 3], (sa, sb): (i32, i32), e: i32, t: [i32; 3], masses: Masses) -> ([i32; 3], [i32; 3]) {
    let mut a = [0; 3];
    let mut b = [0; 3];
    for k in 0..D {
        let v0 = vb[k] + mulq(va[k] - vb[k], sa, 16); // centre-of-mass velocity V0
        let u = mulq(t[k], e, 16);
        let ak = v0 + mulq(u, sb, 16); // eq. 7
        let bk = v0 - mulq(u, sa, 16); // eq. 8
        (a[k], b[k]) = conserve(va[k], vb[k], ak, bk, masses);
    }
    (a, b)
}

/// The difference `a - b` of the first `D` components.
#[inline(always)]
pub(crate) fn difference<const D: usize>(a: [i32; 3], b: [i32; 3]) -> [i32; 3] {
    let mut d = [0; 3];
    for k in 0..D {
        d[k] = a[k] - b[k];
    }
    d
}

/// M5.2b: eqs. 7-8 with `R` uniform among the directions for which both
/// outgoing squared speeds are at most `limit2` (fine units squared), by
/// drawing `R` again until they are. Such directions always exist: `R`
/// along `va - vb` gives each particle a weighted mean of the two incoming
/// velocities (`(sa + sb e) va + sb (1 - e) vb` for `a`), no faster than
/// the faster of them. After [`SPEED_LIMIT_TRIES`] refused draws (a set of
/// admissible directions too small to hit), that direction is taken, for
/// which `|va - vb| R` is `va - vb` itself.
///
/// One copy for both dimensions (`dim`), out of line, in the build's widest
/// ([`WIDEST`]): in 2D the third components are set to 0 first, which no
/// 2D stage reads, so that the 3D arithmetic is the 2D rule (only the turn
/// tells the two apart).
#[inline(never)]
#[allow(clippy::too_many_arguments)]
pub(crate) fn collide_limited(mut va: [i32; 3], mut vb: [i32; 3], s: (i32, i32), e: i32, limit2: u64, masses: Masses, rng: &mut Stream, dim: usize) -> ([i32; 3], [i32; 3]) {
    if WIDEST == 3 && dim == 2 {
        (va[2], vb[2]) = (0, 0);
    }
    let fits = |v: [i32; 3]| sq::<WIDEST>(v) <= limit2;
    let d = difference::<WIDEST>(va, vb);
    for _ in 0..SPEED_LIMIT_TRIES {
        let t = if dim == 2 { turned::<2>(d, rng) } else { turned::<WIDEST>(d, rng) };
        let (a, b) = collide_pair::<WIDEST>(va, vb, s, e, t, masses);
        if fits(a) && fits(b) {
            return (a, b);
        }
    }
    collide_pair::<WIDEST>(va, vb, s, e, d, masses)
}

/// M1b in fine units (M1c): the pair `(a, b)`, just collided, with mass
/// shares `(A, B)` in Q16 and `2^fine` fine units a quantum, with its
/// relative velocity shrunk about the centre of mass by `l` so that the
/// kinetic energy it loses equals what the stochastic rounding of both (M1)
/// adds on average: rounding `x` adds `f (1 - f)` quanta^2 per component,
/// `f` its fraction, which is `phi (2^fine - phi)` fine units^2 for the
/// fraction `phi` in fine units. Both sides are divided by the pair's
/// mass, so only the shares appear: `sa sb |a - b|^2 (1 - l^2) = sa Fa + sb
/// Fb` with `F` the summed gains. The ratio is taken in Q32 and `l` in
/// Q30: the correction is small against 1, and coarser steps of `l` would
/// be as large as it. Momentum is kept as [`collide_pair`] keeps it; a pair
/// with less relative energy than that ends at its centre-of-mass
/// velocity. The third components are 0 in and out in 2D (as
/// [`collide_pair`] leaves them), so one copy, out of line, in the build's
/// widest dimension ([`WIDEST`]) serves both.
#[inline(never)]
pub(crate) fn energy_neutral(a: [i32; 3], b: [i32; 3], (sa, sb): (i32, i32), fine: u32, masses: Masses) -> ([i32; 3], [i32; 3]) {
    const D: usize = WIDEST;
    let gain = |x: [i32; 3]| {
        let mut sum = 0u64;
        for &c in &x[..D] {
            let phi = (c & ((1 << fine) - 1)) as u64;
            sum += phi * ((1 << fine) - phi);
        }
        sum
    };
    let d = difference::<D>(a, b);
    let kinetic = (sq::<D>(d) >> 16) * ((sa as u64 * sb as u64) >> 16);
    // At most 3 2^(2 fine - 2): shifted by 32 it fits 64 bits.
    let lost = (sa as u64 * gain(a) + sb as u64 * gain(b)) >> 16;
    let l = if kinetic > lost { isqrt(((1 << 32) - udiv(lost << 32, kinetic)) << 28) as i32 } else { 0 };
    let mut out = (a, b);
    for k in 0..D {
        let v0 = b[k] + mulq(d[k], sa, 16);
        let ak = v0 + mulq(a[k] - v0, l, 30);
        let bk = v0 + mulq(b[k] - v0, l, 30);
        (out.0[k], out.1[k]) = conserve(a[k], b[k], ak, bk, masses);
    }
    out
}

/// The widest dimension of the build's worlds: the routines that serve both
/// dimensions with one copy compute in it.
pub(crate) const WIDEST: usize = if cfg!(feature = "dim3") { 3 } else { 2 };

/// Draws of `R` M5.2b makes before it takes the direction of the relative
/// velocity.
pub(crate) const SPEED_LIMIT_TRIES: u32 = 16;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::rng::block_stream;

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

    /// The length of the first three components, in f64.
    fn length(x: [i32; 3]) -> f64 {
        x.iter().map(|&c| f64::from(c).powi(2)).sum::<f64>().sqrt()
    }

    /// A random velocity in fine units of 8-bit storage, of length up to
    /// a unit speed, the third component 0 in 2D.
    fn velocity(rng: &mut Stream, d: usize) -> [i32; 3] {
        loop {
            let x = [0, 1, 2].map(|k| if k < d { rng.bits(24) as i32 - (1 << 23) } else { 0 });
            if sq::<3>(x) <= (127u64 << 16).pow(2) {
                return x;
            }
        }
    }

    const UNIT: i32 = 127 << 16;

    #[test]
    fn collision_conserves_momentum_and_scales_relative_speed() {
        // Expect: one mass keeps the pair's momentum exactly; masses 4:1
        // keep it to half a fine unit of the heavier particle; the relative
        // speed is scaled by e to a few fine units (the table's length and
        // the flooring; with two masses, and the shares' precision), in 2D
        // and 3D.
        let mut rng = block_stream(11, 0, 0);
        for i in 0..crate::sized(4000, 100) {
            let (one, dim) = (i % 2 == 0, 2 + i / 2 % 2);
            let (va, vb) = (velocity(&mut rng, dim), velocity(&mut rng, dim));
            let (ma, mb) = if one { (1 << 24, 1 << 24) } else { (1 << 24, 1 << 22) };
            let s = if one { HALVES } else { shares(ma, mb) };
            let e = [65536, 45875, 0][i % 3];
            let d = difference::<3>(va, vb);
            let t = if dim == 2 { turned::<2>(d, &mut rng) } else { turned::<3>(d, &mut rng) };
            let m = (!one).then_some((ma, mb));
            let (a, b) = if dim == 2 { collide_pair::<2>(va, vb, s, e, t, m) } else { collide_pair::<3>(va, vb, s, e, t, m) };
            for k in 0..3 {
                let before = i64::from(ma) * i64::from(va[k]) + i64::from(mb) * i64::from(vb[k]);
                let after = i64::from(ma) * i64::from(a[k]) + i64::from(mb) * i64::from(b[k]);
                // The heavier particle's half fine unit.
                let slack = if one { 0 } else { i64::from(ma.max(mb)) / 2 };
                assert!((before - after).abs() <= slack, "{i} momentum {before} {after}");
            }
            // Two masses: the centre of mass to the shares' Q16, |d| 2^-16.
            let want = f64::from(e) / 65536.0 * length(d);
            let got = length(difference::<3>(a, b));
            let slack = if one { 0.0 } else { length(d) / 65536.0 };
            assert!((got - want).abs() <= 4.0 + want * 2e-4 + slack, "{i}: {got} vs {want}");
        }
    }

    #[test]
    fn speed_limited_collisions_stay_below_the_limit_and_keep_momentum() {
        // Expect: outgoing squared speeds at most the limit for any
        // incoming pair within it, momentum kept, the relative speed scaled
        // by e; and for a pair whose admissible directions are a sliver
        // (both fast, nearly parallel, e = 1) the fallback still fits.
        let mut rng = block_stream(12, 0, 0);
        let limit2 = (UNIT as u64).pow(2);
        for i in 0..crate::sized(4000, 200) {
            let (va, vb) = if i % 4 == 0 {
                ([UNIT / 100 * 99, UNIT / 10, 0], [UNIT / 100 * 99, -UNIT / 100 * 12, 0])
            } else {
                (velocity(&mut rng, 3), velocity(&mut rng, 3))
            };
            let e = [65536, 32768, 58982][i % 3];
            let (a, b) = collide_limited(va, vb, HALVES, e, limit2, None, &mut rng, 3);
            assert!(sq::<3>(a) <= limit2 && sq::<3>(b) <= limit2, "{va:?} {vb:?} -> {a:?} {b:?}");
            for k in 0..3 {
                assert_eq!(va[k] + vb[k], a[k] + b[k]);
            }
            let want = f64::from(e) / 65536.0 * length(difference::<3>(va, vb));
            let got = length(difference::<3>(a, b));
            assert!((got - want).abs() <= 4.0 + want * 2e-4, "{i}: {got} vs {want}");
        }
    }

    #[test]
    fn energy_neutral_pairs_keep_the_expected_energy_after_rounding() {
        // Expect: for pairs in fine units (8-bit storage), the kinetic
        // energy after compensation plus what rounding then adds on average
        // (half the mass times phi (2^16 - phi) per component) is the
        // energy before. The compensation is computed from the fractions
        // before the pair is scaled; phi (2^16 - phi) moves by at most 2^16
        // times the distance phi moved, so the two differ by at most half
        // the mass times that; and the flooring of the scaling (a fine unit
        // a component, whose sign follows no velocity, so it cancels over
        // many pairs) moves it by up to the mass times the speed. Momentum
        // kept as the collision keeps it.
        let mut rng = block_stream(13, 0, 0);
        let energy = |x: [i32; 3], m: f64| 0.5 * m * sq::<3>(x) as f64;
        let gain = |x: [i32; 3], m: f64| x.iter().map(|&c| { let phi = f64::from(c & 0xffff); 0.5 * m * phi * (65536.0 - phi) }).sum::<f64>();
        let (mut moves, mut gains) = (0.0, 0.0);
        for i in 0..crate::sized(2000, 200) {
            let (a, b) = (velocity(&mut rng, 3), velocity(&mut rng, 3));
            let one = i % 4 == 0;
            let (ra, rb) = if one { (1 << 24, 1 << 24) } else { (1 << 24, (1 << 24) / (1 + (i % 4) as u32)) };
            let s = if one { HALVES } else { shares(ra, rb) };
            let (ma, mb) = (f64::from(ra), f64::from(rb));
            let (a2, b2) = energy_neutral(a, b, s, 16, (!one).then_some((ra, rb)));
            let before = energy(a, ma) + energy(b, mb);
            let after = energy(a2, ma) + energy(b2, mb) + gain(a2, ma) + gain(b2, mb);
            let moved = |x: [i32; 3], y: [i32; 3], m: f64| 0.5 * m * 65536.0 * (0..3).map(|k| f64::from((x[k] - y[k]).abs()) + 2.0).sum::<f64>();
            // A fine unit of rounding a component moves the energy by up to
            // the mass times that component, either way.
            let floors = |x: [i32; 3], m: f64| m * x.iter().map(|&c| f64::from(c.abs()) + 1.0).sum::<f64>();
            let bound = moved(a, a2, ma) + moved(b, b2, mb) + floors(a2, ma) + floors(b2, mb) + 1e-9 * before;
            assert!((after - before).abs() <= bound, "{i}: {before} -> {after} (bound {bound})");
            moves += moved(a, a2, ma) + moved(b, b2, mb);
            gains += gain(a, ma) + gain(b, mb);
            for k in 0..3 {
                let p = |x: [i32; 3], y: [i32; 3]| f64::from(x[k]) * ma + f64::from(y[k]) * mb;
                assert!((p(a, b) - p(a2, b2)).abs() <= ma.max(mb) / 2.0, "momentum");
            }
        }
        // The bound is small against what is compensated: typical pairs
        // move by far less than a quantum.
        assert!(moves < 0.1 * gains, "moved {moves} against gains {gains}");
    }

    #[test]
    fn shares_follow_the_masses_whatever_they_are() {
        // Expect: the shares add up to 2^16 and give A / 2^16 the mass
        // ratio to half a unit, from equal masses to the extremes.
        for (ma, mb) in [(1u32 << 24, 1u32 << 24), (1 << 24, 1), (1, 1 << 24), (3, 7), (1 << 24, 5_592_405), (0, 0)] {
            let (a, b) = shares(ma, mb);
            assert_eq!(a + b, 1 << 16);
            if ma + mb > 0 {
                let want = 65536.0 * f64::from(ma) / (f64::from(ma) + f64::from(mb));
                assert!((f64::from(a) - want).abs() <= 0.5, "{ma} {mb}: {a}");
            }
        }
    }

    #[test]
    fn turns_are_uniform_and_keep_the_length() {
        // Expect: |t| = |d| (to the table's precision in 2D; to the
        // rounding of the two lengths in 3D); in 2D the angle of t from d
        // falls in each of 12 sectors, and in 3D t in each of 8 octants and
        // 6 bands of z, with its binomial share of 120,000 draws (3,000
        // under Miri) within 5 sd.
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
            let d = velocity(&mut rng, 2);
            let t = turned::<2>(d, &mut rng);
            assert!((length(t) - length(d)).abs() <= 3.0 + length(d) * 1e-8, "{d:?} {t:?}");
            let turn = f64::atan2(f64::from(t[1]), f64::from(t[0])) - f64::atan2(f64::from(d[1]), f64::from(d[0]));
            let turn = turn.rem_euclid(core::f64::consts::TAU);
            if length(d) > 1e4 {
                sectors[((turn / core::f64::consts::TAU * 12.0) as usize).min(11)] += 1;
            } else {
                sectors[rng.below(12) as usize] += 1;
            }
            let d = [UNIT, 0, 0];
            let r = turned::<3>(d, &mut rng);
            assert!((length(r) - f64::from(UNIT)).abs() <= 2.0 + f64::from(UNIT) * 1.3e-4, "{r:?}");
            octants[usize::from(r[0] > 0) | usize::from(r[1] > 0) << 1 | usize::from(r[2] > 0) << 2] += 1;
            // Archimedes: z is uniform on [-1, 1] for a uniform direction.
            bands[((f64::from(r[2]) / f64::from(UNIT) + 1.0) * 3.0).clamp(0.0, 5.0) as usize] += 1;
        }
        check(&sectors);
        check(&octants);
        check(&bands);
    }
}
