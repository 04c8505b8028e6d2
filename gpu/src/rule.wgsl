// The local map of M5 on the blocks of one step, every part of it, as
// docs/model.md states it (M1c, M3, M4, M5, M8), in either dimension: the
// source of a dimension (`step2d.wgsl`, `step3d.wgsl`) comes first and
// gives DIM (2 or 3), CELLS (2^DIM), the draws of M5.3 (`desire`), the
// turn of M5.2 (`turned`) and exact-fast assignment (`exact_fast`), which
// differ between the dimensions; every other rule is written here once, on
// three components, the third 0 in 2D as on the CPU.
//
// One invocation owns one 32-cell word of the occupancy in each of the
// CELLS / 2 domain rows of a row of blocks (y, and z in 3D), and
// everything the particles in those cells carry: it processes every block
// that touches them (at offset 1 the two blocks that straddle its edges
// are also processed by its neighbours, each with the same result) and
// writes only what it owns, into the other buffer of the pair. No two
// invocations write the same word. A block's counts go to the invocation
// that owns its first cell.
//
// 64-bit integers are vec2<u32> (low, high): WGSL has none.

// params, the same every step: 0-1 the seed, 2 nz (1 in 2D), 6 nx, 7 ny,
// 8 u32 words a row of the occupancy, 9 the storage's width (0: 8 bits,
// 1: 16), 10 restitution (Q16), 11 unit W, 12 the uniform wind's z (fine
// units), 14 the faces (2 bits each: x low, x high, y low, y high, z low, z
// high; 0 periodic, 1 wall, 2 open), 15 the walls' restitution (Q16),
// 16-21 the uniform push G (x, y, z as 64-bit pairs), 22 whether a force
// is on (G not 0, a field, a potential or the vortex), 23 the calibrated
// drift rule, 24 speed-limited collisions (M5.2b), 25 their limit L (fine
// units), 26 contacts (M5.7), 27 the vortex force (M5.1), 28-31 the
// vortex's centre (x, y as 64-bit pairs, 2^-8 cells), 32 its core (2^-8
// cells), 35 the emitters, 36 lifetimes, 38 the potential, 39 the force
// field, 40 the surface entries, 41-42 the vortex's strength as a flow
// top(Γ'') (g, e), 43 drag (M5.1b), 44 its weight C (Q16), 45-46 the
// uniform wind U's x and y (fine units), 47 the flow holds the wind plane,
// 48 the flow holds the vortex, 49 S (quanta to a unit speed), 50
// obstacles, 51 energy-neutral rounding (M1b), 52 masses, 53 M6b's planes,
// 54 M5.6's method (0 exhaustive, 1 exact-fast, 2 greedy), 55 turbulence
// (M5.1c) in the flow, 56 its R (Q16), 57-58 its β (64-bit pair), 59 its
// t, 60 its shift e - 30 (i32), 61 its log2(scale), 62 resting contact
// (M5.7b), 63 its support axis, 64 whether G points up it, 65 the lower
// half's cells, 66 its T (fine units). 3-5, 13, 33-34
// and 37 are 0: what depends on the mass (K, the clamp's energy factor,
// the vortex force's strength) is in `classes`, per mass index.
@group(0) @binding(0) var<storage, read> params: array<u32>;
// tables: 0..256 M5.3 move limits; 256..2304 the turns of M5.2 (cos, sin
// as i32); 2304..3600 per 2D key its assignments (start | count << 16,
// count 0 for none); 3600.. the assignments.
@group(0) @binding(1) var<storage, read> tables: array<u32>;
// The occupancy, one bit a cell as the CPU keeps it (rows y + ny z), and
// the stored velocities: in 2D two bytes a cell and two cells a word
// (8-bit) or a word a cell (16-bit); in 3D a word a cell, a byte a
// component (8-bit), or two words, x and y in the first and z in the
// second (16-bit).
@group(0) @binding(2) var<storage, read> occ_in: array<u32>;
@group(0) @binding(3) var<storage, read> vel_in: array<u32>;
@group(0) @binding(4) var<storage, read_write> occ_out: array<u32>;
@group(0) @binding(5) var<storage, read_write> vel_out: array<u32>;
// counters: pairs (low, high) of collisions, clamps, clamp energy,
// displaced, exited; 10 blocks processed in this step; 11 the clamp energy
// saturated; 12 blocks processed in the last step; 13-14 the number of the
// step the world takes next, which `end_step` advances; pairs of the
// particles emitted (15), the emitters' shortfall (17) and the particles
// whose lifetime ended (19); 21 the last id given (M6b), which the
// emitters count up.
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;
// The emitters' pass (`emit`) writes the planes the step then reads.
@group(0) @binding(7) var<storage, read_write> occ_emit: array<u32>;
@group(0) @binding(8) var<storage, read_write> vel_emit: array<u32>;
// Per emitter (M6), 16 words: min x, y, z, max x, y, z, the rate's whole
// part (64 bits), its 24-bit threshold, velocity x, y, z and spread (fine
// units), the lifetime, the mass index and the tag of its particles.
@group(0) @binding(9) var<storage, read> emitters: array<u32>;
// Per emitter, 4 words: requested, delivered (64-bit pairs).
@group(0) @binding(10) var<storage, read_write> emitter_stats: array<u32>;
// The steps each particle has left (M6, 0 for no limit), two cells a
// word, where the world has lifetimes (params[36]): what the step reads,
// what it writes, and what the emitters write.
@group(0) @binding(11) var<storage, read> life_in: array<u32>;
@group(0) @binding(12) var<storage, read_write> life_out: array<u32>;
@group(0) @binding(13) var<storage, read_write> life_emit: array<u32>;
// The f32 settings per cell, as their bits (a word where the world has
// none): M5.1's force field (DIM a cell) and potential, M5.1b's wind plane
// (DIM a cell).
@group(0) @binding(14) var<storage, read> field: array<u32>;
@group(0) @binding(15) var<storage, read> potential: array<u32>;
@group(0) @binding(16) var<storage, read> wind: array<u32>;
// The obstacle cells (M7), one bit a cell laid out as the occupancy, where
// the world has obstacles (params[50]); their surface entries in
// increasing cell order (params[40] of them), five words each: the cell,
// the normal's x, y and z in Q30, the restitution in Q16.
@group(0) @binding(17) var<storage, read> obstacle: array<u32>;
@group(0) @binding(18) var<storage, read> surfaces: array<u32>;
// Per mass index (256), 8 words of its class (M1c): the relative mass M,
// the clamp's energy factor (significand, exponent), K (f32 bits), the
// vortex force's top(Γ') (g, e). The world's one class in each entry
// where it has one mass.
@group(0) @binding(19) var<storage, read> classes: array<u32>;
// What a particle carries in bytes, 16 bits a cell (two cells a word):
// its mass index (low byte, where the world has masses, params[52]) and
// its tag (high byte, M6b), where the world has either: what the step
// reads, what it writes, and what the emitters write.
@group(0) @binding(20) var<storage, read> mass_in: array<u32>;
@group(0) @binding(21) var<storage, read_write> mass_out: array<u32>;
@group(0) @binding(22) var<storage, read_write> mass_emit: array<u32>;
// M6b's ids and ages, two words a cell (id, age), where the world keeps
// either (params[53]: 1 ids, 2 ages, 4 tags): read, written, emitted.
@group(0) @binding(23) var<storage, read> ident_in: array<u32>;
@group(0) @binding(24) var<storage, read_write> ident_out: array<u32>;
@group(0) @binding(25) var<storage, read_write> ident_emit: array<u32>;

// The cells of a block along one row of blocks (x), and its rows (y, z).
const ROWS: u32 = CELLS / 2u;
// The block's pairs (M5.2): C(CELLS, 2).
const PAIRS: u32 = CELLS * (CELLS - 1u) / 2u;
// Targets of a block's cells, 4 bits a cell (cell c goes to
// targets >> 4c & 7): everyone where they are.
const IDENTITY: u32 = 0x76543210u;

// ---- 64-bit arithmetic --------------------------------------------------

fn add64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let lo = a.x + b.x;
    return vec2<u32>(lo, a.y + b.y + select(0u, 1u, lo < a.x));
}

fn sub64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    return vec2<u32>(a.x - b.x, a.y - b.y - select(0u, 1u, a.x < b.x));
}

fn lt64(a: vec2<u32>, b: vec2<u32>) -> bool {
    return a.y < b.y || (a.y == b.y && a.x < b.x);
}

fn is_zero64(a: vec2<u32>) -> bool {
    return (a.x | a.y) == 0u;
}

fn shr64(a: vec2<u32>, n: u32) -> vec2<u32> {
    if n == 0u {
        return a;
    }
    if n < 32u {
        return vec2<u32>((a.x >> n) | (a.y << (32u - n)), a.y >> n);
    }
    if n < 64u {
        return vec2<u32>(a.y >> (n - 32u), 0u);
    }
    return vec2<u32>(0u, 0u);
}

fn shl64(a: vec2<u32>, n: u32) -> vec2<u32> {
    if n == 0u {
        return a;
    }
    if n < 32u {
        return vec2<u32>(a.x << n, (a.y << n) | (a.x >> (32u - n)));
    }
    if n < 64u {
        return vec2<u32>(0u, a.x << (n - 32u));
    }
    return vec2<u32>(0u, 0u);
}

// The whole product of two 32-bit numbers.
fn mul32(a: u32, b: u32) -> vec2<u32> {
    let a0 = a & 0xffffu;
    let a1 = a >> 16u;
    let b0 = b & 0xffffu;
    let b1 = b >> 16u;
    let p00 = a0 * b0;
    let p01 = a0 * b1;
    let p10 = a1 * b0;
    let mid = (p00 >> 16u) + (p01 & 0xffffu) + (p10 & 0xffffu);
    return vec2<u32>((p00 & 0xffffu) | (mid << 16u), a1 * b1 + (p01 >> 16u) + (p10 >> 16u) + (mid >> 16u));
}

// The low 64 bits of a product.
fn mul64(a: vec2<u32>, b: vec2<u32>) -> vec2<u32> {
    let p = mul32(a.x, b.x);
    return vec2<u32>(p.x, p.y + a.x * b.y + a.y * b.x);
}

fn bitlen64(a: vec2<u32>) -> u32 {
    if a.y != 0u {
        return 64u - countLeadingZeros(a.y);
    }
    return 32u - countLeadingZeros(a.x);
}

// ---- M8: the block's stream ---------------------------------------------

