// Exclusive prefix sum of a u32 array in place, in levels of 256-element blocks: each block
// is scanned in workgroup memory and its total written to `sums`; the host scans `sums`
// the same way (recursively) and adds each block's scanned total back (cs_add_blocks).

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
var<workgroup> tmp: array<u32, BLOCK>;

fn block_of(wid: vec3<u32>) -> u32 {
    return wid.y * params.groups_x + wid.x;
}

@compute @workgroup_size(256)
fn cs_scan_blocks(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let b = block_of(wid);
    let i = b * BLOCK + lid.x;
    var v = 0u;
    if i < params.n {
        v = data[i];
    }
    tmp[lid.x] = v;
    workgroupBarrier();
    // Hillis-Steele inclusive scan over the block.
    for (var off = 1u; off < BLOCK; off *= 2u) {
        var t = 0u;
        if lid.x >= off {
            t = tmp[lid.x - off];
        }
        workgroupBarrier();
        tmp[lid.x] += t;
        workgroupBarrier();
    }
    if i < params.n {
        data[i] = tmp[lid.x] - v;
    }
    if lid.x == BLOCK - 1u {
        sums[b] = tmp[BLOCK - 1u];
    }
}

@compute @workgroup_size(256)
fn cs_add_blocks(@builtin(local_invocation_id) lid: vec3<u32>, @builtin(workgroup_id) wid: vec3<u32>) {
    let b = block_of(wid);
    let i = b * BLOCK + lid.x;
    if i < params.n {
        data[i] += sums[b];
    }
}
