// Hybrid transparency (Maule et al. 2013, Algorithm 1) and its k-TAB baseline.
//   fs_store      geometry pass 1: keep the K nearest <depth, alpha> words per pixel,
//                 sorted, by the single-pass atomic bubble (one atomicMax per slot).
//   cs_visibility full screen: transmittance in front of each core slot (eq. 2).
//   fs_shade      geometry pass 2: core fragments add C * v (eq. 3), the others the tail
//                 sums C * alpha, alpha and their count (eqs. 5-6), by fixed-point storage
//                 atomics (tail = "exact": bit-identical under any order);
//   fs_shade_blend  or by additive blending into float targets, as the paper does
//                 (tail = "blend": faster, order-dependent in float rounding).
//   fs_final      full screen: eqs. 7-11 over the opaque scene or background (fs_final_blend
//                 reads the blended targets).
// With COMPACT (tail = "compact", Eq. 12's 2k + 2 words a pixel), fs_clear zeroes the tile's
// output, fs_shade_compact blends the core's C * v into the output and the tail's sums into one
// RGBA16F target, and fs_final_compact adds the rest over the output: there is no accumulator
// buffer (group 2's binding 2 is the census counts, which give the tail count), the nearest
// evicted key lives in the first slot's visibility word (the transmittance in front of the
// first slot is always 1), and T_core is computed again from the keys.
// Keys, ties and error bounds: docs/methods.md ("hybrid").
//!include common/scene.wgsl
//!include common/targets.wgsl
//!include common/fullscreen.wgsl

// Per-pixel accumulator words (mirrors oit_core::method::hybrid::ACCUM_WORDS), kept by
// atomicMax; the sums are 64-bit words at binding 4.
const EVICTED: u32 = 0u;     // nearest key pushed out of the full k-TAB (0: none)
const TAIL_LO: u32 = 1u;     // smallest tail color channel (f32 bits, inverted: 0 = none)
const TAIL_HI: u32 = 2u;     // largest tail color channel (f32 bits)
const ACCUM_WORDS: u32 = HYBRID_ACCUM_WORDS;
// 64-bit words a pixel at binding 4: the tail's three (common/tail_words.wgsl), then the core's
// three, as (lo, hi) halves of 32-bit fixed-point sums, none of which can carry into the next:
//   CORE + 0: sum C_r v, sum C_g v; CORE + 1: sum C_b v, sum |alpha - q| T' (error bound);
//   CORE + 2: sum |alpha - q| (error bound), and T_core as f32 bits (set by cs_visibility).
// A core and a tail fragment add to their own three words with the same three adds.
const PIXEL_WORDS: u32 = (HYBRID_TAIL_WORDS + HYBRID_CORE_WORDS) / 2u;
const CORE: u32 = HYBRID_TAIL_WORDS / 2u;

@group(2) @binding(0) var<storage, read_write> ktab: array<atomic<u32>>;
// Transmittance in front of each core slot; with COMPACT as f32 bits in atomic words, the first
// slot's word holding the evicted key instead (front_trans).
//!if COMPACT
@group(2) @binding(1) var<storage, read_write> vis: array<atomic<u32>>;

fn vis_load(i: u32) -> f32 {
    return bitcast<f32>(atomicLoad(&vis[i]));
}

fn vis_store(i: u32, v: f32) {
    atomicStore(&vis[i], bitcast<u32>(v));
}
//!else
@group(2) @binding(1) var<storage, read_write> vis: array<f32>;

fn vis_load(i: u32) -> f32 {
    return vis[i];
}

fn vis_store(i: u32, v: f32) {
    vis[i] = v;
}
//!endif
// The accumulators; with COMPACT, the census counts, a fragment count a pixel.
@group(2) @binding(2) var<storage, read_write> accum: array<atomic<u32>>;
// The tail's and the core's sums in 64-bit words (PIXEL_WORDS a pixel, above;
// common/tail_words.wgsl); with COMPACT the slot-offset placeholder (never accessed; the
// compact pipelines set ATOMIC64 to 0, so that its 4 bytes fit).
//!if ATOMIC64
@group(2) @binding(4) var<storage, read_write> tail_words: array<atomic<u64>>;
//!else
@group(2) @binding(4) var<storage, read_write> tail_words: array<atomic<u32>>;
//!endif
@group(2) @binding(5) var<storage, read_write> overflow: atomic<u32>;
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
//!include common/tail_words.wgsl
//!include common/alpha8.wgsl