fn mix64(z0: vec2<u32>) -> vec2<u32> {
    var z = z0 ^ shr64(z0, 30u);
    z = mul64(z, vec2<u32>(0x1ce4e5b9u, 0xbf58476du));
    z = z ^ shr64(z, 27u);
    z = mul64(z, vec2<u32>(0x133111ebu, 0x94d049bbu));
    return z ^ shr64(z, 31u);
}

// M8: the step's key, increment and the stride between blocks' first
// counters, from the seed and the step number.
struct StepKey {
    key: vec2<u32>,
    gamma: vec2<u32>,
    stride: vec2<u32>,
}

// A domain's key for a step: `domain` the blocks' or the emitters' tag,
// `window` the bits of the counters each stream owns (16 a block, 32 an
// emitter).
fn step_key(seed: vec2<u32>, step: vec2<u32>, domain: vec2<u32>, window: u32) -> StepKey {
    let a = mix64(seed ^ domain);
    let key = mix64(a ^ mul64(step, vec2<u32>(0x7f4a7c15u, 0x9e3779b9u)));
    var g = mix64(key ^ vec2<u32>(0x78bd642fu, 0xa0761d64u)) | vec2<u32>(1u, 0u);
    let t = g ^ shr64(g, 1u);
    if countOneBits(t.x) + countOneBits(t.y) < 24u {
        g = g ^ vec2<u32>(0xaaaaaaaau, 0xaaaaaaaau);
    }
    return StepKey(key, g, shl64(g, window));
}

// The stream `index` of a domain's key for a step.
fn stream_of(k: StepKey, index: u32) -> Stream {
    var s: Stream;
    s.counter = add64(k.key, mul64(k.stride, vec2<u32>(index, 0u)));
    s.gamma = k.gamma;
    s.pool = vec2<u32>(0u, 0u);
    s.left = 0u;
    return s;
}

struct Stream {
    counter: vec2<u32>,
    gamma: vec2<u32>,
    pool: vec2<u32>,
    left: u32,
}

fn next64(s: ptr<function, Stream>) -> vec2<u32> {
    (*s).counter = add64((*s).counter, (*s).gamma);
    return mix64((*s).counter);
}

fn bits(s: ptr<function, Stream>, n: u32) -> u32 {
    if (*s).left < n {
        (*s).pool = next64(s);
        (*s).left = 64u;
    }
    let r = (*s).pool.x & (0xffffffffu >> (32u - n));
    (*s).pool = shr64((*s).pool, n);
    (*s).left = (*s).left - n;
    return r;
}

// A uniform number below n: Lemire's multiply and reject, 16 bits a try
// (32 where n > 2^16).
fn below(s: ptr<function, Stream>, n: u32) -> u32 {
    if n > 65536u {
        var m = mul32(bits(s, 32u), n);
        if m.x < n {
            let threshold = (0u - n) % n;
            while m.x < threshold {
                m = mul32(bits(s, 32u), n);
            }
        }
        return m.y;
    }
    var m = bits(s, 16u) * n;
    if (m & 0xffffu) < n {
        let threshold = (65536u - n) % n;
        while (m & 0xffffu) < threshold {
            m = bits(s, 16u) * n;
        }
    }
    return m >> 16u;
}

// ---- M1c operations -----------------------------------------------------

// floor((a b + 2^(s-1)) / 2^s), s in 1..31, as the low 32 bits.
fn mulq(a: i32, b: i32, s: u32) -> i32 {
    var p = mul32(u32(abs(a)), u32(abs(b)));
    if (a < 0) != (b < 0) {
        p = add64(~p, vec2<u32>(1u, 0u));
    }
    p = add64(p, vec2<u32>(1u << (s - 1u), 0u));
    return bitcast<i32>((p.x >> s) | (p.y << (32u - s)));
}

// M1c's sq: the exact squared length, of three components (the third 0
// in 2D).
fn sq(x: vec3<i32>) -> vec2<u32> {
    var s = vec2<u32>(0u, 0u);
    for (var k = 0; k < 3; k++) {
        s = add64(s, mul32(u32(abs(x[k])), u32(abs(x[k]))));
    }
    return s;
}

// floor(sqrt(n)) digit by digit.
fn isqrt64(n: vec2<u32>) -> vec2<u32> {
    if is_zero64(n) {
        return n;
    }
    var rest = n;
    var root = vec2<u32>(0u, 0u);
    var bit = shl64(vec2<u32>(1u, 0u), (bitlen64(n) - 1u) & ~1u);
    while !is_zero64(bit) {
        let t = add64(root, bit);
        if !lt64(rest, t) {
            rest = sub64(rest, t);
            root = add64(shr64(root, 1u), bit);
        } else {
            root = shr64(root, 1u);
        }
        bit = shr64(bit, 2u);
    }
    return root;
}

// floor(rest 2^(rounds - 1) / d) for rest < 2d, d at most 2^31.
fn long_division(rest0: u32, d: u32, rounds: u32) -> u32 {
    var rest = rest0;
    var q = 0u;
    for (var i = 0u; i < rounds; i++) {
        q = q << 1u;
        if rest >= d {
            rest = rest - d;
            q = q | 1u;
        }
        rest = rest << 1u;
    }
    return q;
}

// M5.5's energy counter: floor(n h), n cut to its top 40 bits, h = m 2^e.
fn count_times(n: vec2<u32>, m: u32, e: i32) -> vec2<u32> {
    if m == 0u || is_zero64(n) {
        return vec2<u32>(0u, 0u);
    }
    let cut = max(i32(bitlen64(n)) - 40, 0);
    let p = mul64(shr64(n, u32(cut)), vec2<u32>(m, 0u));
    let e2 = e + cut;
    if e2 >= 0 {
        if e2 >= 64 || lt64(shr64(vec2<u32>(0xffffffffu, 0xffffffffu), u32(e2)), p) {
            return vec2<u32>(0xffffffffu, 0xffffffffu);
        }
        return shl64(p, u32(e2));
    }
    if e2 <= -64 {
        return vec2<u32>(0u, 0u);
    }
    return shr64(p, u32(-e2));
}

// ---- What an invocation counts ------------------------------------------

struct Counts {
    collisions: u32,
    clamps: u32,
    energy: vec2<u32>,
    saturated: bool,
    displaced: u32,
    processed: u32,
    exited: u32,
    expired: u32,
}

// M5.5: x clamped to the unit speed, counted.
fn clamp_speed(x: vec3<i32>, mass_class: u32, counts: ptr<function, Counts>) -> vec3<i32> {
    let unit = bitcast<i32>(params[11]);
    let s2 = sq(x);
    let limit = mul32(u32(unit), u32(unit));
    if !lt64(limit, s2) {
        return x;
    }
    (*counts).clamps += 1u;
    let removed = count_times(sub64(s2, limit), classes[8u * mass_class + 1u], bitcast<i32>(classes[8u * mass_class + 2u]));
    let total = add64((*counts).energy, removed);
    if lt64(total, removed) {
        (*counts).saturated = true;
    }
    (*counts).energy = total;
    return shorten(x, s2);
}

// x, of squared length s2 above W^2, scaled back to W (M5.5): ceil(sqrt(s2)),
// then floor(2^32 W / L), so never longer than W.
fn shorten(x: vec3<i32>, s2: vec2<u32>) -> vec3<i32> {
    let unit = params[11];
    let r = isqrt64(s2);
    let length = r.x + select(0u, 1u, lt64(mul32(r.x, r.x), s2));
    let factor = long_division(unit << 1u, length, 32u);
    var out = x;
    for (var k = 0; k < 3; k++) {
        let scaled = i32(mul32(u32(abs(x[k])), factor).y);
        out[k] = select(scaled, -scaled, x[k] < 0);
    }
    return out;
}

// 16-bit storage (params[9]).
fn wide() -> bool {
    return params[9] != 0u;
}

// M1c's F: fine bits a quantum.
fn fine() -> u32 {
    return select(16u, 12u, wide());
}

// M1: a working velocity (fine units of 2^-F quanta) to stored quanta, the
// low F of 16 random bits a component: bits 16k.. of 32 random bits in 2D,
// of a 64-bit output in 3D.
fn round_velocity(x: vec3<i32>, s: ptr<function, Stream>) -> vec3<i32> {
    var r: vec2<u32>;
    if DIM == 2u {
        r = vec2<u32>(bits(s, 32u), 0u);
    } else {
        r = next64(s);
    }
    let mask = (1u << fine()) - 1u;
    let noise = vec3<u32>(r.x, r.x >> 16u, r.y) & vec3<u32>(mask);
    return (x + vec3<i32>(noise)) >> vec3<u32>(fine());
}

// M5.3 for 16-bit storage: one less than the threshold of |q| (M1c),
// floor((num 2^17 + den) / (2 den)) with (num, den) = (a, S) under the
// paper's rule and (2a, S + a) under the calibrated one (params[23]), by
// long division: the numerator takes 34 bits.
fn move_limit_16(q: i32) -> u32 {
    let a = min(u32(abs(q)), 32767u);
    let calibrated = params[23] != 0u;
    let num = select(a, 2u * a, calibrated);
    let den = select(32767u, 32767u + a, calibrated);
    let n = add64(shl64(vec2<u32>(num, 0u), 17u), vec2<u32>(den, 0u));
    let d = 2u * den;
    var rest = 0u;
    var quotient = 0u;
    for (var i = 34; i >= 0; i--) {
        rest = (rest << 1u) | (shr64(n, u32(i)).x & 1u);
        quotient = quotient << 1u;
        if rest >= d {
            rest -= d;
            quotient |= 1u;
        }
    }
    return max(quotient, 1u) - 1u;
}

// M5.3: the largest 16 random bits that say "move" for the stored
// component q: the 8-bit table's entry, or M1c's limit for 16 bits.
fn move_limit(q: i32) -> u32 {
    return select(tables[u32(q) & 0xffu], move_limit_16(q), wide());
}

// ---- The block ----------------------------------------------------------

struct Block {
    occ: u32,
    v: array<vec3<i32>, CELLS>,
    // Steps left (M6), where the world has lifetimes.
    life: array<u32, CELLS>,
    // Mass indices (M9), where the world has masses; 0 otherwise.
    mass: array<u32, CELLS>,
    // M6b's tags, ids and ages, where the world keeps them.
    tag: array<u32, CELLS>,
    id: array<u32, CELLS>,
    age: array<u32, CELLS>,
}

// Where a block lies (M3, M4): its cells' raw coordinates (one beyond a
// face where they lie there) and, resolved, inside the domain; its cells
// beyond a wall face (with their normals in Q30), beyond an open one, and
// the cells no particle may enter (beyond a wall, or an obstacle's).
struct Site {
    raw: array<vec3<i32>, CELLS>,
    at: array<vec3<u32>, CELLS>,
    wall: u32,
    open: u32,
    blocked: u32,
    normal: array<vec3<i32>, CELLS>,
}

