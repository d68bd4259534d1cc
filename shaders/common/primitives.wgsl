// Strands, particles and Gaussian splats (oit_core::primitive, whose float64 `expand` this
// mirrors): a chunk of kind PRIM_STRANDS or PRIM_PARTICLES holds one set's points as four floats
// each (x, y, z and half the width, or the radius) and their colors, a PRIM_GAUSSIANS chunk
// twelve a splat and 3 k more (its mean, its count k of spherical-harmonic coefficients, its
// covariance's upper triangle, 0, 0, then the k RGB coefficients); a strand chunk has a word a segment in
// `indices` (its first point, FIRST_SEGMENT, LAST_SEGMENT). Once a frame, before any geometry
// pass, shaders/expand.wgsl builds the corners facing the eye into `expanded` (each point's two
// ribbon corners and its tangent, or each particle's four quad corners, for each instance of
// the set); every pass that pulls corners (the vertex shader, triangle setup, the compact
// A-buffer's records) reads them there, six corners a segment or particle in the order of
// primitive::CORNERS, so all of them see the same triangles.

//!if EXPANDING
@group(0) @binding(9) var<storage, read_write> expanded: array<vec4<f32>>;
//!else
@group(0) @binding(9) var<storage, read> expanded: array<vec4<f32>>;
//!endif

struct Corner {
    world: vec3<f32>,
    color: vec4<f32>,
    // A strand's unit tangent (what 'hair' shading reads as the normal); zero for particles.
    tangent: vec3<f32>,
    // A particle's disc coordinates, the rim at |uv| = 1; zero for strands.
    uv: vec2<f32>,
}

// From `p` towards the homogeneous eye E = inv_view_proj (0, 0, 1, 0): the camera's center, or
// for an orthographic camera its view direction at infinity (not normalized).
fn towards_eye(p: vec3<f32>) -> vec3<f32> {
    let e = frame.inv_view_proj[2];
    return e.xyz - p * e.w;
}

fn point_at(i: u32, ii: u32) -> vec3<f32> {
    return placed_at(vec3<f32>(positions[4u * i], positions[4u * i + 1u], positions[4u * i + 2u]), ii).xyz;
}

// `v` / |v|, or zero where |v|² <= 1e-30 (primitive.rs: normalize_or_zero and its cut).
fn unit_or_zero(v: vec3<f32>) -> vec3<f32> {
    let l2 = dot(v, v);
    return select(vec3<f32>(0.0), v * inverseSqrt(l2), l2 > 1e-30);
}

// Where instance `ii`'s corners of the chunk's set begin in `expanded`: strands keep two
// corners a point, then a tangent a point; particles and splats four corners each.
fn expanded_base(ii: u32) -> u32 {
    let per = select(4u, 3u, chunk.kind == PRIM_STRANDS);
    return (ii - chunk.set_instance) * per * chunk.set_points;
}

// Corner `vi` of the chunk (corner vi % 3 of local triangle vi / 3) under instance `ii`.
// Written without a branch on the chunk's kind, so that a strand corner does not also pay a
// particle's loads where both sides of a branch run (llvmpipe runs a vertex shader's lanes
// masked): one load of the position and one of the color, their indices chosen by the kind.
fn corner_of(vi: u32, ii: u32) -> Corner {
    let unit = vi / 6u;
    let c = vi % 6u;
    let far = u32(c == 2u || c == 3u || c == 5u);
    let side = u32(c == 1u || c == 4u || c == 5u);
    let base = expanded_base(ii);
    let strands = chunk.kind == PRIM_STRANDS;
    // A strand's corner: its point i's side; a particle's: its quad corner.
    let i = select(unit, (indices[unit] & POINT_MASK) + far, strands);
    let at = select(base + 4u * unit + 2u * far + side, base + 2u * i + side, strands);
    var k: Corner;
    k.world = expanded[at].xyz;
    k.color = placed_color(i, ii);
    if chunk.kind == PRIM_GAUSSIANS {
        // The splat's RGB, evaluated by the expansion into its first three corners' w.
        let first = base + 4u * unit;
        k.color = vec4<f32>(expanded[first].w, expanded[first + 1u].w, expanded[first + 2u].w, k.color.a);
    }
//!if SHADED
    if strands {
        k.tangent = expanded[base + 2u * chunk.set_points + i].xyz;
    } else {
        k.uv = vec2<f32>(f32(side) * 2.0 - 1.0, f32(far) * 2.0 - 1.0);
    }
//!endif
    return k;
}

