// The shading model of docs/shading.md, per fragment, shared by every method; the float64
// twin is oit_core::shading::shade. Every fragment entry starts with `let in = shaded(raw);`.
// Where no mesh is shaded (SHADED == 0) a fragment keeps its vertex color, bit for bit, and
// the pipeline is compiled without any of this: the constants SHADED, LIGHTS, TEXTURES and
// SHADING_COST (oit_core::shader::SceneVariant) choose the code.

// Materials mirror oit_core::gpu_types::GpuMaterial, two vec4 of `surfaces` each; the flag
// constants (SHADING_MODE, SHADING_FLAT, TWO_SIDED, TEXTURED ...) come from consts.rs.

//!if TEXTURES
// One texel, repeat wrap; `first` is the texture's first texel in `surfaces`.
fn texel(first: u32, size: vec2<i32>, x: i32, y: i32) -> vec4<f32> {
    let w = ((x % size.x) + size.x) % size.x;
    let h = ((y % size.y) + size.y) % size.y;
    return surfaces[first + u32(h * size.x + w)];
}

// Bilinear, repeat wrap, texel centers at (i + 1/2) / w; row 0 is v = 0.
fn texture_sample(first: u32, size: vec2<i32>, uv: vec2<f32>) -> vec4<f32> {
    let p = uv * vec2<f32>(size) - 0.5;
    let f = floor(p);
    let t = p - f;
    let x = i32(f.x);
    let y = i32(f.y);
    let top = texel(first, size, x, y) * (1.0 - t.x) + texel(first, size, x + 1, y) * t.x;
    let bottom = texel(first, size, x, y + 1) * (1.0 - t.x) + texel(first, size, x + 1, y + 1) * t.x;
    return top * (1.0 - t.y) + bottom * t.y;
}

//!endif

// Unit vector from a target position (pixels) towards the eye: the pixel's ray, reversed.
fn to_eye(tile_at: vec2<f32>) -> vec3<f32> {
    let at = frame_xy(tile_at);
    let ndc = vec2<f32>(at.x * 2.0 / f32(frame.size.x) - 1.0, 1.0 - at.y * 2.0 / f32(frame.size.y));
    let near = frame.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    return normalize(near.xyz / near.w - far.xyz / far.w);
}

// The shading-cost knob: `count` Blinn-Phong light evaluations whose sum the caller multiplies
// by frame.ambient.w (0, which the compiler cannot know), so that the color is unchanged.
fn shading_cost(n: vec3<f32>, v: vec3<f32>, count: u32) -> f32 {
    var sum = 0.0;
    for (var i = 0u; i < count; i++) {
        let l = normalize(frame.lights[i % MAX_LIGHTS].to_light.xyz + v * f32(i + 1u));
        sum += pow(max(dot(n, l), 0.0), 8.0 + f32(i % 7u));
    }
    return sum;
}

//!if SHADED
// The vertex color times the texture, alpha times opacity: all that alpha depends on.
fn surface_base(in: VsOut, m0: vec4<f32>) -> vec4<f32> {
    var base = in.color;
//!if TEXTURES
    if (bitcast<u32>(m0.w) & TEXTURED) != 0u {
        let m1 = bitcast<vec4<u32>>(surfaces[2u * in.material + 1u]);
        base = base * texture_sample(m1.x, vec2<i32>(m1.yz), in.uv);
    }
//!endif
    base.a = base.a * m0.z;
//!if FALLOFF
    base.a = base.a * falloff((bitcast<u32>(m0.w) & FALLOFF_MASK) >> FALLOFF_SHIFT, in.uv);
//!endif
    return base;
}

fn shade(in: VsOut) -> vec4<f32> {
    let m0 = surfaces[2u * in.material];
    let flags = bitcast<u32>(m0.w);
    let base = surface_base(in, m0);
    let v = to_eye(in.clip.xy);
    var extra = 0.0;
    if SHADING_COST != 0u {
        extra = shading_cost(normalize(in.normal), v, SHADING_COST) * frame.ambient.w;
    }
    if (flags & SHADING_MODE) == SHADING_UNLIT {
        return vec4<f32>(base.rgb + extra, base.a);
    }
//!if PRIMITIVES
    if (flags & SHADING_MODE) == SHADING_HAIR {
        return vec4<f32>(hair(base.rgb, normalize(in.normal), v, m0) + extra, base.a);
    }
//!endif
//!if PHONG
    var n = normalize(in.normal);
    if (flags & TWO_SIDED) != 0u && dot(n, v) < 0.0 {
        n = -n;
    }
    var diffuse = frame.ambient.rgb;
    var highlight = vec3<f32>(0.0);
    for (var i = 0u; i < LIGHTS; i++) {
        let l = frame.lights[i].to_light.xyz;
        let radiance = frame.lights[i].radiance.rgb;
        diffuse += radiance * max(dot(n, l), 0.0);
        let hv = l + v;
        let h = hv * inverseSqrt(max(dot(hv, hv), 1e-30));
        highlight += radiance * pow(max(dot(n, h), 0.0), m0.y);
    }
    let rgb = clamp(base.rgb * diffuse + m0.x * highlight, vec3<f32>(0.0), vec3<f32>(1.0));
    return vec4<f32>(rgb + extra, base.a);
//!else
    // No surface of the scene shades flat or smooth (PHONG = 0): never reached.
    return vec4<f32>(base.rgb + extra, base.a);
//!endif
}

// The fragment with its shaded alpha (the same bits as shade()'s) and its vertex RGB: for
// passes that read only alpha (hybrid's k-TAB store, stochastic's depth pass), no lights.
fn shaded_alpha(raw: VsOut) -> VsOut {
    var out = raw;
    out.color.a = surface_base(raw, surfaces[2u * raw.material]).a;
    return out;
}
//!else
fn shade(in: VsOut) -> vec4<f32> {
    if SHADING_COST == 0u {
        return in.color;
    }
    let extra = shading_cost(normalize(in.color.rgb + 0.5), to_eye(in.clip.xy), SHADING_COST) * frame.ambient.w;
    return vec4<f32>(in.color.rgb + extra, in.color.a);
}

// Unlit: alpha is the vertex alpha.
fn shaded_alpha(raw: VsOut) -> VsOut {
    return raw;
}
//!endif

// The fragment with its shaded color: the rest of a fragment entry reads `in.color` as before.
fn shaded(raw: VsOut) -> VsOut {
    if SHADED == 0u && SHADING_COST == 0u {
        return raw;
    }
    var out = raw;
    out.color = shade(raw);
    return out;
}
