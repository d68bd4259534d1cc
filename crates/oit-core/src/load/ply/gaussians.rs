//! The standard 3DGS PLY layout (Kerbl et al. 2023's training output): a vertex a Gaussian with
//! x y z, f_dc_0..2 (degree-0 spherical-harmonic coefficients), opacity (a logit), scale_0..2
//! (logs of the standard deviations) and rot_0..3 (a wxyz quaternion, not normalized), found by
//! these property names, and f_rest_0 .. f_rest_{3(k-1)-1} where the file has harmonics of a
//! higher degree (k = 4, 9 or 16 coefficients: the trainer writes them channel after channel,
//! red's k - 1, then green's, then blue's). Read as `Mesh::gaussians` or `Mesh::gaussians_sh`
//! (src/splat.rs).

use super::header::Element;

pub use crate::splat::SH_C0;

/// Where a vertex element's 3DGS properties are, when it has all of them.
pub struct SplatLayout {
    xyz: [usize; 3],
    dc: [usize; 3],
    opacity: usize,
    scale: [usize; 3],
    rot: [usize; 4],
    /// f_rest_0 .. in order, 3 (k - 1) of them.
    rest: Vec<usize>,
}

/// The splats read so far.
#[derive(Default)]
pub struct Splats {
    pub means: Vec<[f32; 3]>,
    pub scales: Vec<[f32; 3]>,
    pub rotations: Vec<[f32; 4]>,
    pub opacities: Vec<f32>,
    pub colors: Vec<[f32; 3]>,
    /// k RGB coefficients a splat (the DC first) where the file has f_rest, else empty.
    pub sh: Vec<[f32; 3]>,
    pub degree: u32,
}

impl SplatLayout {
    pub fn find(e: &Element) -> Option<Self> {
        let one = |n: &str| e.find(&[n]);
        let all = |names: &[&str]| names.iter().map(|n| one(n)).collect::<Option<Vec<usize>>>();
        let xyz = all(&["x", "y", "z"])?;
        let dc = all(&["f_dc_0", "f_dc_1", "f_dc_2"])?;
        let scale = all(&["scale_0", "scale_1", "scale_2"])?;
        let rot = all(&["rot_0", "rot_1", "rot_2", "rot_3"])?;
        let rest: Vec<usize> = (0..).map_while(|i| one(&format!("f_rest_{i}"))).collect();
        // Harmonics of degree 1 to 3 (9, 24 or 45 values); any other count is read past.
        let rest = if [9, 24, 45].contains(&rest.len()) { rest } else { Vec::new() };
        Some(Self {
            rest,
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
        if !self.rest.is_empty() {
            let m = self.rest.len() / 3;
            out.degree = ((m + 1) as f64).sqrt() as u32 - 1;
            out.sh.push(self.dc.map(|i| values[i] as f32));
            for j in 0..m {
                out.sh.push([0, 1, 2].map(|c| values[self.rest[c * m + j]] as f32));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::SH_C0;
    use crate::load::{load_file, Surface};
    use crate::primitive::Primitive;

    /// A binary little-endian 3DGS PLY of `rows` (x y z, f_dc_0..2, opacity, scale_0..2,
    /// rot_0..3) in the trainer's property order, normals and `rest` f_rest coefficients
    /// written between them, f_rest_j of row i being `rest_value(i, j)`.
    fn file(rows: &[[f32; 14]], rest: usize) -> Vec<u8> {
        let mut names: Vec<String> = ["x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"].map(String::from).to_vec();
        names.extend((0..rest).map(|j| format!("f_rest_{j}")));
        names.extend(["opacity", "scale_0", "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"].map(String::from));
        let mut h = format!("ply\nformat binary_little_endian 1.0\nelement vertex {}\n", rows.len());
        for n in &names {
            h += &format!("property float {n}\n");
        }
        h += "end_header\n";
        let mut out = h.into_bytes();
        for (i, r) in rows.iter().enumerate() {
            let extra: Vec<f32> = (0..rest).map(|j| rest_value(i, j)).collect();
            let values = [&r[0..3], &[0.1, 0.2, 0.3], &r[3..6], &extra, &r[6..14]].concat();
            for v in values {
                out.extend(v.to_le_bytes());
            }
        }
        out
    }

    fn rest_value(i: usize, j: usize) -> f32 {
        0.01 * (j + 1) as f32 - i as f32
    }

    fn load(rows: &[[f32; 14]], rest: usize) -> crate::scene::Mesh {
        let dir = std::env::temp_dir().join(format!("oit-core-3dgs-{}-{rest}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("splats.ply");
        std::fs::write(&path, file(rows, rest)).unwrap();
        let loaded = load_file(&path, Surface::default()).unwrap();
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(loaded.meshes.len(), 1);
        loaded.meshes[0].mesh.clone()
    }

    #[test]
    fn the_harmonics_load_channel_after_channel() {
        // Degree 1: 9 f_rest values, red's three, green's, blue's.
        let rows = [[0.0, 0.0, 0.0, 0.1, 0.2, 0.3, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]; 2];
        let m = load(&rows, 9);
        let Primitive::Gaussians { sh, degree, .. } = &m.primitive else { panic!("{:?}", m.primitive) };
        assert_eq!((*degree, sh.len()), (1, 8));
        for i in 0..2 {
            assert_eq!(sh[4 * i], [0.1, 0.2, 0.3]);
            for j in 1..4 {
                assert_eq!(sh[4 * i + j], [0, 1, 2].map(|c| rest_value(i, c * 3 + j - 1)));
            }
        }
        // Three f_rest values are no degree: read past, colors from f_dc alone.
        let Primitive::Gaussians { sh, .. } = &load(&rows, 3).primitive else { panic!() };
        assert!(sh.is_empty());
    }

    #[test]
    fn a_3dgs_ply_loads_every_field_as_written() {
        let rows: [[f32; 14]; 2] = [
            [0.5, -1.0, 2.0, 0.3, -0.2, 1.0, 0.0, -1.0, -2.0, -3.0, 1.0, 0.0, 0.0, 0.0],
            [1.0, 2.0, 3.0, -5.0, 0.0, 0.5, 2.0, 0.1, 0.2, 0.3, 0.5, 0.5, 0.5, 0.5],
        ];
        let m = &load(&rows, 3);
        let Primitive::Gaussians { scales, rotations, .. } = &m.primitive else { panic!("{:?}", m.primitive) };
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
