// The local map of M5 on the 2D blocks of one step, for 8-bit storage, as
// docs/model.md states it (M1c, M3, M5, M8). One invocation owns one
// 32-cell word of the occupancy in each of the two domain rows of a row of
// blocks, and the velocities of those cells: it processes every block that
// touches them (at offset 1 the two blocks that straddle its edges are also
// processed by its neighbours, each with the same result) and writes only
// what it owns, into the other buffer of the pair. No two invocations write
// the same word. A block's counts go to the invocation that owns its first
// cell.
//
// 64-bit integers are vec2<u32> (low, high): WGSL has none.

// params: 0-1 key, 2-3 gamma, 4-5 stride, 6 nx, 7 ny, 8 u32 words a row of
// the occupancy, 9 offset, 10 restitution (Q16), 11 unit W, 12-13 the
// clamp's energy factor (significand, exponent).
@group(0) @binding(0) var<storage, read> params: array<u32>;
// tables: 0..256 M5.3 move limits; 256..2304 the turns of M5.2 (cos, sin
// as i32); 2304..3600 per 2D key its assignments (start | count << 16,
// count 0 for none); 3600.. the assignments.
@group(0) @binding(1) var<storage, read> tables: array<u32>;
@group(0) @binding(2) var<storage, read> occ_in: array<u32>;
@group(0) @binding(3) var<storage, read> vel_in: array<u32>;
@group(0) @binding(4) var<storage, read_write> occ_out: array<u32>;
@group(0) @binding(5) var<storage, read_write> vel_out: array<u32>;
// counters: pairs (low, high) of collisions, clamps, clamp energy,
// displaced, exited; 10 blocks processed in this step; 11 the clamp energy
// saturated.
@group(0) @binding(6) var<storage, read_write> counters: array<atomic<u32>>;

const TURNS_AT: u32 = 256u;
const KEYS_AT: u32 = 2304u;
const LISTS_AT: u32 = 3600u;

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

