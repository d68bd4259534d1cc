//! Meshes, scenes and cameras, with validation of everything a caller hands in.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DMat4, DVec4, Mat4};

use crate::error::{invalid, Result};

/// A triangle mesh with straight (not premultiplied) linear RGBA per vertex.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    pub colors: Vec<[f32; 4]>,
    pub opaque: bool,
}

impl Mesh {
    /// Checks finiteness, ranges and index bounds; `colors` may hold one color for the
    /// whole mesh, which is expanded per vertex.
    pub fn new(positions: Vec<[f32; 3]>, indices: Vec<[u32; 3]>, mut colors: Vec<[f32; 4]>, opaque: bool) -> Result<Self> {
        if let Some(i) = positions.iter().position(|p| p.iter().any(|c| !c.is_finite())) {
            return Err(invalid!("positions[{i}] = {:?} is not finite: remove NaN/Inf vertices", positions[i]));
        }
        let n = positions.len();
        if colors.len() == 1 && n != 1 {
            colors = vec![colors[0]; n];
        }
        if colors.len() != n {
            return Err(invalid!(
                "colors has {} rows but positions has {n}: pass one RGBA per vertex or a single RGBA for the mesh",
                colors.len()
            ));
        }
        if let Some(i) = colors.iter().position(|c| c.iter().any(|x| !(0.0..=1.0).contains(x))) {
            return Err(invalid!("colors[{i}] = {:?} is outside [0, 1] (or NaN): colors are straight linear RGBA in [0, 1]", colors[i]));
        }
        if let Some(t) = indices.iter().position(|t| t.iter().any(|&v| v as usize >= n)) {
            return Err(invalid!(
                "indices[{t}] = {:?} refers past the last vertex ({} vertices): indices must be in [0, {n})",
                indices[t],
                n
            ));
        }
        Ok(Self { positions, indices, colors, opaque })
    }

    pub fn triangle_count(&self) -> usize {
        self.indices.len()
    }
}

static NEXT_SCENE_ID: AtomicU64 = AtomicU64::new(1);

/// An ordered list of meshes. Submission order is the order of `add_mesh` calls.
#[derive(Debug)]
pub struct Scene {
    meshes: Vec<Mesh>,
    id: u64,
    revision: u64,
}

impl Default for Scene {
    fn default() -> Self {
        Self::new()
    }
}

impl Clone for Scene {
    fn clone(&self) -> Self {
        Self { meshes: self.meshes.clone(), id: NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed), revision: 0 }
    }
}

impl Scene {
    pub fn new() -> Self {
        Self { meshes: Vec::new(), id: NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed), revision: 0 }
    }

    pub fn add_mesh(&mut self, mesh: Mesh) -> usize {
        self.meshes.push(mesh);
        self.revision += 1;
        self.meshes.len() - 1
    }

    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// Changes one mesh's alpha (all vertices), e.g. from a viewer slider.
    pub fn set_mesh_alpha(&mut self, mesh: usize, alpha: f32) -> Result<()> {
        if !(0.0..=1.0).contains(&alpha) {
            return Err(invalid!("alpha {alpha} is outside [0, 1]"));
        }
        let m = self.meshes.get_mut(mesh).ok_or_else(|| invalid!("no mesh {mesh}"))?;
        m.colors.iter_mut().for_each(|c| c[3] = alpha);
        self.revision += 1;
        Ok(())
    }

    /// Identity for GPU upload caches: changes whenever the content may have changed.
    pub fn key(&self) -> (u64, u64) {
        (self.id, self.revision)
    }

    pub fn transparent(&self) -> impl Iterator<Item = &Mesh> {
        self.meshes.iter().filter(|m| !m.opaque)
    }

    pub fn opaque(&self) -> impl Iterator<Item = &Mesh> {
        self.meshes.iter().filter(|m| m.opaque)
    }
}

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
