// The A-buffer with coverage masks (Carpenter 1984): one node per pixel a triangle touches,
// with the mask of the samples it covers in front of the opaque scene, rasterized once at the
// standard multisample positions. The sweeps composite each sample from the fragments that
// cover it, in one front-to-back order per pixel (depth at the pixel center), and the resolve
// averages the samples. docs/methods.md ("Antialiasing").
//!include common/scene.wgsl
//!include common/targets_samples.wgsl
//!include common/fullscreen.wgsl

// Mirrors oit_core::gpu_types::CoverageNode.
struct Node {
    depth: f32,
    next: u32,
    rg: vec2<f32>,
    ba: vec2<f32>,
    mask: u32,
    pad: u32,
}
//!include common/pool.wgsl

@fragment
fn fs_capture(raw: VsOut, @builtin(sample_mask) coverage: u32) {
    let in = shaded(raw);
    // Derivatives first, while every invocation of the quad is still running.
    let slope = vec2<f32>(dpdx(in.clip.z), dpdy(in.clip.z));
    let mask = visible_samples(in.clip, slope, coverage);
    if mask == 0u {
        return;
    }
    // Shaded once at the pixel center, as multisampling does: clamped, since the center may lie
    // outside a triangle that covers only some samples.
    let c = clamp(in.color, vec4<f32>(0.0), vec4<f32>(1.0));
    push_node(pixel_index(in.clip), Node(in.clip.z, 0u, c.rg, c.ba, mask, 0u));
}

fn node_frag(node: Node, link: u32, px: u32) -> Frag {
    return Frag(node.depth, vec4<f32>(node.rg, node.ba), link);
}

// The node's sample mask, read back by its link when the fragment is composited.
fn frag_mask(f: Frag) -> u32 {
    return load_node(f.id - 1u).mask;
}
//!include common/list_cursor.wgsl
//!include common/stored_color.wgsl
//!include common/sweep.wgsl
