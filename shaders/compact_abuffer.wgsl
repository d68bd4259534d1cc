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
//!if PRIMITIVES
        if chunk.kind != PRIM_MESH {
            let c = corner_of(3u * t.t + k, t.inst);
            s.clip[k] = frame.view_proj * vec4<f32>(c.world, 1.0);
            s.color[k] = c.color;
            s.normal[k] = vec4<f32>(0.0);
            s.uv[k] = vec2<f32>(0.0);
            if SHADED != 0u {
                s.normal[k] = vec4<f32>(c.tangent, bitcast<f32>(chunk.set_surface));
                s.uv[k] = c.uv;
            }
            continue;
        }
//!endif
//!if !SETS_ONLY
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
//!endif
    }
    shading[t.prim] = s;
}

@fragment @early_depth_test(force)
fn fs_capture(raw: VsOut) {
    let in = splat_depth(raw);
    if behind_opaque(in.clip) {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.prim));
}

// The node keeps only depth and triangle. The sweep orders fragments by depth, then by their
// interpolated vertex color (what an unlit scene composites), then by their triangles' records
// (tie_key), all from the record without shading; frag_shaded shades each fragment once, when
// it is composited, and only while the pixel can still change (the composite stops at
// transmittance 0). docs/methods.md ("compact_abuffer").
fn node_frag(node: Node, link: u32, px: u32) -> Frag {
    let s = shading[node.prim];
    let b = pixel_barycentrics(s, px);
    let color = b.x * s.color[0] + b.y * s.color[1] + b.z * s.color[2];
    return Frag(node.depth, clamp(color, vec4<f32>(0.0), vec4<f32>(1.0)), node.prim);
}

// A fragment's id is its triangle, not its node's link (a triangle covers a pixel center
// once, so it is unique in a pixel's list): frag_shaded and tie_key read the record with no
// node load. The sweep takes links from its keys only where runs are KEYED.
const_assert KEYED != 0u;

// Perspective-correct barycentrics of the pixel center `px` in a triangle's record.
fn pixel_barycentrics(s: PrimShading, px: u32) -> vec3<f32> {
    let fa = frame_xy(vec2<f32>(pixel_position(px)) + 0.5);
    let ndc = vec2<f32>(fa.x * 2.0 / f32(frame.size.x) - 1.0, 1.0 - fa.y * 2.0 / f32(frame.size.y));
    return barycentrics(s.clip[0], s.clip[1], s.clip[2], ndc);
}

// The fragment shaded (deferred shading): an unlit scene's interpolated color is already what
// shading gives, unless the shading-cost knob asks for the work.
fn frag_shaded(f: Frag, px: u32) -> Frag {
    if SHADED == 0u && SHADING_COST == 0u {
        return f;
    }
    let prim = f.id;
    let s = shading[prim];
    let b = pixel_barycentrics(s, px);
    var v: VsOut;
    v.clip = vec4<f32>(vec2<f32>(pixel_position(px)) + 0.5, f.depth, 1.0);
    v.color = b.x * s.color[0] + b.y * s.color[1] + b.z * s.color[2];
    v.prim = prim;
//!if SHADED
    v.normal = b.x * s.normal[0].xyz + b.y * s.normal[1].xyz + b.z * s.normal[2].xyz;
    v.uv = b.x * s.uv[0] + b.y * s.uv[1] + b.z * s.uv[2];
    v.material = bitcast<u32>(s.normal[0].w);
//!endif
//!if TEXTURES
    let planes = uv_planes(s.clip[0], s.clip[1], s.clip[2], s.uv[0], s.uv[1], s.uv[2]);
    v.uv_plane_u = planes[0];
    v.uv_plane_v = planes[1];
    v.uv_plane_w = planes[2];
//!endif
    return Frag(f.depth, clamp(shade(v), vec4<f32>(0.0), vec4<f32>(1.0)), f.id);
}

// Fragments of equal depth and vertex color may still shade differently (their normals, UVs or
// materials differ): a hash of what shades them (the triangle's clip corners, normals and UVs,
// and its material's contents: not its index in the table, nor its texture's place there,
// which follow submission) orders them, so the order depends on the triangles, never on
// their submission. Unlit, the color is all there is.
fn tie_key(f: Frag) -> u32 {
    if SHADED == 0u {
        return 0u;
    }
    let s = shading[f.id];
    let material = bitcast<u32>(s.normal[0].w);
    let base = MATERIAL_VEC4S * material;
    var h = 2166136261u;
    h = mix4(h, s.clip[0]);
    h = mix4(h, s.clip[1]);
    h = mix4(h, s.clip[2]);
    h = mix4(h, vec4<f32>(s.normal[0].xyz, s.normal[1].x));
    h = mix4(h, vec4<f32>(s.normal[1].yz, s.normal[2].xy));
    h = mix4(h, vec4<f32>(s.normal[2].z, s.uv[0].x, s.uv[0].y, s.uv[1].x));
    h = mix4(h, vec4<f32>(s.uv[1].y, s.uv[2].x, s.uv[2].y, 0.0));
    h = mix4(h, surfaces[base]);
    h = mix4(h, surfaces[base + 1u]);
    // The texture maps' sampler bits and UV transforms, not their images' places.
    h = mix4(h, vec4<f32>(surfaces[base + 2u].yzw, surfaces[base + 3u].x));
    h = mix4(h, vec4<f32>(surfaces[base + 3u].yzw, surfaces[base + 4u].y));
    h = mix4(h, vec4<f32>(surfaces[base + 4u].zw, surfaces[base + 5u].xy));
    h = mix4(h, vec4<f32>(surfaces[base + 5u].zw, 0.0, 0.0));
    return h;
}

// FNV-1a over four words, unrolled (llvmpipe's loop limiter counts loops).
fn mix4(h: u32, v: vec4<f32>) -> u32 {
    let w = bitcast<vec4<u32>>(v);
    var x = (h ^ w.x) * 16777619u;
    x = (x ^ w.y) * 16777619u;
    x = (x ^ w.z) * 16777619u;
    return (x ^ w.w) * 16777619u;
}

fn frag_mask(f: Frag) -> u32 {
    return 1u;
}
//!include common/list_cursor.wgsl
//!include common/sweep.wgsl
