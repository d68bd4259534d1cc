// Stochastic transparency (Enderton et al. 2010) with its alpha correction, on S samples
// per pixel kept in a storage buffer (so any S works without MSAA targets):
//   fs_depth   each fragment covers each sample with probability alpha (a hash of the seed,
//              triangle, pixel and sample) and keeps the sample's nearest depth (atomicMax
//              of inverted depth bits: a cleared word is empty);
//   fs_accum   each fragment's visibility is the fraction of samples whose nearest depth is
//              not in front of it; it adds (C alpha vis, alpha vis) and multiplies the
//              revealage by 1 - alpha (blending);
//   resolve    C = sum(C alpha vis) / sum(alpha vis) * (1 - R) + R * background.
// SAMPLES is injected; docs/methods.md ("stochastic").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

@group(2) @binding(0) var<storage, read_write> samples: array<atomic<u32>>;
@group(2) @binding(1) var accum_tex: texture_2d<f32>;
@group(2) @binding(2) var aux_tex: texture_2d<f32>;

// Integer hash (lowbias32, Wellons): well mixed, cheap, the same on every adapter.
fn hash(x: u32) -> u32 {
    var h = x;
    h ^= h >> 16u;
    h *= 0x7feb352du;
    h ^= h >> 15u;
    h *= 0x846ca68bu;
    h ^= h >> 16u;
    return h;
}

fn covers(prim: u32, px: u32, s: u32, alpha: f32) -> bool {
    let h = hash(prim ^ hash(px ^ hash(s ^ hash(frame.seed))));
    return f32(h >> 8u) * (1.0 / 16777216.0) < alpha;
}

@fragment @early_depth_test(force)
fn fs_depth(raw: VsOut) {
    let in = shaded_alpha(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let px = pixel_index(in.clip);
    // The noise follows the frame's pixel, not the tile's, so tiles do not change it.
    let at = vec2<u32>(frame_xy(in.clip.xy));
    let frame_px = at.y * frame.size.x + at.x;
    let key = ~bitcast<u32>(in.clip.z);
    for (var s = 0u; s < SAMPLES; s++) {
        if covers(in.prim, frame_px, s, in.color.a) {
            atomicMax(&samples[px * SAMPLES + s], key);
        }
    }
}

//!include common/accum_targets.wgsl

@fragment
fn fs_accum(raw: VsOut) -> Accum {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        discard;
    }
    let px = pixel_index(in.clip);
    let key = ~bitcast<u32>(in.clip.z);
    var seen = 0u;
    for (var s = 0u; s < SAMPLES; s++) {
        if key >= atomicLoad(&samples[px * SAMPLES + s]) {
            seen++;
        }
    }
    let w = in.color.a * f32(seen) / f32(SAMPLES);
    return Accum(vec4<f32>(in.color.rgb * w, w), vec4<f32>(in.color.a, 0.0, 0.0, 0.0));
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let base = base_at(pos);
    let p = vec2<i32>(pos.xy);
    let acc = textureLoad(accum_tex, p, 0);
    let reveal = textureLoad(aux_tex, p, 0).r;
    if acc.a <= 0.0 {
        // Nothing seen in any sample: only the total coverage is known.
        return vec4<f32>(base.rgb * reveal, 1.0 - reveal * (1.0 - base.a));
    }
    return vec4<f32>(acc.rgb / acc.a * (1.0 - reveal) + base.rgb * reveal, 1.0 - reveal * (1.0 - base.a));
}
