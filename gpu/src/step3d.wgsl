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

// ---- M5.6 exact-fast in 3D ----------------------------------------------
//
// The core's method, step for step, so that its one draw picks the same
// assignment: a block where every particle alone wants a free cell gives
// each its cell; one or two particles are counted directly; any other
// block goes through the Hungarian method (shortest augmenting paths),
// whose prices mark the (particle, cell) pairs an optimal assignment may
// use (tight) and the cells every one fills (lifted); the optimal
// assignments along them are counted group by group of particles that
// share tight cells, and one uniform rank among them all picks one.

// The weight of the distance to the wanted cell against the distance to
// the current one: at most 24 of the latter in a block.
const PRIMARY: i32 = 32;
// No particle, or no cell.
const NONE: u32 = 255u;
// Added to the cost of a cell that is not free: more than any real cost
// and lift together, so such a cell is never the cheapest nor tight.
const SHUT: i32 = 0x2000;

// What the Hungarian method keeps: the combined costs (SHUT added on the
// cells that are not free), the cells' lifts (minus their prices), how much
// further than a cell the search may get before its holder's moves need
// looking at (defer) and lift + defer (bias), -1 on the cells that are not
// free, each particle's cell and each cell's particle.
struct Prices {
    costs: array<array<i32, 8>, 8>,
    lift: array<i32, 8>,
    defer: array<i32, 8>,
    bias: array<i32, 8>,
    shut: array<i32, 8>,
    at: array<u32, 8>,
    owner: array<u32, 8>,
}

// The combined cost of cell t for a particle in cell now that wants cell
// want.
fn move_cost(t: u32, want: u32, now: u32) -> i32 {
    return PRIMARY * i32(dist(t, want)) + i32(dist(t, now));
}

// Each particle that wants a free cell nobody before it wants takes it;
// everyone else waits for `augment`.
fn prices_start(cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32) -> Prices {
    var p: Prices;
    for (var t = 0u; t < 8u; t++) {
        p.shut[t] = select(-1, 0, (free >> t & 1u) != 0u);
        p.lift[t] = 0;
        p.defer[t] = 0;
        p.bias[t] = 0;
        p.at[t] = NONE;
        p.owner[t] = NONE;
    }
    for (var i = 0u; i < count; i++) {
        for (var t = 0u; t < 8u; t++) {
            p.costs[i][t] = move_cost(t, wished[i], cells[i]) + (p.shut[t] & SHUT);
        }
    }
    for (var i = 0u; i < count; i++) {
        let want = wished[i];
        if (free >> want & 1u) != 0u && p.owner[want] == NONE {
            p.owner[want] = i;
            p.at[i] = want;
            p.defer[want] = PRIMARY - p.costs[i][want];
            p.bias[want] = p.defer[want];
        }
    }
    return p;
}

// Places particle s at the end of a cheapest alternating path (Dijkstra
// over the free cells, a holder's moves looked at only once the search is
// `defer` further than its cell), lifting every cell reached sooner than
// the end by how much sooner.
fn augment(p: ptr<function, Prices>, s: u32) {
    var reach: array<i32, 8>;
    var via: array<u32, 8>;
    var closed: array<i32, 8>;
    for (var t = 0u; t < 8u; t++) {
        reach[t] = 32767;
        via[t] = 0u;
        closed[t] = (*p).shut[t];
    }
    var row = s;
    var offset = 0;
    var end = 0u;
    var length = 0;
    loop {
        // Distance (with defer) times 8 plus the cell: the least is the
        // nearest open cell, the first among equals.
        var least = 32767;
        for (var t = 0u; t < 8u; t++) {
            let d = offset + (*p).costs[row][t] + (*p).bias[t];
            if d < reach[t] {
                reach[t] = d;
                via[t] = row;
            }
            if closed[t] == 0 {
                least = min(least, reach[t] << 3u | i32(t));
            }
        }
        let next = u32(least & 7);
        let best = least >> 3u;
        if (*p).owner[next] == NONE {
            end = next;
            length = best;
            break;
        }
        closed[next] = -1;
        row = (*p).owner[next];
        // The holder's price is what its (tight) cell costs it.
        offset = best - (*p).costs[row][next] - (*p).bias[next];
    }
    for (var t = 0u; t < 8u; t++) {
        let gain = max(length - reach[t] + (*p).defer[t], 0) & ~(*p).shut[t];
        (*p).lift[t] += gain;
        (*p).defer[t] = max((*p).defer[t] - gain, 0);
        (*p).bias[t] = (*p).lift[t] + (*p).defer[t];
    }
    // Everyone on the path moves one cell along it; s takes the first.
    var cell = end;
    loop {
        let i = via[cell];
        let left = (*p).at[i];
        (*p).owner[cell] = i;
        (*p).at[i] = cell;
        (*p).defer[cell] = max(PRIMARY - (*p).costs[i][cell] - (*p).lift[cell], 0);
        (*p).bias[cell] = (*p).lift[cell] + (*p).defer[cell];
        if i == s {
            break;
        }
        cell = left;
    }
}

