// Hybrid transparency (Maule et al. 2013, Algorithm 1) and its k-TAB baseline.
//   fs_store      geometry pass 1: keep the K nearest <depth, alpha> words per pixel,
//                 sorted, by the single-pass atomic bubble (one atomicMax per slot).
//   cs_visibility full screen: transmittance in front of each core slot (eq. 2).
//   fs_shade      geometry pass 2: core fragments add C * v (eq. 3), the others the tail
//                 sums C * alpha, alpha and their count (eqs. 5-6).
//   fs_final      full screen: eqs. 7-11 over the opaque scene or background.
// Keys, ties and error bounds: docs/methods.md ("hybrid").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Per-pixel accumulator words (mirrors oit_core::method::hybrid::ACCUM_WORDS).
const CORE_R: u32 = 0u;      // 3 words: core color, fixed point
const TAIL_R: u32 = 3u;      // 8 words: tail C * alpha (rgb) and alpha, (lo, hi) pairs
const TAIL_COUNT: u32 = 11u; // tail fragment count
const T_CORE: u32 = 12u;     // transmittance behind the core (f32 bits)
const EVICTED: u32 = 13u;    // nearest key pushed out of the full k-TAB (0: none)
const QUANT_W: u32 = 14u;    // sum over core fragments of |alpha - q| * T' (fixed point)
const QUANT_D: u32 = 15u;    // sum over core fragments of |alpha - q| (fixed point)
const TAIL_LO: u32 = 16u;    // smallest tail color channel (f32 bits, inverted: 0 = none)
const TAIL_HI: u32 = 17u;    // largest tail color channel (f32 bits)
const ACCUM_WORDS: u32 = HYBRID_ACCUM_WORDS;

@group(2) @binding(0) var<storage, read_write> ktab: array<atomic<u32>>;
@group(2) @binding(1) var<storage, read_write> vis: array<f32>;
@group(2) @binding(2) var<storage, read_write> accum: array<atomic<u32>>;
@group(2) @binding(4) var<storage, read_write> overflow: atomic<u32>;
// With PER_PIXEL, pixel px owns slots offsets[px] .. offsets[px + 1] (a prefix sum of each
// pixel's own k, chosen by auto); otherwise K slots a pixel and this binding is unused.
@group(2) @binding(3) var<storage, read_write> offsets: array<u32>;

// The first slot and the slot count of pixel px.
fn slots(px: u32) -> vec2<u32> {
    if PER_PIXEL != 0u {
        let first = offsets[px];
        return vec2<u32>(first, offsets[px + 1u] - first);
    }
    return vec2<u32>(px * K, K);
}
//!include common/fixed.wgsl
//!include common/alpha8.wgsl

// 24-bit depth over 8-bit alpha, inverted so that a cleared (zero) slot is empty and
// atomicMax keeps the nearest: a larger key is a nearer fragment (lower alpha first on ties).
fn pack_key(z: f32, alpha: f32) -> u32 {
    let d = min(u32(z * DEPTH_SCALE), DEPTH_MAX);
    return ~((d << 8u) | alpha_8bit(alpha));
}

fn key_alpha(key: u32) -> f32 {
    return f32((~key) & 0xffu) / 255.0;
}

