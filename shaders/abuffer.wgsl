// Exact A-buffer: per-pixel linked lists in a global node pool (Yang et al. 2010).
// Capture: one atomic allocation and one atomic head exchange per fragment.
// Resolve: sort each list front to back in batches of BATCH and composite (docs/methods.md).
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

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let head = atomicLoad(&heads[pixel_index(pos)]);
    var accum = vec3<f32>(0.0);
    var trans = 1.0;
    var batch: array<Frag, BATCH>;
    var have_prev = false;
    var prev: Frag;
    // Each sweep selects the BATCH nearest fragments behind the previous batch.
    loop {
        var n = 0u;
        var i = head;
        while i != NIL {
            let node = load_node(i - 1u);
            let f = Frag(node.depth, vec4<f32>(node.rg, node.ba), i);
            i = node.next;
            if have_prev && !frag_less(prev, f) {
                continue;
            }
            if n == BATCH && !frag_less(f, batch[BATCH - 1u]) {
                continue;
            }
            // Insertion into the sorted batch, dropping the farthest when full.
            var j = min(n, BATCH - 1u);
            while j > 0u && frag_less(f, batch[j - 1u]) {
                batch[j] = batch[j - 1u];
                j -= 1u;
            }
            batch[j] = f;
            n = min(n + 1u, BATCH);
        }
        for (var b = 0u; b < n; b++) {
            let c = batch[b].color;
            accum += trans * c.a * c.rgb;
            trans *= 1.0 - c.a;
        }
        if n < BATCH || trans == 0.0 {
            break;
        }
        prev = batch[BATCH - 1u];
        have_prev = true;
    }
    return vec4<f32>(accum + trans * base.rgb, 1.0 - trans * (1.0 - base.a));
}
