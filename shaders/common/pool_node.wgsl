// The node of the lists that keep a fragment's depth and color (abuffer, pall, sbuffer).
// Mirrors oit_core::gpu_types::PoolNode.
struct Node {
    depth: f32,
    next: u32,
    rg: vec2<f32>,
    ba: vec2<f32>,
}
