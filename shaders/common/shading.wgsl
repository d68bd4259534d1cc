// The shading model of docs/shading.md, per fragment, shared by every method; the float64
// twin is oit_core::shading::shade. Every fragment entry starts with `let in = shaded(raw);`.
// Where no mesh is shaded (SHADED == 0) a fragment keeps its vertex color, bit for bit, and
// the pipeline is compiled without any of this: the constants SHADED, LIGHTS, TEXTURES and
// SHADING_COST (oit_core::shader::SceneVariant) choose the code.

// Materials mirror oit_core::gpu_types::GpuMaterial, two vec4 of `surfaces` each; the flag
// constants (SHADING_MODE, SHADING_FLAT, TWO_SIDED, TEXTURED ...) come from consts.rs.

//!if TEXTURES
// The texture atlas (oit_core::upload::Atlas): every image's levels in the layers of one 8-bit
// RGBA array. An image's record in `surfaces` is a header (levels, where its sRGB decoding
// table is (0: linear), width, height), then (x, y, layer, width | height << 16) a level.
@group(0) @binding(10) var atlas: texture_2d_array<f32>;

// A sampler's bits (oit_core::shading::Sampler::bits): wrap u in bits 0-1 and v in 2-3
// (0 repeat, 1 mirrored repeat, 2 clamp to edge), then these.
const SAMPLER_MAG_LINEAR: u32 = 16u;
const SAMPLER_MIN_LINEAR: u32 = 32u;
const SAMPLER_MIPS: u32 = 64u;
const SAMPLER_MIPS_LINEAR: u32 = 128u;

// Texel `i` of a row of `n` brought into [0, n), as Vulkan addresses (Wrap::texel), in float
// (texel indices are integers far below 2^24, so every step is exact): selects rather than
// branches, and no integer division, which llvmpipe runs lane by lane.
fn wrap_texel(i: f32, n: f32, mode: u32) -> f32 {
    let repeated = remainder(i, n);
    let m = remainder(i, 2.0 * n);
    let mirrored = select(2.0 * n - 1.0 - m, m, m < n);
    return select(select(mirrored, clamp(i, 0.0, n - 1.0), mode == 2u), repeated, mode == 0u);
}

// i mod n in [0, n) for integer-valued floats below 2^24: the quotient's rounding, off by one
// at most, put right.
fn remainder(i: f32, n: f32) -> f32 {
    let r = i - n * floor(i / n);
    return select(select(r, r - n, r >= n), r + n, r < 0.0);
}

// One texel at atlas position `at` of `layer`, linear: sRGB color decoded through the table at
// `srgb` in `surfaces` (256 values, four a vec4: exact, where an sRGB view's decoding is
// approximate on some adapters).
fn atlas_texel(at: vec2<i32>, layer: u32, srgb: u32) -> vec4<f32> {
    let t = textureLoad(atlas, at, layer, 0);
    if srgb == 0u {
        return t;
    }
    let code = vec3<u32>(round(t.rgb * 255.0));
    let r = surfaces[srgb + code.x / 4u][code.x % 4u];
    let g = surfaces[srgb + code.y / 4u][code.y % 4u];
    let b = surfaces[srgb + code.z / 4u][code.z % 4u];
    return vec4<f32>(r, g, b, t.a);
}

// Level `l` of the image at `image` at `uv`, texel centers at (i + 1/2) / w: bilinear, or
// nearest as the bilinear blend with weights (1, 0) at the texel under `uv` (the same bits,
// and one path for llvmpipe to run).
fn sample_level(image: u32, srgb: u32, l: u32, uv: vec2<f32>, linear: bool, wrap: u32) -> vec4<f32> {
    let level = bitcast<vec4<u32>>(surfaces[image + 1u + l]);
    let size = vec2<f32>(f32(level.w & 0xffffu), f32(level.w >> 16u));
    let p = uv * size;
    let q = select(floor(p), p - 0.5, linear);
    let f = floor(q);
    let t = select(vec2<f32>(0.0), q - f, linear);
    let origin = vec2<i32>(level.xy);
    let x0 = origin.x + i32(wrap_texel(f.x, size.x, wrap & 3u));
    let x1 = origin.x + i32(wrap_texel(f.x + 1.0, size.x, wrap & 3u));
    let y0 = origin.y + i32(wrap_texel(f.y, size.y, (wrap >> 2u) & 3u));
    let y1 = origin.y + i32(wrap_texel(f.y + 1.0, size.y, (wrap >> 2u) & 3u));
    let top = atlas_texel(vec2<i32>(x0, y0), level.z, srgb) * (1.0 - t.x) + atlas_texel(vec2<i32>(x1, y0), level.z, srgb) * t.x;
    let bottom = atlas_texel(vec2<i32>(x0, y1), level.z, srgb) * (1.0 - t.x) + atlas_texel(vec2<i32>(x1, y1), level.z, srgb) * t.x;
    return top * (1.0 - t.y) + bottom * t.y;
}

