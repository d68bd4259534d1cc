// The sorted resolve's compositing (common/sweep.wgsl): front to back per sample of the pixel,
// kept in the pixel's state between dispatches, and the full-screen pass that adds the opaque
// scene or background.

// Front-to-back compositing per sample of the pixel.
struct Acc {
    color: array<vec3<f32>, PIXEL_SAMPLES>,
    trans: array<f32, PIXEL_SAMPLES>,
}

fn acc_empty() -> Acc {
    var c: Acc;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        c.trans[k] = 1.0;
    }
    return c;
}

// Composites one fragment into every sample it covers; true when all samples are opaque.
fn composite(c: ptr<function, Acc>, f: Frag) -> bool {
    let mask = frag_mask(f);
    var opaque = true;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        if (mask & (1u << k)) != 0u {
            (*c).color[k] += (*c).trans[k] * f.color.a * f.color.rgb;
            (*c).trans[k] *= 1.0 - f.color.a;
        }
        opaque = opaque && (*c).trans[k] == 0.0;
    }
    return opaque;
}

fn load_acc(px: u32) -> Acc {
    var c: Acc;
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let w = px * STATE_WORDS + SAMPLE_STATE + 4u * k;
        c.color[k] = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
        c.trans[k] = bitcast<f32>(state[w + 3u]);
    }
    return c;
}

fn save_acc(px: u32, c: Acc) {
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let w = px * STATE_WORDS + SAMPLE_STATE + 4u * k;
        state[w] = bitcast<u32>(c.color[k].r);
        state[w + 1u] = bitcast<u32>(c.color[k].g);
        state[w + 2u] = bitcast<u32>(c.color[k].b);
        state[w + 3u] = bitcast<u32>(c.trans[k]);
    }
}

// The pixel: the mean over its samples of the composite over that sample's opaque scene or
// background (one sample without coverage masks).
@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let at = pixel_index(pos) * STATE_WORDS;
    let started = (state[at + S_PHASE] & 0xfu) == DONE;
    var sum = vec4<f32>(0.0);
    for (var k = 0u; k < PIXEL_SAMPLES; k++) {
        let base = base_at_sample(pos, k);
        if !started {
            sum += base;
            continue;
        }
        let w = at + SAMPLE_STATE + 4u * k;
        let accum = vec3<f32>(bitcast<f32>(state[w]), bitcast<f32>(state[w + 1u]), bitcast<f32>(state[w + 2u]));
        let trans = bitcast<f32>(state[w + 3u]);
        sum += vec4<f32>(accum + trans * base.rgb, 1.0 - trans * (1.0 - base.a));
    }
    return sum / f32(PIXEL_SAMPLES);
}
