// Adaptive transparency (Salvi et al. 2011) as the paper's proof of concept: fragments are
// captured in per-pixel lists (unbounded memory), then one full-screen pass per pixel
//   1. inserts the fragments in submission order (primitive index) into a visibility
//      function of at most NODES steps; on overflow it removes the node whose removal
//      changes the area under the curve least, merging it into the node in front of it
//      (transmittance is underestimated, as in the paper);
//   2. composites every fragment as C * alpha * vis(z), and the background by the function's
//      last value. Error discussion: docs/methods.md ("adaptive").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Mirrors oit_core::gpu_types::PrimNode.
struct Node {
    depth: f32,
    next: u32,
    rg: vec2<f32>,
    ba: vec2<f32>,
    prim: u32,
    pad: u32,
}
//!include common/pool.wgsl

@group(2) @binding(6) var<storage, read_write> state: array<u32>; // unused: one dispatch

struct Frag {
    prim: u32,
    depth: f32,
    alpha: f32,
}

fn frag_less(a: Frag, b: Frag) -> bool {
    return a.prim < b.prim; // a triangle covers a pixel center at most once
}
//!include common/select.wgsl

@fragment
fn fs_capture(in: VsOut) {
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.color.rg, in.color.ba, in.prim, 0u));
}

// The visibility function: steps at depth[i] down to trans[i], sorted by depth.
var<private> depth: array<f32, NODES_PLUS_ONE>;
var<private> trans: array<f32, NODES_PLUS_ONE>;
var<private> count: u32;

fn insert(z: f32, a: f32) {
    // After every node at the same or a smaller depth.
    var p = count;
    while p > 0u && depth[p - 1u] > z {
        depth[p] = depth[p - 1u];
        trans[p] = trans[p - 1u] * (1.0 - a);
        p--;
    }
    var front = 1.0;
    if p > 0u {
        front = trans[p - 1u];
    }
    depth[p] = z;
    trans[p] = front * (1.0 - a);
    count++;
    if count <= NODES {
        return;
    }
    // Remove the node whose merge into its predecessor changes the area least.
    var best = 1u;
    var best_area = 3.4e38;
    for (var i = 1u; i < count; i++) {
        let area = (depth[i] - depth[i - 1u]) * (trans[i - 1u] - trans[i]);
        if area < best_area {
            best_area = area;
            best = i;
        }
    }
    trans[best - 1u] = trans[best];
    for (var i = best; i + 1u < count; i++) {
        depth[i] = depth[i + 1u];
        trans[i] = trans[i + 1u];
    }
    count--;
}

// Transmittance in front of depth z: the last step strictly nearer than z.
fn vis(z: f32) -> f32 {
    var t = 1.0;
    for (var i = 0u; i < count; i++) {
        if depth[i] >= z {
            break;
        }
        t = trans[i];
    }
    return t;
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let head = atomicLoad(&heads[pixel_index(pos)]);
    count = 0u;
    // 1. Submission order: each sweep takes the BATCH smallest primitive indices above the
    //    last one taken.
    var heap: array<Frag, BATCH>;
    var last = 0u;
    var have_last = false;
    loop {
        var n = 0u;
        var i = head;
        while i != NIL {
            let node = load_node(i - 1u);
            i = node.next;
            if !have_last || node.prim > last {
                n = heap_offer(&heap, n, Frag(node.prim, node.depth, node.ba.y));
            }
        }
        heap_sort(&heap, n);
        for (var b = 0u; b < n; b++) {
            insert(heap[b].depth, heap[b].alpha);
        }
        if n < BATCH {
            break;
        }
        last = heap[BATCH - 1u].prim;
        have_last = true;
    }
    // 2. Composite every fragment by the approximate visibility.
    var accum = vec3<f32>(0.0);
    var i = head;
    while i != NIL {
        let n = load_node(i - 1u);
        i = n.next;
        accum += vec3<f32>(n.rg, n.ba.x) * n.ba.y * vis(n.depth);
    }
    var t = 1.0;
    if count > 0u {
        t = trans[count - 1u];
    }
    return vec4<f32>(accum + t * base.rgb, 1.0 - t * (1.0 - base.a));
}
