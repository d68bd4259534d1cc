// Strands, particles and Gaussian splats facing the eye, once a frame before its geometry passes
// (common/primitives.wgsl), an entry point a kind: one invocation a segment or particle of the
// chunk, for each instance of its set, writes its corners into `expanded` (compiled with
// EXPANDING, which makes it writable). A segment writes its first point's corners and tangent,
// and its strand's last segment its second point's too, so each point is expanded once; the
// tangent only where the scene is shaded (the one reader, "hair" shading).
//!define EXPANDING 1
//!define PRIMITIVES 1
const EXPAND_GROUP: u32 = 256u;
//!include common/scene.wgsl

// The unit (segment or particle) of this invocation; OUTSIDE past the chunk's.
fn unit_of(gid: vec3<u32>) -> u32 {
    let unit = gid.y * (65535u * EXPAND_GROUP) + gid.x;
    return select(OUTSIDE, unit, chunk.triangles != 0u && unit < chunk.triangles / 2u);
}

@compute @workgroup_size(EXPAND_GROUP)
fn cs_expand_strands(@builtin(global_invocation_id) gid: vec3<u32>) {
    let unit = unit_of(gid);
    if unit == OUTSIDE {
        return;
    }
    let word = indices[unit];
    let i = word & POINT_MASK;
    for (var ii = chunk.set_instance; ii < chunk.set_instance + chunk.drawn / chunk.triangles; ii++) {
        let base = expanded_base(ii);
        let near = strand_point(word, false, ii);
        expanded[base + 2u * i] = vec4<f32>(near[0], 1.0);
        expanded[base + 2u * i + 1u] = vec4<f32>(near[1], 1.0);
//!if SHADED
        expanded[base + 2u * chunk.set_points + i] = vec4<f32>(near[2], 0.0);
//!endif
        if (word & LAST_SEGMENT) != 0u {
            let far = strand_point(word, true, ii);
            expanded[base + 2u * i + 2u] = vec4<f32>(far[0], 1.0);
            expanded[base + 2u * i + 3u] = vec4<f32>(far[1], 1.0);
//!if SHADED
            expanded[base + 2u * chunk.set_points + i + 1u] = vec4<f32>(far[2], 0.0);
//!endif
        }
    }
}

@compute @workgroup_size(EXPAND_GROUP)
fn cs_expand_particles(@builtin(global_invocation_id) gid: vec3<u32>) {
    let unit = unit_of(gid);
    if unit == OUTSIDE {
        return;
    }
    for (var ii = chunk.set_instance; ii < chunk.set_instance + chunk.drawn / chunk.triangles; ii++) {
        let base = expanded_base(ii);
        let c = particle_corners(unit, ii);
        for (var j = 0u; j < 4u; j++) {
            expanded[base + 4u * unit + j] = vec4<f32>(c[j], 1.0);
        }
    }
}

@compute @workgroup_size(EXPAND_GROUP)
fn cs_expand_gaussians(@builtin(global_invocation_id) gid: vec3<u32>) {
    let unit = unit_of(gid);
    if unit == OUTSIDE {
        return;
    }
    for (var ii = chunk.set_instance; ii < chunk.set_instance + chunk.drawn / chunk.triangles; ii++) {
        let base = expanded_base(ii);
        let c = gaussian_corners(unit, ii);
        // The splat's RGB rides in its first three corners' w (read by corner_of).
        let rgb = gaussian_color(unit, ii);
        let w = vec4<f32>(rgb, 1.0);
        for (var j = 0u; j < 4u; j++) {
            expanded[base + 4u * unit + j] = vec4<f32>(c[j], w[j]);
        }
    }
}
