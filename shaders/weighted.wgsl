// Blended one-pass methods: weighted sum (Meshkin 2007), weighted average (Bavoil & Myers
// 2008) and weighted blended OIT (McGuire & Bavoil 2013), as written in RTR 5.5.
// Geometry pass: additive blending into accum (rgb: sum of weighted C * alpha, a: sum of
// weighted alpha) and aux (wavg: fragment count; wboit: revealage, multiplied by 1 - alpha).
// Resolve: one full-screen pass per method. Alpha-0 fragments are skipped (they are invisible).
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

@group(2) @binding(0) var accum_tex: texture_2d<f32>;
@group(2) @binding(1) var aux_tex: texture_2d<f32>;

//!include common/accum_targets.wgsl

@fragment
fn fs_sum(raw: VsOut) -> Accum {
    let in = shaded(raw);
    if in.color.a <= 0.0 { discard; }
    let a = in.color.a;
    return Accum(vec4<f32>(in.color.rgb * a, a), vec4<f32>(1.0, 0.0, 0.0, 0.0));
}

// McGuire & Bavoil 2013, eqs. 7-10 (the weight includes alpha). WEIGHT selects the equation;
// eqs. 7-9 take the view distance |z| as clip w (perspective cameras), eq. 10 the window depth.
// The integer powers are products (pow is exp2(y log2 x) on most GPUs: slower, and less exact).
fn wboit_weight(z: f32, w: f32, a: f32) -> f32 {
    let d = abs(w);
    let far = d / 200.0;
    let far2 = far * far;
    switch WEIGHT {
        case 7u: {
            let near = d / 5.0;
            return a * clamp(10.0 / (1e-5 + near * near + far2 * far2 * far2), 1e-2, 3e3);
        }
        case 8u: {
            let near = d / 10.0;
            return a * clamp(10.0 / (1e-5 + near * near * near + far2 * far2 * far2), 1e-2, 3e3);
        }
        case 9u: { return a * clamp(0.03 / (1e-5 + far2 * far2), 1e-2, 3e3); }
        default: {
            let t = 1.0 - z;
            return a * max(1e-2, 3e3 * t * t * t);
        }
    }
}

@fragment
fn fs_wboit(raw: VsOut) -> Accum {
    let in = shaded(raw);
    if in.color.a <= 0.0 { discard; }
    let a = in.color.a;
    let w = wboit_weight(in.clip.z, in.view_w, a);
    return Accum(vec4<f32>(in.color.rgb * a, a) * w, vec4<f32>(a, 0.0, 0.0, 0.0));
}

fn load(pos: vec4<f32>) -> array<vec4<f32>, 2> {
    let p = vec2<i32>(pos.xy);
    return array<vec4<f32>, 2>(textureLoad(accum_tex, p, 0), textureLoad(aux_tex, p, 0));
}

@fragment
fn fs_resolve_wsum(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let s = load(pos)[0];
    // RTR 5.5: c = sum(alpha C) + c_d (1 - sum(alpha)); neither clamped, as in the paper.
    return vec4<f32>(s.rgb + base.rgb * (1.0 - s.a), 1.0 - (1.0 - s.a) * (1.0 - base.a));
}

@fragment
fn fs_resolve_wavg(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let t = load(pos);
    let n = t[1].r;
    if t[0].a <= 0.0 || n <= 0.0 {
        return base; // no visible fragment: the opaque scene or background, exactly
    }
    let c = t[0].rgb / t[0].a;
    let a_avg = min(t[0].a / n, 1.0);
    let u = select(pow(1.0 - a_avg, n), 0.0, a_avg >= 1.0);
    return vec4<f32>(c * (1.0 - u) + base.rgb * u, 1.0 - u * (1.0 - base.a));
}

@fragment
fn fs_resolve_wboit(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let t = load(pos);
    let revealage = t[1].r;
    if t[0].a <= 0.0 {
        return base;
    }
    let c = t[0].rgb / clamp(t[0].a, 1e-5, 5e4);
    return vec4<f32>(c * (1.0 - revealage) + base.rgb * revealage, 1.0 - revealage * (1.0 - base.a));
}