// round(2^30 / sqrt(2)) and round(2^30 / sqrt(3)): the diagonals'
// components in Q30 (M1c).
const DIAGONAL: i32 = 759250125;
const DIAGONAL_3D: i32 = 619925131;

// The unit vector along dir (components -1, 0 or 1) in Q30: an axis, a 2D
// or a 3D diagonal.
fn axis_q30(dir: vec3<i32>) -> vec3<i32> {
    let count = dot(abs(dir), vec3<i32>(1));
    return dir * select(select(DIAGONAL_3D, DIAGONAL, count == 2), 1 << 30u, count == 1);
}

// The cells of M5.2's pair p, pairs in order (0, 1), (0, 2), ...
fn pair_cells(p: u32) -> vec2<u32> {
    var k = p;
    for (var a = 0u; a < CELLS; a++) {
        let after = CELLS - 1u - a;
        if k < after {
            return vec2<u32>(a, a + 1u + k);
        }
        k -= after;
    }
    return vec2<u32>(0u, 1u);
}

// The face of axis k (0 x, 1 y, 2 z) on its high side or low: 0 periodic,
// 1 wall, 2 open.
fn face(k: u32, high: bool) -> u32 {
    return params[14] >> (4u * k + select(0u, 2u, high)) & 3u;
}

fn neg64(a: vec2<u32>) -> vec2<u32> {
    return add64(~a, vec2<u32>(1u, 0u));
}

fn is_negative64(a: vec2<u32>) -> bool {
    return (a.y >> 31u) != 0u;
}

// An i32 as a 64-bit pair.
fn wide64(a: i32) -> vec2<u32> {
    return vec2<u32>(bitcast<u32>(a), select(0u, 0xffffffffu, a < 0));
}

// A 64-bit value clamped to [-bound, bound] (bound < 2^31).
fn clamp64(a: vec2<u32>, bound: i32) -> i32 {
    if is_negative64(a) {
        let fits = a.y == 0xffffffffu && (a.x >> 31u) != 0u;
        return select(-bound, max(bitcast<i32>(a.x), -bound), fits);
    }
    let fits = a.y == 0u && (a.x >> 31u) == 0u;
    return select(bound, min(bitcast<i32>(a.x), bound), fits);
}

// M5.1's Rankine vortex at cell (x, y) as a push (M1c), or M5.1b's as a
// flow: the 16-bit strength (g, exponent e) over max(|d|^2, R'^2), with the
// offsets and the core (params[28..33]) cut to 15 bits, one 32-bit
// division, the last shift saturated at 2^59. Two 64-bit components: the
// vortex's axis is z.
fn swirl(x: u32, y: u32, g: i32, exponent: i32) -> array<vec2<u32>, 2> {
    let reach = 1 << 28u;
    let at = array<u32, 2>(x, y);
    var d: array<i32, 2>;
    for (var k = 0u; k < 2u; k++) {
        let cell = vec2<u32>((at[k] << 8u) + 128u, at[k] >> 24u);
        d[k] = clamp64(sub64(cell, vec2<u32>(params[28u + 2u * k], params[29u + 2u * k])), reach);
    }
    var zero: array<vec2<u32>, 2>;
    let core = params[32];
    var ax = u32(abs(d[0]));
    var ay = u32(abs(d[1]));
    let big = max(max(ax, ay), core);
    if big == 0u || g == 0 {
        return zero;
    }
    let cut = max(32u - countLeadingZeros(big), 15u) - 15u;
    ax = ax >> cut;
    ay = ay >> cut;
    let c = core >> cut;
    let n = max(ax * ax + ay * ay, c * c);
    let b = 32u - countLeadingZeros(n);
    let top = select(n << (16u - b), n >> (b - 16u), b > 16u);
    let f = (u32(abs(g)) << 15u) / top;
    let e = exponent - i32(cut) - i32(b) + 1;
    var out: array<vec2<u32>, 2>;
    let parts = array<u32, 2>(ay, ax);
    let negative = array<bool, 2>(d[1] > 0, d[0] < 0);
    for (var k = 0u; k < 2u; k++) {
        let y = f * parts[k];
        var m: vec2<u32>;
        if e < 0 {
            m = vec2<u32>(select(0u, y >> u32(-e), -e < 32), 0u);
        } else if lt64(shr64(vec2<u32>(0u, 1u << 27u), u32(e)), vec2<u32>(y, 0u)) {
            m = vec2<u32>(0u, 1u << 27u); // 2^59
        } else {
            m = shl64(vec2<u32>(y, 0u), u32(e));
        }
        out[k] = select(m, neg64(m), negative[k] != (g < 0));
    }
    return out;
}

// A working velocity with the push dv (three 64-bit components) added,
// brought below 2^30 with its direction kept (M1c's fit): every component
// of dv counts in the shift, as on the CPU, and the world's DIM are kept.
fn pushed(x: vec3<i32>, dv: array<vec2<u32>, 3>) -> vec3<i32> {
    var sum: array<vec2<u32>, 3>;
    var top = 0u;
    for (var k = 0u; k < 3u; k++) {
        sum[k] = add64(wide64(select(0, x[k], k < DIM)), dv[k]);
        top = max(top, bitlen64(select(sum[k], neg64(sum[k]), is_negative64(sum[k]))));
    }
    let shift = max(top, 30u) - 30u;
    var out = vec3<i32>(0);
    for (var k = 0u; k < DIM; k++) {
        if shift == 0u {
            out[k] = bitcast<i32>(sum[k].x);
        } else {
            out[k] = bitcast<i32>((sum[k].x >> shift) | (sum[k].y << (32u - shift)));
        }
    }
    return out;
}

// M1c's conv: the exact product a b c 2^shift of two f32 (their bits)
// and a whole c below 2^15, rounded to nearest (halves away from zero) and
// saturated to +-2^59, 64-bit two's complement; NaN gives 0.
fn conv(a: u32, b: u32, c: u32, shift: i32) -> vec2<u32> {
    if (a & 0x7fffffffu) > 0x7f800000u || (b & 0x7fffffffu) > 0x7f800000u {
        return vec2<u32>(0u, 0u);
    }
    // |x| = m 2^e, m below 2^24.
    let ea = i32(a >> 23u & 0xffu);
    let eb = i32(b >> 23u & 0xffu);
    let ma = select((a & 0x7fffffu) | 0x800000u, a & 0x7fffffu, ea == 0);
    let mb = select((b & 0x7fffffu) | 0x800000u, b & 0x7fffffu, eb == 0);
    let e = select(ea - 150, -149, ea == 0) + select(eb - 150, -149, eb == 0) + shift;
    let p = mul64(mul32(ma, mb), vec2<u32>(c, 0u));
    let most = vec2<u32>(0u, 1u << 27u);
    var m = vec2<u32>(0u, 0u);
    if is_zero64(p) {
        m = p;
    } else if e >= 0 {
        if e >= 59 || lt64(shr64(most, u32(e)), p) {
            m = most;
        } else {
            m = shl64(p, u32(e));
        }
    } else if e >= -63 {
        m = shr64(add64(shr64(p, u32(-e - 1)), vec2<u32>(1u, 0u)), 1u);
    }
    if lt64(most, m) {
        m = most;
    }
    return select(m, neg64(m), (a >> 31u) != (b >> 31u));
}

// M1c's U of a speed (f32 bits) in fine units: conv(u, W, 0), saturated to
// +-2^30.
fn to_fine(u: u32) -> i32 {
    return clamp64(conv(u, 0x3f800000u, params[49], i32(fine())), 1 << 30u);
}

// The potential at cell i as a push for a class of K (f32 bits):
// conv(U, K S, F).
fn potential_at(i: u32, k_push: u32) -> vec2<u32> {
    return conv(potential[i], k_push, params[49], i32(fine()));
}

// The domain's size, (nx, ny, nz).
fn sizes() -> vec3<u32> {
    return vec3<u32>(params[6], params[7], params[2]);
}

// The dense index of the cell at p: x + nx (y + ny z).
fn cell_index(p: vec3<u32>) -> u32 {
    return (p.z * params[7] + p.y) * params[6] + p.x;
}

// M5.1's push on the particle in cell p: G (params[16..22]), the force
// field's conv(f, K S, F), -grad U by central differences of the converted
// potential (one-sided at a face that is not periodic), and the vortex's
// push, where each is on; 64 bits a component.
fn push_at(p: vec3<u32>, mass_class: u32) -> array<vec2<u32>, 3> {
    let k_push = classes[8u * mass_class + 3u];
    let n = sizes();
    let cell = cell_index(p);
    var dv: array<vec2<u32>, 3>;
    for (var k = 0u; k < 3u; k++) {
        dv[k] = vec2<u32>(params[16u + 2u * k], params[17u + 2u * k]);
    }
    if params[39] != 0u {
        for (var k = 0u; k < DIM; k++) {
            dv[k] = add64(dv[k], conv(field[DIM * cell + k], k_push, params[49], i32(fine())));
        }
    }
    if params[38] != 0u {
        var stride = 1u;
        for (var k = 0u; k < DIM; k++) {
            let periodic = face(k, false) == 0u;
            let lo_in = p[k] > 0u || periodic;
            let hi_in = p[k] + 1u < n[k] || periodic;
            let lo = select(cell + (n[k] - 1u) * stride, cell - stride, p[k] > 0u);
            let hi = select(cell - (n[k] - 1u) * stride, cell + stride, p[k] + 1u < n[k]);
            var g = vec2<u32>(0u, 0u);
            if lo_in && hi_in {
                // An arithmetic shift by one of the 64-bit difference.
                let d = sub64(potential_at(lo, k_push), potential_at(hi, k_push));
                g = vec2<u32>((d.x >> 1u) | (d.y << 31u), bitcast<u32>(bitcast<i32>(d.y) >> 1u));
            } else if hi_in {
                g = sub64(potential_at(cell, k_push), potential_at(hi, k_push));
            } else if lo_in {
                g = sub64(potential_at(lo, k_push), potential_at(cell, k_push));
            }
            dv[k] = add64(dv[k], g);
            stride *= n[k];
        }
    }
    if params[27] != 0u {
        let t = swirl(p.x, p.y, bitcast<i32>(classes[8u * mass_class + 4u]), bitcast<i32>(classes[8u * mass_class + 5u]));
        dv[0] = add64(dv[0], t[0]);
        dv[1] = add64(dv[1], t[1]);
    }
    return dv;
}

// ---- M5.1c: turbulence ---------------------------------------------------

