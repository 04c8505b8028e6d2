// Draws a 2D world from the GPU backend's exports (src/export.rs): the
// density texture as a glow behind, then every particle as a cell-sized
// quad coloured by speed (blue slow, through green and yellow, to red at 1
// cell a step; the square root spreads the slow speeds, where a cooling gas
// spends its time), as the C scenes colour them.

// x, y: the world's cells along each axis; z: a particle's width in cells.
@group(0) @binding(0) var<uniform> world: vec4<f32>;
@group(0) @binding(1) var density: texture_2d<f32>;
@group(0) @binding(2) var filtering: sampler;

struct Glow {
    @builtin(position) at: vec4<f32>,
    @location(0) uv: vec2<f32>,
}

// One triangle that covers the target.
@vertex
fn glow_vs(@builtin(vertex_index) i: u32) -> Glow {
    let uv = vec2<f32>(f32((i << 1u) & 2u), f32(i & 2u));
    return Glow(vec4<f32>(uv.x * 2.0 - 1.0, 1.0 - uv.y * 2.0, 0.0, 1.0), uv);
}

@fragment
fn glow_fs(in: Glow) -> @location(0) vec4<f32> {
    let d = textureSample(density, filtering, in.uv).r;
    return vec4<f32>(vec3<f32>(0.02, 0.03, 0.06) + d * vec3<f32>(0.10, 0.16, 0.32), 1.0);
}

struct Dot {
    @builtin(position) at: vec4<f32>,
    @location(0) speed: f32,
}

@vertex
fn dot_vs(@builtin(vertex_index) v: u32, @location(0) particle: vec4<f32>) -> Dot {
    let corners = array<vec2<f32>, 6>(vec2(-0.5, -0.5), vec2(0.5, -0.5), vec2(-0.5, 0.5), vec2(0.5, -0.5), vec2(0.5, 0.5), vec2(-0.5, 0.5));
    let p = (particle.xy + corners[v] * world.z) / world.xy;
    return Dot(vec4<f32>(p.x * 2.0 - 1.0, 1.0 - p.y * 2.0, 0.0, 1.0), length(particle.zw));
}

@fragment
fn dot_fs(in: Dot) -> @location(0) vec4<f32> {
    let stops = array<vec3<f32>, 4>(vec3(0.15, 0.35, 1.0), vec3(0.1, 0.85, 0.3), vec3(1.0, 0.9, 0.1), vec3(1.0, 0.15, 0.1));
    let t = clamp(sqrt(in.speed), 0.0, 1.0) * 3.0;
    let i = min(u32(t), 2u);
    return vec4<f32>(mix(stops[i], stops[i + 1u], t - f32(i)), 1.0);
}
