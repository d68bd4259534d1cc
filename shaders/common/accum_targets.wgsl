// The two float targets a blended accumulation pass writes (oit_core::method::accum:
// ACCUM_FORMAT, then AUX_FORMAT, the count or revealage in its red channel).
struct Accum {
    @location(0) accum: vec4<f32>,
    @location(1) aux: vec4<f32>,
}