// A ribbon corner at point `i` of segment word `word` (`far`: its second point): the point
// moved by half its width across the strand and across the view, and the strand's unit
// tangent there. The tangent at a point is the chord from the point before it to the point
// after it (one-sided at a strand's ends), so that the two segments meeting at a joint would
// compute its corners from the same numbers: each point is expanded once, by the segment that
// starts at it (and a strand's last point by its last segment).
fn strand_point(word: u32, far: bool, ii: u32) -> array<vec3<f32>, 3> {
    let i = (word & POINT_MASK) + u32(far);
    let prev = select(i - 1u, i, !far && (word & FIRST_SEGMENT) != 0u);
    let next = select(i + 1u, i, far && (word & LAST_SEGMENT) != 0u);
    let p = point_at(i, ii);
    let t = point_at(next, ii) - point_at(prev, ii);
    let across = unit_or_zero(cross(t, towards_eye(p))) * positions[4u * i + 3u];
    return array<vec3<f32>, 3>(p - across, p + across, unit_or_zero(t));
}

// A particle's quad corner (u, v in {-1, 1}): its center moved by the radius along the axes of
// the plane that faces the eye (right from the camera's up, the world direction of clip y).
fn particle_corners(q: u32, ii: u32) -> array<vec3<f32>, 4> {
    let c = point_at(q, ii);
    let d = unit_or_zero(towards_eye(c));
    let hint = vec3<f32>(frame.view_proj[0].y, frame.view_proj[1].y, frame.view_proj[2].y);
    var right = cross(hint, d);
    if dot(right, right) <= 1e-30 {
        right = cross(vec3<f32>(1.0, 0.0, 0.0), d);
    }
    right = unit_or_zero(right) * positions[4u * q + 3u];
    let up = unit_or_zero(cross(d, right)) * positions[4u * q + 3u];
    return array<vec3<f32>, 4>(c - right - up, c + right - up, c - right + up, c + right + up);
}

// A splat's quad corners (u, v in {-1, 1}, in the order of particle_corners): oit_core::splat's
// `footprint` and `corner`. The world covariance A Σ Aᵀ (A the instance's linear part) carried
// to pixels by J, the Jacobian of world to pixels at the mean, plus the low-pass; the quad
// reaches SPLAT_SIGMAS standard deviations along the ellipse's axes, at the mean's clip depth
// and w (so the disc coordinates interpolate affinely on screen), back in world space. A mean
// behind the eye gives four equal corners, no fragments.
fn gaussian_corners(q: u32, ii: u32) -> array<vec3<f32>, 4> {
    let mean = gaussian_mean(q, ii);
    let cov = gaussian_covariance(q, ii);
    let vp = frame.view_proj;
    let c = vp * vec4<f32>(mean, 1.0);
    if !(c.w > 1e-30) {
        return array<vec3<f32>, 4>(mean, mean, mean, mean);
    }
    let size = vec2<f32>(frame.size);
    let r3 = vec3<f32>(vp[0].w, vp[1].w, vp[2].w);
    let jx = (vec3<f32>(vp[0].x, vp[1].x, vp[2].x) * c.w - r3 * c.x) * (0.5 * size.x / (c.w * c.w));
    let jy = (vec3<f32>(vp[0].y, vp[1].y, vp[2].y) * c.w - r3 * c.y) * (0.5 * size.y / (c.w * c.w));
    let xx = dot(jx, cov * jx) + SPLAT_LOW_PASS;
    let xy = dot(jx, cov * jy);
    let yy = dot(jy, cov * jy) + SPLAT_LOW_PASS;
    let theta = 0.5 * atan2(2.0 * xy, xx - yy);
    let co = cos(theta);
    let si = sin(theta);
    let l1 = xx * co * co + 2.0 * xy * si * co + yy * si * si;
    let l2 = xx * si * si - 2.0 * xy * si * co + yy * co * co;
    // The half axes in NDC units times w: a pixel is 2 / size of NDC.
    let scale = 2.0 * c.w / size;
    let e1 = vec2<f32>(co, si) * (SPLAT_SIGMAS * sqrt(max(l1, 0.0))) * scale;
    let e2 = vec2<f32>(-si, co) * (SPLAT_SIGMAS * sqrt(max(l2, 0.0))) * scale;
    var out: array<vec3<f32>, 4>;
    for (var j = 0u; j < 4u; j++) {
        let uv = vec2<f32>(f32(j & 1u) * 2.0 - 1.0, f32(j >> 1u) * 2.0 - 1.0);
        let h = frame.inv_view_proj * (c + vec4<f32>(e1 * uv.x + e2 * uv.y, 0.0, 0.0));
        out[j] = h.xyz / h.w;
    }
    return out;
}

