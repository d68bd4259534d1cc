// Bucket depth peeling (Liu et al. 2009; RTR 5.5's "up to 32 layers in one pass"): the
// pixel's transparent depth range [z_min, z_max] (pass 1, atomic min/max) is split into
// BUCKETS equal buckets; each bucket keeps its nearest fragment by a 64-bit atomicMin of
// (depth, triangle) (pass 2); that fragment writes its color into the bucket (pass 3) and
// every other fragment of the bucket is dropped and counted; the resolve composites the
// buckets front to back. Exact while no two fragments share a bucket. docs/methods.md.
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Per pixel: nearest depth (inverted bits, so a cleared word is empty) and farthest depth.
@group(2) @binding(0) var<storage, read_write> bounds: array<atomic<u32>>;
// Per pixel and bucket: the nearest fragment's inverted (depth, triangle) key; 0 is empty.
@group(2) @binding(1) var<storage, read_write> keys: array<atomic<u64>>;
@group(2) @binding(2) var<storage, read_write> bucket_colors: array<vec4<f32>>;
@group(2) @binding(3) var<storage, read_write> dropped: atomic<u32>;

// Inverted so that a zero-cleared bucket is empty and atomicMax keeps the nearest.
fn frag_key(z: f32, prim: u32) -> u64 {
    return ~((u64(bitcast<u32>(z)) << 32u) | u64(prim));
}

fn bucket(px: u32, z: f32) -> u32 {
    let lo = bitcast<f32>(~atomicLoad(&bounds[2u * px]));
    let hi = bitcast<f32>(atomicLoad(&bounds[2u * px + 1u]));
    if hi <= lo {
        return 0u;
    }
    return min(u32((z - lo) / (hi - lo) * f32(BUCKETS)), BUCKETS - 1u);
}

@fragment @early_depth_test(force)
fn fs_bounds(raw: VsOut) {
    let in = splat_depth(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let px = pixel_index(in.clip);
    let bits = bitcast<u32>(in.clip.z);
    atomicMax(&bounds[2u * px], ~bits);
    atomicMax(&bounds[2u * px + 1u], bits);
}

@fragment @early_depth_test(force)
fn fs_keys(raw: VsOut) {
    let in = splat_depth(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let px = pixel_index(in.clip);
    atomicMax(&keys[px * BUCKETS + bucket(px, in.clip.z)], frag_key(in.clip.z, in.prim));
}

@fragment @early_depth_test(force)
fn fs_shade(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) {
        return;
    }
    let px = pixel_index(in.clip);
    let slot = px * BUCKETS + bucket(px, in.clip.z);
    if atomicLoad(&keys[slot]) == frag_key(in.clip.z, in.prim) {
        bucket_colors[slot] = in.color;
    } else {
        atomicAdd(&dropped, 1u);
    }
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let px = pixel_index(pos);
    var accum = vec3<f32>(0.0);
    var t = 1.0;
    for (var b = 0u; b < BUCKETS; b++) {
        let slot = px * BUCKETS + b;
        if atomicLoad(&keys[slot]) != 0lu {
            let c = bucket_colors[slot];
            accum += t * c.a * c.rgb;
            t *= 1.0 - c.a;
        }
    }
    return vec4<f32>(accum + t * base.rgb, 1.0 - t * (1.0 - base.a));
}
