// The optical depth of a fragment and the depth warp, shared by the methods that blend
// functions of the optical depth over depth (mboit, wavelet; docs/methods.md).

fn optical_depth(a: f32) -> f32 {
    // Alpha 1 would be infinite: capped at -ln(MBOIT_MIN_TRANSMITTANCE).
    return -log(max(1.0 - a, MBOIT_MIN_TRANSMITTANCE));
}

// The depth warp to [-1, 1] (Münstermann et al. 2018, Sec. 3.2): under a perspective camera
// the logarithm of the view depth w between the near and far planes (where window depth 0 and 1
// are, found through the inverse projection: there w = 1 / h.w); under an orthographic one (w
// the same at both planes) the window depth, linear in the view depth already.
fn warp(clip: vec4<f32>, view_w: f32) -> f32 {
    // The w rows of the inverse projection times (0, 0, 0, 1) and (0, 0, 1, 1).
    let near = 1.0 / frame.inv_view_proj[3].w;
    let far = 1.0 / (frame.inv_view_proj[2].w + frame.inv_view_proj[3].w);
    if !(abs(far - near) > 1e-6 * abs(near)) || near <= 0.0 || view_w <= 0.0 {
        return 2.0 * clip.z - 1.0;
    }
    return clamp(2.0 * log(view_w / near) / log(far / near) - 1.0, -1.0, 1.0);
}