// The transmittance in front of core slot i of the pixel whose slots start at `base`; with
// COMPACT 1 in front of the first, whose word holds the evicted key.
fn front_trans(base: u32, i: u32) -> f32 {
    if COMPACT != 0u && i == 0u {
        return 1.0;
    }
    return vis_load(base + i);
}

// The nearest key pushed out of pixel px's full table (0: none), kept by atomicMax.
fn raise_evicted(px: u32, v: u32) {
//!if COMPACT
    atomicMax(&vis[slots(px).x], v);
//!else
    atomicMax(&accum[px * ACCUM_WORDS + EVICTED], v);
//!endif
}

fn evicted_key(px: u32) -> u32 {
//!if COMPACT
    return atomicLoad(&vis[slots(px).x]);
//!else
    return atomicLoad(&accum[px * ACCUM_WORDS + EVICTED]);
//!endif
}

// 24-bit depth over 8-bit alpha, inverted so that a cleared (zero) slot is empty and
// atomicMax keeps the nearest: a larger key is a nearer fragment (lower alpha first on ties).
fn pack_key(z: f32, alpha: f32) -> u32 {
    let d = min(u32(z * DEPTH_SCALE), DEPTH_MAX);
    return ~((d << 8u) | alpha_8bit(alpha));
}

fn key_alpha(key: u32) -> f32 {
    return f32((~key) & 0xffu) / 255.0;
}

@fragment @early_depth_test(force)
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
        return; // no slots: everything is tail, and core_bound needs no evicted key
    }
    // Slots only ever grow (atomicMax), so a key not above a full table's last one now will
    // not be in the final table. The evicted key only matters where it equals the final last
    // slot's (core_bound's split tie), and a key below the last slot now is below it then.
    let last = atomicLoad(&ktab[base + sl.y - 1u]);
    if last != 0u && v <= last {
        if v == last {
            raise_evicted(px, v);
        }
        return;
    }
    for (var i = 0u; i < sl.y; i++) {
        let old = atomicMax(&ktab[base + i], v);
        if old == 0u {
            return; // took an empty slot
        }
        v = min(old, v); // the farther of the two moves on
    }
    raise_evicted(px, v);
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
    let evicted = evicted_key(px);
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
        if COMPACT == 0u || i > 0u {
            vis_store(base + i, t); // transmittance in front of slot i: v_i = alpha_i * t (eq. 2)
        }
        t *= 1.0 - key_alpha(atomicLoad(&ktab[base + i]));
    }
    if COMPACT == 0u {
        store_hi(px * PIXEL_WORDS + CORE + 2u, bitcast<u32>(t));
    }
}

// T_core of pixel px from its n core keys, as cs_visibility computes it (COMPACT keeps no word).
fn core_trans(px: u32, n: u32) -> f32 {
    let base = slots(px).x;
    var t = 1.0;
    for (var i = 0u; i < n; i++) {
        t *= 1.0 - key_alpha(atomicLoad(&ktab[base + i]));
    }
    return t;
}

// Where a fragment of pixel px with depth z and alpha a goes: the core, with the weight of its
// color and its alpha's quantization error, or the tail.
struct Placed {
    core: bool,
    // v * share: the weight of C in the core sum (eq. 3).
    w: f32,
    // The transmittance in front of its slot, and |alpha - its 8-bit alpha| (error bound).
    vis: f32,
    d: f32,
}

fn place(px: u32, z: f32, a: f32) -> Placed {
    let sl = slots(px);
    let base = sl.x;
    let key = pack_key(z, a);
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
            let share = select((1.0 - pow(1.0 - a, f32(m))) / f32(m), a, m == 1u);
            let v = front_trans(base, lo);
            return Placed(true, v * share, v, abs(a - key_alpha(key)));
        }
    }
    return Placed(false, 0.0, 0.0, 0.0);
}

