// Exact A-buffer: per-pixel linked lists in a global node pool (Yang et al. 2010).
// Capture: one atomic allocation and one atomic head exchange per fragment; the resolve is
// common/sweep.wgsl. docs/methods.md.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Mirrors oit_core::gpu_types::PoolNode.
struct Node {
    depth: f32,
    next: u32,
    rg: vec2<f32>,
    ba: vec2<f32>,
}
//!include common/pool.wgsl

@group(2) @binding(6) var<storage, read_write> state: array<u32>;

@fragment
fn fs_capture(in: VsOut) {
    if behind_opaque(in.clip) {
        return;
    }
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, in.color.rg, in.color.ba));
}

struct Cursor {
    link: u32,
}

fn cursor_begin(px: u32) -> Cursor {
    return Cursor(atomicLoad(&heads[px]));
}

fn cursor_more(c: Cursor) -> bool {
    return c.link != NIL;
}

fn cursor_step(c: ptr<function, Cursor>) -> Frag {
    let i = (*c).link;
    let node = load_node(i - 1u);
    (*c).link = node.next;
    return Frag(node.depth, vec4<f32>(node.rg, node.ba), i);
}
//!include common/sweep.wgsl
