//! The camera: a view-projection matrix, checked, and the rays through it.

use glam::{DMat4, DVec4, Mat4};

use crate::error::{invalid, Result};

/// A view-projection matrix in the column-vector convention, mapping to wgpu clip space
/// (x, y in [-1, 1] with y up, z in [0, 1]).
#[derive(Clone, Copy, Debug)]
pub struct Camera {
    pub view_proj: DMat4,
}

impl Camera {
    /// `m` in row-major order (as numpy stores a 4x4 array): `clip = M @ [x, y, z, 1]`.
    pub fn from_rows(m: [[f64; 4]; 4]) -> Result<Self> {
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(invalid!("camera matrix has NaN or Inf entries"));
        }
        let view_proj = DMat4::from_cols_array_2d(&m).transpose();
        let det = view_proj.determinant();
        if !det.is_finite() || det.abs() < 1e-300 {
            return Err(invalid!("camera matrix is singular (determinant {det:e}): build it with Camera.look_at or Camera.orthographic"));
        }
        Ok(Self { view_proj })
    }

    /// The unit direction the view looks along: its middle ray, from near to far.
    pub fn view_direction(&self) -> glam::DVec3 {
        let (near, far) = self.unproject_segment(&self.view_proj.inverse(), 0.0, 0.0);
        (far - near).normalize()
    }

    pub fn matrix_f32(&self) -> Mat4 {
        self.view_proj.as_mat4()
    }

    /// World-space points on the near (z = 0) and far (z = 1) planes under NDC (x, y).
    pub fn unproject_segment(&self, inv: &DMat4, x: f64, y: f64) -> (glam::DVec3, glam::DVec3) {
        let a = *inv * DVec4::new(x, y, 0.0, 1.0);
        let b = *inv * DVec4::new(x, y, 1.0, 1.0);
        (a.truncate() / a.w, b.truncate() / b.w)
    }
}