@fragment @early_depth_test(force)
fn fs_shade(raw: VsOut) {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        return;
    }
    let px = pixel_index(in.clip);
    let p = place(px, in.clip.z, in.color.a);
    // Core and tail fragments make the same adds, to their own words (no branch: llvmpipe runs
    // both sides of one), and the same two atomicMax, a core fragment's with 0 (no change).
    // A core fragment's 8-bit alpha moved every transmittance behind it (error bound).
    let rgb = in.color.rgb * p.w;
    let core = Terms(vec2<u32>(fixed32(rgb.r), fixed32(rgb.g)), vec2<u32>(fixed32(rgb.b), fixed32(p.d * p.vis)),
                     vec2<u32>(fixed32(p.d), 0u));
    let tail = tail_terms(in.color.rgb, in.color.a, TAIL != 0u);
    let w = px * PIXEL_WORDS;
    add_terms(select(w, w + CORE, p.core),
              Terms(select(tail.w0, core.w0, p.core), select(tail.w1, core.w1, p.core), select(tail.w2, core.w2, p.core)));
    // The range of the tail's colors bounds what the estimate behind the core can be off by.
    let c = clamp(in.color.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let acc = px * ACCUM_WORDS;
    atomicMax(&accum[acc + TAIL_LO], select(~bitcast<u32>(min(c.r, min(c.g, c.b))), 0u, p.core));
    atomicMax(&accum[acc + TAIL_HI], select(bitcast<u32>(max(c.r, max(c.g, c.b))), 0u, p.core));
}

// The same sums by fixed-function blending (oit_core::method::ktab::blend_targets): added
// (core color and tail count; tail C * alpha and alpha; the quantization terms) or kept by
// max (the tail's largest channel, and 1 - its smallest).
struct Shade {
    @location(0) core: vec4<f32>,
    @location(1) tail: vec4<f32>,
    @location(2) quant: vec4<f32>,
    @location(3) low: vec4<f32>,
}

@fragment @early_depth_test(force)
fn fs_shade_blend(raw: VsOut) -> Shade {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        discard;
    }
    let p = place(pixel_index(in.clip), in.clip.z, in.color.a);
    if p.core {
        return Shade(vec4<f32>(in.color.rgb * p.w, 0.0), vec4<f32>(0.0), vec4<f32>(p.d * p.vis, p.d, 0.0, 0.0), vec4<f32>(0.0));
    }
    let c = clamp(in.color.rgb, vec3<f32>(0.0), vec3<f32>(1.0));
    let sums = select(vec4<f32>(0.0), vec4<f32>(in.color.rgb * in.color.a, in.color.a), TAIL != 0u);
    let hi = max(c.r, max(c.g, c.b));
    return Shade(vec4<f32>(0.0, 0.0, 0.0, 1.0), sums, vec4<f32>(0.0, 0.0, 0.0, hi), vec4<f32>(1.0 - min(c.r, min(c.g, c.b)), 0.0, 0.0, 0.0));
}

// Eq. 11 and the error bound, from the core color, the transmittance behind the core, the
// tail (count fragments), the quantization sums, and the tail's color range [lo, hi].
// `sums` bounds the rounding of the float sums of the blended tail (0 in fixed point).
fn finish(pos: vec4<f32>, core: vec3<f32>, t_core: f32, count: u32, tail: Tail, quant: vec2<f32>, lo_hi: vec2<f32>, sums: f32) -> Final {
    let base = base_at(pos);
    if count > 0u {
        atomicAdd(&overflow, count);
    }
    let rgb = core + t_core * (tail.color + tail.trans * base.rgb); // eq. 11
    // Quantized core alphas: sum |d| T' plus the second-order D^2; whatever lies behind the
    // core (tail or, for ktab, nothing) and its estimate are both mixes of the tail colors and
    // the base, so they differ by at most T_core times the range of those values; float32
    // and fixed-point rounding of K + count terms.
    let d = quant.y;
    var bound = quant.x + d * d + f32(slots(pixel_index(pos)).y + count + 2u) * ROUNDING_TERM + sums;
    if count > 0u {
        let lo = min(lo_hi.x, min(base.r, min(base.g, base.b)));
        let hi = max(lo_hi.y, max(base.r, max(base.g, base.b)));
        bound += t_core * (hi - lo);
    }
    return Final(vec4<f32>(rgb, 1.0 - t_core * tail.trans * (1.0 - base.a)), bound);
}

