// What the 2D rule does its own way (M5.2's turn, M5.3's draws, M5.6's
// exact-fast table); `rule.wgsl`, which follows, holds the rest.

const DIM: u32 = 2u;
const CELLS: u32 = 4u;

const TURNS_AT: u32 = 256u;
const KEYS_AT: u32 = 2304u;
const LISTS_AT: u32 = 3600u;
// A cell's place value in the 2D table's key (M5.6): base 6.
const PLACE = array<u32, 4>(1u, 6u, 36u, 216u);

// d turned by one of 1,024 angles, uniformly (10 bits): |d| R for M5.2.
fn turned(d: vec3<i32>, s: ptr<function, Stream>) -> vec3<i32> {
    let j = bits(s, 10u);
    let cs = bitcast<i32>(tables[TURNS_AT + 2u * j]);
    let sn = bitcast<i32>(tables[TURNS_AT + 2u * j + 1u]);
    return vec3<i32>(mulq(d.x, cs, 30u) - mulq(d.y, sn, 30u), mulq(d.x, sn, 30u) + mulq(d.y, cs, 30u), 0);
}

// M5.3 with M5.4: the axes each particle wants to cross, two bits a cell.
// Where some particle could cross an axis, one 64-bit output whose byte
// 2c + k is the high half of cell c's 16 bits for axis k; the low half
// drawn (8 bits) only where the high half ties with the limit's.
fn desire(b: ptr<function, Block>, site: ptr<function, Site>, s: ptr<function, Stream>, counts: ptr<function, Counts>) -> u32 {
    var inward = 0u;
    for (var c = 0u; c < 4u; c++) {
        if ((*b).occ >> c & 1u) != 0u {
            inward |= inward_axes((*b).v[c], c) << (2u * c);
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
        let c = i / 2u;
        let q = (*b).v[c][i % 2u];
        let high = select(bytes.y, bytes.x, i < 4u) >> (8u * (i % 4u)) & 0xffu;
        let limit = move_limit(q);
        let top = limit >> 8u;
        if high < top || (high == top && bits(s, 8u) <= (limit & 0xffu)) {
            want |= 1u << i;
        }
        // M5.4 once both axes of the cell are decided.
        let m = want >> (2u * c) & 3u;
        if (inward >> (i + 1u) & select(1u, 0u, i % 2u == 1u)) == 0u && m != 0u && ((*site).blocked >> (c ^ m) & 1u) != 0u {
            reflect_off(b, site, c, c ^ m, s, counts);
            want &= ~(3u << (2u * c));
        }
    }
    return want;
}

// M5.6 exact-fast: one look-up in the table of every block state's optimal
// assignments (the core's), one draw among them where there are several.
// The cell each particle goes to, 4 bits a particle.
fn exact_fast(cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32, occ: u32, blocked: u32, want: u32, s: ptr<function, Stream>) -> u32 {
    var key = 0u;
    for (var c = 0u; c < 4u; c++) {
        if (occ >> c & 1u) != 0u {
            key += PLACE[c] * (2u + (want >> (2u * c) & 3u));
        } else if (blocked >> c & 1u) != 0u {
            key += PLACE[c];
        }
    }
    let span = tables[KEYS_AT + key];
    let ways = span >> 16u;
    var pick = 0u;
    if ways > 1u {
        pick = below(s, ways);
    }
    let moves = tables[LISTS_AT + (span & 0xffffu) + pick];
    var packed = 0u;
    for (var i = 0u; i < count; i++) {
        packed |= (moves >> (2u * cells[i]) & 3u) << (4u * i);
    }
    return packed;
}
