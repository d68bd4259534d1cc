// A node pool split across up to four storage bindings (2 to 5 of group 2), so that it can
// pass the adapter's per-binding limit. NODES_PER_BINDING is injected by the pipeline
// (oit_core::shader). Unused bindings hold a one-node placeholder buffer. The including
// shader defines `struct Node`.
@group(2) @binding(2) var<storage, read_write> pool0: array<Node>;
@group(2) @binding(3) var<storage, read_write> pool1: array<Node>;
@group(2) @binding(4) var<storage, read_write> pool2: array<Node>;
@group(2) @binding(5) var<storage, read_write> pool3: array<Node>;

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