// The turbulence of this invocation's step (`eddies_of`), where it is on.
struct Eddies {
    keys: vec2<u32>,
    // Per axis, its size where it is periodic, else 0.
    wrap: vec3<u32>,
    time: u32,
}

var<private> eddies: Eddies;

fn h32(x0: u32) -> u32 {
    var x = (x0 ^ (x0 >> 16u)) * 0x1ce4e5b9u;
    x = (x ^ (x >> 15u)) * 0x133111ebu;
    return x ^ (x >> 16u);
}

fn smoothstep15(x: u32) -> u32 {
    return (((x * x) >> 15u) * (3u * 32768u - 2u * x)) >> 15u;
}

fn lerp15(a: i32, b: i32, w: u32) -> i32 {
    return a + (((b - a) * i32(w)) >> 15u);
}

// The step's two slices' keys and the weight between them.
fn eddies_of(step: vec2<u32>) -> Eddies {
    let phase = mul64(step, vec2<u32>(params[56], 0u));
    let slice = shr64(phase, 16u);
    let base = vec2<u32>(params[57], params[58]);
    var e: Eddies;
    e.keys = vec2<u32>(mix64(base ^ slice).x, mix64(base ^ add64(slice, vec2<u32>(1u, 0u))).x);
    let n = sizes();
    for (var k = 0u; k < DIM; k++) {
        e.wrap[k] = select(0u, n[k], face(k, false) == 0u);
    }
    e.time = smoothstep15((phase.x & 0xffffu) >> 1u);
    return e;
}

// Component c of the potential at a corner: the lattice values round it
// blended along x, then y, then z for each slice (a value blended with the
// one kept for its axis as soon as its partner is known), then the slices.
fn eddy_potential(corner: vec3<u32>, c: u32) -> i32 {
    let lambda = params[61];
    var points: array<vec2<u32>, 3>;
    var w = vec3<u32>(0u);
    for (var k = 0u; k < DIM; k++) {
        let i = corner[k] >> lambda;
        points[k] = vec2<u32>(i, select(i + 1u, 0u, i + 1u == eddies.wrap[k] >> lambda));
        w[k] = smoothstep15((corner[k] & ((1u << lambda) - 1u)) << (15u - lambda));
    }
    var slices = vec2<i32>(0);
    for (var j = 0u; j < 2u; j++) {
        let key = eddies.keys[j];
        var kept = vec3<i32>(0);
        for (var m = 0u; m < CELLS; m++) {
            var x = c * 0xa0761d65u;
            let spread = vec3<u32>(0x9e3779b9u, 0xbf58476du, 0x94d049bbu);
            for (var k = 0u; k < DIM; k++) {
                x += points[k][m >> k & 1u] * spread[k];
            }
            var value = bitcast<i32>(h32(key ^ x)) >> 16u;
            // Loops of constant bounds only (`carry` the first axis whose
            // bit is 0): a compiler unrolls them, and lavapipe counts the
            // iterations of the loops it does not against its limit.
            var carry = DIM;
            for (var k = 0u; k < DIM; k++) {
                if carry == DIM && (m >> k & 1u) == 0u {
                    carry = k;
                }
                if carry == DIM {
                    value = lerp15(kept[k], value, w[k]);
                }
            }
            if carry < DIM {
                kept[carry] = value;
            } else {
                slices[j] = value;
            }
        }
    }
    return lerp15(slices.x, slices.y, eddies.time);
}

// The turbulent flow at cell p in fine units: d = sum of sign x A over the
// cell's corners (A = (0, 0, psi) in 2D), times t, shifted.
fn turbulence_at(p: vec3<u32>) -> vec3<i32> {
    var d = vec3<i32>(0);
    for (var m = 0u; m < CELLS; m++) {
        var corner = vec3<u32>(0u);
        var sign = vec3<i32>(0);
        for (var k = 0u; k < DIM; k++) {
            let upper = (m >> k & 1u) != 0u;
            let q = p[k] + select(0u, 1u, upper);
            corner[k] = select(q, 0u, upper && q == eddies.wrap[k]);
            sign[k] = select(-1, 1, upper);
        }
        var a = vec3<i32>(0);
        for (var c = 0u; c < 3u; c++) {
            if DIM == 3u || c == 2u {
                a[c] = eddy_potential(corner, c);
            }
        }
        d += vec3<i32>(sign.y * a.z - sign.z * a.y, sign.z * a.x - sign.x * a.z, sign.x * a.y - sign.y * a.x);
    }
    let t = bitcast<i32>(params[59]);
    let shift = bitcast<i32>(params[60]);
    var u = vec3<i32>(0);
    for (var k = 0u; k < DIM; k++) {
        let y = d[k] * t;
        if shift >= 0 {
            u[k] = y << u32(shift);
        } else {
            u[k] = y >> u32(min(-shift, 31));
        }
    }
    return u;
}

// M5.1b's flow at cell p in fine units: the uniform wind, the wind plane's
// value, the vortex read as a velocity and the turbulence (M5.1c), where
// each is on, each component saturated to +-2^30.
fn flow_at(p: vec3<u32>) -> vec3<i32> {
    let cell = cell_index(p);
    let uniform = vec3<i32>(bitcast<i32>(params[45]), bitcast<i32>(params[46]), bitcast<i32>(params[12]));
    var u: array<vec2<u32>, 3>;
    for (var k = 0u; k < DIM; k++) {
        u[k] = wide64(uniform[k]);
        if params[47] != 0u {
            u[k] = add64(u[k], wide64(to_fine(wind[DIM * cell + k])));
        }
    }
    if params[48] != 0u {
        let t = swirl(p.x, p.y, bitcast<i32>(params[41]), bitcast<i32>(params[42]));
        u[0] = add64(u[0], t[0]);
        u[1] = add64(u[1], t[1]);
    }
    if params[55] != 0u {
        let t = turbulence_at(p);
        for (var k = 0u; k < DIM; k++) {
            u[k] = add64(u[k], wide64(t[k]));
        }
    }
    var out = vec3<i32>(0);
    for (var k = 0u; k < DIM; k++) {
        out[k] = clamp64(u[k], 1 << 30u);
    }
    return out;
}

// The world has masses (params[52]).
fn masses_on() -> bool {
    return params[52] != 0u;
}

// The mass shares (A, B) of a pair of relative masses (M1c), Q16; halves
// in a world of one mass.
fn shares(ma: u32, mb: u32) -> vec2<i32> {
    if !masses_on() {
        return vec2<i32>(32768, 32768);
    }
    // Each at most 2^24: the sum fits a word.
    let total = vec2<u32>(max(ma + mb, 1u), 0u);
    let a = i32(div64(add64(shl64(vec2<u32>(ma, 0u), 16u), shr64(total, 1u)), total).x);
    return vec2<i32>(a, 65536 - a);
}

// floor(n / d) for a signed 64-bit n and 0 < d < 2^31, the result within
// 32 bits.
fn floor_div(n: vec2<u32>, d: u32) -> i32 {
    if is_negative64(n) {
        return -i32(div64(add64(neg64(n), vec2<u32>(d - 1u, 0u)), vec2<u32>(d, 0u)).x);
    }
    return i32(div64(n, vec2<u32>(d, 0u)).x);
}

// The heavier particle's component after the lighter one went from light
// to light2 (M1c): heavy + M_l (light - light2) / M_h, rounded to nearest.
fn balance(heavy: i32, light: i32, light2: i32, mh: u32, ml: u32) -> i32 {
    let diff = light - light2;
    var n = mul32(ml, u32(abs(diff)));
    if diff < 0 {
        n = neg64(n);
    }
    let m = max(mh, 1u);
    return heavy + floor_div(add64(shl64(n, 1u), vec2<u32>(m, 0u)), 2u * m);
}

// A pair's components after a stage gave them a and b from va and vb:
// momentum kept exactly with one mass; with masses, the heavier balanced
// against the lighter (equal masses are the one-mass rule exactly).
fn conserve(va: i32, vb: i32, a: i32, b: i32, ma: u32, mb: u32) -> vec2<i32> {
    if !masses_on() {
        return vec2<i32>(a, va + vb - a);
    }
    if ma > mb {
        return vec2<i32>(balance(va, vb, b, ma, mb), b);
    }
    return vec2<i32>(a, balance(vb, va, a, mb, ma));
}

// Eqs. 7-8 for the pair (a, c) with working velocities xa, xc, relative
// masses ma, mc and |xa - xc| R = t: out[0] for a, out[1] for c. The
// components from DIM on are 0.
fn eqs_7_8(xa: vec3<i32>, xc: vec3<i32>, t: vec3<i32>, ma: u32, mc: u32) -> array<vec3<i32>, 2> {
    let e = bitcast<i32>(params[10]);
    let sh = shares(ma, mc);
    var out = array<vec3<i32>, 2>(vec3<i32>(0), vec3<i32>(0));
    for (var k = 0u; k < DIM; k++) {
        let v0 = xc[k] + mulq(xa[k] - xc[k], sh.x, 16u);
        let u = mulq(t[k], e, 16u);
        let kept = conserve(xa[k], xc[k], v0 + mulq(u, sh.y, 16u), v0 - mulq(u, sh.x, 16u), ma, mc);
        out[0][k] = kept.x;
        out[1][k] = kept.y;
    }
    return out;
}

// floor(n / d) for 64-bit n and d (d not 0), one quotient bit a round.
fn div64(n: vec2<u32>, d: vec2<u32>) -> vec2<u32> {
    var rest = vec2<u32>(0u, 0u);
    var q = vec2<u32>(0u, 0u);
    for (var i = 63; i >= 0; i--) {
        rest = shl64(rest, 1u) | vec2<u32>(shr64(n, u32(i)).x & 1u, 0u);
        q = shl64(q, 1u);
        if !lt64(rest, d) {
            rest = sub64(rest, d);
            q = q | vec2<u32>(1u, 0u);
        }
    }
    return q;
}

// M1c's rsqrt: sqrt(n) rounded to nearest.
fn rsqrt(n: vec2<u32>) -> u32 {
    let root = isqrt64(n).x;
    return root + select(0u, 1u, lt64(vec2<u32>(root, 0u), sub64(n, mul32(root, root))));
}

