//! Meshes, scenes and cameras, with validation of everything a caller hands in.

use std::sync::atomic::{AtomicU64, Ordering};

use glam::{DMat3, DMat4, DVec4, Mat4};

use crate::error::{invalid, Result};
use crate::primitive::Primitive;
use crate::shading::{self, Light, Lighting, Material, Shading, MAX_LIGHTS};

/// A triangle mesh with straight (not premultiplied) linear RGBA per vertex, and its surface:
/// unit vertex normals and UVs (empty when not given) and a material (src/shading.rs). A
/// strand or particle set (`primitive`, src/primitive.rs) is one too: its positions are its
/// points, it has no indices, and its triangles are built facing the camera.
#[derive(Clone, Debug, Default)]
pub struct Mesh {
    pub positions: Vec<[f32; 3]>,
    pub indices: Vec<[u32; 3]>,
    pub colors: Vec<[f32; 4]>,
    pub opaque: bool,
    pub normals: Vec<[f32; 3]>,
    pub uvs: Vec<[f32; 2]>,
    pub material: Material,
    pub primitive: Primitive,
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
        Ok(Self { positions, indices, colors, opaque, ..Default::default() })
    }

    /// Gives the mesh a surface. Normals are renormalized; with `Shading::Smooth` and no
    /// normals they are computed (angle-weighted); a texture needs UVs.
    pub fn with_surface(mut self, normals: Option<Vec<[f32; 3]>>, uvs: Option<Vec<[f32; 2]>>, material: Material) -> Result<Self> {
        material.validate()?;
        if self.primitive != Primitive::Triangles {
            return Err(invalid!("{} take their surface from with_primitive_surface", self.primitive.name()));
        }
        if material.falloff != crate::shading::Falloff::None {
            return Err(invalid!("a falloff is for particles: add_particles"));
        }
        if material.shading == Shading::Hair && normals.is_none() {
            return Err(invalid!("'hair' shading reads each vertex's strand tangent: pass the tangents as normals"));
        }
        let n = self.positions.len();
        self.normals = match normals {
            Some(v) => shading::check_normals(v, n)?,
            None if material.shading == Shading::Smooth => shading::vertex_normals(&self.positions, &self.indices),
            None => Vec::new(),
        };
        if let Some(uv) = &uvs {
            if uv.len() != n {
                return Err(invalid!("uvs has {} rows but positions has {n}: pass one (u, v) per vertex", uv.len()));
            }
            if let Some(i) = uv.iter().position(|t| t.iter().any(|x| !x.is_finite())) {
                return Err(invalid!("uvs[{i}] = {:?} is not finite", uv[i]));
            }
        }
        if material.texture.is_some() && uvs.is_none() {
            return Err(invalid!("a texture needs uvs: pass one (u, v) per vertex"));
        }
        self.uvs = uvs.unwrap_or_default();
        self.material = material;
        Ok(self)
    }

    /// Triangles drawn for one placement: a mesh's own, two a strand segment or particle.
    pub fn triangle_count(&self) -> usize {
        match self.primitive {
            Primitive::Triangles => self.indices.len(),
            _ => 2 * self.primitive_count(),
        }
    }
}

/// One placement of a mesh: an affine transform (column-vector convention, `world = M @ [p, 1]`)
/// and an RGBA factor that multiplies the mesh's vertex colors. A mesh is drawn once for each
/// of its instances, from one copy of its vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Instance {
    pub transform: DMat4,
    pub color: [f32; 4],
}

impl Instance {
    pub const IDENTITY: Instance = Instance { transform: DMat4::IDENTITY, color: [1.0; 4] };

    /// `m` in row-major order (as numpy stores a 4x4 array). The transform must be affine
    /// (last row 0, 0, 0, 1) and finite; `color` straight RGBA in [0, 1].
    pub fn from_rows(m: [[f64; 4]; 4], color: [f32; 4]) -> Result<Self> {
        if m.iter().flatten().any(|v| !v.is_finite()) {
            return Err(invalid!("transform {m:?} has NaN or Inf entries"));
        }
        if m[3] != [0.0, 0.0, 0.0, 1.0] {
            return Err(invalid!("transform's last row is {:?}: instance transforms must be affine, with last row (0, 0, 0, 1)", m[3]));
        }
        if color.iter().any(|x| !(0.0..=1.0).contains(x)) {
            return Err(invalid!("instance color {color:?} is outside [0, 1] (or NaN): it multiplies straight linear RGBA"));
        }
        Ok(Self { transform: DMat4::from_cols_array_2d(&m).transpose(), color })
    }

    pub fn is_identity(&self) -> bool {
        *self == Self::IDENTITY
    }

    /// The matrix that carries normals: the inverse transpose of the linear part, computed as
    /// the cofactor matrix times the determinant's sign (the same direction, and defined for a
    /// singular transform too). Normals are renormalized after it.
    pub fn normal_matrix(&self) -> DMat3 {
        let a = DMat3::from_mat4(self.transform);
        let (c0, c1, c2) = (a.x_axis, a.y_axis, a.z_axis);
        let cof = DMat3::from_cols(c1.cross(c2), c2.cross(c0), c0.cross(c1));
        if a.determinant() < 0.0 {
            -cof
        } else {
            cof
        }
    }

    /// Whether the transform mirrors (negative determinant): its front faces are clockwise
    /// on screen, as glTF defines for such nodes, so back-face culling flips with it.
    pub fn mirrors(&self) -> bool {
        DMat3::from_mat4(self.transform).determinant() < 0.0
    }

    /// `p` carried into world space, in f64.
    pub fn apply(&self, p: [f32; 3]) -> glam::DVec3 {
        self.transform.transform_point3(glam::DVec3::from(p.map(|x| x as f64)))
    }
}

/// The box around every drawn vertex of meshes with their instances (a scene's, a loaded
/// file's), in f64; None when nothing is drawn.
pub fn placed_bounds<'a>(placed: impl Iterator<Item = (&'a Mesh, &'a [Instance])>) -> Option<(glam::DVec3, glam::DVec3)> {
    let mut lo = glam::DVec3::splat(f64::INFINITY);
    let mut hi = -lo;
    for (m, list) in placed {
        for w in list.iter().flat_map(|inst| m.positions.iter().map(|p| inst.apply(*p))) {
            lo = lo.min(w);
            hi = hi.max(w);
        }
    }
    (lo.x <= hi.x).then_some((lo, hi))
}

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
