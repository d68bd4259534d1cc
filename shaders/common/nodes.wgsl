// A node pool split across up to four storage bindings (2 to 5 of group 2), so that it can
// pass the adapter's per-binding limit. NODES_PER_BINDING and POOL_SPLIT (the bindings in
// use) are injected by the pipeline (oit_core::method::pool): a pool in one binding skips
// the switch, which costs every lane all four loads on a SIMD software rasterizer. Unused
// bindings hold a one-node placeholder buffer. The including shader defines `struct Node`
// with a `next: u32` field.
@group(2) @binding(2) var<storage, read_write> pool0: array<Node>;
@group(2) @binding(3) var<storage, read_write> pool1: array<Node>;
@group(2) @binding(4) var<storage, read_write> pool2: array<Node>;
@group(2) @binding(5) var<storage, read_write> pool3: array<Node>;

fn store_node(i: u32, n: Node) {
    if POOL_SPLIT == 1u {
        pool0[i] = n;
        return;
    }
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { pool0[o] = n; }
        case 1u: { pool1[o] = n; }
        case 2u: { pool2[o] = n; }
        default: { pool3[o] = n; }
    }
}

fn load_node(i: u32) -> Node {
    if POOL_SPLIT == 1u {
        return pool0[i];
    }
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { return pool0[o]; }
        case 1u: { return pool1[o]; }
        case 2u: { return pool2[o]; }
        default: { return pool3[o]; }
    }
}

// A node's link field alone (the resolve relinks lists while sorting them).
fn load_next(i: u32) -> u32 {
    if POOL_SPLIT == 1u {
        return pool0[i].next;
    }
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { return pool0[o].next; }
        case 1u: { return pool1[o].next; }
        case 2u: { return pool2[o].next; }
        default: { return pool3[o].next; }
    }
}

fn store_next(i: u32, next: u32) {
    if POOL_SPLIT == 1u {
        pool0[i].next = next;
        return;
    }
    let o = i % NODES_PER_BINDING;
    switch i / NODES_PER_BINDING {
        case 0u: { pool0[o].next = next; }
        case 1u: { pool1[o].next = next; }
        case 2u: { pool2[o].next = next; }
        default: { pool3[o].next = next; }
    }
}
