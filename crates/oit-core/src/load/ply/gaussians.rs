//! The standard 3DGS PLY layout (Kerbl et al. 2023's training output): a vertex a Gaussian with
//! x y z, f_dc_0..2 (degree-0 spherical-harmonic coefficients), opacity (a logit), scale_0..2
//! (logs of the standard deviations) and rot_0..3 (a wxyz quaternion, not normalized), found by
//! these property names. Read as `Mesh::gaussians` (src/splat.rs).

use super::header::Element;

/// The SH basis constant of degree 0: color = 0.5 + C0 f_dc.
pub const SH_C0: f64 = 0.282_094_791_773_878_14;

/// Where a vertex element's 3DGS properties are, when it has all of them.
pub struct SplatLayout {
    xyz: [usize; 3],
    dc: [usize; 3],
    opacity: usize,
    scale: [usize; 3],
    rot: [usize; 4],
}

/// The splats read so far.
#[derive(Default)]
pub struct Splats {
    pub means: Vec<[f32; 3]>,
    pub scales: Vec<[f32; 3]>,
    pub rotations: Vec<[f32; 4]>,
    pub opacities: Vec<f32>,
    pub colors: Vec<[f32; 3]>,
}

impl SplatLayout {
    pub fn find(e: &Element) -> Option<Self> {
        let one = |n: &str| e.find(&[n]);
        let all = |names: &[&str]| names.iter().map(|n| one(n)).collect::<Option<Vec<usize>>>();
        let xyz = all(&["x", "y", "z"])?;
        let dc = all(&["f_dc_0", "f_dc_1", "f_dc_2"])?;
        let scale = all(&["scale_0", "scale_1", "scale_2"])?;
        let rot = all(&["rot_0", "rot_1", "rot_2", "rot_3"])?;
        Some(Self {
            xyz: [xyz[0], xyz[1], xyz[2]],
            dc: [dc[0], dc[1], dc[2]],
            opacity: one("opacity")?,
            scale: [scale[0], scale[1], scale[2]],
            rot: [rot[0], rot[1], rot[2], rot[3]],
        })
    }

    /// One vertex's values as a splat: color 0.5 + C0 f_dc clamped to [0, 1], opacity the
    /// logit's sigmoid, standard deviations the logs' exponentials, the quaternion as stored
    /// (normalized by `Mesh::gaussians`; a zero one is refused there).
    pub fn push(&self, values: &[f64], out: &mut Splats) {
        out.means.push(self.xyz.map(|i| values[i] as f32));
        out.colors.push(self.dc.map(|i| (0.5 + SH_C0 * values[i]).clamp(0.0, 1.0) as f32));
        out.opacities.push((1.0 / (1.0 + (-values[self.opacity]).exp())) as f32);
        out.scales.push(self.scale.map(|i| values[i].exp() as f32));
        out.rotations.push(self.rot.map(|i| values[i] as f32));
    }
}

#[cfg(test)]
mod tests {
    use super::SH_C0;
    use crate::load::{load_file, Surface};
    use crate::primitive::Primitive;

    /// A binary little-endian 3DGS PLY of `rows` (x y z, f_dc_0..2, opacity, scale_0..2,
    /// rot_0..3) in the trainer's property order, normals and three f_rest coefficients
    /// written between them (read past).
    fn file(rows: &[[f32; 14]]) -> Vec<u8> {
        let names = ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2", "f_rest_0", "f_rest_1", "f_rest_2"];
        let rest = ["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"];
        let mut h = format!("ply\nformat binary_little_endian 1.0\nelement vertex {}\n", rows.len());
        for n in names.iter().chain(&rest) {
            h += &format!("property float {n}\n");
        }
        h += "end_header\n";
        let mut out = h.into_bytes();
        for r in rows {
            let values = [&r[0..3], &[0.1, 0.2, 0.3], &r[3..6], &[7.0, 8.0, 9.0], &r[6..14]].concat();
            for v in values {
                out.extend(v.to_le_bytes());
            }
        }
        out
    }

    #[test]
    fn a_3dgs_ply_loads_every_field_as_written() {
        let rows: [[f32; 14]; 2] = [
            [0.5, -1.0, 2.0, 0.3, -0.2, 1.0, 0.0, -1.0, -2.0, -3.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0, -5.0, 0.0, 0.5, 2.0, 0.1, 0.2, 0.3, 0.5, 0.5, 0.5, 0.5],
        ];
        let dir = std::env::temp_dir().join(format!("oit-core-3dgs-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("splats.ply");
        std::fs::write(&path, file(&rows)).unwrap();
        let loaded = load_file(&path, Surface::default()).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(loaded.meshes.len(), 1);
        let m = &loaded.meshes[0].mesh;
        let Primitive::Gaussians { scales, rotations } = &m.primitive else { panic!("{:?}", m.primitive) };
        for (i, row) in rows.iter().enumerate() {
            let r = row.map(|x| x as f64);
            assert_eq!(m.positions[i], [row[0], row[1], row[2]]);
            for k in 0..3 {
                // -5 clamps to 0: 0.5 + C0 f_dc is below it.
                let dc = (0.5 + SH_C0 * r[3 + k]).clamp(0.0, 1.0);
                assert!((m.colors[i][k] as f64 - dc).abs() < 1e-6, "color {i} {k}");
                assert!((scales[i][k] as f64 - r[7 + k].exp()).abs() < 1e-6 * r[7 + k].exp(), "scale {i} {k}");
            }
            let sigmoid = 1.0 / (1.0 + (-r[6]).exp());
            assert!((m.colors[i][3] as f64 - sigmoid).abs() < 1e-6, "opacity {i}");
            assert_eq!(rotations[i], [row[10], row[11], row[12], row[13]]);
        }
    }
}
