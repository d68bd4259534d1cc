// Per-frame uniform and scene buffers (group 0), shared by every geometry pass.
// Mirrors oit_core::gpu_types::FrameUniform; a Rust test checks the size.
struct FrameUniform {
    view_proj: mat4x4<f32>,
    background: vec4<f32>,
    size: vec2<u32>,
    triangle_count: u32,
    seed: u32,
    // The screen tile this pass renders (the whole frame unless the renderer tiles), in its
    // targets' pixels: per-pixel storage is indexed within it, and passes are scissored to it.
    // The targets' pixel (0, 0) is the frame's pixel target_origin (tile-sized targets, tiles.rs).
    tile_origin: vec2<u32>,
    tile_size: vec2<u32>,
    target_origin: vec2<u32>,
    pad: vec2<u32>,
    // Shading (common/shading.wgsl): the inverse view-projection for a pixel's eye direction,
    // ambient RGB (w = 0, the factor of the shading-cost loop's result), the lights. Whether a
    // mesh is shaded, the light count and the shading-cost loop count are the constants SHADED,
    // LIGHTS and SHADING_COST the pipelines are compiled with (loop bounds the compiler knows).
    inv_view_proj: mat4x4<f32>,
    ambient: vec4<f32>,
    lights: array<Light, MAX_LIGHTS>,
}

// Mirrors oit_core::gpu_types::GpuLight: unit L (towards the light) and color times intensity.
struct Light {
    to_light: vec4<f32>,
    radiance: vec4<f32>,
}

@group(0) @binding(0) var<uniform> frame: FrameUniform;
// Vertex pulling: positions as packed xyz floats, straight RGBA per vertex, three indices a triangle.
@group(0) @binding(1) var<storage, read> positions: array<f32>;
@group(0) @binding(2) var<storage, read> colors: array<vec4<f32>>;
@group(0) @binding(3) var<storage, read> indices: array<u32>;
// Geometry is uploaded in chunks that each fit a binding: this chunk's first uploaded triangle
// in the scene's order, its uploaded triangle count, its segments (common/setup.wgsl) and the
// triangles drawn from it, instances included. Indices are local to the chunk.
// A chunk holds meshes, or one strand, particle or splat set (`kind`: PRIM_MESH, PRIM_STRANDS,
// PRIM_PARTICLES, PRIM_GAUSSIANS; common/primitives.wgsl) whose material is the chunk's.
struct Chunk {
    first_triangle: u32,
    triangles: u32,
    segments: u32,
    drawn: u32,
    kind: u32,
    set_surface: u32,
    // A strand or particle set's first instance (its row of the instance table; 0 without
    // instances) and its points in this chunk (the stride of `expanded` per instance).
    set_instance: u32,
    set_points: u32,
}
@group(0) @binding(4) var<uniform> chunk: Chunk;
// Two vec4 a vertex where the scene is shaded: (unit normal, material index bits), (u, v, 0, 0).
@group(0) @binding(5) var<storage, read> attributes: array<vec4<f32>>;
// The material table (MATERIAL_VEC4S vec4 a material: oit_core::gpu_types::GpuMaterial), then
// each image's record (common/shading.wgsl); the same in every chunk.
@group(0) @binding(6) var<storage, read> surfaces: array<vec4<f32>>;
//!if INSTANCED
// A mesh drawn other than once in place: each instance's transform, the inverse transpose of
// its linear part (normals), an RGBA factor of the vertex colors, what turns an uploaded
// triangle's index into its drawn one (the drawn order: every triangle of instance 0, then of
// instance 1, mesh after mesh), and whether it mirrors. Mirrors oit_core::gpu_types::GpuInstance.
struct Instance {
    model: mat4x4<f32>,
    normal: mat3x3<f32>,
    color: vec4<f32>,
    prim_offset: u32,
    mirror: u32,
    pad0: u32,
    pad1: u32,
}
@group(0) @binding(7) var<storage, read> instances: array<Instance>;
//!endif

