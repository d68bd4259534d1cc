// Submission-order methods over captured lists (adaptive, mlab): capture every fragment
// with its triangle index, then walk a pixel's fragments in submission order (ascending
// triangle index: unique within a pixel) in heap-selected batches, calling the including
// shader's `fn visit(f: Frag)` for each. The including shader includes the scene, targets
// and fullscreen helpers first.

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

struct Frag {
    prim: u32,
    depth: f32,
    color: vec4<f32>,
}

fn frag_less(a: Frag, b: Frag) -> bool {
    return a.prim < b.prim;
}
//!include common/select.wgsl

@fragment @early_depth_test(force)
fn fs_capture(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.color.rg, in.color.ba, in.prim, 0u));
}

// Visits the list starting at `head` in submission order: each sweep takes the BATCH
// smallest triangle indices above the last one visited.
fn visit_in_submission_order(head: u32) {
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
                n = heap_offer(&heap, n, Frag(node.prim, node.depth, vec4<f32>(node.rg, node.ba)));
            }
        }
        heap_sort(&heap, n);
        for (var b = 0u; b < n; b++) {
            visit(heap[b]);
        }
        if n < BATCH {
            break;
        }
        last = heap[BATCH - 1u].prim;
        have_last = true;
    }
}
