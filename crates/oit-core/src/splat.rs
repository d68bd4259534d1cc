//! Gaussian splats (3D Gaussian splatting, Kerbl et al. 2023) in float64: each Gaussian's 3D
//! covariance Σ = R S Sᵀ Rᵀ, its EWA screen footprint (the 2D covariance J Σ Jᵀ plus a
//! 0.3 px² low-pass, J the Jacobian of world to pixels at the mean, which is J W of the paper
//! with the view W folded in) and the 3-sigma quad that covers it. The quad's corners lie at
//! the mean's clip w, so its disc coordinates interpolate affinely on screen and the falloff
//! exp(-4.5 |uv|²) of `Falloff::Splat` is exactly exp(-½ dᵀ Σ'⁻¹ d) (docs/methods.md,
//! "Gaussian splats"). Mirrored in WGSL by `gaussian_corners` (shaders/common/primitives.wgsl).

use glam::{DMat3, DMat4, DQuat, DVec2, DVec3, DVec4};

/// The screen-space low-pass added to the 2D covariance's diagonal (pixels², as 3DGS).
pub const LOW_PASS: f64 = 0.3;
/// The quad reaches this many standard deviations along each axis of the ellipse; the
/// Gaussian is cut (alpha 0) past this Mahalanobis distance.
pub const SIGMAS: f64 = 3.0;
/// 3DGS's clamp of a fragment's alpha: at most `ALPHA_MAX`, dropped (0) below `ALPHA_MIN`.
pub const ALPHA_MAX: f64 = 0.99;
pub const ALPHA_MIN: f64 = 1.0 / 255.0;

/// The spherical-harmonic basis constants of 3DGS (degree 0, 1, 2, 3).
pub const SH_C0: f64 = 0.282_094_791_773_878_14;
pub const SH_C1: f64 = 0.488_602_511_902_919_9;
pub const SH_C2: [f64; 5] =
    [1.092_548_430_592_079_2, -1.092_548_430_592_079_2, 0.315_391_565_252_520_05, -1.092_548_430_592_079_2, 0.546_274_215_296_039_6];
pub const SH_C3: [f64; 7] = [
    -0.590_043_589_926_643_5,
    2.890_611_442_640_554,
    -0.457_045_799_464_465_8,
    0.373_176_332_590_115_4,
    -0.457_045_799_464_465_8,
    1.445_305_721_320_277,
    -0.590_043_589_926_643_5,
];

/// The unit direction from the eye to `p`: from the homogeneous eye `e` (inv_view_proj times
/// (0, 0, 1, 0), primitive.rs) its center e.xyz / e.w, or for an orthographic camera (e.w = 0)
/// the view direction e.xyz.
pub fn view_direction(e: DVec4, p: DVec3) -> DVec3 {
    if e.w.abs() > 1e-300 {
        (p - e.truncate() / e.w).normalize_or_zero()
    } else {
        e.truncate().normalize_or_zero()
    }
}

/// 3DGS's color of spherical-harmonic coefficients `c` ((degree + 1)² RGB, the DC first) in
/// the unit direction `d` from the eye: 0.5 + Σ Y_lm(d) c_lm with its basis and signs, clamped
/// to [0, 1] (3DGS clamps at 0 alone; colors here are in [0, 1], as every vertex color is).
pub fn sh_color(c: &[[f32; 3]], d: DVec3) -> DVec3 {
    let c: Vec<DVec3> = c.iter().map(|v| DVec3::from(v.map(|x| x as f64))).collect();
    let (x, y, z) = (d.x, d.y, d.z);
    let mut r = SH_C0 * c[0];
    if c.len() > 1 {
        r += -SH_C1 * y * c[1] + SH_C1 * z * c[2] - SH_C1 * x * c[3];
    }
    if c.len() > 4 {
        let (xx, yy, zz, xy, yz, xz) = (x * x, y * y, z * z, x * y, y * z, x * z);
        r += SH_C2[0] * xy * c[4]
            + SH_C2[1] * yz * c[5]
            + SH_C2[2] * (2.0 * zz - xx - yy) * c[6]
            + SH_C2[3] * xz * c[7]
            + SH_C2[4] * (xx - yy) * c[8];
        if c.len() > 9 {
            r += SH_C3[0] * y * (3.0 * xx - yy) * c[9]
                + SH_C3[1] * xy * z * c[10]
                + SH_C3[2] * y * (4.0 * zz - xx - yy) * c[11]
                + SH_C3[3] * z * (2.0 * zz - 3.0 * xx - 3.0 * yy) * c[12]
                + SH_C3[4] * x * (4.0 * zz - xx - yy) * c[13]
                + SH_C3[5] * z * (xx - yy) * c[14]
                + SH_C3[6] * x * (xx - 3.0 * yy) * c[15];
        }
    }
    (r + DVec3::splat(0.5)).clamp(DVec3::ZERO, DVec3::ONE)
}

