//! Scenes: an ordered list of meshes with their instances, the lights and the ambient term,
//! with validation of everything a caller hands in. Meshes (mesh.rs) and the camera
//! (camera.rs) have files of their own; their paths here stay.

use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{invalid, Result};
use crate::shading::{Light, Lighting, MAX_LIGHTS};

pub use crate::camera::Camera;
pub use crate::mesh::{placed_bounds, Instance, Mesh};

static NEXT_SCENE_ID: AtomicU64 = AtomicU64::new(1);

/// An ordered list of meshes, each drawn once for each of its instances. Submission order is
/// the order of `add_mesh` calls, and within a mesh the order of its instances: every triangle
/// of instance 0, then of instance 1, and so on.
#[derive(Debug)]
pub struct Scene {
    meshes: Vec<Mesh>,
    instances: Vec<Vec<Instance>>,
    lights: Vec<Light>,
    ambient: [f32; 3],
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
        Self {
            meshes: self.meshes.clone(),
            instances: self.instances.clone(),
            lights: self.lights.clone(),
            ambient: self.ambient,
            id: NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed),
            revision: 0,
        }
    }
}

impl Scene {
    pub fn new() -> Self {
        Self {
            meshes: Vec::new(),
            instances: Vec::new(),
            lights: Vec::new(),
            ambient: [0.0; 3],
            id: NEXT_SCENE_ID.fetch_add(1, Ordering::Relaxed),
            revision: 0,
        }
    }

    /// Adds a directional light (at most MAX_LIGHTS); with none, a headlight shines.
    pub fn add_light(&mut self, light: Light) -> Result<usize> {
        if self.lights.len() as u32 >= MAX_LIGHTS {
            return Err(invalid!("a scene holds at most {MAX_LIGHTS} lights: merge some"));
        }
        self.lights.push(light);
        Ok(self.lights.len() - 1)
    }

    pub fn lights(&self) -> &[Light] {
        &self.lights
    }

    pub fn clear_lights(&mut self) {
        self.lights.clear();
    }

    /// The ambient term, linear RGB (default black).
    pub fn set_ambient(&mut self, rgb: [f32; 3]) -> Result<()> {
        if rgb.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
            return Err(invalid!("ambient {rgb:?} must be three finite linear RGB values >= 0"));
        }
        self.ambient = rgb;
        Ok(())
    }

    pub fn ambient(&self) -> [f32; 3] {
        self.ambient
    }

    /// Whether any mesh has a material other than plain unlit (else fragments keep their
    /// vertex colors, bit for bit).
    pub fn shaded(&self) -> bool {
        self.meshes.iter().any(|m| !m.material.is_plain())
    }

    /// Lights (L, radiance) and ambient under `camera`: the scene's lights, or one white
    /// headlight travelling along the view direction when it has none.
    pub fn lighting(&self, camera: &Camera) -> Lighting {
        Lighting::new(&self.lights, self.ambient, camera.view_direction())
    }

    /// Adds a mesh drawn once, where its vertices are.
    pub fn add_mesh(&mut self, mesh: Mesh) -> usize {
        self.add_placed(mesh, vec![Instance::IDENTITY])
    }

    /// Adds a mesh drawn once for each of `instances` (none: uploaded, not drawn).
    /// A set of Gaussian splats (`Mesh::gaussians`, src/splat.rs), after the meshes so far.
    pub fn add_gaussians(
        &mut self,
        means: Vec<[f32; 3]>,
        scales: Vec<[f32; 3]>,
        rotations: Vec<[f32; 4]>,
        opacities: Vec<f32>,
        colors: Vec<[f32; 3]>,
    ) -> Result<usize> {
        Ok(self.add_mesh(Mesh::gaussians(means, scales, rotations, opacities, colors)?))
    }

    pub fn add_placed(&mut self, mesh: Mesh, instances: Vec<Instance>) -> usize {
        self.meshes.push(mesh);
        self.instances.push(instances);
        self.revision += 1;
        self.meshes.len() - 1
    }

    /// `mesh` as the index of one of the scene's meshes (what `add_mesh` returned), or an error
    /// that says how many there are; callers with signed indices (Python) pass them as they are.
    pub fn mesh_index(&self, mesh: i64) -> Result<usize> {
        let count = self.meshes.len();
        usize::try_from(mesh)
            .ok()
            .filter(|&i| i < count)
            .ok_or_else(|| invalid!("mesh index {mesh} is out of range: the scene has {count} meshes (add_mesh returns the index to pass)"))
    }

    /// Appends instances to mesh `mesh`; returns the index of the first one added.
    pub fn add_instances(&mut self, mesh: usize, instances: &[Instance]) -> Result<usize> {
        let mesh = self.mesh_index(mesh as i64)?;
        let list = &mut self.instances[mesh];
        list.extend_from_slice(instances);
        self.revision += 1;
        Ok(list.len() - instances.len())
    }

    /// Replaces the instances of mesh `mesh`.
    pub fn set_instances(&mut self, mesh: usize, instances: Vec<Instance>) -> Result<()> {
        let mesh = self.mesh_index(mesh as i64)?;
        self.instances[mesh] = instances;
        self.revision += 1;
        Ok(())
    }

    pub fn meshes(&self) -> &[Mesh] {
        &self.meshes
    }

    /// The instances of mesh `mesh` (one identity instance for a mesh added by `add_mesh`).
    pub fn instances(&self, mesh: usize) -> &[Instance] {
        &self.instances[mesh]
    }

    /// Every mesh with its instances, in submission order.
    pub fn placed(&self) -> impl Iterator<Item = (&Mesh, &[Instance])> {
        self.meshes.iter().zip(self.instances.iter().map(|v| v.as_slice()))
    }

    /// Whether any mesh is drawn other than once where its vertices are (the constant
    /// INSTANCED the geometry passes compile with: else they carry no transform).
    pub fn instanced(&self) -> bool {
        self.instances.iter().any(|v| v.len() != 1 || !v[0].is_identity())
    }

    /// Instances drawn, over every mesh.
    pub fn instance_count(&self) -> usize {
        self.instances.iter().map(|v| v.len()).sum()
    }

    /// Triangles drawn: each mesh's times its instances.
    pub fn triangle_count(&self) -> usize {
        self.placed().map(|(m, i)| m.triangle_count() * i.len()).sum()
    }

    /// Triangles uploaded: each mesh's once.
    pub fn unique_triangle_count(&self) -> usize {
        self.meshes.iter().map(|m| m.triangle_count()).sum()
    }

    /// The box around every drawn vertex (instances included), in f64; None when nothing is drawn.
    pub fn bounds(&self) -> Option<(glam::DVec3, glam::DVec3)> {
        placed_bounds(self.placed())
    }

    /// Changes one mesh's alpha (all vertices), e.g. from a viewer slider.
    pub fn set_mesh_alpha(&mut self, mesh: usize, alpha: f32) -> Result<()> {
        if !(0.0..=1.0).contains(&alpha) {
            return Err(invalid!("alpha {alpha} is outside [0, 1]"));
        }
        let mesh = self.mesh_index(mesh as i64)?;
        let m = &mut self.meshes[mesh];
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
