// Triangle setup in compute passes over the transparent triangles as drawn (one invocation
// each, instances included): clip-space vertices by vertex pulling, and the pixel-center
// bounding box.

// Drawn triangle of an invocation, within the chunk: dispatches over more than 65,535 groups
// of 64 use y as well.
fn triangle_of(gid: vec3<u32>) -> u32 {
    return gid.y * (65535u * 64u) + gid.x;
}

// A drawn triangle: its local uploaded triangle in the chunk, its instance and its drawn index.
struct Drawn {
    t: u32,
    inst: u32,
    prim: u32,
}

//!if INSTANCED
// A mesh's local triangles lo .. lo + triangles in the chunk, drawn once for each of its
// instances from first_instance on, the chunk's drawn triangles from drawn_first on.
// Mirrors `GpuSegment` in oit_core's gpu_types.rs.
struct Segment {
    drawn_first: u32,
    lo: u32,
    triangles: u32,
    first_instance: u32,
}
@group(0) @binding(8) var<storage, read> segments: array<Segment>;

// The segment of drawn triangle `d` (d < chunk.drawn), by binary search over the chunk's
// segments, then its instance and local triangle: instance-major, as the draws are.
fn drawn_triangle(d: u32) -> Drawn {
    var lo = 0u;
    var hi = chunk.segments;
    while hi - lo > 1u {
        let mid = (lo + hi) / 2u;
        if segments[mid].drawn_first <= d {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    let g = segments[lo];
    let k = d - g.drawn_first;
    let inst = g.first_instance + k / g.triangles;
    let t = g.lo + k % g.triangles;
    return Drawn(t, inst, drawn_prim(t, inst));
}
//!else
fn drawn_triangle(d: u32) -> Drawn {
    return Drawn(d, 0u, chunk.first_triangle + d);
}
//!endif

// Corner `corner` of a drawn triangle in clip space.
fn clip_vertex(tri: Drawn, corner: u32) -> vec4<f32> {
//!if SETS_ONLY
    return frame.view_proj * vec4<f32>(corner_of(3u * tri.t + corner, tri.inst).world, 1.0);
//!else
//!if PRIMITIVES
    if chunk.kind != PRIM_MESH {
        return frame.view_proj * vec4<f32>(corner_of(3u * tri.t + corner, tri.inst).world, 1.0);
    }
//!endif
    return frame.view_proj * placed(indices[3u * tri.t + corner], tri.inst);
//!endif
}

// Inclusive pixel range [lo, hi] whose centers a triangle can cover, clamped to the tile; the
// whole tile when a vertex is behind the eye (w <= 0). Empty when hi < lo.
struct PixelBox {
    lo: vec2<i32>,
    hi: vec2<i32>,
}

fn pixel_box(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>) -> PixelBox {
    let size = vec2<f32>(frame.size);
    let first = vec2<i32>(frame.tile_origin + frame.target_origin);
    let last = vec2<i32>(frame.tile_origin + frame.target_origin + frame.tile_size) - 1;
    if c0.w <= 0.0 || c1.w <= 0.0 || c2.w <= 0.0 {
        return PixelBox(first, last);
    }
    // NDC to pixels: x right, y down; a center (i + 0.5) is covered only inside the box.
    let p0 = vec2<f32>(c0.x / c0.w + 1.0, 1.0 - c0.y / c0.w) * 0.5 * size;
    let p1 = vec2<f32>(c1.x / c1.w + 1.0, 1.0 - c1.y / c1.w) * 0.5 * size;
    let p2 = vec2<f32>(c2.x / c2.w + 1.0, 1.0 - c2.y / c2.w) * 0.5 * size;
    // Pixel i's center i + 0.5 lies in [lo, hi]; 1/16 pixel of slack covers the rasterizer's
    // vertex snapping (1/256 pixel) and float rounding.
    let lo = min(min(p0, p1), p2) - 0.0625;
    let hi = max(max(p0, p1), p2) + 0.0625;
    let a = max(vec2<i32>(ceil(lo - 0.5)), first);
    let b = min(vec2<i32>(floor(hi - 0.5)), last);
    return PixelBox(a, b);
}

// Perspective-correct barycentrics of the point of the triangle under NDC (x, y): solves
// sum(b_i * (c_i.xy - ndc * c_i.w)) = 0 with sum(b_i) = 1, valid whatever the signs of w.
fn barycentrics(c0: vec4<f32>, c1: vec4<f32>, c2: vec4<f32>, ndc: vec2<f32>) -> vec3<f32> {
    let r1 = vec3<f32>(c0.x - ndc.x * c0.w, c1.x - ndc.x * c1.w, c2.x - ndc.x * c2.w);
    let r2 = vec3<f32>(c0.y - ndc.y * c0.w, c1.y - ndc.y * c1.w, c2.y - ndc.y * c2.w);
    let b = cross(r1, r2);
    return b / (b.x + b.y + b.z);
}