struct VsOut {
    @builtin(position) @invariant clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    // The triangle's index in the drawn order (instances included): what passes key it by.
    @location(1) @interpolate(flat) prim: u32,
    // Clip w, interpolated: the view distance under a perspective camera (1 for orthographic).
    @location(2) view_w: f32,
//!if SHADED
    // Shaded scenes only (an unlit scene compiles without them): the shading normal (flat
    // meshes are uploaded with a vertex per corner carrying the face normal), UVs and the
    // mesh's material.
    @location(3) normal: vec3<f32>,
    @location(4) uv: vec2<f32>,
    @location(5) @interpolate(flat) material: u32,
//!endif
//!if SPLAT_RAY
    // A ray-depth splat's world mean (w = 1; zero for every other fragment) and the adjugate
    // of its world covariance (xx xy xz, yy yz zz): what `splat_depth` reads.
    @location(9) @interpolate(flat) splat_mean: vec4<f32>,
    @location(10) @interpolate(flat) splat_adj0: vec3<f32>,
    @location(11) @interpolate(flat) splat_adj1: vec3<f32>,
//!endif
//!if TEXTURES
    // The triangle's UV planes (`uv_planes`): what a texture's mip level is chosen from.
    @location(6) @interpolate(flat) uv_plane_u: vec3<f32>,
    @location(7) @interpolate(flat) uv_plane_v: vec3<f32>,
    @location(8) @interpolate(flat) uv_plane_w: vec3<f32>,
//!endif
}

@vertex
fn vs_main(
    @builtin(vertex_index) vi: u32,
//!if INSTANCED
    @builtin(instance_index) ii: u32,
//!endif
) -> VsOut {
//!if !INSTANCED
    let ii = 0u;
//!endif
//!if SETS_ONLY
    // No triangle meshes in the scene: every chunk is a strand or particle set.
    return expanded_vertex(vi, ii);
//!else
//!if PRIMITIVES
    if chunk.kind != PRIM_MESH {
        return expanded_vertex(vi, ii);
    }
//!endif
    let v = indices[vi];
    var out: VsOut;
    out.clip = frame.view_proj * placed(v, ii);
    out.color = placed_color(v, ii);
    out.prim = drawn_prim(vi / 3u, ii);
    out.view_w = out.clip.w;
//!if SHADED
    let a = attributes[2u * v];
    out.material = bitcast<u32>(a.w);
    out.normal = placed_normal(a.xyz, ii);
    out.uv = attributes[2u * v + 1u].xy;
//!if TEXTURES
    let planes = triangle_uv_planes(vi, ii);
    out.uv_plane_u = planes[0];
    out.uv_plane_v = planes[1];
    out.uv_plane_w = planes[2];
//!endif
    if (bitcast<u32>(surfaces[MATERIAL_VEC4S * out.material].w) & CULL_BACK) != 0u && !faces_front(vi, ii) {
        // A culled back face: all three corners behind the near plane, so nothing is drawn.
        out.clip = vec4<f32>(0.0, 0.0, -1.0, 1.0);
    }
//!endif
    return out;
//!endif
}

// Whether the triangle of vertex `vi` is counter-clockwise on screen (wgpu's front face), or
// clockwise under a mirroring instance: the sign of det[x y w] of its clip corners, right for
// corners behind the eye too (Olano and Greer, "Triangle scan conversion using 2D homogeneous
// coordinates"). Every corner computes the same value, so a triangle is kept or dropped whole;
// the reference's test is the same.
fn faces_front(vi: u32, ii: u32) -> bool {
    let first = vi - vi % 3u;
    let a = frame.view_proj * placed(indices[first], ii);
    let b = frame.view_proj * placed(indices[first + 1u], ii);
    let c = frame.view_proj * placed(indices[first + 2u], ii);
    return (determinant(mat3x3<f32>(a.xyw, b.xyw, c.xyw)) > 0.0) != mirrors(ii);
}

//!if TEXTURES
// The UV planes of the triangle of vertex `vi` (every corner computes the same).
fn triangle_uv_planes(vi: u32, ii: u32) -> mat3x3<f32> {
    let first = vi - vi % 3u;
    let i = vec3<u32>(indices[first], indices[first + 1u], indices[first + 2u]);
    let a = frame.view_proj * placed(i.x, ii);
    let b = frame.view_proj * placed(i.y, ii);
    let c = frame.view_proj * placed(i.z, ii);
    return uv_planes(a, b, c, attributes[2u * i.x + 1u].xy, attributes[2u * i.y + 1u].xy, attributes[2u * i.z + 1u].xy);
}

// A triangle's UVs as ratios of planes in NDC: with X, Y, W its clip corners' x, y and w, its
// barycentrics at (px, py) are c / (c0 + c1 + c2), c = X×Y - px W×Y - py X×W; the rows are
// (f·X×Y, f·W×Y, f·X×W) for f = its u, its v and 1. The float64 twin is
// oit_core::shading::uv_footprint.
fn uv_planes(a: vec4<f32>, b: vec4<f32>, c: vec4<f32>, ua: vec2<f32>, ub: vec2<f32>, uc: vec2<f32>) -> mat3x3<f32> {
    let x = vec3<f32>(a.x, b.x, c.x);
    let y = vec3<f32>(a.y, b.y, c.y);
    let w = vec3<f32>(a.w, b.w, c.w);
    let c0 = cross(x, y);
    let cx = cross(w, y);
    let cy = cross(x, w);
    let u = vec3<f32>(ua.x, ub.x, uc.x);
    let v = vec3<f32>(ua.y, ub.y, uc.y);
    let one = vec3<f32>(1.0);
    return mat3x3<f32>(
        vec3<f32>(dot(u, c0), dot(u, cx), dot(u, cy)),
        vec3<f32>(dot(v, c0), dot(v, cx), dot(v, cy)),
        vec3<f32>(dot(one, c0), dot(one, cx), dot(one, cy)),
    );
}
//!endif

