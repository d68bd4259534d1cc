// A node pool split across up to four storage bindings, so that it can pass the adapter's
// per-binding limit. NODES_PER_BINDING is injected by the pipeline (oit_core::shader).
// Unused bindings hold a one-node placeholder buffer. Links (heads, next) store a node's
// index + 1, so that a zero-cleared head buffer means empty lists. The including shader
// defines `struct Node` with a `next: u32` field (abuffer.wgsl, adaptive.wgsl).

struct Alloc {
    count: atomic<u32>,
    capacity: u32,
    // Fragments a method could not place where its allocation said (pall: outside the
    // triangle's bound); any is an error the host reports.
    escaped: atomic<u32>,
    pad: u32,
}

@group(2) @binding(0) var<storage, read_write> heads: array<atomic<u32>>;
@group(2) @binding(1) var<storage, read_write> alloc: Alloc;
@group(2) @binding(2) var<storage, read_write> pool0: array<Node>;
@group(2) @binding(3) var<storage, read_write> pool1: array<Node>;
@group(2) @binding(4) var<storage, read_write> pool2: array<Node>;
@group(2) @binding(5) var<storage, read_write> pool3: array<Node>;

const NIL: u32 = 0u;

fn store_node(i: u32, n: Node) {
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { pool0[o] = n; }
        case 1u: { pool1[o] = n; }
        case 2u: { pool2[o] = n; }
        default: { pool3[o] = n; }
    }
}

fn load_node(i: u32) -> Node {
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { return pool0[o]; }
        case 1u: { return pool1[o]; }
        case 2u: { return pool2[o]; }
        default: { return pool3[o]; }
    }
}

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
