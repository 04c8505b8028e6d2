// What a renderer reads of a 2D world, written on the GPU from its
// occupancy and velocities (no read-back): every particle's position and
// velocity in cell order, the same order as the CPU's `World::particles`,
// as a buffer a render pass binds as instanced vertices; the count as the
// instance count of an indirect draw; and per tile of cells the share
// occupied and the mean velocity, as a texture. The rule is not involved:
// floats are fine here.

// info: 0 nx, 1 ny, 2 u32 words a row of the occupancy, 3 the tile's side
// in cells, 4 the particles' buffer's capacity, 5 quanta to a unit speed,
// 6 16-bit storage.
@group(0) @binding(0) var<storage, read> info: array<u32>;
@group(0) @binding(1) var<storage, read> occ: array<u32>;
@group(0) @binding(2) var<storage, read> vel: array<u32>;
// Per domain row: its particle count, then (after `scan_rows`) the index
// of its first particle.
@group(0) @binding(3) var<storage, read_write> rows: array<u32>;
// Per particle: x and y of its cell's centre, its velocity in cells per
// step.
@group(0) @binding(4) var<storage, read_write> particles: array<vec4<f32>>;
// An indirect draw: vertices a particle, particles, first vertex, first
// instance.
@group(0) @binding(5) var<storage, read_write> draw: array<u32>;
@group(0) @binding(6) var density: texture_storage_2d<rgba16float, write>;

// Cell i's velocity in cells a step: two bytes a cell (8-bit), or a word
// of two 16-bit halves.
fn velocity(i: u32) -> vec2<f32> {
    var q: vec2<i32>;
    if info[6] != 0u {
        q = vec2<i32>(i32(vel[i] << 16u) >> 16u, i32(vel[i]) >> 16u);
    } else {
        let half = vel[i >> 1u] >> (16u * (i & 1u));
        q = vec2<i32>(i32(half << 24u) >> 24u, i32(half << 16u) >> 24u);
    }
    return vec2<f32>(q) / f32(info[5]);
}

@compute @workgroup_size(64)
fn count_rows(@builtin(global_invocation_id) id: vec3<u32>) {
    let y = id.x;
    if y >= info[1] {
        return;
    }
    var n = 0u;
    for (var w = 0u; w < info[2]; w++) {
        n += countOneBits(occ[y * info[2] + w]);
    }
    rows[y] = n;
}

// One invocation: the rows' counts become their first indices.
@compute @workgroup_size(1)
fn scan_rows() {
    var total = 0u;
    for (var y = 0u; y < info[1]; y++) {
        let n = rows[y];
        rows[y] = total;
        total += n;
    }
    draw[0] = 6u;
    draw[1] = min(total, info[4]);
    draw[2] = 0u;
    draw[3] = 0u;
}

@compute @workgroup_size(64)
fn write_particles(@builtin(global_invocation_id) id: vec3<u32>) {
    let y = id.x;
    if y >= info[1] {
        return;
    }
    var at = rows[y];
    for (var w = 0u; w < info[2]; w++) {
        var bits = occ[y * info[2] + w];
        while bits != 0u && at < info[4] {
            let x = 32u * w + firstTrailingBit(bits);
            bits &= bits - 1u;
            particles[at] = vec4<f32>(f32(x) + 0.5, f32(y) + 0.5, velocity(y * info[0] + x));
            at += 1u;
        }
    }
}

@compute @workgroup_size(8, 8)
fn write_density(@builtin(global_invocation_id) id: vec3<u32>) {
    let tile = info[3];
    let size = textureDimensions(density);
    if id.x >= size.x || id.y >= size.y {
        return;
    }
    var n = 0u;
    var v = vec2<f32>(0.0, 0.0);
    for (var dy = 0u; dy < tile; dy++) {
        let y = id.y * tile + dy;
        for (var dx = 0u; dx < tile; dx++) {
            let x = id.x * tile + dx;
            if x < info[0] && y < info[1] && (occ[y * info[2] + (x >> 5u)] >> (x & 31u) & 1u) != 0u {
                n += 1u;
                v += velocity(y * info[0] + x);
            }
        }
    }
    let mean = select(vec2<f32>(0.0, 0.0), v / f32(max(n, 1u)), n > 0u);
    textureStore(density, vec2<i32>(id.xy), vec4<f32>(f32(n) / f32(tile * tile), mean, 1.0));
}
