// Hybrid transparency's tail (Maule et al. 2013, eqs. 5-6) in three 64-bit words a pixel: the
// count and the sums of alpha and of C * alpha, each term a fixed-point integer at TAIL_SCALE
// (the values and the rounding of the unpacked pairs before them), so that integer adds make
// the words the same in any fragment order:
//   word 0: the tail count (bits 0-21) and sum alpha (bits 22-63);
//   word 1: sum C_r alpha (bits 0-41) and the low 22 bits of sum C_g alpha (bits 42-63);
//   word 2: the rest of sum C_g alpha (bits 0-19) and sum C_b alpha (bits 20-61).
// A fragment makes three adds (the unpacked count and sums took five, and carries): word 1's
// carry out of bit 63, read from the value its add returns, goes into word 2 with word 2's own
// add. Each term is at most 2^24 (TAIL_SCALE), so every field is exact while a pixel's tail has
// fewer than TAIL_LIMIT = 2^18 fragments; the count itself holds up to 2^22 - 1, so fs_final can
// tell a pixel past that (docs/methods.md, "hybrid").
// With ATOMIC64 the words are 64-bit atomics (SHADER_INT64_ATOMIC_ALL_OPS). Without, each is a
// (lo, hi) pair of 32-bit atomics with the carry between them taken from the value atomicAdd
// returns: the same integers at two adds a word.
// The including shader declares them, `tail_words: array<atomic<u64>>` with ATOMIC64 and
// `array<atomic<u32>>` without, and says where a pixel's words start (hybrid64: three a pixel;
// hybrid: six, its core's sums in three more words with the same adds, add_terms).

// The tail of hybrid transparency (Maule et al. 2013, eqs. 7-10): its premultiplied color
// C_tail * alpha_tail and its transmittance T_tail = (1 - alpha_avg)^count.
struct Tail {
    color: vec3<f32>,
    trans: f32,
}

// Eqs. 7-10 from the sums of C * alpha (sum_c) and alpha (sum_a) over count fragments.
fn tail_from_sums(sum_c: vec3<f32>, sum_a: f32, count: u32) -> Tail {
    var tail = Tail(vec3<f32>(0.0), 1.0);
    if count == 0u || sum_a <= 0.0 {
        return tail;
    }
    let n = f32(count);
    let a_avg = min(sum_a / n, 1.0);                            // eq. 8
    tail.trans = select(pow(1.0 - a_avg, n), 0.0, a_avg >= 1.0); // eq. 9
    tail.color = (sum_c / sum_a) * (1.0 - tail.trans);           // eqs. 7 and 10
    return tail;
}

const TAIL_LIMIT: u32 = 262144u; // 2^18

// A pixel's error bound, 1 where its tail passed TAIL_LIMIT: the packed sums may have wrapped,
// so the tail can be anything.
fn tail_bound(bound: f32, count: u32) -> f32 {
    return select(bound, max(bound, 1.0), count >= TAIL_LIMIT);
}

//!if ATOMIC64
// Adds the 64-bit value v = (lo, hi) plus `carry` to word i; returns 1 when the word wrapped
// past 2^64 (the carry into the next word).
fn add_tail_word(i: u32, v: vec2<u32>, carry: u32) -> u32 {
    let x = (u64(v.x) | (u64(v.y) << 32u)) + u64(carry);
    let old = atomicAdd(&tail_words[i], x);
    return select(0u, 1u, old > ~x);
}

fn tail_word(i: u32) -> vec2<u32> {
    let x = atomicLoad(&tail_words[i]);
    return vec2<u32>(u32(x & 0xfffffffflu), u32(x >> 32u));
}