/// The unit rotation of a wxyz quaternion (normalized; the caller refuses zero ones).
pub fn rotation(q: [f32; 4]) -> DMat3 {
    let [w, x, y, z] = q.map(|c| c as f64);
    DMat3::from_quat(DQuat::from_xyzw(x, y, z, w).normalize())
}

/// Σ = R S Sᵀ Rᵀ of a Gaussian with standard deviations `scale` along its axes rotated by `q`.
pub fn covariance(scale: [f32; 3], q: [f32; 4]) -> DMat3 {
    let m = rotation(q) * DMat3::from_diagonal(DVec3::from(scale.map(|s| s as f64)));
    m * m.transpose()
}

/// The upper triangle of a covariance: xx, xy, xz, yy, yz, zz (the order the GPU reads).
pub fn upper(s: &DMat3) -> [f64; 6] {
    [s.x_axis.x, s.y_axis.x, s.z_axis.x, s.y_axis.y, s.z_axis.y, s.z_axis.z]
}

/// A Gaussian's screen footprint: the mean in clip space and the quad's half axes in pixels
/// (y up): `SIGMAS` standard deviations along the eigenvectors of the 2D covariance.
#[derive(Clone, Copy, Debug)]
pub struct SplatFootprint {
    pub clip: DVec4,
    pub axes: [DVec2; 2],
}

/// The 2D covariance (pixels², y up) of a Gaussian of world covariance `cov` at `mean` under
/// `view_proj` on a frame of `size` pixels, low-pass included, as (xx, xy, yy); `None` where
/// the mean is not in front of the eye (clip w <= 0).
pub fn screen_covariance(mean: DVec3, cov: &DMat3, view_proj: &DMat4, size: DVec2) -> Option<(DVec4, [f64; 3])> {
    let c = *view_proj * mean.extend(1.0);
    if c.w.partial_cmp(&1e-30) != Some(std::cmp::Ordering::Greater) {
        return None;
    }
    let row = |i: usize| view_proj.row(i).truncate();
    // d(ndc)/d(world) = (row_i w - row_3 c_i) / w², times half the frame in pixels.
    let jx = (row(0) * c.w - row(3) * c.x) * (0.5 * size.x / (c.w * c.w));
    let jy = (row(1) * c.w - row(3) * c.y) * (0.5 * size.y / (c.w * c.w));
    let (sx, sy) = (*cov * jx, *cov * jy);
    Some((c, [jx.dot(sx) + LOW_PASS, jx.dot(sy), jy.dot(sy) + LOW_PASS]))
}

/// The footprint of `screen_covariance`: its eigenvectors at angle θ = ½ atan2(2b, a - c),
/// each scaled by `SIGMAS` times the square root of its eigenvalue.
pub fn footprint(mean: DVec3, cov: &DMat3, view_proj: &DMat4, size: DVec2) -> Option<SplatFootprint> {
    let (clip, [a, b, c]) = screen_covariance(mean, cov, view_proj, size)?;
    let theta = 0.5 * (2.0 * b).atan2(a - c);
    let (s, co) = theta.sin_cos();
    let e1 = DVec2::new(co, s);
    let e2 = DVec2::new(-s, co);
    let l1 = a * co * co + 2.0 * b * s * co + c * s * s;
    let l2 = a * s * s - 2.0 * b * s * co + c * co * co;
    Some(SplatFootprint { clip, axes: [e1 * (SIGMAS * l1.max(0.0).sqrt()), e2 * (SIGMAS * l2.max(0.0).sqrt())] })
}