// Splat `q`'s mean placed by instance `ii`, and its world covariance A Σ Aᵀ (A the instance's
// linear part).
fn gaussian_mean(q: u32, ii: u32) -> vec3<f32> {
    let b = splat_stride() * q;
    return placed_at(vec3<f32>(positions[b], positions[b + 1u], positions[b + 2u]), ii).xyz;
}

fn gaussian_covariance(q: u32, ii: u32) -> mat3x3<f32> {
    let b = splat_stride() * q;
    let local = mat3x3<f32>(
        vec3<f32>(positions[b + 4u], positions[b + 5u], positions[b + 6u]),
        vec3<f32>(positions[b + 5u], positions[b + 7u], positions[b + 8u]),
        vec3<f32>(positions[b + 6u], positions[b + 8u], positions[b + 9u]),
    );
    let a = placed_linear(ii);
    return a * local * transpose(a);
}

// Floats a splat in `positions`: 12, and 3 a harmonic coefficient (the chunk's set has one
// degree; its first splat says how many).
fn splat_stride() -> u32 {
    return 12u + 3u * u32(positions[3]);
}

// A splat's RGB under instance `ii`: its color, or its spherical harmonics evaluated in the
// direction from the eye to its mean (oit_core::splat::sh_color and view_direction: 3DGS's
// basis, 0.5 + Σ Y_lm(d) c_lm clamped to [0, 1]), times the instance's color.
fn gaussian_color(q: u32, ii: u32) -> vec3<f32> {
    let k = u32(positions[3]);
    if k == 0u {
        return placed_color(q, ii).rgb;
    }
    let b = splat_stride() * q;
    let mean = placed_at(vec3<f32>(positions[b], positions[b + 1u], positions[b + 2u]), ii).xyz;
    let e = frame.inv_view_proj[2];
    var d = normalize(e.xyz);
    if abs(e.w) > 1e-30 {
        d = normalize(mean - e.xyz / e.w);
    }
    var c: array<vec3<f32>, 16>;
    for (var j = 0u; j < k; j++) {
        let at = b + 12u + 3u * j;
        c[j] = vec3<f32>(positions[at], positions[at + 1u], positions[at + 2u]);
    }
    let x = d.x;
    let y = d.y;
    let z = d.z;
    var r = SH_C0 * c[0];
    if k > 1u {
        r += -SH_C1 * y * c[1] + SH_C1 * z * c[2] - SH_C1 * x * c[3];
    }
    if k > 4u {
        let xx = x * x;
        let yy = y * y;
        let zz = z * z;
        r += SH_C2_0 * x * y * c[4] + SH_C2_1 * y * z * c[5] + SH_C2_2 * (2.0 * zz - xx - yy) * c[6]
            + SH_C2_3 * x * z * c[7] + SH_C2_4 * (xx - yy) * c[8];
        if k > 9u {
            r += SH_C3_0 * y * (3.0 * xx - yy) * c[9] + SH_C3_1 * x * y * z * c[10]
                + SH_C3_2 * y * (4.0 * zz - xx - yy) * c[11] + SH_C3_3 * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * c[12]
                + SH_C3_4 * x * (4.0 * zz - xx - yy) * c[13] + SH_C3_5 * z * (xx - yy) * c[14]
                + SH_C3_6 * x * (xx - 3.0 * yy) * c[15];
        }
    }
    return clamp(r + vec3<f32>(0.5), vec3<f32>(0.0), vec3<f32>(1.0)) * placed_tint(ii).rgb;
}