// A uniform number below n (at most 2^16): 16 bits a try, Lemire's
// multiply and reject.
fn below(s: ptr<function, Stream>, n: u32) -> u32 {
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

fn sq2(x: vec2<i32>) -> vec2<u32> {
    return add64(mul32(u32(abs(x.x)), u32(abs(x.x))), mul32(u32(abs(x.y)), u32(abs(x.y))));
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
}

// M5.5: x clamped to the unit speed, counted.
fn clamp_speed(x: vec2<i32>, counts: ptr<function, Counts>) -> vec2<i32> {
    let unit = bitcast<i32>(params[11]);
    let s2 = sq2(x);
    let limit = mul32(u32(unit), u32(unit));
    if !lt64(limit, s2) {
        return x;
    }
    (*counts).clamps += 1u;
    let removed = count_times(sub64(s2, limit), params[12], bitcast<i32>(params[13]));
    let total = add64((*counts).energy, removed);
    if lt64(total, removed) {
        (*counts).saturated = true;
    }
    (*counts).energy = total;
    // ceil(sqrt(s2)), then floor(2^32 W / L): never longer than W.
    let r = isqrt64(s2);
    let length = r.x + select(0u, 1u, lt64(mul32(r.x, r.x), s2));
    let factor = long_division(u32(unit) << 1u, length, 32u);
    var out = x;
    for (var k = 0; k < 2; k++) {
        let scaled = i32(mul32(u32(abs(x[k])), factor).y);
        out[k] = select(scaled, -scaled, x[k] < 0);
    }
    return out;
}

// M1: a working velocity (fine units of 2^-16 quanta) to stored quanta,
// 16 random bits a component.
fn round_velocity(x: vec2<i32>, s: ptr<function, Stream>) -> vec2<i32> {
    let r = bits(s, 32u);
    return vec2<i32>((x.x + i32(r & 0xffffu)) >> 16u, (x.y + i32(r >> 16u)) >> 16u);
}

// ---- The block ----------------------------------------------------------

struct Block {
    occ: u32,
    v: array<vec2<i32>, 4>,
}

const PAIR_A = array<u32, 6>(0u, 0u, 0u, 1u, 1u, 2u);
const PAIR_B = array<u32, 6>(1u, 2u, 3u, 2u, 3u, 3u);
const PLACE = array<u32, 4>(1u, 6u, 36u, 216u);

// M5.2 on the block's pair: eqs. 7-8 with R a turn of 1,024 (one mass),
// both clamped, then both rounded (M1).
fn collide(b: ptr<function, Block>, a: u32, c: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) {
    (*counts).collisions += 1u;
    let xa = (*b).v[a] << vec2<u32>(16u);
    let xc = (*b).v[c] << vec2<u32>(16u);
    let unit = bitcast<i32>(params[11]);
    if all(xa == xc) && !lt64(mul32(u32(unit), u32(unit)), sq2(xa)) {
        return;
    }
    let d = xa - xc;
    let j = bits(s, 10u);
    let cs = bitcast<i32>(tables[TURNS_AT + 2u * j]);
    let sn = bitcast<i32>(tables[TURNS_AT + 2u * j + 1u]);
    let t = vec2<i32>(mulq(d.x, cs, 30u) - mulq(d.y, sn, 30u), mulq(d.x, sn, 30u) + mulq(d.y, cs, 30u));
    let e = bitcast<i32>(params[10]);
    var na: vec2<i32>;
    var nc: vec2<i32>;
    for (var k = 0; k < 2; k++) {
        let v0 = xc[k] + mulq(xa[k] - xc[k], 32768, 16u);
        let u = mulq(t[k], e, 16u);
        na[k] = v0 + mulq(u, 32768, 16u);
        nc[k] = xa[k] + xc[k] - na[k];
    }
    na = clamp_speed(na, counts);
    nc = clamp_speed(nc, counts);
    (*b).v[a] = round_velocity(na, s);
    (*b).v[c] = round_velocity(nc, s);
}

// M5.3: the axes each particle wants to cross, two bits a cell.
fn desire(b: ptr<function, Block>, s: ptr<function, Stream>) -> u32 {
    var inward = 0u;
    for (var c = 0u; c < 4u; c++) {
        if ((*b).occ >> c & 1u) == 0u {
            continue;
        }
        let q = (*b).v[c];
        let low_x = (c & 1u) == 0u;
        let low_y = (c & 2u) == 0u;
        if (low_x && q.x > 0) || (!low_x && q.x < 0) {
            inward |= 1u << (2u * c);
        }
        if (low_y && q.y > 0) || (!low_y && q.y < 0) {
            inward |= 2u << (2u * c);
        }
    }
    if inward == 0u {
        return 0u;
    }
    let bytes = next64(s);
    var want = 0u;
    for (var i = 0u; i < 8u; i++) {
        if (inward >> i & 1u) == 0u {
            continue;
        }
        let q = (*b).v[i / 2u][i % 2u];
        let high = select(bytes.y, bytes.x, i < 4u) >> (8u * (i % 4u)) & 0xffu;
        let limit = tables[u32(q) & 0xffu];
        let top = limit >> 8u;
        if high < top || (high == top && bits(s, 8u) <= (limit & 0xffu)) {
            want |= 1u << i;
        }
    }
    return want;
}

// M5.6, exact-fast: the cell each particle goes to, 2 bits a cell.
fn assign(b: ptr<function, Block>, want: u32, s: ptr<function, Stream>, counts: ptr<function, Counts>) -> u32 {
    let occ = (*b).occ;
    if want == 0u {
        return 0xe4u; // everyone stays: cell c to c
    }
    if (occ & (occ - 1u)) == 0u {
        let c = firstTrailingBit(occ);
        return 0xe4u ^ ((want >> (2u * c) & 3u) << (2u * c));
    }
    var key = 0u;
    for (var c = 0u; c < 4u; c++) {
        if (occ >> c & 1u) != 0u {
            key += PLACE[c] * (2u + (want >> (2u * c) & 3u));
        }
    }
    let span = tables[KEYS_AT + key];
    let count = span >> 16u;
    var pick = 0u;
    if count > 1u {
        pick = below(s, count);
    }
    let packed = tables[LISTS_AT + (span & 0xffffu) + pick];
    (*counts).displaced += packed >> 12u;
    var targets = 0u;
    for (var c = 0u; c < 4u; c++) {
        if (occ >> c & 1u) != 0u {
            targets |= (packed >> (2u * c) & 3u) << (2u * c);
        } else {
            targets |= c << (2u * c);
        }
    }
    return targets;
}

// ---- The sweep ----------------------------------------------------------

fn occupied(x: u32, y: u32) -> u32 {
    return occ_in[y * params[8] + (x >> 5u)] >> (x & 31u) & 1u;
}

fn velocity(x: u32, y: u32) -> vec2<i32> {
    let i = y * params[6] + x;
    let half = vel_in[i >> 1u] >> (16u * (i & 1u));
    return vec2<i32>(i32(half << 24u) >> 24u, i32(half << 16u) >> 24u);
}

@compute @workgroup_size(64)
fn step_2d(@builtin(global_invocation_id) id: vec3<u32>) {
    let nx = params[6];
    let ny = params[7];
    let row_u32 = params[8];
    let o = params[9];
    let w = id.x;
    let r = id.y;
    if w * 32u >= nx || r >= ny / 2u {
        return;
    }
    let ys = array<u32, 2>(2u * r + o, (2u * r + o + 1u) % ny);
    let lo = 32u * w;
    let hi = min(lo + 32u, nx);
    // Nothing to do where neither row holds a particle in the word or
    // beside it.
    var near = occ_in[ys[0] * row_u32 + w] | occ_in[ys[1] * row_u32 + w];
    if o == 1u {
        let before = (lo + nx - 1u) % nx;
        let after = hi % nx;
        near |= occupied(before, ys[0]) | occupied(before, ys[1]) | occupied(after, ys[0]) | occupied(after, ys[1]);
    }
    if near == 0u {
        occ_out[ys[0] * row_u32 + w] = 0u;
        occ_out[ys[1] * row_u32 + w] = 0u;
        return;
    }
    var out_occ = array<u32, 2>(0u, 0u);
    var out_vel: array<array<u32, 16>, 2>;
    for (var i = 0u; i < 16u; i++) {
        out_vel[0][i] = 0u;
        out_vel[1][i] = 0u;
    }
    var counts = Counts(0u, 0u, vec2<u32>(0u, 0u), false, 0u, 0u);
    let blocks_x = nx / 2u;
    let first_bx = select(16u * w, 16u * w + blocks_x - 1u, o == 1u);
    // At offset 1 the block before the word (the one that wraps round x,
    // for the first word) is one of the word's own where a row has 16
    // blocks or fewer: each once.
    let count = min(select(min(16u, blocks_x - 16u * w), min(17u, blocks_x - 16u * w + 1u), o == 1u), blocks_x);
    for (var j = 0u; j < count; j++) {
        let bx = (first_bx + j) % blocks_x;
        let x0 = 2u * bx + o;
        let xs = array<u32, 2>(x0, (x0 + 1u) % nx);
        var b: Block;
        b.occ = 0u;
        for (var c = 0u; c < 4u; c++) {
            let x = xs[c & 1u];
            let y = ys[c >> 1u];
            if occupied(x, y) != 0u {
                b.occ |= 1u << c;
                b.v[c] = velocity(x, y);
            } else {
                b.v[c] = vec2<i32>(0, 0);
            }
        }
        if b.occ == 0u {
            continue;
        }
        var block_counts = Counts(0u, 0u, vec2<u32>(0u, 0u), false, 0u, 1u);
        let index = bx + blocks_x * r;
        var s: Stream;
        s.counter = add64(vec2<u32>(params[0], params[1]), mul64(vec2<u32>(params[4], params[5]), vec2<u32>(index, 0u)));
        s.gamma = vec2<u32>(params[2], params[3]);
        s.pool = vec2<u32>(0u, 0u);
        s.left = 0u;
        // M5.2's pair, the block's first draw.
        if (b.occ & (b.occ - 1u)) != 0u {
            let p = below(&s, 6u);
            let a = PAIR_A[p];
            let c = PAIR_B[p];
            if (b.occ >> a & b.occ >> c & 1u) != 0u {
                collide(&b, a, c, &s, &block_counts);
            }
        }
        let want = desire(&b, &s);
        let targets = assign(&b, want, &s, &block_counts);
        for (var c = 0u; c < 4u; c++) {
            if (b.occ >> c & 1u) == 0u {
                continue;
            }
            let t = targets >> (2u * c) & 3u;
            let x = xs[t & 1u];
            if x < lo || x >= hi {
                continue;
            }
            let row = t >> 1u;
            out_occ[row] |= 1u << (x - lo);
            let k = (x - lo) >> 1u;
            let byte_pair = (u32(b.v[c].x) & 0xffu) | (u32(b.v[c].y) & 0xffu) << 8u;
            out_vel[row][k] |= byte_pair << (16u * (x & 1u));
        }
        if x0 >= lo && x0 < hi {
            counts.collisions += block_counts.collisions;
            counts.clamps += block_counts.clamps;
            let total = add64(counts.energy, block_counts.energy);
            counts.saturated = counts.saturated || block_counts.saturated || lt64(total, block_counts.energy);
            counts.energy = total;
            counts.displaced += block_counts.displaced;
            counts.processed += 1u;
        }
    }
    for (var row = 0u; row < 2u; row++) {
        occ_out[ys[row] * row_u32 + w] = out_occ[row];
        let base = (ys[row] * nx + lo) >> 1u;
        for (var k = 0u; k < (hi - lo) / 2u; k++) {
            vel_out[base + k] = out_vel[row][k];
        }
    }
    add_count(0u, counts.collisions);
    add_count(2u, counts.clamps);
    add_wide(4u, counts.energy);
    if counts.saturated {
        atomicOr(&counters[11], 1u);
    }
    add_count(6u, counts.displaced);
    if counts.processed != 0u {
        atomicAdd(&counters[10], counts.processed);
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

fn add_wide(at: u32, n: vec2<u32>) {
    if is_zero64(n) {
        return;
    }
    let old = atomicAdd(&counters[at], n.x);
    let carry = select(0u, 1u, old + n.x < old);
    let high = n.y + carry;
    if high != 0u {
        let before = atomicAdd(&counters[at + 1u], high);
        if before + high < before {
            atomicOr(&counters[11], 1u);
        }
    }
}
