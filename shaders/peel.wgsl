// Depth peeling (Everitt 2001; RTR 5.5) and dual depth peeling (Bavoil & Myers 2008) over
// 64-bit fragment keys: depth bits over the triangle index, a strict order even for
// coplanar fragments. Each geometry pass shades the layer(s) the previous pass found — the
// fragment whose key equals the pixel's current front (and, dual, back) key writes its color
// — and finds the next ones among the fragments strictly inside with 64-bit atomicMin (and
// atomicMax). A compute pass after each geometry pass composites the shaded layers (front:
// under operator, front to back; back: over operator, back to front) and moves the next keys
// in. DUAL (0 or 1) is injected. docs/methods.md ("depth_peeling").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Per pixel: current front and back keys, next front and back keys (u64 each).
@group(2) @binding(0) var<storage, read_write> keys: array<atomic<u64>>;
// Per pixel: the shaded front and back layers' straight colors (vec4 each).
@group(2) @binding(1) var<storage, read_write> layers: array<vec4<f32>>;
// Per pixel (PEEL_WORDS): front color and transmittance, back color and transmittance,
// and a flag: FRESH (nothing found yet), ACTIVE (front/back keys name layers to shade), DONE.
@group(2) @binding(2) var<storage, read_write> acc: array<f32>;
// Fragments shaded into a layer, for the stats.
@group(2) @binding(3) var<storage, read_write> peeled: atomic<u32>;

// Mirrors oit_core::method::peel::PEEL_WORDS.
// No fragment has this key (its depth bits would be a NaN).
const NO_KEY: u64 = 0xfffffffffffffffflu;

fn frag_key(z: f32, prim: u32) -> u64 {
    return (u64(bitcast<u32>(z)) << 32u) | u64(prim);
}

fn key_of(px: u32, i: u32) -> u64 {
    return atomicLoad(&keys[4u * px + i]);
}

const FRESH: f32 = 0.0;
const ACTIVE: f32 = 1.0;
const DONE: f32 = 2.0;

@compute @workgroup_size(8, 8)
fn cs_init(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = compute_pixel(gid);
    if px == OUTSIDE {
        return;
    }
    for (var i = 0u; i < 3u; i++) {
        atomicStore(&keys[4u * px + i], NO_KEY);
    }
    atomicStore(&keys[4u * px + 3u], 0lu);
    let a = px * PEEL_WORDS;
    for (var i = 0u; i < PEEL_WORDS; i++) {
        acc[a + i] = 0.0;
    }
    acc[a + 3u] = 1.0;
    acc[a + 7u] = 1.0;
}

@fragment @early_depth_test(force)
fn fs_peel(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let px = pixel_index(in.clip);
    let flag = acc[px * PEEL_WORDS + 8u];
    if flag == DONE {
        return;
    }
    let key = frag_key(in.clip.z, in.prim);
    let front = key_of(px, 0u);
    let back = key_of(px, 1u);
    if flag == ACTIVE {
        if key == front {
            layers[2u * px] = in.color;
            atomicAdd(&peeled, 1u);
            return;
        }
        if DUAL != 0u && key == back {
            layers[2u * px + 1u] = in.color;
            atomicAdd(&peeled, 1u);
            return;
        }
        if key < front || (DUAL != 0u && key > back) {
            return; // peeled already
        }
    }
    atomicMin(&keys[4u * px + 2u], key);
    if DUAL != 0u {
        atomicMax(&keys[4u * px + 3u], key);
    }
}

@compute @workgroup_size(8, 8)
fn cs_composite(@builtin(global_invocation_id) gid: vec3<u32>) {
    let px = compute_pixel(gid);
    if px == OUTSIDE {
        return;
    }
    let a = px * PEEL_WORDS;
    let flag = acc[a + 8u];
    if flag == DONE {
        return;
    }
    if flag == ACTIVE {
        let c = layers[2u * px];
        let t = acc[a + 3u];
        acc[a] += t * c.a * c.r;
        acc[a + 1u] += t * c.a * c.g;
        acc[a + 2u] += t * c.a * c.b;
        acc[a + 3u] = t * (1.0 - c.a);
        if DUAL != 0u && key_of(px, 1u) != key_of(px, 0u) {
            let b = layers[2u * px + 1u];
            acc[a + 4u] = b.a * b.r + (1.0 - b.a) * acc[a + 4u];
            acc[a + 5u] = b.a * b.g + (1.0 - b.a) * acc[a + 5u];
            acc[a + 6u] = b.a * b.b + (1.0 - b.a) * acc[a + 6u];
            acc[a + 7u] *= 1.0 - b.a;
        }
    }
    // The next pass shades what this one found.
    let next_front = atomicLoad(&keys[4u * px + 2u]);
    atomicStore(&keys[4u * px], next_front);
    atomicStore(&keys[4u * px + 1u], atomicLoad(&keys[4u * px + 3u]));
    atomicStore(&keys[4u * px + 2u], NO_KEY);
    atomicStore(&keys[4u * px + 3u], 0lu);
    acc[a + 8u] = select(ACTIVE, DONE, next_front == NO_KEY);
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let a = pixel_index(pos) * PEEL_WORDS;
    let front = vec3<f32>(acc[a], acc[a + 1u], acc[a + 2u]);
    let back = vec3<f32>(acc[a + 4u], acc[a + 5u], acc[a + 6u]);
    let t = acc[a + 3u] * acc[a + 7u];
    return vec4<f32>(front + acc[a + 3u] * (back + acc[a + 7u] * base.rgb), 1.0 - t * (1.0 - base.a));
}
