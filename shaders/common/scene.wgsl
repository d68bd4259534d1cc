// Per-frame uniform and scene buffers (group 0), shared by every geometry pass.
// Mirrors oit_core::gpu_types::FrameUniform; a Rust test checks the size.
struct FrameUniform {
    view_proj: mat4x4<f32>,
    background: vec4<f32>,
    size: vec2<u32>,
    triangle_count: u32,
    seed: u32,
}

@group(0) @binding(0) var<uniform> frame: FrameUniform;
// Vertex pulling: positions as packed xyz floats, straight RGBA per vertex, three indices a triangle.
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> colors: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> indices: array<u32>;

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    // Global triangle index in submission order (non-indexed draw: vertex_index / 3).
    @location(1) @interpolate(flat) prim: u32,
    // Clip w, interpolated: the view distance under a perspective camera (1 for orthographic).
    @location(2) view_w: f32,
}

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let v = indices[vi];
    let p = vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(p, 1.0);
    out.color = colors[v];
    out.prim = vi / 3u;
    out.view_w = out.clip.w;
    return out;
}

fn pixel_index(pos: vec4<f32>) -> u32 {
    return u32(pos.y) * frame.size.x + u32(pos.x);
}

// Pixel index of a compute invocation laid over the frame; `OUTSIDE` past its edges.
const OUTSIDE: u32 = 0xffffffffu;

fn compute_pixel(gid: vec3<u32>) -> u32 {
    if gid.x >= frame.size.x || gid.y >= frame.size.y {
        return OUTSIDE;
    }
    return gid.y * frame.size.x + gid.x;
}
