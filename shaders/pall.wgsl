// Primitive-allocated linked lists (Kerzner et al. 2013): one atomic allocation per
// triangle, sized by a conservative bound of its fragments (the pixel centers inside its
// screen bounding box, widened by 1/16 pixel, clamped to the frame), in a compute pass
// before capture. A
// fragment's node is the triangle's block start plus its pixel's offset inside the box, so
// capture needs no global atomic, only the per-pixel head exchange. Resolve:
// common/sweep.wgsl. docs/methods.md ("pall").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl
//!include common/setup.wgsl

//!include common/pool_node.wgsl
//!include common/pool.wgsl
// Per triangle: its block's first node and its box (origin and extent, 16 bits each).
// Mirrors oit_core::gpu_types::PallBlock.
struct Block {
    start: u32,
    origin: u32,
    extent: u32,
    pad: u32,
}
@group(2) @binding(7) var<storage, read_write> blocks: array<Block>;

@compute @workgroup_size(64)
fn cs_allocate(@builtin(global_invocation_id) gid: vec3<u32>) {
    let d = triangle_of(gid); // drawn, within the chunk
    if d >= chunk.drawn {
        return;
    }
    let t = drawn_triangle(d);
    let b = pixel_box(clip_vertex(t, 0u), clip_vertex(t, 1u), clip_vertex(t, 2u));
    var extent = vec2<u32>(0u);
    if all(b.hi >= b.lo) {
        extent = vec2<u32>(b.hi - b.lo + 1);
    }
    let start = atomicAdd(&alloc.count, extent.x * extent.y);
    let lo = vec2<u32>(max(b.lo, vec2<i32>(0)));
    blocks[t.prim] = Block(start, lo.x | (lo.y << 16u), extent.x | (extent.y << 16u), 0u);
}

@fragment @early_depth_test(force)
fn fs_capture(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let blk = blocks[in.prim];
    // Offsets inside the box (in frame pixels); left of or above it they wrap to large values.
    let at = vec2<u32>(frame_xy(in.clip.xy));
    let x = at.x - (blk.origin & 0xffffu);
    let y = at.y - (blk.origin >> 16u);
    let w = blk.extent & 0xffffu;
    if x >= w || y >= (blk.extent >> 16u) {
        atomicAdd(&alloc.escaped, 1u); // the bound was not conservative: reported as an error
        return;
    }
    let i = blk.start + y * w + x;
    if i >= alloc.capacity {
        return; // the allocation pass counted it; the host grows the pool
    }
    var node = Node(in.clip.z, 0u, in.color.rg, in.color.ba);
    node.next = atomicExchange(&heads[pixel_index(in.clip)], i + 1u);
    store_node(i, node);
}

fn node_frag(node: Node, link: u32, px: u32) -> Frag {
    return Frag(node.depth, vec4<f32>(node.rg, node.ba), link);
}

fn frag_mask(f: Frag) -> u32 {
    return 1u;
}
//!include common/list_cursor.wgsl
//!include common/stored_color.wgsl
//!include common/sweep.wgsl
