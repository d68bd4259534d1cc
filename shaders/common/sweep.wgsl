// The exact resolve shared by the fragment-storing methods (abuffer, sbuffer, pall,
// compact_abuffer): sweeps (compute, one dispatch each) in which every pixel takes the BATCH
// nearest fragments behind the last one it composited, sorts them and composites them front
// to back, then a full-screen pass over the opaque scene or background. The host dispatches
// floor(max depth complexity / BATCH) + 1 sweeps, so each invocation's work is one pass over
// its fragments (llvmpipe ends an invocation's loops after 65,535 iterations).
// The including shader defines how a pixel's fragments are walked:
//   struct Cursor; fn cursor_begin(px: u32) -> Cursor; fn cursor_more(c: Cursor) -> bool;
//   fn cursor_step(c: ptr<function, Cursor>) -> Frag  (returns the fragment, advances)
// and declares the `state` storage binding. docs/methods.md ("abuffer").

// Per-pixel sweep state (STATE_WORDS words): accumulated color, transmittance, the last
// composited fragment's key, flags.
const STATE_WORDS: u32 = 12u;
const STARTED: u32 = 1u;
const DONE: u32 = 2u;

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
    var c = cursor_begin(px);
    while cursor_more(c) {
        let f = cursor_step(&c);
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