// M1b (params[51]) on a pair's results a, b (one mass: shares of 2^15):
// the relative velocity scaled about the centre of mass by lambda (Q30),
// so that the kinetic energy given up is what the two roundings add on
// average; momentum kept as eqs. 7-8 keep it.
fn energy_neutral(pair: array<vec3<i32>, 2>, ma: u32, mb: u32) -> array<vec3<i32>, 2> {
    let a = pair[0];
    let b = pair[1];
    let sh = shares(ma, mb);
    let mask = (1u << fine()) - 1u;
    var gain = array<vec2<u32>, 2>(vec2<u32>(0u, 0u), vec2<u32>(0u, 0u));
    for (var j = 0; j < 2; j++) {
        for (var k = 0u; k < DIM; k++) {
            let phi = u32(pair[j][k]) & mask;
            gain[j] = add64(gain[j], vec2<u32>(phi * ((1u << fine()) - phi), 0u));
        }
    }
    let d = a - b;
    let kinetic = mul64(shr64(sq(d), 16u), vec2<u32>((u32(sh.x) * u32(sh.y)) >> 16u, 0u));
    let lost = shr64(add64(mul64(vec2<u32>(u32(sh.x), 0u), gain[0]), mul64(vec2<u32>(u32(sh.y), 0u), gain[1])), 16u);
    var l = 0;
    if lt64(lost, kinetic) {
        let q = div64(shl64(lost, 32u), kinetic);
        l = i32(isqrt64(shl64(sub64(vec2<u32>(0u, 1u), q), 28u)).x);
    }
    var out = array<vec3<i32>, 2>(vec3<i32>(0), vec3<i32>(0));
    for (var k = 0u; k < DIM; k++) {
        let v0 = b[k] + mulq(d[k], sh.x, 16u);
        let kept = conserve(a[k], b[k], v0 + mulq(a[k] - v0, l, 30u), v0 + mulq(b[k] - v0, l, 30u), ma, mb);
        out[0][k] = kept.x;
        out[1][k] = kept.y;
    }
    return out;
}

// M5.2 on the pair (a, c) with working velocities xa, xc (R uniform, from
// `turned`; with M5.2b, params[24], drawn again until both outgoing speeds
// are within the limit L, params[25], at most 16 times, then along
// xa - xc), both clamped. False where the pair has one velocity within the
// speed limit (nothing drawn, nothing changed).
fn collide(xa: vec3<i32>, xc: vec3<i32>, ca: u32, cc: u32, out: ptr<function, array<vec3<i32>, 2>>, s: ptr<function, Stream>, counts: ptr<function, Counts>) -> bool {
    (*counts).collisions += 1u;
    let ma = classes[8u * ca];
    let mc = classes[8u * cc];
    let unit = bitcast<i32>(params[11]);
    if all(xa == xc) && !lt64(mul32(u32(unit), u32(unit)), sq(xa)) {
        return false;
    }
    let d = xa - xc;
    var pair: array<vec3<i32>, 2>;
    if params[24] == 0u {
        pair = eqs_7_8(xa, xc, turned(d, s), ma, mc);
    } else {
        let limit2 = mul32(params[25], params[25]);
        var fits = false;
        for (var i = 0; i < 16 && !fits; i++) {
            pair = eqs_7_8(xa, xc, turned(d, s), ma, mc);
            fits = !lt64(limit2, sq(pair[0])) && !lt64(limit2, sq(pair[1]));
        }
        if !fits {
            pair = eqs_7_8(xa, xc, d, ma, mc);
        }
    }
    if params[51] != 0u {
        pair = energy_neutral(pair, ma, mc);
    }
    (*out)[0] = clamp_speed(pair[0], ca, counts);
    (*out)[1] = clamp_speed(pair[1], cc, counts);
    return true;
}

// ---- M5.7b: resting contact ---------------------------------------------

// What a block's particles rest on: whether the support holds, what a fast
// particle of the upper half does there (0 left to M5.4, 1 reflects, 2
// stops) and the particles that rest.
struct Resting {
    held: bool,
    fast: u32,
    cells: u32,
}

// A component along the support axis, positive into the support.
fn into_support(x: i32) -> i32 {
    return select(-x, x, params[64] != 0u);
}

// Which particles of the block rest, from their stored velocities, and
// whether its lower half is all walls, obstacles (`blocked`) or particles.
fn resting_of(b: ptr<function, Block>, blocked: u32) -> Resting {
    let axis = params[63];
    let lower = params[65];
    let occ = (*b).occ;
    var still = 0u;
    var falling = 0u;
    for (var c = 0u; c < CELLS; c++) {
        if (occ >> c & 1u) != 0u {
            let q = (*b).v[c];
            still |= select(0u, 1u, all(q == vec3<i32>(0))) << c;
            falling |= select(0u, 1u, into_support(q[axis]) > 0) << c;
        }
    }
    let held = (lower & ~(blocked | occ)) == 0u;
    let upper = ~lower & ((1u << CELLS) - 1u);
    var fast = 2u;
    if (lower & occ) == 0u {
        fast = 0u;
    } else if (upper & ~(occ | blocked)) != 0u {
        fast = 1u;
    }
    let on = held && (lower & falling) == 0u;
    return Resting(held, fast, still & select(lower, 0xffu, on));
}

// M5.7b's second step where the support holds: each particle of the upper
// half coming into it slowly (or caged) takes the support's speed, and
// what little it slides across too; one coming fast with room above
// reflects with e; against walls and obstacles alone it is left to M5.4.
fn settle(b: ptr<function, Block>, x: ptr<function, array<vec3<i32>, CELLS>>, changed: ptr<function, u32>, r: Resting) {
    let axis = params[63];
    let lower = params[65];
    let slow = params[66];
    let occ = (*b).occ;
    var floor = 0x7fffffff;
    for (var c = 0u; c < CELLS; c++) {
        if (lower >> c & 1u) != 0u {
            var away = 0;
            if (occ >> c & 1u) != 0u {
                away = into_support((*x)[c][axis]);
            }
            floor = min(floor, max(away, 0));
        }
    }
    for (var c = 0u; c < CELLS; c++) {
        if (occ >> c & 1u) == 0u || (lower >> c & 1u) != 0u {
            continue;
        }
        var y = (*x)[c];
        let closing = into_support(y[axis]) - floor;
        var after = floor;
        if u32(abs(closing)) <= slow {
            for (var k = 0u; k < DIM; k++) {
                if k != axis && u32(abs(y[k])) <= slow {
                    y[k] = 0;
                }
            }
        } else if closing < 0 || r.fast == 0u {
            continue;
        } else if r.fast == 1u {
            after = floor - mulq(closing, bitcast<i32>(params[10]), 16u);
        }
        y[axis] = into_support(after);
        (*x)[c] = y;
        *changed |= 1u << c;
    }
}

// M5.1 on every particle (where a force is on; less the uniform push for a
// particle at rest, M5.7b), M5.1b, M5.7b, M5.2 on the block's pair, then
// M1 for every velocity they changed, in cell order.
fn change(b: ptr<function, Block>, at: array<vec3<u32>, CELLS>, blocked: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) {
    var x: array<vec3<i32>, CELLS>;
    var changed = 0u;
    var resting = Resting(false, 0u, 0u);
    if params[62] != 0u {
        resting = resting_of(b, blocked);
    }
    for (var c = 0u; c < CELLS; c++) {
        x[c] = (*b).v[c] << vec3<u32>(fine());
        if params[22] != 0u && ((*b).occ >> c & 1u) != 0u {
            // A push of exactly zero touches nothing (M5.1).
            var dv = push_at(at[c], (*b).mass[c]);
            if (resting.cells >> c & 1u) != 0u {
                for (var k = 0u; k < 3u; k++) {
                    dv[k] = sub64(dv[k], vec2<u32>(params[16u + 2u * k], params[17u + 2u * k]));
                }
            }
            if !is_zero64(dv[0] | dv[1] | dv[2]) {
                x[c] = clamp_speed(pushed(x[c], dv), (*b).mass[c], counts);
                changed |= 1u << c;
            }
        }
    }
    // M5.1b: towards the flow, C v + (1 - C) u.
    if params[43] != 0u {
        let keep = bitcast<i32>(params[44]);
        for (var c = 0u; c < CELLS; c++) {
            if ((*b).occ >> c & 1u) == 0u {
                continue;
            }
            let u = flow_at(at[c]);
            var y = vec3<i32>(0);
            for (var k = 0u; k < DIM; k++) {
                let a = mulq(x[c][k], keep, 16u);
                let w = mulq(u[k], 65536 - keep, 16u);
                y[k] = clamp64(add64(wide64(a), wide64(w)), 1 << 30u);
            }
            x[c] = clamp_speed(y, (*b).mass[c], counts);
            changed |= 1u << c;
        }
    }
    if params[62] != 0u && resting.held {
        settle(b, &x, &changed, resting);
    }
    // M5.2's pair, the block's first draw.
    if ((*b).occ & ((*b).occ - 1u)) != 0u {
        let pair = pair_cells(below(s, PAIRS));
        let a = pair.x;
        let c = pair.y;
        var out: array<vec3<i32>, 2>;
        if ((*b).occ >> a & (*b).occ >> c & 1u) != 0u && collide(x[a], x[c], (*b).mass[a], (*b).mass[c], &out, s, counts) {
            x[a] = out[0];
            x[c] = out[1];
            changed |= (1u << a) | (1u << c);
        }
    }
    for (var c = 0u; c < CELLS; c++) {
        if (changed >> c & 1u) != 0u {
            (*b).v[c] = round_velocity(x[c], s);
        }
    }
}

// The surface entry of the cell at p, by binary search: its index, or the
// count where it has none.
fn surface_of(p: vec3<u32>) -> u32 {
    let cell = cell_index(p);
    var lo = 0u;
    var hi = params[40];
    while lo < hi {
        let mid = (lo + hi) / 2u;
        let at = surfaces[5u * mid];
        if at == cell {
            return mid;
        }
        if at < cell {
            lo = mid + 1u;
        } else {
            hi = mid;
        }
    }
    return params[40];
}

// M4: a cell at raw coordinates (one cell beyond a face at most), with
// every axis resolved: the cell inside, or beyond a wall (kind 1, which
// wins at a corner) or an open face (kind 2), with the sum of the walls'
// inward normals.
struct Place {
    at: vec3<u32>,
    kind: u32,
    inward: vec3<i32>,
}

fn place(raw: vec3<i32>) -> Place {
    let n = sizes();
    var p = Place(vec3<u32>(0u), 0u, vec3<i32>(0));
    for (var k = 0u; k < DIM; k++) {
        let r = resolve(raw[k], k, n[k]);
        p.at[k] = r.at;
        p.inward[k] = r.inward;
        if r.kind == 1u {
            p.kind = 1u;
        } else if r.kind == 2u && p.kind == 0u {
            p.kind = 2u;
        }
    }
    return p;
}

