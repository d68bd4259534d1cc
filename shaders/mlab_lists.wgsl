// Multi-layer alpha blending (Salvi & Vaidyanathan 2014). WebGPU has no pixel
// synchronization, so, as the adaptive transparency proof of concept does, fragments are
// captured in per-pixel lists and one full-screen pass per pixel replays them in submission
// order (common/submission.wgsl) through the MLAB update: a fragment is inserted into a
// depth-sorted array of LAYERS blended layers (premultiplied color, transmittance, depth);
// when the array overflows, its two farthest layers are merged with the over operator.
// The layers are then composited front to back. docs/methods.md ("mlab").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl
//!include common/submission.wgsl

var<private> layer_c: array<vec3<f32>, LAYERS_PLUS_ONE>;
var<private> layer_t: array<f32, LAYERS_PLUS_ONE>;
var<private> layer_z: array<f32, LAYERS_PLUS_ONE>;
var<private> count: u32;

fn visit(f: Frag) {
    // Insert behind every layer at the same or a smaller depth.
    var p = count;
    while p > 0u && layer_z[p - 1u] > f.depth {
        layer_c[p] = layer_c[p - 1u];
        layer_t[p] = layer_t[p - 1u];
        layer_z[p] = layer_z[p - 1u];
        p--;
    }
    layer_c[p] = f.color.rgb * f.color.a;
    layer_t[p] = 1.0 - f.color.a;
    layer_z[p] = f.depth;
    count++;
    if count > LAYERS {
        // Merge the farthest layer into the one in front of it (over operator).
        let k = LAYERS - 1u;
        layer_c[k] += layer_t[k] * layer_c[LAYERS];
        layer_t[k] *= layer_t[LAYERS];
        count = LAYERS;
    }
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    count = 0u;
    visit_in_submission_order(atomicLoad(&heads[pixel_index(pos)]));
    var accum = vec3<f32>(0.0);
    var t = 1.0;
    for (var i = 0u; i < count; i++) {
        accum += t * layer_c[i];
        t *= layer_t[i];
    }
    return vec4<f32>(accum + t * base.rgb, 1.0 - t * (1.0 - base.a));
}
