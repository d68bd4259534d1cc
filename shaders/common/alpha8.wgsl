// hybrid's 8-bit alpha (its k-TAB keys, hybrid64's words, auto's estimate). Rounded after a
// bias of 2^-10 of a step: alphas a user types (0.1, 0.3, 0.5, 0.7 ...) are exact half steps
// of 1/255, where plain rounding would go up or down with the last bit of the interpolated
// alpha, from pixel to pixel and frame to frame; biased, they sit 2^-10 of a step from the
// boundary and always round up. Error: |q - alpha| <= (1/2 + 2^-10) / 255.
// ALPHA_8BIT_BIAS and ALPHA_8BIT_ERROR come from crates/oit-core/src/consts.rs.

fn alpha_8bit(alpha: f32) -> u32 {
    return min(u32(floor(clamp(alpha, 0.0, 1.0) * 255.0 + 0.5 + ALPHA_8BIT_BIAS)), 255u);
}