/// The world position of the quad corner at disc coordinates `uv` (±1, ±1): the mean's clip
/// position moved on screen by u axes[0] + v axes[1] pixels at the mean's clip depth and w,
/// carried back to world space by `inv_view_proj`.
pub fn corner(f: &SplatFootprint, uv: DVec2, inv_view_proj: &DMat4, size: DVec2) -> DVec3 {
    let px = f.axes[0] * uv.x + f.axes[1] * uv.y;
    let ndc = DVec2::new(2.0 * px.x / size.x, 2.0 * px.y / size.y);
    let clip = f.clip + DVec4::new(ndc.x * f.clip.w, ndc.y * f.clip.w, 0.0, 0.0);
    let h = *inv_view_proj * clip;
    h.truncate() / h.w
}

/// The NDC depth of the Gaussian's peak along the ray `o + t d` (`SplatDepth::Ray`, as
/// StopThePop): t* = dᵀP(μ - o) / dᵀPd, P the covariance's inverse (or any positive multiple of
/// it: the GPU takes its adjugate, which a thin splat's tiny determinant does not blow up),
/// then the point o + t* d under `view_proj`, its depth z / w clamped to [0, 1]; 0 where the
/// peak is not in front of the eye (w <= 0). Mirrored by `splat_peak_depth`
/// (shaders/common/shading.wgsl).
pub fn ray_depth(view_proj: &DMat4, mean: DVec3, precision: &DMat3, o: DVec3, d: DVec3) -> (f64, f64) {
    let t = d.dot(*precision * (mean - o)) / d.dot(*precision * d);
    let c = *view_proj * (o + d * t).extend(1.0);
    if c.w > 0.0 {
        ((c.z / c.w).clamp(0.0, 1.0), c.w)
    } else {
        (0.0, c.w)
    }
}

