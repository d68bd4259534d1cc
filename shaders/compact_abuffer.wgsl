// The compact A-buffer (Kerzner et al. 2013): per-pixel linked lists whose nodes hold only
// depth and the triangle index (12 bytes); each triangle's shading data (clip-space vertices
// and vertex colors) is stored once, by a compute pass before capture, and the resolve
// shades every fragment from it (perspective-correct interpolation at the pixel center).
// Resolve: common/sweep.wgsl. docs/methods.md ("compact_abuffer").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl
//!include common/setup.wgsl

// Mirrors oit_core::gpu_types::CompactNode.
struct Node {
    depth: f32,
    next: u32,
    prim: u32,
}
//!include common/pool.wgsl

// Mirrors oit_core::gpu_types::PrimShading: clip-space corners and their colors, and (shaded
// scenes) their shading normals with the material index in w, and UVs.
struct PrimShading {
    clip: array<vec4<f32>, 3>,
    color: array<vec4<f32>, 3>,
    normal: array<vec4<f32>, 3>,
    uv: array<vec2<f32>, 3>,
}
@group(2) @binding(7) var<storage, read_write> shading: array<PrimShading>;

@compute @workgroup_size(64)
fn cs_allocate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let d = triangle_of(gid); // drawn, within the chunk
    if d >= chunk.drawn {
        return;
    }
    let t = drawn_triangle(d);
    var s: PrimShading;
    for (var k = 0u; k < 3u; k++) {
        let v = indices[3u * t.t + k];
        s.clip[k] = clip_vertex(t, k);
        s.color[k] = placed_color(v, t.inst);
        s.normal[k] = vec4<f32>(0.0);
        s.uv[k] = vec2<f32>(0.0);
        if SHADED != 0u {
            let a = attributes[2u * v];
            s.normal[k] = vec4<f32>(placed_normal(a.xyz, t.inst), a.w);
            s.uv[k] = attributes[2u * v + 1u].xy;
        }
    }
    shading[t.prim] = s;
}

@fragment @early_depth_test(force)
fn fs_capture(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.prim));
}

// The node keeps only depth and triangle: its color is interpolated and shaded here, at the
// pixel center (deferred shading: only the fragments the sweep composites are shaded).
fn node_frag(node: Node, link: u32, px: u32) -> Frag {
    let s = shading[node.prim];
    let at = vec2<f32>(pixel_position(px)) + 0.5;
    let fa = frame_xy(at);
    let ndc = vec2<f32>(fa.x * 2.0 / f32(frame.size.x) - 1.0, 1.0 - fa.y * 2.0 / f32(frame.size.y));
    let b = barycentrics(s.clip[0], s.clip[1], s.clip[2], ndc);
    var f: VsOut;
    f.clip = vec4<f32>(at, node.depth, 1.0);
    f.color = b.x * s.color[0] + b.y * s.color[1] + b.z * s.color[2];
    f.prim = node.prim;
//!if SHADED
    f.normal = b.x * s.normal[0].xyz + b.y * s.normal[1].xyz + b.z * s.normal[2].xyz;
    f.uv = b.x * s.uv[0] + b.y * s.uv[1] + b.z * s.uv[2];
    f.material = bitcast<u32>(s.normal[0].w);
//!endif
    let color = clamp(shade(f), vec4<f32>(0.0), vec4<f32>(1.0));
    return Frag(node.depth, color, link);
}

fn frag_mask(f: Frag) -> u32 {
    return 1u;
}
//!include common/list_cursor.wgsl
//!include common/sweep.wgsl
