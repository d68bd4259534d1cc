// S-buffer (Vasilakis & Fudos 2012): a counting pass, an exclusive prefix sum of the counts
// (scan.wgsl, compute) that gives every pixel a contiguous range, then a capture pass that
// writes each fragment into its pixel's range; the pool is allocated to exactly the counted
// fragments. Resolve: common/sweep.wgsl. docs/methods.md ("sbuffer").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Capture links each range's nodes in order, so that the resolve sorts a range by relinking it
// like a list.
//!include common/pool_node.wgsl
// `heads` serves as each pixel's fill cursor (a copy of its range start).
//!include common/pool.wgsl
// Counts, then (scanned in place) range starts; entry W * H is the total.
@group(2) @binding(7) var<storage, read_write> offsets: array<atomic<u32>>;

@fragment @early_depth_test(force)
fn fs_count(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    atomicAdd(&offsets[pixel_index(in.clip)], 1u);
}

@fragment @early_depth_test(force)
fn fs_capture(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let i = atomicAdd(&heads[pixel_index(in.clip)], 1u);
    if i >= alloc.capacity {
        return; // the scan's total says how many; the host grows the pool
    }
    let end = atomicLoad(&offsets[pixel_index(in.clip) + 1u]);
    store_node(i, Node(in.clip.z, select(0u, i + 2u, i + 1u < end), in.color.rg, in.color.ba));
}

fn list_head(px: u32) -> u32 {
    let start = atomicLoad(&offsets[px]);
    return select(0u, start + 1u, start < atomicLoad(&offsets[px + 1u]));
}

fn walk(link: u32, px: u32) -> Walked {
    let node = load_node(link - 1u);
    return Walked(Frag(node.depth, vec4<f32>(node.rg, node.ba), link), node.next);
}

fn frag_mask(f: Frag) -> u32 {
    return 1u;
}
//!include common/stored_color.wgsl
//!include common/sweep.wgsl