// The UVs' derivatives along the frame's x and y in pixels at the fragment, (d/dx, d/dy),
// from its triangle's UV planes (common/scene.wgsl `uv_planes`).
fn uv_footprint(in: VsOut) -> vec4<f32> {
    let at = frame_xy(in.clip.xy);
    let ndc = vec2<f32>(at.x * 2.0 / f32(frame.size.x) - 1.0, 1.0 - at.y * 2.0 / f32(frame.size.y));
    let pu = in.uv_plane_u;
    let pv = in.uv_plane_v;
    let pd = in.uv_plane_w;
    let nu = pu.x - ndc.x * pu.y - ndc.y * pu.z;
    let nv = pv.x - ndc.x * pv.y - ndc.y * pv.z;
    let d = pd.x - ndc.x * pd.y - ndc.y * pd.z;
    let dd = d * d;
    let dx = vec2<f32>(-pu.y * d + nu * pd.y, -pv.y * d + nv * pd.y) / dd;
    let dy = vec2<f32>(-pu.z * d + nu * pd.z, -pv.z * d + nv * pd.z) / dd;
    return vec4<f32>(dx * (2.0 / f32(frame.size.x)), dy * (-2.0 / f32(frame.size.y)));
}

// A material's texture map `k` (0 base color, 1 emissive) at `uv` for a fragment whose UVs
// change by `footprint` to its neighbours: the level and filters as oit_core::shading::
// TextureMap::sample chooses them (the float64 twin).
fn sample_map(material: u32, k: u32, uv_in: vec2<f32>, footprint: vec4<f32>) -> vec4<f32> {
    let m0 = surfaces[MATERIAL_VEC4S * material + 2u + 2u * k];
    let m1 = surfaces[MATERIAL_VEC4S * material + 3u + 2u * k];
    let image = bitcast<u32>(m0.x);
    let bits = bitcast<u32>(m0.y);
    let uv = vec2<f32>(m0.z * uv_in.x + m0.w * uv_in.y + m1.x, m1.y * uv_in.x + m1.z * uv_in.y + m1.w);
    let header = bitcast<vec4<u32>>(surfaces[image]);
    let srgb = header.y;
    let size = vec2<f32>(f32(header.z), f32(header.w));
    let dx = vec2<f32>(m0.z * footprint.x + m0.w * footprint.y, m1.y * footprint.x + m1.z * footprint.y) * size;
    let dy = vec2<f32>(m0.z * footprint.z + m0.w * footprint.w, m1.y * footprint.z + m1.z * footprint.w) * size;
    let lod = log2(max(length(dx), length(dy)));
    let wrap = bits & 15u;
    // The level and the blend between levels without branches: λ <= 0 (and NaN) magnifies
    // from level 0; without mips level 0; nearest mips round λ (ties down); linear mips blend
    // floor(λ) and the next level, the last one holding.
    let magnify = !(lod > 0.0);
    let mips = (bits & SAMPLER_MIPS) != 0u && !magnify;
    let mips_linear = mips && (bits & SAMPLER_MIPS_LINEAR) != 0u;
    let top = f32(header.x - 1u);
    let lambda = select(0.0, lod, mips);
    let base = min(floor(lambda), top);
    let level = select(clamp(ceil(lambda + 0.5) - 1.0, 0.0, top), base, mips_linear);
    let t = select(0.0, select(lambda - base, 0.0, base == top), mips_linear);
    let linear = select((bits & SAMPLER_MIN_LINEAR) != 0u, (bits & SAMPLER_MAG_LINEAR) != 0u, magnify);
    let a = sample_level(image, srgb, u32(level), uv, linear, wrap);
    if t == 0.0 {
        return a;
    }
    return a * (1.0 - t) + sample_level(image, srgb, u32(level) + 1u, uv, linear, wrap) * t;
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
// The vertex color times the texture, alpha times opacity and tested against the cutoff: all
// that alpha depends on.
fn surface_base(in: VsOut, m0: vec4<f32>) -> vec4<f32> {
    var base = in.color;
    let flags = bitcast<u32>(m0.w);
//!if TEXTURES
    if (flags & TEXTURED) != 0u {
        base = base * sample_map(in.material, 0u, in.uv, uv_footprint(in));
    }
//!endif
    base.a = base.a * m0.z;
//!if FALLOFF
    let falloff_mode = (flags & FALLOFF_MASK) >> FALLOFF_SHIFT;
    base.a = base.a * falloff(falloff_mode, in.uv);
    if falloff_mode == FALLOFF_SPLAT {
        // 3DGS's clamp (oit_core::splat::clamp_alpha).
        base.a = select(min(base.a, SPLAT_ALPHA_MAX), 0.0, base.a < SPLAT_ALPHA_MIN);
    }
//!endif
//!if ALPHA_TESTS
    if (flags & ALPHA_TEST) != 0u {
        base.a = select(0.0, 1.0, base.a >= surfaces[MATERIAL_VEC4S * in.material + 1u].w);
    }
//!endif
    return base;
}

//!if EMISSIVE
// The light the surface gives off: its emissive color times its emissive texture.
fn surface_emission(in: VsOut, flags: u32) -> vec3<f32> {
    var e = surfaces[MATERIAL_VEC4S * in.material + 1u].rgb;
//!if TEXTURES
    if (flags & EMISSIVE_TEXTURED) != 0u {
        e = e * sample_map(in.material, 1u, in.uv, uv_footprint(in)).rgb;
    }
//!endif
    return e;
}
//!endif

fn shade(in: VsOut) -> vec4<f32> {
    let m0 = surfaces[MATERIAL_VEC4S * in.material];
    let flags = bitcast<u32>(m0.w);
    let base = surface_base(in, m0);
//!if EMISSIVE
    let emission = surface_emission(in, flags);
//!endif
    let v = to_eye(in.clip.xy);
    var extra = 0.0;
    if SHADING_COST != 0u {
        extra = shading_cost(normalize(in.normal), v, SHADING_COST) * frame.ambient.w;
    }
    if (flags & SHADING_MODE) == SHADING_UNLIT {
//!if EMISSIVE
        return vec4<f32>(clamp(base.rgb + emission, vec3<f32>(0.0), vec3<f32>(1.0)) + extra, base.a);
//!else
        return vec4<f32>(base.rgb + extra, base.a);
//!endif
    }
//!if PRIMITIVES
    if (flags & SHADING_MODE) == SHADING_HAIR {
//!if EMISSIVE
        return vec4<f32>(clamp(hair(base.rgb, normalize(in.normal), v, m0) + emission, vec3<f32>(0.0), vec3<f32>(1.0)) + extra, base.a);
//!else
        return vec4<f32>(hair(base.rgb, normalize(in.normal), v, m0) + extra, base.a);
//!endif
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
//!if EMISSIVE
    let rgb = clamp(base.rgb * diffuse + m0.x * highlight + emission, vec3<f32>(0.0), vec3<f32>(1.0));
//!else
    let rgb = clamp(base.rgb * diffuse + m0.x * highlight, vec3<f32>(0.0), vec3<f32>(1.0));
//!endif
    return vec4<f32>(rgb + extra, base.a);
//!else
    // No surface of the scene shades flat or smooth (PHONG = 0): never reached.
    return vec4<f32>(base.rgb + extra, base.a);
//!endif
}

// The fragment with its shaded alpha (the same bits as shade()'s) and its vertex RGB: for
// passes that read only alpha (hybrid's k-TAB store, stochastic's depth pass), no lights.
fn shaded_alpha(raw: VsOut) -> VsOut {
    var out = splat_depth(raw);
    out.color.a = surface_base(raw, surfaces[MATERIAL_VEC4S * raw.material]).a;
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
    return splat_depth(raw);
}
//!endif

// The fragment with its shaded color: the rest of a fragment entry reads `in.color` as before.
fn shaded(placed: VsOut) -> VsOut {
    let raw = splat_depth(placed);
    if SHADED == 0u && SHADING_COST == 0u {
        return raw;
    }
    var out = raw;
    out.color = shade(raw);
    return out;
}

//!if SPLAT_RAY
// A ray-depth splat's fragment at the depth of the Gaussian's peak along its pixel's ray
// o + t d (o on the near plane, d to the far plane): t* = dᵀP(μ - o) / dᵀPd, P the
// covariance's adjugate, the point's NDC depth clamped to [0, 1] (0 where it is not in front
// of the eye) and its clip w as view_w (oit_core::splat::ray_depth). Every other fragment as
// it is. The opaque depth test of the rasterizer has seen the quad's depth, the mean's.
fn splat_depth(raw: VsOut) -> VsOut {
    if raw.splat_mean.w == 0.0 {
        return raw;
    }
    let at = frame_xy(raw.clip.xy);
    let ndc = vec2<f32>(at.x * 2.0 / f32(frame.size.x) - 1.0, 1.0 - at.y * 2.0 / f32(frame.size.y));
    let near = frame.inv_view_proj * vec4<f32>(ndc, 0.0, 1.0);
    let far = frame.inv_view_proj * vec4<f32>(ndc, 1.0, 1.0);
    let o = near.xyz / near.w;
    let d = far.xyz / far.w - o;
    let a = raw.splat_adj0;
    let b = raw.splat_adj1;
    let p = mat3x3<f32>(a, vec3<f32>(a.y, b.x, b.y), vec3<f32>(a.z, b.y, b.z));
    let t = dot(d, p * (raw.splat_mean.xyz - o)) / dot(d, p * d);
    let c = frame.view_proj * vec4<f32>(o + d * t, 1.0);
    var out = raw;
    out.clip.z = select(0.0, clamp(c.z / c.w, 0.0, 1.0), c.w > 0.0);
    out.view_w = select(raw.view_w, c.w, c.w > 0.0);
    return out;
}
//!else
fn splat_depth(raw: VsOut) -> VsOut {
    return raw;
}
//!endif
