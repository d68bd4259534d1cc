// Screen-door transparency (RTR 5.5): a fragment survives where its alpha exceeds an ordered
// 4 x 4 Bayer threshold at its pixel, and the nearest survivor is drawn opaque (depth test
// and write on a copy of the opaque depth). One geometry pass, no blending, no sorting.
//!include common/scene.wgsl

const BAYER: array<u32, 16> = array<u32, 16>(0u, 8u, 2u, 10u, 12u, 4u, 14u, 6u, 3u, 11u, 1u, 9u, 15u, 7u, 13u, 5u);

@fragment
fn fs_door(raw: VsOut) -> @location(0) vec4<f32> {
    let in = shaded(raw);
    let p = vec2<u32>(frame_xy(in.clip.xy)); // the frame's pattern, whatever the tile
    let threshold = (f32(BAYER[(p.y % 4u) * 4u + p.x % 4u]) + 0.5) / 16.0;
    if in.color.a <= threshold {
        discard;
    }
    return vec4<f32>(in.color.rgb, 1.0);
}
