// Multi-layer alpha blending (Salvi & Vaidyanathan 2014) as the paper designs it: one
// geometry pass in which each fragment, inside its pixel's critical section
// (common/pixel_lock.wgsl), is inserted into a depth-sorted array of LAYERS blended layers
// (premultiplied color, transmittance, depth); when the array overflows, its two farthest
// layers are merged with the over operator. A full-screen pass composites the layers front to
// back over the opaque scene or background. The update is that of mlab_lists.wgsl (the proof
// of concept over captured lists) step for step. docs/methods.md ("mlab").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Layer i of pixel px: LAYER_WORDS words from layer_word(px, i): premultiplied color (3),
// transmittance, depth, each a float's bits.
@group(2) @binding(0) var<storage, read_write> layers: array<atomic<u32>>;
const LAYER_WORDS: u32 = 5u;

struct Incoming {
    depth: f32,
    color: vec4<f32>,
}
//!include common/pixel_lock.wgsl

var<private> layer_c: array<vec3<f32>, LAYERS_PLUS_ONE>;
var<private> layer_t: array<f32, LAYERS_PLUS_ONE>;
var<private> layer_z: array<f32, LAYERS_PLUS_ONE>;

fn layer_word(px: u32, i: u32) -> u32 {
    return LAYER_WORDS * (px * LAYERS + i);
}

fn load_word(w: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&layers[w]));
}

fn store_word(w: u32, v: f32) {
    atomicStore(&layers[w], bitcast<u32>(v));
}

fn critical(px: u32, count: u32, f: Incoming) -> u32 {
    for (var i = 0u; i < count; i++) {
        let w = layer_word(px, i);
        layer_c[i] = vec3<f32>(load_word(w), load_word(w + 1u), load_word(w + 2u));
        layer_t[i] = load_word(w + 3u);
        layer_z[i] = load_word(w + 4u);
    }
    // Insert behind every layer at the same or a smaller depth.
    var p = count;
    while p > 0u && layer_z[p - 1u] > f.depth {
        layer_c[p] = layer_c[p - 1u];
        layer_t[p] = layer_t[p - 1u];
        layer_z[p] = layer_z[p - 1u];
        p--;
    }
    layer_c[p] = f.color.rgb * f.color.a;
    layer_t[p] = 1.0 - f.color.a;
    layer_z[p] = f.depth;
    var n = count + 1u;
    var first = p; // the first layer that changed
    if n > LAYERS {
        // Merge the farthest layer into the one in front of it (over operator).
        let k = LAYERS - 1u;
        layer_c[k] += layer_t[k] * layer_c[LAYERS];
        layer_t[k] *= layer_t[LAYERS];
        n = LAYERS;
        first = min(first, k);
    }
    for (var i = first; i < n; i++) {
        let w = layer_word(px, i);
        store_word(w, layer_c[i].r);
        store_word(w + 1u, layer_c[i].g);
        store_word(w + 2u, layer_c[i].b);
        store_word(w + 3u, layer_t[i]);
        store_word(w + 4u, layer_z[i]);
    }
    return n;
}

@fragment @early_depth_test(force)
fn fs_insert(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    with_pixel_lock(pixel_index(in.clip), Incoming(in.clip.z, in.color));
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let px = pixel_index(pos);
    let count = entries(px);
    var accum = vec3<f32>(0.0);
    var t = 1.0;
    for (var i = 0u; i < count; i++) {
        let w = layer_word(px, i);
        accum += t * vec3<f32>(load_word(w), load_word(w + 1u), load_word(w + 2u));
        t *= load_word(w + 3u);
    }
    return vec4<f32>(accum + t * base.rgb, 1.0 - t * (1.0 - base.a));
}