// The tight cells of the placed particle i: its own cell alone where its
// price is below PRIMARY (it is in the cell it wants), else every cell
// that costs it its price.
fn tight_cells(p: ptr<function, Prices>, i: u32) -> u32 {
    let at = (*p).at[i] & 7u;
    let price = (*p).costs[i][at] + (*p).lift[at];
    if price < PRIMARY {
        return 1u << at;
    }
    var cells = 0u;
    for (var t = 0u; t < 8u; t++) {
        cells |= select(0u, 1u << t, (*p).costs[i][t] + (*p).lift[t] == price);
    }
    return cells;
}

// The index of the set bit of rank `rank` in `bits_set`, lowest first.
fn nth_bit(bits_set: u32, rank: u32) -> u32 {
    var rest = bits_set;
    for (var k = 0u; k < rank; k++) {
        rest &= rest - 1u;
    }
    return firstTrailingBit(rest);
}

// The least combined cost of `row` (a particle's costs) over `cells` (not
// empty), and the cells that have it.
fn least_cost(row: array<i32, 8>, cells: u32) -> vec2<u32> {
    var best = 0x7fffffff;
    var tied = 0u;
    for (var t = 0u; t < 8u; t++) {
        if (cells >> t & 1u) == 0u {
            continue;
        }
        if row[t] < best {
            best = row[t];
            tied = 0u;
        }
        if row[t] == best {
            tied |= 1u << t;
        }
    }
    return vec2<u32>(u32(best), tied);
}

// Two particles (the step settles one without a draw), counted directly:
// each has its cells of least cost, a free wanted cell alone; two take
// any two distinct ones, one from each, unless each has the same single
// cell x: then one of them takes x and the other a cell of least cost
// among the rest. Ways numbered by particle 0's cell, or by who takes x,
// then by the other's cell. 4 bits a particle.
fn exact_two(cells: array<u32, CELLS>, wished: array<u32, CELLS>, free: u32, s: ptr<function, Stream>) -> u32 {
    var rows: array<array<i32, 8>, 2>;
    var best: array<u32, 2>;
    var tied: array<u32, 2>;
    for (var i = 0u; i < 2u; i++) {
        for (var t = 0u; t < 8u; t++) {
            rows[i][t] = move_cost(t, wished[i], cells[i]);
        }
        if (free >> wished[i] & 1u) != 0u {
            best[i] = u32(rows[i][wished[i]]);
            tied[i] = 1u << wished[i];
        } else {
            let l = least_cost(rows[i], free);
            best[i] = l.x;
            tied[i] = l.y;
        }
    }
    if tied[0] != tied[1] || (tied[0] & (tied[0] - 1u)) != 0u {
        let ways = countOneBits(tied[0]) * countOneBits(tied[1]) - countOneBits(tied[0] & tied[1]);
        var rank = 0u;
        if ways > 1u {
            rank = below(s, ways);
        }
        for (var a = 0u; a < 8u; a++) {
            if (tied[0] >> a & 1u) == 0u {
                continue;
            }
            let others = tied[1] & ~(1u << a);
            let n = countOneBits(others);
            if rank < n {
                return a | nth_bit(others, rank) << 4u;
            }
            rank -= n;
        }
        return 0u;
    }
    let x = firstTrailingBit(tied[0]);
    let rest = free & ~tied[0];
    let rest0 = least_cost(rows[0], rest);
    let rest1 = least_cost(rows[1], rest);
    // Particle 0 in x leaves particle 1 its best of the rest, and the other
    // way round.
    let total0 = best[0] + rest1.x;
    let total1 = best[1] + rest0.x;
    let optimum = min(total0, total1);
    let ways0 = select(0u, countOneBits(rest1.y), total0 == optimum);
    let ways1 = select(0u, countOneBits(rest0.y), total1 == optimum);
    var rank = 0u;
    if ways0 + ways1 > 1u {
        rank = below(s, ways0 + ways1);
    }
    if rank < ways0 {
        return x | nth_bit(rest1.y, rank) << 4u;
    }
    return nth_bit(rest0.y, rank - ways0) | x << 4u;
}

