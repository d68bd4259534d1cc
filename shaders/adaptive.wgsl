// Adaptive transparency (Salvi et al. 2011) as the paper designs it: a visibility function of
// at most NODES steps a pixel in bounded storage, independent of the fragment count.
//   fs_insert   geometry pass 1: inside its pixel's critical section (common/pixel_lock.wgsl)
//               a fragment inserts its node (depth, transmittance), multiplies the nodes
//               behind it by 1 - alpha and, past NODES, removes the node whose removal changes
//               the area under the visibility curve least, merging it into the node in front
//               (transmittance is underestimated, as in the paper);
//   fs_shade    geometry pass 2: each fragment adds C * alpha * vis(z) by additive blending;
//   fs_resolve  full screen: the sum over the opaque scene or background at vis(infinity).
// The update is that of adaptive_lists.wgsl (the proof of concept over captured lists) step for
// step. Error discussion and what the critical section guarantees where: docs/methods.md.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

fn node_word(px: u32, i: u32) -> u32 {
    return 2u * (px * NODES + i);
}

// Node i of pixel px: its depth's bits at nodes[2 (px NODES + i)], its transmittance's next.
// The insert pass reads and writes them with atomics, inside the pixel's critical section; the
// passes after it (READ_NODES: fs_shade, fs_resolve) only read what the insert pass left, which
// the barrier between passes makes visible, and so load a node's two words at once, as one
// plain 8-byte load (docs/results.md: two 4-byte loads, atomic or not, cost the same).
//!if READ_NODES
@group(2) @binding(0) var<storage, read_write> nodes: array<vec2<u32>>;
// locks[px]: bits 1.. count pixel px's nodes (common/pixel_lock.wgsl).
@group(2) @binding(1) var<storage, read_write> locks: array<u32>;

fn entries(px: u32) -> u32 {
    return locks[px] >> 1u;
}

// Node i of pixel px as (depth, transmittance), one load.
fn node(px: u32, i: u32) -> vec2<f32> {
    return bitcast<vec2<f32>>(nodes[px * NODES + i]);
}
//!else
// The same two words, as one 64-bit atomic a node where the device has 64-bit atomic loads
// and stores (ATOMIC64; depth in the low half, so the memory is the plain reads' layout), else as
// two 32-bit atomics.
//!if ATOMIC64
@group(2) @binding(0) var<storage, read_write> nodes: array<atomic<u64>>;

fn node(px: u32, i: u32) -> vec2<f32> {
    let x = atomicLoad(&nodes[px * NODES + i]);
    return vec2<f32>(bitcast<f32>(u32(x & 0xfffffffflu)), bitcast<f32>(u32(x >> 32u)));
}

fn store_node(px: u32, i: u32, depth: f32, trans: f32) {
    atomicStore(&nodes[px * NODES + i], u64(bitcast<u32>(depth)) | (u64(bitcast<u32>(trans)) << 32u));
}
//!else
@group(2) @binding(0) var<storage, read_write> nodes: array<atomic<u32>>;

fn node(px: u32, i: u32) -> vec2<f32> {
    return vec2<f32>(bitcast<f32>(atomicLoad(&nodes[node_word(px, i)])), bitcast<f32>(atomicLoad(&nodes[node_word(px, i) + 1u])));
}

fn store_node(px: u32, i: u32, depth: f32, trans: f32) {
    atomicStore(&nodes[node_word(px, i)], bitcast<u32>(depth));
    atomicStore(&nodes[node_word(px, i) + 1u], bitcast<u32>(trans));
}
//!endif

struct Incoming {
    depth: f32,
    alpha: f32,
}
//!include common/pixel_lock.wgsl