// The vertex shader's output for corner `vi` of a strand or particle chunk.
fn expanded_vertex(vi: u32, ii: u32) -> VsOut {
    let k = corner_of(vi, ii);
    var out: VsOut;
    out.clip = frame.view_proj * vec4<f32>(k.world, 1.0);
    out.color = k.color;
    out.prim = drawn_prim(vi / 3u, ii);
    out.view_w = out.clip.w;
//!if SHADED
    out.normal = k.tangent;
    out.uv = k.uv;
    out.material = chunk.set_surface;
//!endif
//!if SPLAT_RAY
    let ray = (bitcast<u32>(surfaces[MATERIAL_VEC4S * chunk.set_surface].w) & RAY_DEPTH) != 0u;
    if chunk.kind == PRIM_GAUSSIANS && ray {
        // Its peak along each pixel's ray needs the mean and the covariance's adjugate (the
        // inverse times the determinant, which cancels in t*: a thin splat's tiny
        // determinant is never divided by).
        let c = gaussian_covariance(vi / 6u, ii);
        out.splat_mean = vec4<f32>(gaussian_mean(vi / 6u, ii), 1.0);
        out.splat_adj0 = vec3<f32>(
            c[1].y * c[2].z - c[2].y * c[2].y,
            c[2].x * c[2].y - c[1].x * c[2].z,
            c[1].x * c[2].y - c[2].x * c[1].y,
        );
        out.splat_adj1 = vec3<f32>(c[0].x * c[2].z - c[2].x * c[2].x, c[1].x * c[2].x - c[0].x * c[2].y, c[0].x * c[1].y - c[1].x * c[1].x);
    }
//!endif
    return out;
}

// A particle's alpha factor at disc coordinates `uv` (shading::Falloff::factor): 1 inside a
// hard disc, 1 - r linear, exp(-4.5 r²) Gaussian or splat, 0 past the rim; 1 where there is no
// falloff.
fn falloff(mode: u32, uv: vec2<f32>) -> f32 {
    if mode == 0u {
        return 1.0;
    }
    let r2 = dot(uv, uv);
    var f = 1.0;
    if mode == FALLOFF_LINEAR {
        f = 1.0 - sqrt(r2);
    } else if mode == FALLOFF_GAUSSIAN || mode == FALLOFF_SPLAT {
        f = exp(-4.5 * r2);
    }
    return select(0.0, f, r2 <= 1.0);
}

// Kajiya and Kay's strand model with unit tangent `t` (shading::hair): diffuse sin(T, L), a
// highlight sin(T, H)^shininess = (1 - (T·H)²)^(shininess / 2), H the half vector of L and the
// eye direction `v`.
fn hair(base: vec3<f32>, t: vec3<f32>, v: vec3<f32>, m0: vec4<f32>) -> vec3<f32> {
    var diffuse = frame.ambient.rgb;
    var highlight = vec3<f32>(0.0);
    for (var i = 0u; i < LIGHTS; i++) {
        let l = frame.lights[i].to_light.xyz;
        let radiance = frame.lights[i].radiance.rgb;
        let tl = dot(t, l);
        diffuse += radiance * sqrt(max(1.0 - tl * tl, 0.0));
        let hv = l + v;
        let th = dot(t, hv * inverseSqrt(max(dot(hv, hv), 1e-30)));
        highlight += radiance * pow(max(1.0 - th * th, 0.0), 0.5 * m0.y);
    }
    return clamp(base * diffuse + m0.x * highlight, vec3<f32>(0.0), vec3<f32>(1.0));
}