// The most sets of cells the members of a group can end in: C(8, 4).
const MAX_ENDS: u32 = 70u;

// Particles that share tight cells with each other and no one else, those
// with two tight cells listed first; the sets of cells they can end in
// that fill every cell that must be filled, and their ways in all.
struct Group {
    members: array<u32, 8>,
    choices: array<u32, 8>,
    len: u32,
    ends: array<u32, MAX_ENDS>,
    end_count: u32,
    ways: u32,
}

// Counts a group's ways a member at a time into `table` (for every set of
// cells, the ways the first members can take exactly those: groups share
// no cell, so one table serves them all), from the sets the members before
// reach, and keeps the final sets that hold `must`.
fn count_group(group: Group, must: u32, table: ptr<function, array<u32, 256>>) -> Group {
    var g = group;
    var sets: array<u32, MAX_ENDS>;
    var next: array<u32, MAX_ENDS>;
    var len = 1u;
    sets[0] = 0u;
    (*table)[0] = 1u;
    for (var k = 0u; k < g.len; k++) {
        let choices = g.choices[k];
        var grown = 0u;
        for (var j = 0u; j < len; j++) {
            let used = sets[j];
            let ways = (*table)[used];
            var open = choices & ~used;
            while open != 0u {
                let bigger = used | (open & (0u - open));
                open &= open - 1u;
                if (*table)[bigger] == 0u {
                    next[grown] = bigger;
                    grown += 1u;
                }
                (*table)[bigger] += ways;
            }
        }
        sets = next;
        len = grown;
    }
    g.ways = 0u;
    g.end_count = 0u;
    for (var j = 0u; j < len; j++) {
        let used = sets[j];
        if (must & ~used) == 0u {
            g.ends[g.end_count] = used;
            g.end_count += 1u;
            g.ways += (*table)[used];
        }
    }
    return g;
}

// The way of rank `rank` of a group (below its ways): the final set whose
// ways reach past the rank, then, last member first, the cell whose
// removal leaves a set with ways reaching past what is left of it. The
// cell of each member.
fn nth_way(g: Group, rank0: u32, table: ptr<function, array<u32, 256>>) -> array<u32, 8> {
    var chosen: array<u32, 8>;
    var rank = rank0;
    var used = 0u;
    for (var j = 0u; j < g.end_count; j++) {
        let ways = (*table)[g.ends[j]];
        if rank < ways {
            used = g.ends[j];
            break;
        }
        rank -= ways;
    }
    var k = g.len;
    while k > 0u {
        k -= 1u;
        var open = g.choices[k] & used;
        while open != 0u {
            let cell = open & (0u - open);
            open &= open - 1u;
            let before = used & ~cell;
            let ways = select((*table)[before], select(0u, 1u, before == 0u), k == 0u);
            if rank < ways {
                chosen[k] = firstTrailingBit(cell);
                used = before;
                break;
            }
            rank -= ways;
        }
    }
    return chosen;
}