// The update indexes its arrays only by loop counters with constant bounds, which the
// compiler unrolls into registers: a dynamically indexed private array is a gather per lane
// on llvmpipe and local memory on GPUs. Only the pixel's `count` nodes are loaded, and only
// the nodes that change are stored. Step for step the arithmetic of adaptive_lists' `visit`.
fn critical(px: u32, count: u32, f: Incoming) -> u32 {
    var d: array<f32, NODES_PLUS_ONE>;
    var t: array<f32, NODES_PLUS_ONE>;
    // p: the nodes at the same or a smaller depth, which stay in front of the new one (the
    // steps are sorted by depth, and transmittance never rises along them).
    var p = 0u;
    var front = 1.0;
    for (var i = 0u; i < NODES; i++) {
        d[i] = 0.0;
        t[i] = 0.0;
        if i < count {
            let n = node(px, i);
            d[i] = n.x;
            t[i] = n.y;
            if d[i] <= f.depth {
                p = i + 1u;
                front = t[i];
            }
        }
    }
    // Insert at p: the nodes behind move one step back, attenuated by 1 - alpha.
    let keep = 1.0 - f.alpha;
    var nd: array<f32, NODES_PLUS_ONE>;
    var nt: array<f32, NODES_PLUS_ONE>;
    nd[0] = select(d[0], f.depth, p == 0u);
    nt[0] = select(t[0], front * keep, p == 0u);
    for (var i = 1u; i < NODES_PLUS_ONE; i++) {
        let moved = i > p;
        nd[i] = select(select(d[i], f.depth, i == p), d[i - 1u], moved);
        nt[i] = select(select(t[i], front * keep, i == p), t[i - 1u] * keep, moved);
    }
    var n = count + 1u;
    var first = p; // the first node that changed
    if n > NODES {
        // Remove the node whose merge into its predecessor changes the area least (the first
        // of equal areas); its predecessor takes its transmittance.
        var best = 1u;
        var best_area = 3.4e38;
        for (var i = 1u; i < NODES_PLUS_ONE; i++) {
            let area = (nd[i] - nd[i - 1u]) * (nt[i - 1u] - nt[i]);
            if area < best_area {
                best_area = area;
                best = i;
            }
        }
        for (var i = 0u; i < NODES; i++) {
            nd[i] = select(nd[i], nd[i + 1u], i >= best);
            nt[i] = select(nt[i], nt[i + 1u], i + 1u >= best);
        }
        n = NODES;
        first = min(first, best - 1u);
    }
    for (var i = 0u; i < NODES; i++) {
        if i >= first && i < n {
            store_node(px, i, nd[i], nt[i]);
        }
    }
    return n;
}

@fragment @early_depth_test(force)
fn fs_insert(raw: VsOut) {
    let in = shaded_alpha(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    with_pixel_lock(pixel_index(in.clip), Incoming(in.clip.z, in.color.a));
}
//!endif

@group(3) @binding(0) var accum_tex: texture_2d<f32>;

// Transmittance in front of depth z: the last step strictly nearer than z. The steps are
// sorted by depth, so those nearer than z are a prefix, found by a binary search: at most
// log2(NODES) + 1 depth loads and one node load, where a walk along the prefix took as many
// steps as the deepest lane of a SIMD group needed (up to NODES loads on deep pixels).
fn vis(px: u32, z: f32) -> f32 {
    var lo = 0u;
    var hi = min(entries(px), NODES);
    while lo < hi {
        let mid = (lo + hi) / 2u;
        if node(px, mid).x < z { lo = mid + 1u; } else { hi = mid; }
    }
    if lo == 0u {
        return 1.0;
    }
    return node(px, lo - 1u).y;
}

@fragment @early_depth_test(force)
fn fs_shade(raw: VsOut) -> @location(0) vec4<f32> {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        discard;
    }
    let v = vis(pixel_index(in.clip), in.clip.z);
    return vec4<f32>(in.color.rgb * in.color.a * v, 0.0);
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let px = pixel_index(pos);
    let count = entries(px);
    var t = 1.0;
    if count > 0u {
        t = node(px, count - 1u).y;
    }
    let c = textureLoad(accum_tex, vec2<i32>(pos.xy), 0).rgb;
    return vec4<f32>(c + t * base.rgb, 1.0 - t * (1.0 - base.a));
}