// M5.4's test of a particle at raw p with working velocity v: whether a
// cell along one axis of its velocity is neither an obstacle's nor beyond
// a wall.
fn axis_move_free(p: vec3<i32>, v: vec3<i32>) -> bool {
    for (var k = 0u; k < DIM; k++) {
        if v[k] == 0 {
            continue;
        }
        var to = p;
        to[k] += select(-1, 1, v[k] > 0);
        let there = place(to);
        if there.kind == 2u || (there.kind == 0u && !is_obstacle(there.at)) {
            return true;
        }
    }
    return false;
}

// M5.4: the particle in cell c wants the blocked cell t. Its surface: a
// wall's normal and the walls' restitution, an obstacle cell's entry, or
// (an obstacle cell without one) the direction back to the particle with
// the walls' restitution. Where the particle already leaves that surface
// (N.v >= 0), it keeps its velocity (nothing drawn) if N faces its cell
// and it has a free cell along an axis of its velocity; otherwise it is
// reflected off the face it came through. Eq. 9 in fine units, then the
// clamp and M1.
fn reflect_off(b: ptr<function, Block>, site: ptr<function, Site>, c: u32, t: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) {
    let x = (*b).v[c] << vec3<u32>(fine());
    var n = back_normal(c, t);
    var e = bitcast<i32>(params[15]);
    if ((*site).wall >> t & 1u) != 0u {
        n = (*site).normal[t];
    } else {
        let i = surface_of((*site).at[t]);
        if i < params[40] {
            n = vec3<i32>(bitcast<i32>(surfaces[5u * i + 1u]), bitcast<i32>(surfaces[5u * i + 2u]), bitcast<i32>(surfaces[5u * i + 3u]));
            e = bitcast<i32>(surfaces[5u * i + 4u]);
        }
    }
    if !is_negative64(dot_q30(x, n)) {
        let back = back_normal(c, t);
        let facing = dot_q30(n, back);
        if !is_negative64(facing) && !is_zero64(facing) && axis_move_free((*site).raw[c], x) {
            return;
        }
        n = back;
    }
    let dot = dot_q30(x, n);
    var y = x;
    if is_negative64(dot) {
        // dot >> 30 fits 32 bits: |x| < 2^28, |n| <= 2^30.
        let d = bitcast<i32>((dot.x >> 30u) | (dot.y << 2u));
        let sigma = mulq(d, 65536 + e, 16u);
        for (var k = 0; k < 3; k++) {
            y[k] = clamp(x[k] - mulq(sigma, n[k], 30u), -(1 << 30u), 1 << 30u);
        }
    }
    (*b).v[c] = round_velocity(clamp_speed(y, (*b).mass[c], counts), s);
}

// The exact dot product of a working velocity and a Q30 vector, 64 bits
// (two's complement).
fn dot_q30(x: vec3<i32>, n: vec3<i32>) -> vec2<u32> {
    var dot = vec2<u32>(0u, 0u);
    for (var k = 0; k < 3; k++) {
        var p = mul32(u32(abs(x[k])), u32(abs(n[k])));
        if (x[k] < 0) != (n[k] < 0) {
            p = neg64(p);
        }
        dot = add64(dot, p);
    }
    return dot;
}

// The unit vector from cell `toward` of a block back to cell `back`, in
// Q30: an axis or a diagonal.
fn back_normal(back: u32, toward: u32) -> vec3<i32> {
    var n = vec3<i32>(0);
    for (var k = 0u; k < DIM; k++) {
        n[k] = i32(back >> k & 1u) - i32(toward >> k & 1u);
    }
    return axis_q30(n);
}

// M5.7 (params[26]): every particle refused the cell it wanted meets the
// particle placed there, in the order of the refused particles' cells:
// eqs. 7-8 with R from the wanted cell back to its own, where it was
// closing in; both clamped; then M1 for every velocity a contact changed,
// in cell order.
fn contacts(b: ptr<function, Block>, want: u32, targets: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) {
    let occ = (*b).occ;
    let axes = (1u << DIM) - 1u;
    var x: array<vec3<i32>, CELLS>;
    for (var c = 0u; c < CELLS; c++) {
        x[c] = (*b).v[c] << vec3<u32>(fine());
    }
    var changed = 0u;
    for (var a = 0u; a < CELLS; a++) {
        let m = want >> (DIM * a) & axes;
        let wanted = a ^ m;
        if (occ >> a & 1u) == 0u || m == 0u || (targets >> (4u * a) & 7u) == wanted {
            continue;
        }
        var h = CELLS;
        for (var c = 0u; c < CELLS; c++) {
            if h == CELLS && (occ >> c & 1u) != 0u && (targets >> (4u * c) & 7u) == wanted {
                h = c;
            }
        }
        if h == CELLS {
            continue;
        }
        let r = back_normal(a, wanted);
        let d = x[a] - x[h];
        if !is_negative64(dot_q30(d, r)) {
            continue; // not closing in
        }
        // |d| rounded to nearest: one square root a contact.
        let length = i32(rsqrt(sq(d)));
        let ca = (*b).mass[a];
        let ch = (*b).mass[h];
        let t = vec3<i32>(mulq(length, r.x, 30u), mulq(length, r.y, 30u), mulq(length, r.z, 30u));
        var pair = eqs_7_8(x[a], x[h], t, classes[8u * ca], classes[8u * ch]);
        if params[51] != 0u {
            pair = energy_neutral(pair, classes[8u * ca], classes[8u * ch]);
        }
        x[a] = clamp_speed(pair[0], ca, counts);
        x[h] = clamp_speed(pair[1], ch, counts);
        changed |= (1u << a) | (1u << h);
    }
    for (var c = 0u; c < CELLS; c++) {
        if (changed >> c & 1u) != 0u {
            (*b).v[c] = round_velocity(x[c], s);
        }
    }
}

// M5.3: the axes along which the particle in cell c with stored velocity
// q could move inside its block: towards +k from the low side, towards -k
// from the high.
fn inward_axes(q: vec3<i32>, c: u32) -> u32 {
    var inward = 0u;
    for (var k = 0u; k < DIM; k++) {
        let low = (c >> k & 1u) == 0u;
        if (low && q[k] > 0) || (!low && q[k] < 0) {
            inward |= 1u << k;
        }
    }
    return inward;
}

// Cells apart within a block: the axes along which a and b differ.
fn dist(a: u32, b: u32) -> u32 {
    return countOneBits((a ^ b) & 7u);
}

// M5.6 by exhaustive search (the paper's method): every way of giving the
// particles (in cell order, cells[0..count]) distinct free cells, in the
// order of the CPU's depth-first search (the first particle's cell
// slowest, cells in increasing order), the cost (distance to the wanted
// cell, then to the current, lexicographically) summed; one optimum kept
// by reservoir sampling, a draw at each tie. The cell each particle goes
// to, 4 bits a particle.
fn exhaustive(cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32, s: ptr<function, Stream>) -> u32 {
    var best = 0xffffffffu;
    var ties = 0u;
    var kept = 0u;
    // The search's stack: per particle the cells it has still to try, the
    // cost of the particles before it, the cell it is in.
    var open: array<u32, CELLS>;
    var sums: array<u32, CELLS>;
    var path = 0u;
    var used = 0u;
    var i = 0u;
    open[0] = free;
    sums[0] = 0u;
    loop {
        if open[i] == 0u {
            if i == 0u {
                break;
            }
            i -= 1u;
            used &= ~(1u << (path >> (4u * i) & 7u));
            continue;
        }
        let cell = firstTrailingBit(open[i]);
        open[i] &= open[i] - 1u;
        path = (path & ~(15u << (4u * i))) | cell << (4u * i);
        let cost = sums[i] + (dist(cell, wished[i]) << 8u | dist(cell, cells[i]));
        if i + 1u < count {
            used |= 1u << cell;
            i += 1u;
            open[i] = free & ~used;
            sums[i] = cost;
            continue;
        }
        if cost < best {
            best = cost;
            ties = 1u;
            kept = path;
        } else if cost == best {
            ties += 1u;
            if below(s, ties) == 0u {
                kept = path;
            }
        }
    }
    return kept;
}

// M5.6 by greedy (the paper's 3D approximation): particles by stored
// squared speed, fastest first (equal speeds in cell order), each to the
// free untaken cell of least cost (32 times the distance to its wanted
// cell plus the distance to its own), a draw among ties. 4 bits a
// particle.
fn greedy(b: ptr<function, Block>, cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32, s: ptr<function, Stream>) -> u32 {
    var order: array<u32, CELLS>;
    for (var i = 0u; i < count; i++) {
        let speed = stored_speed2((*b).v[cells[i]]);
        var slot = i;
        while slot > 0u {
            if stored_speed2((*b).v[cells[order[slot - 1u]]]) >= speed {
                break;
            }
            order[slot] = order[slot - 1u];
            slot -= 1u;
        }
        order[slot] = i;
    }
    var taken = 0u;
    var packed = 0u;
    for (var k = 0u; k < count; k++) {
        let i = order[k];
        var best = 0xffffffffu;
        var tied: array<u32, CELLS>;
        var ties = 0u;
        for (var cell = 0u; cell < CELLS; cell++) {
            if (free >> cell & 1u) == 0u || (taken >> cell & 1u) != 0u {
                continue;
            }
            let cost = 32u * dist(cell, wished[i]) + dist(cell, cells[i]);
            if cost < best {
                best = cost;
                ties = 0u;
            }
            if cost == best {
                tied[ties] = cell;
                ties += 1u;
            }
        }
        var pick = 0u;
        if ties > 1u {
            pick = below(s, ties);
        }
        taken |= 1u << tied[pick];
        packed |= tied[pick] << (4u * i);
    }
    return packed;
}

// The exact squared length of a stored velocity, which greedy ranks by
// (M5.6): 3 32767^2 fits a word.
fn stored_speed2(q: vec3<i32>) -> u32 {
    return u32(q.x * q.x) + u32(q.y * q.y) + u32(q.z * q.z);
}

// M5.6: the cell each particle goes to, 4 bits a cell, counting those not
// placed in the cell they want; exact-fast (`exact_fast`, the dimension's),
// exhaustive search or greedy, as the description chooses (params[54]).
fn assign(b: ptr<function, Block>, blocked: u32, want: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) -> u32 {
    let occ = (*b).occ;
    let axes = (1u << DIM) - 1u;
    // Where nobody wants to move, or the block holds one particle, the
    // optimum is unique and no method draws for it.
    if want == 0u {
        return IDENTITY;
    }
    if (occ & (occ - 1u)) == 0u {
        let c = firstTrailingBit(occ);
        return IDENTITY ^ ((want >> (DIM * c) & axes) << (4u * c));
    }
    var cells: array<u32, CELLS>;
    var wished: array<u32, CELLS>;
    var count = 0u;
    for (var c = 0u; c < CELLS; c++) {
        if (occ >> c & 1u) != 0u {
            cells[count] = c;
            wished[count] = c ^ (want >> (DIM * c) & axes);
            count += 1u;
        }
    }
    let free = ~blocked & ((1u << CELLS) - 1u);
    var packed: u32;
    if params[54] == 1u {
        packed = exact_fast(cells, wished, count, free, occ, blocked, want, s);
    } else if params[54] == 0u {
        packed = exhaustive(cells, wished, count, free, s);
    } else {
        packed = greedy(b, cells, wished, count, free, s);
    }
    var targets = IDENTITY;
    for (var i = 0u; i < count; i++) {
        let t = packed >> (4u * i) & 7u;
        targets = (targets & ~(15u << (4u * cells[i]))) | t << (4u * cells[i]);
        (*counts).displaced += select(0u, 1u, t != wished[i]);
    }
    return targets;
}