/// 3DGS's alpha: `alpha` clamped to `ALPHA_MAX` and 0 below `ALPHA_MIN`, and whether float32
/// may land on the other side of the cut (an ambiguous pixel).
pub fn clamp_alpha(alpha: f64) -> (f64, bool) {
    let ambiguous = (alpha - ALPHA_MIN).abs() < 1e-5;
    (if alpha < ALPHA_MIN { 0.0 } else { alpha.min(ALPHA_MAX) }, ambiguous)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_ray_peak_is_the_closest_point_of_a_round_gaussian_and_the_plane_of_a_flat_one() {
        // Depth as the parameter itself: view_proj maps z to NDC z, w = 1 (orthographic).
        let vp = DMat4::IDENTITY;
        let (o, d) = (DVec3::new(0.1, -0.2, 0.0), DVec3::new(0.0, 0.0, 1.0));
        let mean = DVec3::new(0.5, 0.3, 0.4);
        // Round: the point of the ray nearest the mean, whatever the scale.
        let round = covariance([0.2; 3], [1.0, 0.0, 0.0, 0.0]).inverse();
        assert!((ray_depth(&vp, mean, &round, o, d).0 - 0.4).abs() < 1e-12);
        // Flat (thin along z' tilted 45 degrees about y): where the ray meets its plane, for
        // any positive multiple of the inverse (the GPU's adjugate).
        let q = [std::f32::consts::FRAC_PI_8.cos(), 0.0, std::f32::consts::FRAC_PI_8.sin(), 0.0];
        let flat = covariance([0.3, 0.3, 1e-4], q);
        let normal = rotation(q) * DVec3::Z;
        let plane = (mean - o).dot(normal) / d.dot(normal);
        for p in [flat.inverse(), flat.inverse() * 7.0] {
            assert!((ray_depth(&vp, mean, &p, o, d).0 - plane).abs() < 1e-6, "{plane}");
        }
        // Past the far plane: clamped to 1; behind the eye (w <= 0): 0.
        assert_eq!(ray_depth(&vp, DVec3::new(0.1, -0.2, 3.0), &round, o, d).0, 1.0);
        let flip = DMat4::from_diagonal(glam::DVec4::new(1.0, 1.0, 1.0, -1.0));
        assert_eq!(ray_depth(&flip, mean, &round, o, d).0, 0.0);
    }

    #[test]
    fn covariance_is_r_s_s_r() {
        // 90 degrees about z: x and y swap their scales.
        let h = std::f32::consts::FRAC_1_SQRT_2;
        let s = covariance([1.0, 2.0, 3.0], [h, 0.0, 0.0, h]);
        let want = DMat3::from_diagonal(DVec3::new(4.0, 1.0, 9.0));
        assert!(s.abs_diff_eq(want, 1e-12), "{s:?}");
        // An unnormalized quaternion is the same rotation.
        assert!(covariance([1.0, 2.0, 3.0], [2.0, 0.0, 0.0, 2.0]).abs_diff_eq(want, 1e-12));
    }

    #[test]
    fn an_orthographic_footprint_is_the_scaled_ellipse_plus_the_low_pass() {
        // Orthographic: world x, y in [-1, 1] to 100 x 100 pixels, 50 pixels a unit.
        let vp = DMat4::IDENTITY;
        let size = DVec2::splat(100.0);
        let cov = covariance([0.1, 0.02, 0.05], [1.0, 0.0, 0.0, 0.0]);
        let (_, s) = screen_covariance(DVec3::ZERO, &cov, &vp, size).unwrap();
        // The scales are float32: 0.1 is 0.1 within 1.5e-9.
        assert!((s[0] - (25.0 + LOW_PASS)).abs() < 1e-6 && s[1].abs() < 1e-12 && (s[2] - (1.0 + LOW_PASS)).abs() < 1e-6, "{s:?}");
        let f = footprint(DVec3::ZERO, &cov, &vp, size).unwrap();
        assert!((f.axes[0].length() - 3.0 * s[0].sqrt()).abs() < 1e-12);
        assert!((f.axes[1].length() - 3.0 * s[2].sqrt()).abs() < 1e-12);
        let c = corner(&f, DVec2::new(1.0, 0.0), &vp.inverse(), size);
        assert!((c.x.abs() - f.axes[0].length() / 50.0).abs() < 1e-12 && c.y.abs() < 1e-12);
    }

    /// An orthographic camera on x, y in [-1, 1] (y up), depth 0.5 - z / 10, and the
    /// reference of `scene` under it on 64 x 64 pixels over black: each pixel's alpha.
    fn alphas(scene: &crate::scene::Scene) -> (Vec<f64>, Vec<bool>) {
        let rows = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, -0.1, 0.5], [0.0, 0.0, 0.0, 1.0]];
        let camera = crate::scene::Camera::from_rows(rows).unwrap();
        let r = crate::reference::reference(scene, &camera, 64, 64, [0.0; 3]).unwrap();
        (r.image.chunks_exact(4).map(|p| p[3]).collect(), r.ambiguous)
    }

    /// The world standard deviation whose screen variance, low-pass included, is `px2` pixels²
    /// on the 64-pixel frame of `alphas` (32 pixels a unit).
    fn sigma_for(px2: f64) -> f32 {
        ((px2 - LOW_PASS).sqrt() / 32.0) as f32
    }

    /// The mean that projects onto the center of pixel (32, 32).
    const CENTER: [f32; 3] = [1.0 / 64.0, -1.0 / 64.0, 0.0];

    #[test]
    fn a_gaussian_has_its_analytic_alpha_at_its_center_one_and_two_sigma_and_none_past_three() {
        // 4 pixels of standard deviation across, 3 down the screen, opacity 0.9375, white.
        let mut scene = crate::scene::Scene::new();
        let s = [sigma_for(16.0), sigma_for(9.0), 0.01];
        scene.add_gaussians(vec![CENTER], vec![s], vec![[1.0, 0.0, 0.0, 0.0]], vec![0.9375], vec![[1.0; 3]]).unwrap();
        let (a, ambiguous) = alphas(&scene);
        let at = |dx: i32, dy: i32| {
            let i = ((32 + dy) * 64 + 32 + dx) as usize;
            // The center is on the quad's diagonal, an edge of both triangles: ambiguous for
            // coverage, though either triangle gives it the same alpha.
            assert!(!ambiguous[i] || (dx, dy) == (0, 0), "pixel ({dx}, {dy}) is ambiguous");
            a[i]
        };
        // The standard deviations are float32: 1e-7 of the variance.
        let close = |got: f64, want: f64| assert!((got - want).abs() < 1e-7, "{got} against {want}");
        close(at(0, 0), 0.9375);
        for k in [1.0f64, 2.0] {
            let want = 0.9375 * (-0.5 * k * k).exp();
            close(at(4 * k as i32, 0), want);
            close(at(-4 * k as i32, 0), want);
            close(at(0, 3 * k as i32), want);
            close(at(0, -3 * k as i32), want);
        }
        // Past three sigma (3.25 along x, 3.33 along y), where 0.9375 exp(-½ 3.25²) = 0.0048 is
        // still above 1/255: the quad's cut, not the clamp, hides it.
        close(at(13, 0), 0.0);
        close(at(0, 10), 0.0);
        close(at(0, -10), 0.0);
        // Nothing past the 3-sigma ellipse anywhere.
        let drawn = a.iter().filter(|&&x| x > 0.0).count();
        assert!(drawn > 0 && drawn < 4 * 12 * 9, "{drawn} pixels drawn");
    }

    #[test]
    fn a_rotated_anisotropic_gaussian_matches_its_projected_ellipse() {
        // Standard deviations 6 and 2 pixels (low-pass included) rotated 30 degrees in the view
        // plane.
        let (a2, b2) = (36.0, 4.0);
        let theta = 30f64.to_radians();
        let qz = DQuat::from_rotation_z(theta);
        let q = [qz.w as f32, qz.x as f32, qz.y as f32, qz.z as f32];
        let mut scene = crate::scene::Scene::new();
        scene.add_gaussians(vec![CENTER], vec![[sigma_for(a2), sigma_for(b2), 0.05]], vec![q], vec![0.875], vec![[1.0; 3]]).unwrap();
        let (a, ambiguous) = alphas(&scene);
        // Σ' in pixels, y up: R diag(a², b²) Rᵀ (the low-pass is in a² and b² already).
        let r = glam::DMat2::from_angle(theta);
        let inv = (r * glam::DMat2::from_diagonal(DVec2::new(a2, b2)) * r.transpose()).inverse();
        let (mut checked, mut max_err) = (0, 0.0f64);
        for y in 0..64 {
            for x in 0..64 {
                let d = DVec2::new(x as f64 - 32.0, 32.0 - y as f64);
                let m = d.dot(inv * d);
                let want = if m < 9.0 { clamp_alpha(0.875 * (-0.5 * m).exp()).0 } else { 0.0 };
                let i = y * 64 + x;
                if !ambiguous[i] {
                    checked += 1;
                    max_err = max_err.max((a[i] - want).abs());
                }
            }
        }
        // The standard deviations are float32: 1e-7 of the variance.
        assert!(checked > 4000 && max_err < 1e-7, "{checked} pixels checked, max error {max_err}");
    }

    #[test]
    fn alpha_is_clamped_as_3dgs_clamps_it() {
        assert_eq!(clamp_alpha(1.0).0, ALPHA_MAX);
        assert_eq!(clamp_alpha(0.5).0, 0.5);
        assert_eq!(clamp_alpha(0.003).0, 0.0);
    }
}
