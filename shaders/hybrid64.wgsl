// Single-pass hybrid transparency with 64-bit atomics (the future work of Maule et al.
// 2013): each k-TAB slot is one 64-bit word holding the whole fragment — 24-bit depth,
// 8-bit alpha and the shaded color as R11G11B10 unorm — inverted so that a cleared slot is
// empty and atomicMax keeps the nearest. The atomic bubble (atomicMax returning the old
// word: SHADER_INT64_ATOMIC_ALL_OPS) inserts a fragment; the word that falls off the last
// slot is added to the tail's words (common/tail_words.wgsl, as in hybrid.wgsl) in the same pass. The
// resolve composites the sorted core exactly from the words, then the tail (eqs. 7-11).
// docs/methods.md ("hybrid64").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

@group(2) @binding(0) var<storage, read_write> ktab: array<atomic<u64>>;
// The tail's count and sums, three 64-bit words a pixel. The method needs 64-bit atomic adds,
// so it runs with ATOMIC64 only; the pairs of the other branch keep the shader valid without.
//!if ATOMIC64
@group(2) @binding(1) var<storage, read_write> tail_words: array<atomic<u64>>;
//!else
@group(2) @binding(1) var<storage, read_write> tail_words: array<atomic<u32>>;
//!endif
@group(2) @binding(2) var<storage, read_write> overflow: atomic<u32>;
//!include common/tail_words.wgsl
//!include common/alpha8.wgsl

// 64-bit words a pixel: the tail's three.
const TAIL_WORDS: u32 = HYBRID_TAIL_WORDS / 2u;

fn pack_word(z: f32, c: vec4<f32>) -> u64 {
    let d = min(u32(z * DEPTH_SCALE), DEPTH_MAX);
    let a = alpha_8bit(c.a);
    let q = vec3<u32>(round(clamp(c.rgb, vec3<f32>(0.0), vec3<f32>(1.0)) * vec3<f32>(2047.0, 2047.0, 1023.0)));
    let rgb = (q.r << 21u) | (q.g << 10u) | q.b;
    return ~((u64((d << 8u) | a) << 32u) | u64(rgb));
}

fn unpack_color(word: u64) -> vec4<f32> {
    let w = ~word;
    let rgb = u32(w & 0xfffffffflu);
    let a = u32(w >> 32u) & 0xffu;
    let c = vec3<f32>(f32(rgb >> 21u) / 2047.0, f32((rgb >> 10u) & 0x7ffu) / 2047.0, f32(rgb & 0x3ffu) / 1023.0);
    return vec4<f32>(c, f32(a) / 255.0);
}

// A k-TAB word that fell off the table joins the tail.
fn add_evicted(px: u32, packed: u64) {
    let c = unpack_color(packed);
    add_terms(px * TAIL_WORDS, tail_terms(c.rgb, c.a, true));
}

@fragment @early_depth_test(force)
fn fs_insert(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let px = pixel_index(in.clip);
    let base = px * K;
    var v = pack_word(in.clip.z, in.color);
    // Slots only grow, so a word not above a full table's last one goes to the tail now.
    let last = atomicLoad(&ktab[base + K - 1u]);
    if last == 0lu || v > last {
        for (var i = 0u; i < K; i++) {
            let old = atomicMax(&ktab[base + i], v);
            if old == 0lu {
                return; // took an empty slot
            }
            v = min(old, v); // the farther of the two moves on
        }
    }
    // Quantized like every stored word, so the tail does not depend on arrival order.
    add_evicted(px, v);
}

@fragment
fn fs_resolve(@builtin(position) pos: vec4<f32>) -> Final {
    let base = base_at(pos);
    let px = pixel_index(pos);
    var core = vec3<f32>(0.0);
    var t_core = 1.0;
    // Each core alpha is within ALPHA_8BIT_ERROR of the fragment's: sum (T' + drift so far) * that.
    var alpha_bound = 0.0;
    var drift = 0.0;
    for (var i = 0u; i < K; i++) {
        let w = atomicLoad(&ktab[px * K + i]);
        if w == 0lu {
            break;
        }
        let c = unpack_color(w);
        core += t_core * c.a * c.rgb;
        alpha_bound += (t_core + drift) * ALPHA_8BIT_ERROR;
        drift += ALPHA_8BIT_ERROR;
        t_core *= 1.0 - c.a;
    }
    let count = tail_count(px * TAIL_WORDS);
    if count > 0u {
        atomicAdd(&overflow, count);
    }
    let tail = read_tail(px * TAIL_WORDS, count);
    let rgb = core + t_core * (tail.color + tail.trans * base.rgb); // eq. 11
    // Core colors quantized to 11/11/10 bits (visibilities sum to at most 1), core alphas as
    // above, at most T_core for what lies behind when there is a tail, and rounding.
    var bound = 1.0 / 2046.0 + alpha_bound + f32(K + count + 2u) * ROUNDING_TERM;
    if count > 0u {
        bound += t_core;
    }
    bound = tail_bound(bound, count);
    return Final(vec4<f32>(rgb, 1.0 - t_core * tail.trans * (1.0 - base.a)), bound);
}
