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

// Per-pixel sweep state (STATE_WORDS words): the last composited fragment's key (6 words),
// flags, a spare word, then per sample of the pixel (PIXEL_SAMPLES, from the targets include:
// 1, or the coverage-mask sample count) its accumulated color and transmittance.
const STATE_WORDS: u32 = 8u + 4u * PIXEL_SAMPLES;
const FLAGS: u32 = 6u;
const SAMPLE_STATE: u32 = 8u;
const STARTED: u32 = 1u;
const DONE: u32 = 2u;

// The including shader also defines `fn frag_mask(f: Frag) -> u32`: the pixel's samples the
// fragment covers (bit s: sample s), 1 without coverage masks. The mask stays out of Frag,
// which the heap moves around: one more word there slowed every list sweep by a tenth.
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
    let at = px * STATE_WORDS;
    let flags = state[at + FLAGS];
    if (flags & DONE) != 0u {
        return;
    }
    let started = (flags & STARTED) != 0u;
    var accum: array<vec3<f32>, PIXEL_SAMPLES>;
    var trans: array<f32, PIXEL_SAMPLES>;
    var prev: Frag;
    for (var s = 0u; s < PIXEL_SAMPLES; s++) {
        let w = at + SAMPLE_STATE + 4u * s;
        if started {
            accum[s] = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
            trans[s] = bitcast<f32>(state[w + 3u]);
        } else {
            accum[s] = vec3<f32>(0.0);
            trans[s] = 1.0;
        }
    }
    if started {
        prev = Frag(bitcast<f32>(state[at]),
                    vec4<f32>(bitcast<f32>(state[at + 1u]), bitcast<f32>(state[at + 2u]), bitcast<f32>(state[at + 3u]), bitcast<f32>(state[at + 4u])),
                    state[at + 5u]);
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
        let f = heap[b];
        let mask = frag_mask(f);
        for (var s = 0u; s < PIXEL_SAMPLES; s++) {
            if (mask & (1u << s)) != 0u {
                accum[s] += trans[s] * f.color.a * f.color.rgb;
                trans[s] *= 1.0 - f.color.a;
            }
        }
    }
    var out_flags = STARTED;
    var opaque = true;
    for (var s = 0u; s < PIXEL_SAMPLES; s++) {
        let w = at + SAMPLE_STATE + 4u * s;
        state[w] = bitcast<u32>(accum[s].r);
        state[w + 1u] = bitcast<u32>(accum[s].g);
        state[w + 2u] = bitcast<u32>(accum[s].b);
        state[w + 3u] = bitcast<u32>(trans[s]);
        opaque = opaque && trans[s] == 0.0;
    }
    if n < BATCH || opaque {
        out_flags |= DONE;
    }
    if n > 0u {
        let last = heap[n - 1u];
        state[at] = bitcast<u32>(last.depth);
        state[at + 1u] = bitcast<u32>(last.color.r);
        state[at + 2u] = bitcast<u32>(last.color.g);
        state[at + 3u] = bitcast<u32>(last.color.b);
        state[at + 4u] = bitcast<u32>(last.color.a);
        state[at + 5u] = last.id;
    }
    state[at + FLAGS] = out_flags;
}

// The pixel: the mean over its samples of the composite over that sample's opaque scene or
// background (one sample without coverage masks).
@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let at = pixel_index(pos) * STATE_WORDS;
    let started = (state[at + FLAGS] & STARTED) != 0u;
    var sum = vec4<f32>(0.0);
    for (var s = 0u; s < PIXEL_SAMPLES; s++) {
        let base = base_at_sample(pos, s);
        if !started {
            sum += base;
            continue;
        }
        let w = at + SAMPLE_STATE + 4u * s;
        let accum = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
        let trans = bitcast<f32>(state[w + 3u]);
        sum += vec4<f32>(accum + trans * base.rgb, 1.0 - trans * (1.0 - base.a));
    }
    return sum / f32(PIXEL_SAMPLES);
}
