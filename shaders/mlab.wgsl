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

fn layer_word(px: u32, i: u32) -> u32 {
    return LAYER_WORDS * (px * LAYERS + i);
}

fn load_word(w: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&layers[w]));
}

fn store_word(w: u32, v: f32) {
    atomicStore(&layers[w], bitcast<u32>(v));
}

// Indexed only by loop counters with constant bounds, which the compiler unrolls into
// registers (as adaptive.wgsl's update); loads the pixel's `count` layers and stores those that
// change. Step for step the arithmetic of mlab_lists' `visit`.
fn critical(px: u32, count: u32, f: Incoming) -> u32 {
    var c: array<vec3<f32>, LAYERS_PLUS_ONE>;
    var t: array<f32, LAYERS_PLUS_ONE>;
    var z: array<f32, LAYERS_PLUS_ONE>;
    // p: the layers at the same or a smaller depth, which stay in front of the new one.
    var p = 0u;
    for (var i = 0u; i < LAYERS; i++) {
        if i < count {
            let w = layer_word(px, i);
            c[i] = vec3<f32>(load_word(w), load_word(w + 1u), load_word(w + 2u));
            t[i] = load_word(w + 3u);
            z[i] = load_word(w + 4u);
            if z[i] <= f.depth {
                p = i + 1u;
            }
        }
    }
    let new_c = f.color.rgb * f.color.a;
    let new_t = 1.0 - f.color.a;
    var lc: array<vec3<f32>, LAYERS_PLUS_ONE>;
    var lt: array<f32, LAYERS_PLUS_ONE>;
    var lz: array<f32, LAYERS_PLUS_ONE>;
    lc[0] = select(c[0], new_c, p == 0u);
    lt[0] = select(t[0], new_t, p == 0u);
    lz[0] = select(z[0], f.depth, p == 0u);
    for (var i = 1u; i < LAYERS_PLUS_ONE; i++) {
        let moved = i > p;
        lc[i] = select(select(c[i], new_c, i == p), c[i - 1u], moved);
        lt[i] = select(select(t[i], new_t, i == p), t[i - 1u], moved);
        lz[i] = select(select(z[i], f.depth, i == p), z[i - 1u], moved);
    }
    var n = count + 1u;
    var first = p; // the first layer that changed
    if n > LAYERS {
        // Merge the farthest layer into the one in front of it (over operator).
        let k = LAYERS - 1u;
        lc[k] += lt[k] * lc[LAYERS];
        lt[k] *= lt[LAYERS];
        n = LAYERS;
        first = min(first, k);
    }
    for (var i = 0u; i < LAYERS; i++) {
        if i >= first && i < n {
            let w = layer_word(px, i);
            store_word(w, lc[i].r);
            store_word(w + 1u, lc[i].g);
            store_word(w + 2u, lc[i].b);
            store_word(w + 3u, lt[i]);
            store_word(w + 4u, lz[i]);
        }
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