// Vertex `v` of the chunk placed by instance `ii` (world space, w = 1); its color times the
// instance's; a shading normal carried by the instance (renormalized; zero stays zero); the
// drawn index of the chunk's local triangle `t` under it; whether it mirrors.
//!if INSTANCED
fn placed(v: u32, ii: u32) -> vec4<f32> {
    return placed_at(scene_position(v), ii);
}

fn placed_at(p: vec3<f32>, ii: u32) -> vec4<f32> {
    return instances[ii].model * vec4<f32>(p, 1.0);
}

fn placed_color(v: u32, ii: u32) -> vec4<f32> {
    return colors[v] * instances[ii].color;
}

fn placed_tint(ii: u32) -> vec4<f32> {
    return instances[ii].color;
}

fn placed_linear(ii: u32) -> mat3x3<f32> {
    let m = instances[ii].model;
    return mat3x3<f32>(m[0].xyz, m[1].xyz, m[2].xyz);
}

fn placed_normal(n: vec3<f32>, ii: u32) -> vec3<f32> {
    let m = instances[ii].normal * n;
    return select(vec3<f32>(0.0), normalize(m), dot(m, m) > 0.0);
}

fn drawn_prim(t: u32, ii: u32) -> u32 {
    return instances[ii].prim_offset + chunk.first_triangle + t;
}

fn mirrors(ii: u32) -> bool {
    return instances[ii].mirror != 0u;
}
//!else
fn placed(v: u32, ii: u32) -> vec4<f32> {
    return placed_at(scene_position(v), ii);
}

fn placed_at(p: vec3<f32>, ii: u32) -> vec4<f32> {
    return vec4<f32>(p, 1.0);
}

fn placed_color(v: u32, ii: u32) -> vec4<f32> {
    return colors[v];
}

fn placed_tint(ii: u32) -> vec4<f32> {
    return vec4<f32>(1.0);
}

fn placed_linear(ii: u32) -> mat3x3<f32> {
    return mat3x3<f32>(vec3<f32>(1.0, 0.0, 0.0), vec3<f32>(0.0, 1.0, 0.0), vec3<f32>(0.0, 0.0, 1.0));
}

fn placed_normal(n: vec3<f32>, ii: u32) -> vec3<f32> {
    return n;
}

fn drawn_prim(t: u32, ii: u32) -> u32 {
    return chunk.first_triangle + t;
}

fn mirrors(ii: u32) -> bool {
    return false;
}
//!endif

fn scene_position(v: u32) -> vec3<f32> {
    return vec3<f32>(positions[3u * v], positions[3u * v + 1u], positions[3u * v + 2u]);
}

// Index of a fragment's pixel in per-pixel storage: row-major within the tile. Positions from
// the rasterizer are in the targets' pixels (the frame's viewport moved by target_origin).
fn pixel_index(pos: vec4<f32>) -> u32 {
    let p = vec2<u32>(pos.xy) - frame.tile_origin;
    return p.y * frame.tile_size.x + p.x;
}

// The target position of pixel index `px` (the inverse of pixel_index).
fn pixel_position(px: u32) -> vec2<u32> {
    return frame.tile_origin + vec2<u32>(px % frame.tile_size.x, px / frame.tile_size.x);
}

// The frame position of a target position (pixels): where the pixel is in the whole picture.
fn frame_xy(at: vec2<f32>) -> vec2<f32> {
    return at + vec2<f32>(frame.target_origin);
}

// Pixel index of a compute invocation laid over the tile; `OUTSIDE` past its edges.
const OUTSIDE: u32 = 0xffffffffu;

fn compute_pixel(gid: vec3<u32>) -> u32 {
    if gid.x >= frame.tile_size.x || gid.y >= frame.tile_size.y {
        return OUTSIDE;
    }
    return gid.y * frame.tile_size.x + gid.x;
}
//!if PRIMITIVES
//!include common/primitives.wgsl
//!endif
//!include common/shading.wgsl