@fragment
fn fs_store(raw: VsOut) {
    let in = shaded_alpha(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let px = pixel_index(in.clip);
    let sl = slots(px);
    let base = sl.x;
    var v = pack_key(in.clip.z, in.color.a);
    if sl.y == 0u {
        atomicMax(&accum[px * ACCUM_WORDS + EVICTED], v);
        return;
    }
    // Slots only ever grow (atomicMax), so a key not above a full table's last one now will
    // not be in the final table: record it as evicted without walking the table.
    let last = atomicLoad(&ktab[base + sl.y - 1u]);
    if last != 0u && v <= last {
        atomicMax(&accum[px * ACCUM_WORDS + EVICTED], v);
        return;
    }
    for (var i = 0u; i < sl.y; i++) {
        let old = atomicMax(&ktab[base + i], v);
        if old == 0u {
            return; // took an empty slot
        }
        v = min(old, v); // the farther of the two moves on
    }
    atomicMax(&accum[px * ACCUM_WORDS + EVICTED], v);
}

// The smallest key that counts as core. Every stored key does, except when a fragment with
// the same key as the last slot was pushed out: that tied group is split across the table's
// end, so all of it goes to the tail (no fragment counted twice or dropped).
fn core_bound(px: u32) -> u32 {
    let sl = slots(px);
    if sl.y == 0u {
        return 0xffffffffu; // no slots: nothing is core
    }
    let last = atomicLoad(&ktab[sl.x + sl.y - 1u]);
    let evicted = atomicLoad(&accum[px * ACCUM_WORDS + EVICTED]);
    return select(last, last + 1u, evicted != 0u && evicted == last);
}

fn core_slots(px: u32) -> u32 {
    let bound = core_bound(px);
    let sl = slots(px);
    var n = 0u;
    while n < sl.y {
        let key = atomicLoad(&ktab[sl.x + n]);
        if key == 0u || key < bound {
            break;
        }
        n++;
    }
    return n;
}

@compute @workgroup_size(8, 8)
fn cs_visibility(@builtin(global_invocation_id) id: vec3<u32>) {
    let px = compute_pixel(id);
    if px == OUTSIDE {
        return;
    }
    let base = slots(px).x;
    let n = core_slots(px);
    var t = 1.0;
    for (var i = 0u; i < n; i++) {
        vis[base + i] = t; // transmittance in front of slot i: v_i = alpha_i * t (eq. 2)
        t *= 1.0 - key_alpha(atomicLoad(&ktab[base + i]));
    }
    atomicStore(&accum[px * ACCUM_WORDS + T_CORE], bitcast<u32>(t));
}

@fragment
fn fs_shade(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let px = pixel_index(in.clip);
    let sl = slots(px);
    let base = sl.x;
    let acc = px * ACCUM_WORDS;
    let key = pack_key(in.clip.z, in.color.a);
    if key >= core_bound(px) {
        // Core: the first slot holding this key (the table is sorted by descending key).
        var lo = 0u;
        var hi = sl.y;
        while lo < hi {
            let mid = (lo + hi) / 2u;
            if atomicLoad(&ktab[base + mid]) > key { lo = mid + 1u; } else { hi = mid; }
        }
        var m = 0u;
        while lo + m < sl.y && atomicLoad(&ktab[base + lo + m]) == key {
            m++;
        }
        if m > 0u {
            // m fragments share one quantized key: they share the visibility of their slots.
            let a = in.color.a;
            let share = select((1.0 - pow(1.0 - a, f32(m))) / f32(m), a, m == 1u);
            let w = vis[base + lo] * share;
            // The 8-bit alpha of this key moved every transmittance behind it (error bound).
            let d = abs(a - key_alpha(key));
            add_fixed32(acc + QUANT_W, d * vis[base + lo]);
            add_fixed32(acc + QUANT_D, d);
            add_fixed32(acc + CORE_R, in.color.r * w);
            add_fixed32(acc + CORE_R + 1u, in.color.g * w);
            add_fixed32(acc + CORE_R + 2u, in.color.b * w);
            return;
        }
    }
    atomicAdd(&accum[acc + TAIL_COUNT], 1u);
    // The range of the tail's colors bounds what the estimate behind the core can be off by.
    let c = clamp(in.color.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    atomicMax(&accum[acc + TAIL_LO], ~bitcast<u32>(min(c.r, min(c.g, c.b))));
    atomicMax(&accum[acc + TAIL_HI], bitcast<u32>(max(c.r, max(c.g, c.b))));
    if TAIL != 0u {
        add_tail_sums(acc + TAIL_R, in.color.rgb, in.color.a);
    }
}

@fragment
fn fs_final(@builtin(position) pos: vec4<f32>) -> Final {
    let base = base_at(pos);
    let acc = pixel_index(pos) * ACCUM_WORDS;
    let core = vec3<f32>(read_fixed32(word(acc + CORE_R)), read_fixed32(word(acc + CORE_R + 1u)), read_fixed32(word(acc + CORE_R + 2u)));
    let t_core = bitcast<f32>(word(acc + T_CORE));
    let count = word(acc + TAIL_COUNT);
    if count > 0u {
        atomicAdd(&overflow, count);
    }
    var tail = Tail(vec3<f32>(0.0), 1.0);
    if TAIL != 0u {
        tail = resolve_tail(acc + TAIL_R, count);
    }
    let rgb = core + t_core * (tail.color + tail.trans * base.rgb); // eq. 11
    // Quantized core alphas: sum |d| T' plus the second-order D^2; whatever lies behind the
    // core (tail or, for ktab, nothing) and its estimate are both mixes of the tail colors and
    // the base, so they differ by at most T_core times the range of those values; float32
    // and fixed-point rounding of K + count terms.
    let d = read_fixed32(word(acc + QUANT_D));
    var bound = read_fixed32(word(acc + QUANT_W)) + d * d + f32(slots(pixel_index(pos)).y + count + 2u) * ROUNDING_TERM;
    if count > 0u {
        let lo = min(bitcast<f32>(~word(acc + TAIL_LO)), min(base.r, min(base.g, base.b)));
        let hi = max(bitcast<f32>(word(acc + TAIL_HI)), max(base.r, max(base.g, base.b)));
        bound += t_core * (hi - lo);
    }
    return Final(vec4<f32>(rgb, 1.0 - t_core * tail.trans * (1.0 - base.a)), bound);
}
