// The cursor common/sweep.wgsl walks a pixel's linked list with (common/pool.wgsl lists).
// The including shader turns a node into a fragment:
//   fn node_frag(node: Node, link: u32, px: u32) -> Frag  (link: the node's index + 1)

struct Cursor {
    link: u32,
    px: u32,
}

fn cursor_begin(px: u32) -> Cursor {
    return Cursor(atomicLoad(&heads[px]), px);
}

fn cursor_more(c: Cursor) -> bool {
    return c.link != NIL;
}

fn cursor_step(c: ptr<function, Cursor>) -> Frag {
    let i = (*c).link;
    let node = load_node(i - 1u);
    (*c).link = node.next;
    return node_frag(node, i, (*c).px);
}