// M5.6 exact-fast in 3D: the cell each particle (in cell order) goes to,
// 4 bits a particle, with one draw where there are several optima.
fn exact_fast(cells: array<u32, CELLS>, wished: array<u32, CELLS>, count: u32, free: u32, occ: u32, blocked: u32, want: u32, s: ptr<function, Stream>) -> u32 {
    var wanted = 0u;
    var clash = 0u;
    var packed = 0u;
    for (var i = 0u; i < count; i++) {
        let bit = 1u << wished[i];
        clash |= wanted & bit;
        wanted |= bit;
        packed |= wished[i] << (4u * i);
    }
    if clash == 0u && (wanted & ~free) == 0u {
        return packed;
    }
    if count <= 2u {
        return exact_two(cells, wished, free, s);
    }
    var p = prices_start(cells, wished, count, free);
    for (var i = 0u; i < count; i++) {
        if p.at[i] == NONE {
            augment(&p, i);
        }
    }
    // A particle with one tight cell takes it in every optimal assignment,
    // so that cell is struck from the others' tight cells, until no
    // particle left has one.
    var goes = p.at;
    var tight: array<u32, 8>;
    var open = 0u;
    var taken = 0u;
    for (var i = 0u; i < count; i++) {
        tight[i] = tight_cells(&p, i);
        if (tight[i] & (tight[i] - 1u)) != 0u {
            open |= 1u << i;
        } else {
            taken |= tight[i];
        }
    }
    if open != 0u {
        loop {
            var settled = 0u;
            let round_open = open;
            for (var i = 0u; i < 8u; i++) {
                if (round_open >> i & 1u) == 0u {
                    continue;
                }
                tight[i] &= ~taken;
                if (tight[i] & (tight[i] - 1u)) == 0u {
                    taken |= tight[i];
                    settled |= 1u << i;
                }
            }
            if settled == 0u {
                break;
            }
            open &= ~settled;
        }
        // The cells with lift, which every optimal assignment fills.
        var must = 0u;
        for (var t = 0u; t < 8u; t++) {
            must |= select(0u, 1u << t, p.lift[t] > 0);
        }
        var groups: array<Group, 4>;
        var found = 0u;
        var total = 1u;
        var table: array<u32, 256>;
        while open != 0u {
            // The first particle left and every one linked to it by tight
            // tight cells.
            let first = firstTrailingBit(open);
            var members = 1u << first;
            var linked = tight[first];
            loop {
                var joined = 0u;
                let rest = open & ~members;
                for (var i = 0u; i < 8u; i++) {
                    if (rest >> i & 1u) != 0u && (tight[i] & linked) != 0u {
                        joined |= 1u << i;
                        linked |= tight[i];
                    }
                }
                if joined == 0u {
                    break;
                }
                members |= joined;
            }
            open &= ~members;
            var pair = 0u;
            for (var i = 0u; i < 8u; i++) {
                let rest = tight[i] & (tight[i] - 1u);
                pair |= select(0u, 1u << i, (members >> i & 1u) != 0u && (rest & (rest - 1u)) == 0u);
            }
            groups[found].len = 0u;
            for (var half = 0u; half < 2u; half++) {
                let listed = select(members & ~pair, pair, half == 0u);
                for (var i = 0u; i < 8u; i++) {
                    if (listed >> i & 1u) != 0u {
                        groups[found].members[groups[found].len] = i;
                        groups[found].choices[groups[found].len] = tight[i];
                        groups[found].len += 1u;
                    }
                }
            }
            groups[found] = count_group(groups[found], linked & must, &table);
            total *= groups[found].ways;
            found += 1u;
        }
        var rank = 0u;
        if total > 1u {
            rank = below(s, total);
        }
        for (var g = 0u; g < found; g++) {
            let digit = rank % groups[g].ways;
            rank /= groups[g].ways;
            let chosen = nth_way(groups[g], digit, &table);
            for (var k = 0u; k < groups[g].len; k++) {
                goes[groups[g].members[k]] = chosen[k];
            }
        }
    }
    packed = 0u;
    for (var i = 0u; i < count; i++) {
        packed |= goes[i] << (4u * i);
    }
    return packed;
}
