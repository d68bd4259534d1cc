// How common/sweep.wgsl reaches a pixel's linked list (common/pool.wgsl lists). The including
// shader turns a node into a fragment:
//   fn node_frag(node: Node, link: u32, px: u32) -> Frag  (link: the node's index + 1)

fn list_head(px: u32) -> u32 {
    return atomicLoad(&heads[px]);
}

fn walk(link: u32, px: u32) -> Walked {
    let node = load_node(link - 1u);
    return Walked(node_frag(node, link, px), node.next);
}