// ---- The sweep ----------------------------------------------------------

// The occupancy bit of the cell at p.
fn occupied(p: vec3<u32>) -> u32 {
    return occ_in[(p.z * params[7] + p.y) * params[8] + (p.x >> 5u)] >> (p.x & 31u) & 1u;
}

// `word` with the 16 bits of cell `cell` set to `value`: planes of 16 bits
// a cell keep two cells a word (rows of an even width start on a word).
fn with_half(word: u32, cell: u32, value: u32) -> u32 {
    let half = 16u * (cell & 1u);
    return (word & ~(0xffffu << half)) | (value & 0xffffu) << half;
}

// A stored velocity as its plane keeps it: a byte a component (in the low
// half of a word in 2D), or 16 bits a component, the third in a second
// word.
fn stored(q: vec3<i32>) -> vec2<u32> {
    if wide() {
        return vec2<u32>((u32(q.x) & 0xffffu) | u32(q.y) << 16u, u32(q.z) & 0xffffu);
    }
    return vec2<u32>((u32(q.x) & 0xffu) | (u32(q.y) & 0xffu) << 8u | (u32(q.z) & 0xffu) << 16u, 0u);
}

// Where the velocity of cell i starts in its plane, in words.
fn velocity_word(i: u32) -> u32 {
    if DIM == 2u {
        return select(i >> 1u, i, wide());
    }
    return select(i, 2u * i, wide());
}

// The stored velocity of cell i.
fn velocity(i: u32) -> vec3<i32> {
    let at = velocity_word(i);
    if wide() {
        let word = vel_in[at];
        let z = select(0, i32(vel_in[at + 1u] << 16u) >> 16u, DIM == 3u);
        return vec3<i32>(i32(word << 16u) >> 16u, i32(word) >> 16u, z);
    }
    let w = select(vel_in[at], vel_in[at] >> (16u * (i & 1u)), DIM == 2u);
    let z = select(0, i32(w << 8u) >> 24u, DIM == 3u);
    return vec3<i32>(i32(w << 24u) >> 24u, i32(w << 16u) >> 24u, z);
}

// Writes the stored velocity q of cell i (which this invocation owns, with
// the other cell of its word) into the step's output.
fn put_velocity(i: u32, q: vec3<i32>) {
    let at = velocity_word(i);
    let w = stored(q);
    if DIM == 2u && !wide() {
        vel_out[at] = with_half(vel_out[at], i, w.x);
        return;
    }
    vel_out[at] = w.x;
    if DIM == 3u && wide() {
        vel_out[at + 1u] = w.y;
    }
}

// put_velocity for the emitters' output.
fn put_emitted_velocity(i: u32, q: vec3<i32>) {
    let at = velocity_word(i);
    let w = stored(q);
    if DIM == 2u && !wide() {
        vel_emit[at] = with_half(vel_emit[at], i, w.x);
        return;
    }
    vel_emit[at] = w.x;
    if DIM == 3u && wide() {
        vel_emit[at + 1u] = w.y;
    }
}

// A raw coordinate along axis k of n cells (one cell beyond a face at
// most) resolved (M4): x = the cell inside, or 0 beyond a wall (kind 1) or
// an open face (kind 2), with the inward normal's component for a wall.
struct Resolved {
    at: u32,
    kind: u32,
    inward: i32,
}

fn resolve(raw: i32, k: u32, n: u32) -> Resolved {
    if raw >= 0 && raw < i32(n) {
        return Resolved(u32(raw), 0u, 0);
    }
    let high = raw >= i32(n);
    let f = face(k, high);
    if f == 0u {
        return Resolved(u32(select(raw + i32(n), raw - i32(n), high)), 0u, 0);
    }
    return Resolved(0u, f, select(0, select(1, -1, high), f == 1u));
}

// Whether the cell at p inside the domain is an obstacle's.
fn is_obstacle(p: vec3<u32>) -> bool {
    return params[50] != 0u && (obstacle[(p.z * params[7] + p.y) * params[8] + (p.x >> 5u)] >> (p.x & 31u) & 1u) != 0u;
}

// One domain row of a row of blocks: its y and z resolved (M4), its line
// y + ny z in the planes where it lies inside.
struct Line {
    raw: vec2<i32>,
    kind: u32,
    line: u32,
}

@compute @workgroup_size(64)
fn sweep(@builtin(global_invocation_id) id: vec3<u32>) {
    let n = sizes();
    let nx = n.x;
    let row_u32 = params[8];
    let step = vec2<u32>(atomicLoad(&counters[13]), atomicLoad(&counters[14]));
    if params[55] != 0u {
        eddies = eddies_of(step);
    }
    let o = step.x & 1u;
    // M3: per axis the first block's lowest cell and the block count (one
    // block along z in 2D).
    var first = vec3<i32>(0);
    var blocks = vec3<u32>(nx / 2u, n.y / 2u, 1u);
    if DIM == 3u {
        blocks.z = n.z / 2u;
    }
    for (var k = 0u; k < DIM; k++) {
        let periodic = face(k, false) == 0u;
        if o == 1u {
            first[k] = select(-1, 1, periodic);
            blocks[k] += select(1u, 0u, periodic);
        }
    }
    let w = id.x;
    let r = id.y;
    if w * 32u >= nx || r >= blocks.y * blocks.z {
        return;
    }
    // The block row's domain rows, row j at y0 + (j & 1), z0 + (j >> 1),
    // each inside or beyond a face.
    let y0 = first.y + 2 * i32(r % blocks.y);
    let z0 = first.z + 2 * i32(r / blocks.y);
    var rows: array<Line, ROWS>;
    for (var j = 0u; j < ROWS; j++) {
        let raw = vec2<i32>(y0 + i32(j & 1u), z0 + i32(j >> 1u));
        let p = place(vec3<i32>(0, raw));
        rows[j] = Line(raw, p.kind, p.at.z * n.y + p.at.y);
    }
    let lo = 32u * w;
    let hi = min(lo + 32u, nx);
    // Nothing to do where no row holds a particle in the word or beside
    // it.
    var near = 0u;
    let before = resolve(i32(lo) - 1, 0u, nx);
    let after = resolve(i32(hi), 0u, nx);
    for (var j = 0u; j < ROWS; j++) {
        if rows[j].kind == 0u {
            let at = rows[j].line * row_u32;
            near |= occ_in[at + w];
            if o == 1u {
                if before.kind == 0u {
                    near |= occ_in[at + (before.at >> 5u)] >> (before.at & 31u) & 1u;
                }
                if after.kind == 0u {
                    near |= occ_in[at + (after.at >> 5u)] >> (after.at & 31u) & 1u;
                }
            }
        }
    }
    if near == 0u {
        for (var j = 0u; j < ROWS; j++) {
            if rows[j].kind == 0u {
                occ_out[rows[j].line * row_u32 + w] = 0u;
            }
        }
        return;
    }
    // The occupancy it owns, built up; everything else a particle carries
    // is written to its cell as it is placed (what an empty cell holds is
    // never read).
    var out_occ: array<u32, ROWS>;
    for (var j = 0u; j < ROWS; j++) {
        out_occ[j] = 0u;
    }
    var counts = Counts(0u, 0u, vec2<u32>(0u, 0u), false, 0u, 0u, 0u, 0u);
    // M8's block streams: their domain ("mpcablk"), 2^16 counters a block.
    let sk = step_key(vec2<u32>(params[0], params[1]), step, vec2<u32>(0x626c6b00u, 0x6d706361u), 16u);
    // The blocks with a cell in [lo, hi): x0 + 1 >= lo and x0 < hi.
    let bx_lo = (i32(lo) - first.x) >> 1u;
    let bx_hi = (i32(hi) - 1 - first.x) >> 1u;
    for (var bxi = bx_lo; bxi <= bx_hi; bxi++) {
        // The block before the first cell, on a periodic axis, is the one
        // that wraps round; where it is also one of the word's own (a row
        // of one word) it is taken once.
        var bx = bxi;
        if bx < 0 {
            if bx_hi >= i32(blocks.x) - 1 {
                continue;
            }
            bx += i32(blocks.x);
        }
        if bx >= i32(blocks.x) {
            continue;
        }
        let x0 = first.x + 2 * bx;
        let cols = array<Resolved, 2>(resolve(x0, 0u, nx), resolve(x0 + 1, 0u, nx));
        var b: Block;
        var site: Site;
        b.occ = 0u;
        site.wall = 0u;
        site.open = 0u;
        site.blocked = 0u;
        for (var c = 0u; c < CELLS; c++) {
            let row = rows[c >> 1u];
            let raw = vec3<i32>(x0 + i32(c & 1u), row.raw);
            let p = place(raw);
            site.raw[c] = raw;
            site.at[c] = p.at;
            b.v[c] = vec3<i32>(0);
            site.normal[c] = vec3<i32>(0);
            b.life[c] = 0u;
            b.mass[c] = 0u;
            b.tag[c] = 0u;
            b.id[c] = 0u;
            b.age[c] = 0u;
            if p.kind == 0u {
                if is_obstacle(p.at) {
                    site.blocked |= 1u << c;
                }
                if occupied(p.at) != 0u {
                    b.occ |= 1u << c;
                    let i = cell_index(p.at);
                    b.v[c] = velocity(i);
                    if params[36] != 0u {
                        b.life[c] = life_in[i >> 1u] >> (16u * (i & 1u)) & 0xffffu;
                    }
                    if masses_on() || (params[53] & 4u) != 0u {
                        let carried = mass_in[i >> 1u] >> (16u * (i & 1u));
                        b.mass[c] = select(0u, carried & 0xffu, masses_on());
                        b.tag[c] = carried >> 8u & 0xffu;
                    }
                    if (params[53] & 3u) != 0u {
                        b.id[c] = ident_in[2u * i];
                        b.age[c] = ident_in[2u * i + 1u];
                    }
                }
            } else if p.kind == 1u {
                // A corner beyond a wall and an open face is a wall; its
                // normal is the sum of the walls' inward normals, made unit.
                site.wall |= 1u << c;
                site.blocked |= 1u << c;
                site.normal[c] = axis_q30(p.inward);
            } else {
                site.open |= 1u << c;
            }
        }
        if b.occ == 0u {
            continue;
        }
        var block_counts = Counts(0u, 0u, vec2<u32>(0u, 0u), false, 0u, 1u, 0u, 0u);
        let index = u32(bx) + blocks.x * r;
        var s = stream_of(sk, index);
        change(&b, site.at, site.blocked, &s, &block_counts);
        let want = desire(&b, &site, &s, &block_counts);
        let targets = assign(&b, site.blocked, want, &s, &block_counts);
        if params[26] != 0u && want != 0u {
            contacts(&b, want, targets, &s, &block_counts);
        }
        for (var c = 0u; c < CELLS; c++) {
            if (b.occ >> c & 1u) == 0u {
                continue;
            }
            let t = targets >> (4u * c) & 7u;
            if (site.open >> t & 1u) != 0u {
                block_counts.exited += 1u; // M4: through an open face
                continue;
            }
            if b.life[c] == 1u {
                block_counts.expired += 1u; // M6: its last step
                continue;
            }
            let x = cols[t & 1u].at;
            if x < lo || x >= hi {
                continue;
            }
            let j = t >> 1u;
            out_occ[j] |= 1u << (x - lo);
            // Where two cells share a word, both are this invocation's.
            let cell = rows[j].line * nx + x;
            put_velocity(cell, b.v[c]);
            if params[36] != 0u {
                life_out[cell >> 1u] = with_half(life_out[cell >> 1u], cell, max(b.life[c], 1u) - 1u);
            }
            if masses_on() || (params[53] & 4u) != 0u {
                mass_out[cell >> 1u] = with_half(mass_out[cell >> 1u], cell, b.mass[c] | b.tag[c] << 8u);
            }
            // M6b: the id and the tag go with the particle, its age counts
            // the step (saturating).
            if (params[53] & 3u) != 0u {
                ident_out[2u * cell] = b.id[c];
                ident_out[2u * cell + 1u] = select(b.age[c] + 1u, b.age[c], b.age[c] == 0xffffffffu);
            }
        }
        // Counted by the invocation that owns the block's first cell inside.
        let owner = u32(max(x0, 0));
        if owner >= lo && owner < hi {
            counts.collisions += block_counts.collisions;
            counts.clamps += block_counts.clamps;
            let total = add64(counts.energy, block_counts.energy);
            counts.saturated = counts.saturated || block_counts.saturated || lt64(total, block_counts.energy);
            counts.energy = total;
            counts.displaced += block_counts.displaced;
            counts.exited += block_counts.exited;
            counts.expired += block_counts.expired;
            counts.processed += 1u;
        }
    }
    for (var j = 0u; j < ROWS; j++) {
        if rows[j].kind == 0u {
            occ_out[rows[j].line * row_u32 + w] = out_occ[j];
        }
    }
    add_count(0u, counts.collisions);
    add_count(2u, counts.clamps);
    add_wide(4u, counts.energy);
    if counts.saturated {
        atomicOr(&counters[11], 1u);
    }
    add_count(6u, counts.displaced);
    add_count(8u, counts.exited);
    add_count(19u, counts.expired);
    if counts.processed != 0u {
        atomicAdd(&counters[10], counts.processed);
    }
}

