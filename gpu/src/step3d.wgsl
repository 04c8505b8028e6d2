// What the 3D rule does its own way (M5.2's turn, M5.3's draws, M5.6's
// exact-fast); `rule.wgsl`, which follows, holds the rest.

const DIM: u32 = 3u;
const CELLS: u32 = 8u;

// |d| R for M5.2 with R uniform on the sphere (M1c): a point of three
// 16-bit draws p_k - 2^15 (32 bits, then 16: 48 a try), kept where
// 2^26 < sq(p) <= 2^30, then t_k = sign(p_k) divr(|p_k| L, P) with the
// lengths L = rsqrt(sq(d)) and P = rsqrt(sq(p)), all rounded to nearest.
fn turned(d: vec3<i32>, s: ptr<function, Stream>) -> vec3<i32> {
    var p: vec3<i32>;
    loop {
        let xy = bits(s, 32u);
        let z = bits(s, 16u);
        p = vec3<i32>(i32(xy & 0xffffu), i32(xy >> 16u), i32(z)) - vec3<i32>(32768);
        let r2 = sq(p);
        if lt64(vec2<u32>(1u << 26u, 0u), r2) && !lt64(vec2<u32>(1u << 30u, 0u), r2) {
            break;
        }
    }
    let length = rsqrt(sq(d));
    let radius = rsqrt(sq(p));
    var t: vec3<i32>;
    for (var k = 0; k < 3; k++) {
        let m = i32(div64(add64(mul32(u32(abs(p[k])), length), vec2<u32>(radius >> 1u, 0u)), vec2<u32>(radius, 0u)).x);
        t[k] = select(m, -m, p[k] < 0);
    }
    return t;
}

// M5.3 with M5.4: the axes each particle wants to cross, three bits a
// cell. Each particle that could cross an axis draws 32 bits, then 16
// (16 an axis); a wish for a blocked cell is reflected (M5.4) and turned
// into staying.
fn desire(b: ptr<function, Block>, site: ptr<function, Site>, s: ptr<function, Stream>, counts: ptr<function, Counts>) -> u32 {
    var want = 0u;
    for (var c = 0u; c < CELLS; c++) {
        if ((*b).occ >> c & 1u) == 0u {
            continue;
        }
        let q = (*b).v[c];
        let inward = inward_axes(q, c);
        if inward == 0u {
            continue;
        }
        let xy = bits(s, 32u);
        let r = vec3<u32>(xy & 0xffffu, xy >> 16u, bits(s, 16u));
        var m = 0u;
        for (var k = 0u; k < 3u; k++) {
            if (inward >> k & 1u) != 0u && r[k] <= move_limit(q[k]) {
                m |= 1u << k;
            }
        }
        if m != 0u && ((*site).blocked >> (c ^ m) & 1u) != 0u {
            reflect_off(b, site, c, c ^ m, s, counts);
            m = 0u;
        }
        want |= m << (3u * c);
    }
    return want;
}

// M5.6 exact-fast in 3D is not ported yet: `unsupported` refuses it, so no
// world reaches this.
fn exact_fast(cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32, occ: u32, blocked: u32, want: u32, s: ptr<function, Stream>) -> u32 {
    return exhaustive(cells, wished, count, free, s);
}
