//! Meshes and their placements: a mesh's vertices, indices, colors and surface, how its
//! triangles come about (`Primitive`: its own, or built from strand or particle points), and
//! the instances that place it.

use glam::{DMat3, DMat4};

use crate::error::{invalid, Result};
use crate::shading::{self, Material, Shading};

/// What a chunk of uploaded geometry holds (the chunk uniform's `kind`).
pub const PRIM_MESH: u32 = 0;
pub const PRIM_STRANDS: u32 = 1;
pub const PRIM_PARTICLES: u32 = 2;
pub const PRIM_GAUSSIANS: u32 = 3;

/// How a mesh's triangles come about.
#[derive(Clone, Debug, Default, PartialEq)]
pub enum Primitive {
    /// Its own positions and indices.
    #[default]
    Triangles,
    /// Polylines of `counts[i]` points each (the mesh's positions, in order), `widths` per point
    /// in world units: a ribbon two triangles a segment.
    Strands { counts: Vec<u32>, widths: Vec<f32> },
    /// A disc per position of radius `radii` (per point, world units): a quad, two triangles.
    Particles { radii: Vec<f32> },
    /// A Gaussian splat per position (its mean): standard deviations `scales` along its axes,
    /// rotated by `rotations` (wxyz quaternions), its opacity the color's alpha; drawn as its
    /// 3-sigma screen ellipse's quad, two triangles (src/splat.rs).
    /// Where `sh` is not empty, the color is its spherical harmonics of degree `degree`
    /// evaluated in the view direction ((degree + 1)² RGB coefficients a splat, the DC first;
    /// `splat::sh_color`), and the colors' RGB only their DC part.
    Gaussians { scales: Vec<[f32; 3]>, rotations: Vec<[f32; 4]>, sh: Vec<[f32; 3]>, degree: u32 },
}

impl Primitive {
    /// The chunk kind the shaders read.
    pub fn kind(&self) -> u32 {
        match self {
            Self::Triangles => PRIM_MESH,
            Self::Strands { .. } => PRIM_STRANDS,
            Self::Particles { .. } => PRIM_PARTICLES,
            Self::Gaussians { .. } => PRIM_GAUSSIANS,
        }
    }

    pub fn name(&self) -> &'static str {
        match self {
            Self::Triangles => "triangles",
            Self::Strands { .. } => "strands",
            Self::Particles { .. } => "particles",
            Self::Gaussians { .. } => "gaussians",
        }
    }
}

/// A triangle mesh with straight (not premultiplied) linear RGBA per vertex, and its surface:
/// unit vertex normals and UVs (empty when not given) and a material (src/shading/). A
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

    /// Segments of a strand set, particles of a particle set, triangles of a mesh.
    pub fn primitive_count(&self) -> usize {
        match &self.primitive {
            Primitive::Triangles => self.indices.len(),
            Primitive::Strands { counts, .. } => self.positions.len() - counts.len(),
            Primitive::Particles { .. } | Primitive::Gaussians { .. } => self.positions.len(),
        }
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
