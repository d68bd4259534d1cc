// Per-pixel linked lists over the node pool of common/nodes.wgsl. Links (heads, next) store
// a node's index + 1, so that a zero-cleared head buffer means empty lists. The including
// shader defines `struct Node` with a `next: u32` field (common/pool_node.wgsl,
// adaptive_lists.wgsl, ...). Group 2 is the pool's (oit_core::method::list_pipelines::POOL_LAYOUT):
// heads, allocator, the pool bindings, sweep state (6) and the method's binding 7.

struct Alloc {
    count: atomic<u32>,
    capacity: u32,
    // Fragments a method could not place where its allocation said (pall: outside the
    // triangle's bound); any is an error the host reports.
    escaped: atomic<u32>,
    // The sorted resolve's pixel lists (common/sweep.wgsl): pixels with fragments, and deep
    // pixels, how many of each, and the workgroups of the dispatches over them (x, y, z for
    // the first, then for the second; copied to the indirect dispatches' arguments).
    listed: atomic<u32>,
    deep: atomic<u32>,
    groups: array<u32, 6>,
    pad: u32,
}

@group(2) @binding(0) var<storage, read_write> heads: array<atomic<u32>>;
@group(2) @binding(1) var<storage, read_write> alloc: Alloc;
//!include common/nodes.wgsl

const NIL: u32 = 0u;

// Where a capture counts its own fragments (COUNTING: a frame that runs no census, whose pool
// was sized by an earlier frame), each pixel's count, for the frame's statistics and the
// resolve's plan (oit_core::method::resolve_plan); a placeholder otherwise.
@group(2) @binding(8) var<storage, read_write> pixel_counts: array<atomic<u32>>;

// Appends `n` to pixel `px`'s list; past the capacity it is only counted (the host grows
// the pool and renders again).
fn push_node(px: u32, n: Node) {
//!if COUNTING
    atomicAdd(&pixel_counts[px], 1u);
//!endif
    let i = atomicAdd(&alloc.count, 1u);
    if i >= alloc.capacity {
        return;
    }
    var node = n;
    node.next = atomicExchange(&heads[px], i + 1u);
    store_node(i, node);
}

// Per-pixel state carried between the sorted resolve's sweeps (common/sweep.wgsl); unused by
// the submission-order methods, which resolve in one dispatch.
@group(2) @binding(6) var<storage, read_write> state: array<u32>;
