// The sweep's hooks for fragments that keep their color in the node (common/sweep.wgsl): each
// is composited as stored, and equal depth and color need no order besides the node link.
fn frag_shaded(f: Frag, px: u32) -> Frag {
    return f;
}

fn tie_key(f: Frag) -> u32 {
    return 0u;
}
