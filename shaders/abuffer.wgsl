// Exact A-buffer: per-pixel linked lists in a global node pool (Yang et al. 2010).
// Capture: one atomic allocation and one atomic head exchange per fragment; the resolve is
// common/sweep.wgsl. docs/methods.md.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

//!include common/pool_node.wgsl
//!include common/pool.wgsl

@fragment @early_depth_test(force)
fn fs_capture(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.color.rg, in.color.ba));
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
