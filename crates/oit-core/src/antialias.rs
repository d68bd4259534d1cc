//! Antialiasing: the standard sample patterns and the sub-pixel camera offsets that place a
//! frame's pixel centers on one sample of them. A frame of `antialias` S renders S sample
//! frames, each with the camera offset onto one sample position, and averages them
//! (docs/methods.md, "Antialiasing"); the CPU reference does the same in float64.

use glam::{DMat4, DVec3};

use crate::error::{invalid, Result};
use crate::scene::Camera;

/// Sample counts with a standard pattern.
pub const SAMPLE_COUNTS: [u32; 5] = [1, 2, 4, 8, 16];

// The standard multisample positions (Direct3D and Vulkan's standard sample locations), in
// sixteenths of a pixel from its center, y down.
const P1: [[i8; 2]; 1] = [[0, 0]];
const P2: [[i8; 2]; 2] = [[4, 4], [-4, -4]];
const P4: [[i8; 2]; 4] = [[-2, -6], [6, -2], [-6, 2], [2, 6]];
const P8: [[i8; 2]; 8] = [[1, -3], [-1, 3], [5, 1], [-3, -5], [-5, 5], [-7, -1], [3, 7], [7, -7]];
const P16: [[i8; 2]; 16] = [
    [1, 1],
    [-1, -3],
    [-3, 2],
    [4, -1],
    [-5, -2],
    [2, 5],
    [5, 3],
    [3, -5],
    [-2, 6],
    [0, -7],
    [-4, -6],
    [-6, 4],
    [-8, 0],
    [7, -4],
    [6, 7],
    [-7, -8],
];

/// The sample positions of an S-sample pixel, as offsets from its center in pixels (y down).
pub fn sample_offsets(samples: u32) -> Result<Vec<[f64; 2]>> {
    let pattern: &[[i8; 2]] = match samples {
        1 => &P1,
        2 => &P2,
        4 => &P4,
        8 => &P8,
        16 => &P16,
        _ => return Err(invalid!("antialias must be one of {SAMPLE_COUNTS:?} samples a pixel (the standard patterns), got {samples}")),
    };
    Ok(pattern.iter().map(|p| [p[0] as f64 / 16.0, p[1] as f64 / 16.0]).collect())
}

impl Camera {
    /// The camera whose pixel centers see what this one sees at `offset` (pixels from the
    /// center, y down) in a `width` x `height` frame: clip x and y shifted by a multiple of w,
    /// so depth and perspective are unchanged.
    pub fn jittered(&self, offset: [f64; 2], width: u32, height: u32) -> Camera {
        let shift = DVec3::new(-2.0 * offset[0] / width as f64, 2.0 * offset[1] / height as f64, 0.0);
        Camera { view_proj: DMat4::from_translation(shift) * self.view_proj }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec4;

    #[test]
    fn patterns_stay_inside_the_pixel_and_average_to_its_center() {
        for s in SAMPLE_COUNTS {
            let p = sample_offsets(s).unwrap();
            assert_eq!(p.len(), s as usize);
            assert!(p.iter().flatten().all(|v| (-0.5..0.5).contains(v)));
            if s <= 8 {
                let mean = p.iter().fold([0.0, 0.0], |m, v| [m[0] + v[0], m[1] + v[1]]);
                assert_eq!(mean, [0.0, 0.0]);
            }
        }
        assert!(sample_offsets(3).is_err() && sample_offsets(0).is_err());
    }

    #[test]
    fn a_jittered_center_sees_the_offset_point() {
        // A right-handed perspective (w = -z), columns as glam stores them.
        let cam = Camera {
            view_proj: DMat4::from_cols_array(&[1.2, 0.0, 0.0, 0.0, 0.0, 1.8, 0.0, 0.0, 0.0, 0.0, -1.05, -1.0, 0.0, 0.0, -0.5, 0.0]),
        };
        let (w, h) = (30, 20);
        let offset = [0.25, -0.375];
        let moved = cam.jittered(offset, w, h);
        let p = DVec4::new(0.3, -0.2, -3.0, 1.0);
        let to_px = |c: DVec4| [(c.x / c.w + 1.0) * 0.5 * w as f64, (1.0 - c.y / c.w) * 0.5 * h as f64, c.z / c.w];
        let (a, b) = (to_px(cam.view_proj * p), to_px(moved.view_proj * p));
        assert!((b[0] - (a[0] - offset[0])).abs() < 1e-12 && (b[1] - (a[1] - offset[1])).abs() < 1e-12);
        assert_eq!(a[2], b[2]);
    }
}
