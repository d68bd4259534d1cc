// Exclusive prefix sum of a u32 array in place, in levels of 256-element blocks: one
// invocation scans a block serially and writes its total to `sums` (no workgroup barriers,
// which a software rasterizer runs as context switches); the host scans `sums` the same way
// (recursively) and adds each block's scanned total back (cs_add_blocks).

struct ScanParams {
    n: u32,
    groups_x: u32,
    pad0: u32,
    pad1: u32,
}

@group(0) @binding(0) var<storage, read_write> data: array<u32>;
@group(0) @binding(1) var<storage, read_write> sums: array<u32>;
@group(0) @binding(2) var<uniform> params: ScanParams;

const BLOCK: u32 = 256u;
// One invocation a block, 64 a workgroup (oit_core::scan::SCAN_GROUP).
@compute @workgroup_size(64)
fn cs_scan_blocks(@builtin(global_invocation_id) gid: vec3<u32>) {
    // Row y of blocks as cs_add_blocks lays them out: groups_x blocks a row.
    let b = gid.y * params.groups_x + gid.x;
    let first = b * BLOCK;
    if gid.x >= params.groups_x || first >= max(params.n, 1u) {
        return;
    }
    let end = min(first + BLOCK, params.n);
    var total = 0u;
    for (var i = first; i < end; i++) {
        let v = data[i];
        data[i] = total;
        total += v;
    }
    sums[b] = total;
}

fn block_of(wid: vec3<u32>) -> u32 {
    return wid.y * params.groups_x + wid.x;
}

@compute @workgroup_size(256)
fn cs_add_blocks(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let b = block_of(wid);
    let i = b * BLOCK + lid.x;
    if i < params.n {
        data[i] += sums[b];
    }
}