// M6, once a step before its sweep, in one invocation: each emitter in
// turn asks for the whole part of its rate and one more where 24 random
// bits fall below its threshold, and places them in a uniform choice of
// the free cells of its region (selection sampling, walking the region in
// cell order), each with its velocity, spread over the disc (2D) or ball
// (3D) of its radius (16-bit draws until inside: 32 bits, then 16 in 3D),
// clamped uncounted and rounded (M1, one 64-bit output), from its stream
// of (seed, step, emitter).
@compute @workgroup_size(1)
fn emit() {
    let step = vec2<u32>(atomicLoad(&counters[13]), atomicLoad(&counters[14]));
    let seed = vec2<u32>(params[0], params[1]);
    // M8's emitter streams: their own domain ("mpcaemi"), 2^32 counters
    // an emitter.
    let key = step_key(seed, step, vec2<u32>(0x656d6900u, 0x6d706361u), 32u);
    let row_u32 = params[8];
    let unit = params[11];
    for (var i = 0u; i < params[35]; i++) {
        let e = 16u * i;
        var s = stream_of(key, i);
        var wanted = vec2<u32>(emitters[e + 6u], emitters[e + 7u]);
        if bits(&s, 24u) < emitters[e + 8u] && !all(wanted == vec2<u32>(0xffffffffu)) {
            wanted = add64(wanted, vec2<u32>(1u, 0u));
        }
        if is_zero64(wanted) {
            continue;
        }
        let min_at = vec3<u32>(emitters[e], emitters[e + 1u], emitters[e + 2u]);
        let max_at = vec3<u32>(emitters[e + 3u], emitters[e + 4u], emitters[e + 5u]);
        var free = 0u;
        for (var z = min_at.z; z < max_at.z; z++) {
            for (var y = min_at.y; y < max_at.y; y++) {
                let line = (z * params[7] + y) * row_u32;
                for (var x = min_at.x; x < max_at.x; x++) {
                    free += select(1u - (occ_emit[line + (x >> 5u)] >> (x & 31u) & 1u), 0u, is_obstacle(vec3<u32>(x, y, z)));
                }
            }
        }
        var placing = select(free, wanted.x, wanted.y == 0u && wanted.x < free);
        // M6b: no more particles than ids are left; the rest falls short.
        if (params[53] & 1u) != 0u {
            placing = min(placing, 0xffffffffu - atomicLoad(&counters[21]));
        }
        var need = placing;
        var left = free;
        for (var z = min_at.z; z < max_at.z; z++) {
            for (var y = min_at.y; y < max_at.y; y++) {
                for (var x = min_at.x; x < max_at.x; x++) {
                    let word = (z * params[7] + y) * row_u32 + (x >> 5u);
                    let p = vec3<u32>(x, y, z);
                    if need == 0u || (occ_emit[word] >> (x & 31u) & 1u) != 0u || is_obstacle(p) {
                        continue;
                    }
                    let take = below(&s, left) < need;
                    left -= 1u;
                    if !take {
                        continue;
                    }
                    need -= 1u;
                    var v = vec3<i32>(bitcast<i32>(emitters[e + 9u]), bitcast<i32>(emitters[e + 10u]), bitcast<i32>(emitters[e + 11u]));
                    let radius = bitcast<i32>(emitters[e + 12u]);
                    if radius > 0 {
                        var d: vec3<i32>;
                        loop {
                            let xy = bits(&s, 32u);
                            var z16 = 32768u;
                            if DIM == 3u {
                                z16 = bits(&s, 16u);
                            }
                            d = vec3<i32>(i32(xy & 0xffffu), i32(xy >> 16u), i32(z16)) - vec3<i32>(32768);
                            if !lt64(vec2<u32>(1u << 30u, 0u), sq(d)) {
                                break;
                            }
                        }
                        v += vec3<i32>(mulq(d.x, radius, 15u), mulq(d.y, radius, 15u), mulq(d.z, radius, 15u));
                    }
                    let s2 = sq(v);
                    if lt64(mul32(unit, unit), s2) {
                        v = shorten(v, s2);
                    }
                    let r = next64(&s);
                    let limit = vec3<i32>(select(127, 32767, wide()));
                    let mask = (1u << fine()) - 1u;
                    let noise = vec3<i32>(vec3<u32>(r.x, r.x >> 16u, r.y) & vec3<u32>(mask));
                    let q = clamp((v + noise) >> vec3<u32>(fine()), -limit, limit);
                    occ_emit[word] |= 1u << (x & 31u);
                    let cell = cell_index(p);
                    put_emitted_velocity(cell, q);
                    if params[36] != 0u {
                        life_emit[cell >> 1u] = with_half(life_emit[cell >> 1u], cell, emitters[e + 13u]);
                    }
                    if masses_on() || (params[53] & 4u) != 0u {
                        let carried = select(0u, emitters[e + 14u] & 0xffu, masses_on()) | (emitters[e + 15u] & 0xffu) << 8u;
                        mass_emit[cell >> 1u] = with_half(mass_emit[cell >> 1u], cell, carried);
                    }
                    // M6b: the next id, age 0.
                    if (params[53] & 1u) != 0u {
                        let id = atomicLoad(&counters[21]) + 1u;
                        atomicStore(&counters[21], id);
                        ident_emit[2u * cell] = id;
                    }
                    if (params[53] & 2u) != 0u {
                        ident_emit[2u * cell + 1u] = 0u;
                    }
                }
            }
        }
        add_wide(17u, sub64(wanted, vec2<u32>(placing, 0u)));
        let at = 4u * i;
        let requested = add64(vec2<u32>(emitter_stats[at], emitter_stats[at + 1u]), wanted);
        let delivered = add64(vec2<u32>(emitter_stats[at + 2u], emitter_stats[at + 3u]), vec2<u32>(placing, 0u));
        emitter_stats[at] = requested.x;
        emitter_stats[at + 1u] = requested.y;
        emitter_stats[at + 2u] = delivered.x;
        emitter_stats[at + 3u] = delivered.y;
        add_count(15u, placing);
    }
}

// After a step's sweep: its processed blocks become the last step's, and
// the step number advances (M3's parity with it).
@compute @workgroup_size(1)
fn end_step() {
    atomicStore(&counters[12], atomicExchange(&counters[10], 0u));
    let low = atomicAdd(&counters[13], 1u);
    if low == 0xffffffffu {
        atomicAdd(&counters[14], 1u);
    }
}

fn add_count(at: u32, n: u32) {
    if n != 0u {
        let old = atomicAdd(&counters[at], n);
        if old + n < old {
            atomicAdd(&counters[at + 1u], 1u);
        }
    }
}

// Adds a 64-bit n to the counter pair at `at`; a carry out of the pair
// sets the clamp energy's saturation flag where `at` is that counter (the
// others cannot reach 2^64).
fn add_wide(at: u32, n: vec2<u32>) {
    if is_zero64(n) {
        return;
    }
    let old = atomicAdd(&counters[at], n.x);
    let carry = select(0u, 1u, old + n.x < old);
    let high = n.y + carry;
    if high != 0u {
        let before = atomicAdd(&counters[at + 1u], high);
        if before + high < before && at == 4u {
            atomicOr(&counters[11], 1u);
        }
    }
}
