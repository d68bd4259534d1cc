// Per-pixel linked lists over the node pool of common/nodes.wgsl. Links (heads, next) store
// a node's index + 1, so that a zero-cleared head buffer means empty lists. The including
// shader defines `struct Node` with a `next: u32` field (abuffer.wgsl, adaptive.wgsl, ...).

struct Alloc {
    count: atomic<u32>,
    capacity: u32,
    // Fragments a method could not place where its allocation said (pall: outside the
    // triangle's bound); any is an error the host reports.
    escaped: atomic<u32>,
    // The sorted resolve's deep pixels (common/sweep.wgsl): how many, and the workgroups of
    // the dispatches over them (copied to the indirect dispatches' arguments).
    deep: atomic<u32>,
    deep_groups: array<u32, 3>,
    pad: u32,
}

@group(2) @binding(0) var<storage, read_write> heads: array<atomic<u32>>;
@group(2) @binding(1) var<storage, read_write> alloc: Alloc;
//!include common/nodes.wgsl

const NIL: u32 = 0u;

// Appends `n` to pixel `px`'s list; past the capacity it is only counted (the host grows
// the pool and renders again).
fn push_node(px: u32, n: Node) {
    let i = atomicAdd(&alloc.count, 1u);
    if i >= alloc.capacity {
        return;
    }
    var node = n;
    node.next = atomicExchange(&heads[px], i + 1u);
    store_node(i, node);
}