// Sets word i to (0, hi), before any add to it.
fn store_hi(i: u32, hi: u32) {
    atomicStore(&tail_words[i], u64(hi) << 32u);
}
//!else
// The same add on the pair (2i, 2i + 1). The terms below leave room in both halves for the
// carries: `lo + carry` and `hi + carry` never pass 2^32 - 1 (see tail_terms).
fn add_tail_word(i: u32, v: vec2<u32>, carry: u32) -> u32 {
    let lo = v.x + carry;
    let old_lo = atomicAdd(&tail_words[2u * i], lo);
    let hi = v.y + select(0u, 1u, old_lo > ~lo);
    let old_hi = atomicAdd(&tail_words[2u * i + 1u], hi);
    return select(0u, 1u, old_hi > ~hi);
}

fn tail_word(i: u32) -> vec2<u32> {
    return vec2<u32>(atomicLoad(&tail_words[2u * i]), atomicLoad(&tail_words[2u * i + 1u]));
}

fn store_hi(i: u32, hi: u32) {
    atomicStore(&tail_words[2u * i + 1u], hi);
}
//!endif

// Fixed point at TAIL_SCALE of a value in [0, 1], as the unpacked sums rounded it.
fn tail_fixed(v: f32) -> u32 {
    return u32(round(clamp(v, 0.0, 1.0) * TAIL_SCALE));
}

// What one fragment adds to three consecutive words, each as (lo, hi).
struct Terms {
    w0: vec2<u32>,
    w1: vec2<u32>,
    w2: vec2<u32>,
}

// A fragment of color rgb and alpha a in the tail's words (with sums = false, only its count:
// ktab counts what it drops).
fn tail_terms(rgb: vec3<f32>, a: f32, sums: bool) -> Terms {
    if !sums {
        return Terms(vec2<u32>(1u, 0u), vec2<u32>(0u), vec2<u32>(0u));
    }
    let q = tail_fixed(a);
    let r = tail_fixed(rgb.r * a);
    let g = tail_fixed(rgb.g * a);
    let b = tail_fixed(rgb.b * a);
    // Each term is at most 2^24: word 0's lo is 1 | q << 22 (bit 0 free of q), its hi q >> 10;
    // word 1's lo is r, its hi g's low 22 bits over 10 free bits; word 2's lo g >> 22 (at most 4)
    // under b << 20, its hi b >> 12. No half is near 2^32 - 1, so adding a carry cannot wrap it.
    return Terms(vec2<u32>(1u | (q << 22u), q >> 10u), vec2<u32>(r, (g & 0x3fffffu) << 10u),
                 vec2<u32>((g >> 22u) | (b << 20u), b >> 12u));
}

// Adds `t` to words w, w + 1 and w + 2: word w + 1's carry out of bit 63 goes into word w + 2
// with its own add.
fn add_terms(w: u32, t: Terms) {
    add_tail_word(w, t.w0, 0u);
    let carry = add_tail_word(w + 1u, t.w1, 0u);
    add_tail_word(w + 2u, t.w2, carry);
}

// A 42-bit sum (lo, hi) as the unpacked pairs read it.
fn tail_sum(v: vec2<u32>) -> f32 {
    return (f32(v.y) * 4294967296.0 + f32(v.x)) / TAIL_SCALE;
}

// The tail count of the pixel whose tail words start at w.
fn tail_count(w: u32) -> u32 {
    return tail_word(w).x & 0x3fffffu;
}

// The tail (eqs. 7-10) from the words starting at w, over `count` fragments.
fn read_tail(w: u32, count: u32) -> Tail {
    let w0 = tail_word(w);
    let w1 = tail_word(w + 1u);
    let w2 = tail_word(w + 2u);
    let sum_a = vec2<u32>((w0.x >> 22u) | (w0.y << 10u), w0.y >> 22u);
    let sum_r = vec2<u32>(w1.x, w1.y & 0x3ffu);
    let sum_g = vec2<u32>((w1.y >> 10u) | (w2.x << 22u), (w2.x & 0xfffffu) >> 10u);
    let sum_b = vec2<u32>((w2.x >> 20u) | (w2.y << 12u), (w2.y >> 20u) & 0x3ffu);
    return tail_from_sums(vec3<f32>(tail_sum(sum_r), tail_sum(sum_g), tail_sum(sum_b)), tail_sum(sum_a), count);
}
