// Exact A-buffer: per-pixel linked lists in a global node pool (Yang et al. 2010).
// Capture: one atomic allocation and one atomic head exchange per fragment.
// Sweeps (compute, one dispatch each): every pixel takes the BATCH nearest fragments behind
// the last one it composited, sorts them and composites them front to back; the state
// between dispatches lives in `state`. The host dispatches floor(max depth complexity /
// BATCH) + 1 sweeps, so each invocation's work is one pass over its list.
// Resolve (full screen): the state over the opaque scene or background. docs/methods.md.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Mirrors oit_core::gpu_types::PoolNode.
struct Node {
    depth: f32,
    next: u32,
    rg: vec2<f32>,
    ba: vec2<f32>,
}
//!include common/pool.wgsl

// Per-pixel sweep state (STATE_WORDS words): accumulated color, transmittance, the last
// composited fragment's key, flags.
@group(2) @binding(6) var<storage, read_write> state: array<u32>;
const STATE_WORDS: u32 = 12u;
const STARTED: u32 = 1u;
const DONE: u32 = 2u;

@fragment
fn fs_capture(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.color.rg, in.color.ba));
}

struct Frag {
    depth: f32,
    color: vec4<f32>,
    id: u32,
}

// Strict total order: depth, then color, then node index. Fragments equal in depth and
// color are interchangeable, so the composite does not depend on submission order.
fn frag_less(a: Frag, b: Frag) -> bool {
    if a.depth != b.depth { return a.depth < b.depth; }
    if a.color.r != b.color.r { return a.color.r < b.color.r; }
    if a.color.g != b.color.g { return a.color.g < b.color.g; }
    if a.color.b != b.color.b { return a.color.b < b.color.b; }
    if a.color.a != b.color.a { return a.color.a < b.color.a; }
    return a.id < b.id;
}
//!include common/select.wgsl

@compute @workgroup_size(8, 8)
fn cs_sweep(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = compute_pixel(gid);
    if px == OUTSIDE {
        return;
    }
    let s = px * STATE_WORDS;
    let flags = state[s + 10u];
    if (flags & DONE) != 0u {
        return;
    }
    let started = (flags & STARTED) != 0u;
    var accum = vec3<f32>(0.0);
    var trans = 1.0;
    var prev: Frag;
    if started {
        accum = vec3<f32>(bitcast<f32>(state[s]), bitcast<f32>(state[s + 1u]), bitcast<f32>(state[s + 2u]));
        trans = bitcast<f32>(state[s + 3u]);
        prev = Frag(bitcast<f32>(state[s + 4u]),
                    vec4<f32>(bitcast<f32>(state[s + 5u]), bitcast<f32>(state[s + 6u]), bitcast<f32>(state[s + 7u]), bitcast<f32>(state[s + 8u])),
                    state[s + 9u]);
    }
    var heap: array<Frag, BATCH>;
    var n = 0u;
    var i = atomicLoad(&heads[px]);
    while i != NIL {
        let node = load_node(i - 1u);
        let f = Frag(node.depth, vec4<f32>(node.rg, node.ba), i);
        i = node.next;
        if !started || frag_less(prev, f) {
            n = heap_offer(&heap, n, f);
        }
    }
    heap_sort(&heap, n);
    for (var b = 0u; b < n; b++) {
        let c = heap[b].color;
        accum += trans * c.a * c.rgb;
        trans *= 1.0 - c.a;
    }
    var out_flags = STARTED;
    if n < BATCH || trans == 0.0 {
        out_flags |= DONE;
    }
    state[s] = bitcast<u32>(accum.r);
    state[s + 1u] = bitcast<u32>(accum.g);
    state[s + 2u] = bitcast<u32>(accum.b);
    state[s + 3u] = bitcast<u32>(trans);
    if n > 0u {
        let last = heap[n - 1u];
        state[s + 4u] = bitcast<u32>(last.depth);
        state[s + 5u] = bitcast<u32>(last.color.r);
        state[s + 6u] = bitcast<u32>(last.color.g);
        state[s + 7u] = bitcast<u32>(last.color.b);
        state[s + 8u] = bitcast<u32>(last.color.a);
        state[s + 9u] = last.id;
    }
    state[s + 10u] = out_flags;
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let s = pixel_index(pos) * STATE_WORDS;
    if (state[s + 10u] & STARTED) == 0u {
        return base;
    }
    let accum = vec3<f32>(bitcast<f32>(state[s]), bitcast<f32>(state[s + 1u]), bitcast<f32>(state[s + 2u]));
    let trans = bitcast<f32>(state[s + 3u]);
    return vec4<f32>(accum + trans * base.rgb, 1.0 - trans * (1.0 - base.a));
}