@fragment
fn fs_final(@builtin(position) pos: vec4<f32>) -> Final {
    let px = pixel_index(pos);
    let acc = px * ACCUM_WORDS;
    let w = px * PIXEL_WORDS;
    let c0 = tail_word(w + CORE);
    let c1 = tail_word(w + CORE + 1u);
    let c2 = tail_word(w + CORE + 2u);
    let core = vec3<f32>(read_fixed32(c0.x), read_fixed32(c0.y), read_fixed32(c1.x));
    let count = tail_count(w);
    var tail = Tail(vec3<f32>(0.0), 1.0);
    if TAIL != 0u {
        tail = read_tail(w, count);
    }
    let quant = vec2<f32>(read_fixed32(c1.y), read_fixed32(c2.x));
    let lo_hi = vec2<f32>(bitcast<f32>(~word(acc + TAIL_LO)), bitcast<f32>(word(acc + TAIL_HI)));
    var out = finish(pos, core, bitcast<f32>(c2.y), count, tail, quant, lo_hi, 0.0);
    if TAIL != 0u {
        out.bound = tail_bound(out.bound, count);
    }
    return out;
}

@group(3) @binding(0) var shade_core: texture_2d<f32>;
@group(3) @binding(1) var shade_tail: texture_2d<f32>;
@group(3) @binding(2) var shade_quant: texture_2d<f32>;
@group(3) @binding(3) var shade_low: texture_2d<f32>;

@fragment
fn fs_final_blend(@builtin(position) pos: vec4<f32>) -> Final {
    let at = vec2<i32>(pos.xy);
    let core = textureLoad(shade_core, at, 0);
    let sums = textureLoad(shade_tail, at, 0);
    let quant = textureLoad(shade_quant, at, 0);
    let count = u32(core.a);
    var tail = Tail(vec3<f32>(0.0), 1.0);
    if TAIL != 0u {
        tail = tail_from_sums(sums.rgb, sums.a, count);
    }
    let lo_hi = vec2<f32>(1.0 - textureLoad(shade_low, at, 0).r, quant.a);
    let t_core = bitcast<f32>(tail_word(pixel_index(pos) * PIXEL_WORDS + CORE + 2u).y);
    // Float sums of count terms in [0, 1] in any order: each within count * 2^-24 of its value
    // relative to the sum; eqs. 7-10 move the tail by at most 3 such relative errors.
    let rounding = 3.0 * f32(count) * 5.96e-8 * t_core;
    return finish(pos, core.rgb, t_core, count, tail, quant.xy, lo_hi, rounding);
}

// tail = "compact": the tile's output starts at zero, the shade pass adds the core's C * v to
// it and the tail's C * alpha and alpha to an RGBA16F target, and fs_final_compact adds the rest.
@fragment
fn fs_clear(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    return vec4<f32>(0.0);
}

struct ShadeCompact {
    @location(0) core: vec4<f32>,
    @location(1) tail: vec4<f32>,
}

@fragment @early_depth_test(force)
fn fs_shade_compact(raw: VsOut) -> ShadeCompact {
    let in = shaded(raw);
    if behind_opaque(in.clip) || in.color.a <= 0.0 {
        discard;
    }
    let p = place(pixel_index(in.clip), in.clip.z, in.color.a);
    if p.core {
        return ShadeCompact(vec4<f32>(in.color.rgb * p.w, 0.0), vec4<f32>(0.0));
    }
    return ShadeCompact(vec4<f32>(0.0), vec4<f32>(in.color.rgb * in.color.a, in.color.a));
}

@group(3) @binding(4) var compact_sums: texture_2d<f32>;

// Half-float unit roundoff: each blended RGBA16F sum of n terms is within n 2^-11 of its value
// relative to the sum.
const HALF_ROUNDOFF: f32 = 0.00048828125;

// Eq. 11 without the core color, which is in the output already (blended in by adding), and
// the error bound. The tail count is the census count less the core's fragments (so alpha-0
// fragments, which the other tails skip, count in it); the quantization sums are bounded by
// their largest values (each core alpha within ALPHA_8BIT_ERROR of its key's, each
// transmittance at most 1) and the tail's colors by [0, 1], as no word keeps them.
@fragment
fn fs_final_compact(@builtin(position) pos: vec4<f32>) -> Final {
    let px = pixel_index(pos);
    let n = core_slots(px);
    let t_core = core_trans(px, n);
    let count = atomicLoad(&accum[px]) - n;
    let sums = textureLoad(compact_sums, vec2<i32>(pos.xy), 0);
    let tail = tail_from_sums(sums.rgb, sums.a, count);
    let d = f32(n) * ALPHA_8BIT_ERROR;
    let rounding = 3.0 * f32(count) * HALF_ROUNDOFF * t_core;
    return finish(pos, vec3<f32>(0.0), t_core, count, tail, vec2<f32>(d, d), vec2<f32>(0.0, 1.0), rounding);
}
