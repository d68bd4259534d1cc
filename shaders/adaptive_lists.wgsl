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

//!include common/submission.wgsl

// The visibility function: steps at depth[i] down to trans[i], sorted by depth.
var<private> depth: array<f32, NODES_PLUS_ONE>;
var<private> trans: array<f32, NODES_PLUS_ONE>;
var<private> count: u32;

fn visit(f: Frag) {
    let z = f.depth;
    let a = f.color.a;
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
    // 1. The visibility function, in submission order.
    visit_in_submission_order(head);
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
