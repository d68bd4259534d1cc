//! The orbit camera: a pivot, a direction and a distance, turned into the same matrices as
//! `oit.Camera.look_at` (python/oit/_camera.py), at the view's aspect ratio.

use glam::{DMat4, DVec3, DVec4};

use crate::scenefile::{CameraSpec, NamedMesh};

/// Radians per point of mouse drag.
const ORBIT_SPEED: f64 = 0.008;
/// Keeps the view direction this far (radians) from the turntable axis.
const POLE_MARGIN: f64 = 0.02;

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Orbit {
    pub pivot: DVec3,
    /// Unit vector from the pivot to the eye.
    pub dir: DVec3,
    pub distance: f64,
    /// The turntable axis, also the look-at up vector.
    pub up: DVec3,
    pub fov_y: f64,
    /// Near and far planes as multiples of `distance`, so zooming keeps the depth range.
    pub near_ratio: f64,
    pub far_ratio: f64,
}

/// The camera the viewer shows: an orbit, or a matrix it could not read as a perspective
/// look-at (orthographic, off-center), kept as is until the user moves the view.
#[derive(Clone, Debug)]
pub struct ViewCamera {
    pub orbit: Orbit,
    pub fixed: Option<DMat4>,
    home: (Orbit, Option<DMat4>),
}

/// Center and radius of the bounding sphere of the meshes' bounding box (instances placed).
pub fn bounds(meshes: &[NamedMesh]) -> (DVec3, f64) {
    let Some((lo, hi)) = oit_core::load::bounds(meshes) else { return (DVec3::ZERO, 1.0) };
    let center = (lo + hi) / 2.0;
    (center, ((hi - lo).length() / 2.0).max(1e-6))
}

impl Orbit {
    pub fn eye(&self) -> DVec3 {
        self.pivot + self.dir * self.distance
    }

    /// As `oit.Camera.fit`: the bounding sphere framed from direction (0.3, 0.35, 1), 40° fov.
    pub fn fit(center: DVec3, radius: f64) -> Self {
        let fov_y: f64 = 40.0;
        let distance = radius / (fov_y.to_radians() / 2.0).sin() * 1.05;
        let near = (distance - radius * 1.5).max(distance * 1e-3);
        let far = distance + radius * 1.5;
        Self {
            pivot: center,
            dir: DVec3::new(0.3, 0.35, 1.0).normalize(),
            distance,
            up: DVec3::Y,
            fov_y,
            near_ratio: near / distance,
            far_ratio: far / distance,
        }
    }

    pub fn look_at(eye: DVec3, target: DVec3, up: DVec3, fov_y: f64, near: f64, far: f64) -> Option<Self> {
        let d = eye - target;
        let distance = d.length();
        let ok = distance > 0.0 && d.cross(up).length() > 1e-12 * distance * up.length() && near > 0.0 && far > near;
        ok.then(|| Self {
            pivot: target,
            dir: d / distance,
            distance,
            up: up.normalize(),
            fov_y,
            near_ratio: near / distance,
            far_ratio: far / distance,
        })
    }

    /// Reads a perspective view-projection back into eye, view axes, fov and planes; the
    /// pivot is the point of the view axis nearest `center`. None for other matrices.
    pub fn from_matrix(m: DMat4, center: DVec3) -> Option<Self> {
        let inv = m.inverse();
        let eye_h = inv * DVec4::new(0.0, 0.0, 1.0, 0.0);
        if eye_h.w.abs() < 1e-12 * eye_h.truncate().length().max(1.0) {
            return None; // the eye is at infinity: orthographic
        }
        let eye = eye_h.truncate() / eye_h.w;
        let unproject = |x: f64, y: f64, z: f64| {
            let p = inv * DVec4::new(x, y, z, 1.0);
            p.truncate() / p.w
        };
        let (n, f) = (unproject(0.0, 0.0, 0.0), unproject(0.0, 0.0, 1.0));
        let up_edge = unproject(0.0, 1.0, 0.0) - n;
        let right_edge = unproject(1.0, 0.0, 0.0) - n;
        let near = (n - eye).length();
        let far = (f - eye).length();
        let forward = (n - eye) / near;
        let fov_y = 2.0 * (up_edge.length() / near).atan().to_degrees();
        let aspect = right_edge.length() / up_edge.length();
        let true_up = up_edge.normalize();
        // Prefer world +Y as the turntable axis when it gives the same view (no roll).
        let up = if forward.cross(DVec3::Y).normalize().abs_diff_eq(forward.cross(true_up).normalize(), 1e-9) { DVec3::Y } else { true_up };
        let t = (center - eye).dot(forward);
        let t = if t > near { t } else { (near + far) / 2.0 };
        let orbit = Self::look_at(eye, eye + forward * t, up, fov_y, near, far)?;
        // Only a matrix that is exactly such a look-at is read as one.
        let back = orbit.matrix(aspect);
        let scale = m.to_cols_array().iter().fold(0.0f64, |a, v| a.max(v.abs()));
        let same = back.to_cols_array().iter().zip(m.to_cols_array()).all(|(a, b)| (a - b).abs() <= 1e-9 * scale);
        same.then_some(orbit)
    }

    /// View-projection for a view of the given aspect (width / height).
    pub fn matrix(&self, aspect: f64) -> DMat4 {
        let (near, far) = (self.near_ratio * self.distance, self.far_ratio * self.distance);
        let f = 1.0 / (self.fov_y.to_radians() / 2.0).tan();
        let proj = DMat4::from_cols(
            DVec4::new(f / aspect, 0.0, 0.0, 0.0),
            DVec4::new(0.0, f, 0.0, 0.0),
            DVec4::new(0.0, 0.0, far / (near - far), -1.0),
            DVec4::new(0.0, 0.0, near * far / (near - far), 0.0),
        );
        let eye = self.eye();
        let fwd = (self.pivot - eye).normalize();
        let s = fwd.cross(self.up).normalize();
        let u = s.cross(fwd);
        let view = DMat4::from_cols(
            DVec4::new(s.x, u.x, -fwd.x, 0.0),
            DVec4::new(s.y, u.y, -fwd.y, 0.0),
            DVec4::new(s.z, u.z, -fwd.z, 0.0),
            DVec4::new(-s.dot(eye), -u.dot(eye), fwd.dot(eye), 1.0),
        );
        proj * view
    }

    /// Drag by (dx, dy) points: around the turntable axis, then up and down.
    pub fn rotate(&mut self, dx: f64, dy: f64) {
        let yaw = glam::DQuat::from_axis_angle(self.up, -dx * ORBIT_SPEED);
        let mut dir = yaw * self.dir;
        let right = self.up.cross(dir).normalize();
        let pitched = glam::DQuat::from_axis_angle(right, -dy * ORBIT_SPEED) * dir;
        let polar = pitched.dot(self.up).clamp(-1.0, 1.0).acos();
        if polar > POLE_MARGIN && polar < std::f64::consts::PI - POLE_MARGIN {
            dir = pitched;
        }
        self.dir = dir.normalize();
    }

    /// Moves the pivot so that the scene follows a drag of (dx, dy) over a view `height`
    /// points tall.
    pub fn pan(&mut self, dx: f64, dy: f64, height: f64) {
        let fwd = -self.dir;
        let s = fwd.cross(self.up).normalize();
        let u = s.cross(fwd);
        let per_point = 2.0 * self.distance * (self.fov_y.to_radians() / 2.0).tan() / height.max(1.0);
        self.pivot += (-dx * s + dy * u) * per_point;
    }

    /// Scroll `amount` points: positive moves closer.
    pub fn zoom(&mut self, amount: f64) {
        self.distance *= (-amount * 0.002).exp();
    }
}

impl ViewCamera {
    /// The file's camera (a look-at, or a matrix read back into one where possible) or a fit.
    pub fn new(spec: Option<&CameraSpec>, meshes: &[NamedMesh]) -> Self {
        let (center, radius) = bounds(meshes);
        let fit = Orbit::fit(center, radius);
        let (orbit, fixed) = match spec {
            Some(CameraSpec::LookAt { eye, target, up, fov_y, near, far }) => {
                let o = Orbit::look_at(DVec3::from(*eye), DVec3::from(*target), DVec3::from(*up), *fov_y, *near, *far);
                (o.unwrap_or(fit), None)
            }
            Some(CameraSpec::Matrix(rows)) => {
                let m = DMat4::from_cols_array_2d(rows).transpose();
                match Orbit::from_matrix(m, center) {
                    Some(o) => (o, None),
                    None => (fit, Some(m)),
                }
            }
            None => (fit, None),
        };
        Self { orbit, fixed, home: (orbit, fixed) }
    }

    pub fn reset(&mut self) {
        (self.orbit, self.fixed) = self.home;
    }

    pub fn is_home(&self) -> bool {
        (self.orbit, self.fixed) == self.home
    }

    /// Row-major view-projection, as `Camera::from_rows` takes it.
    pub fn rows(&self, aspect: f64) -> [[f64; 4]; 4] {
        let m = self.fixed.unwrap_or_else(|| self.orbit.matrix(aspect));
        m.transpose().to_cols_array_2d()
    }

    /// Any movement leaves a fixed matrix for the orbit.
    pub fn moved(&mut self) -> &mut Orbit {
        self.fixed = None;
        &mut self.orbit
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The Python look_at's matrix for eye (1.2, 0.9, 1.8), target 0, fov 45, planes 1 and 5,
    /// aspect 1 (the glass scene), computed with numpy.
    #[test]
    fn look_at_matches_python_and_reads_back() {
        let o = Orbit::look_at(DVec3::new(1.2, 0.9, 1.8), DVec3::ZERO, DVec3::Y, 45.0, 1.0, 5.0).unwrap();
        let m = o.matrix(1.0);
        let f = 1.0 / (22.5f64).to_radians().tan();
        let fwd = -DVec3::new(1.2, 0.9, 1.8).normalize();
        let s = fwd.cross(DVec3::Y).normalize();
        // Row 0 of P·V is f·s (aspect 1) and its translation f·(-s·eye) = 0 here.
        assert!((m.row(0) - DVec4::new(f * s.x, f * s.y, f * s.z, 0.0)).length() < 1e-12);
        // Row 3 is -(-fwd) · [x - eye]: w = distance along the view axis.
        assert!((m.row(3).truncate() - fwd).length() < 1e-12);
        let back = Orbit::from_matrix(m, DVec3::ZERO).unwrap();
        assert!((back.matrix(1.0) - m).to_cols_array().iter().all(|d| d.abs() < 1e-9));
        assert_eq!(back.up, DVec3::Y);
        assert!((back.pivot - DVec3::ZERO).length() < 1e-9);
        assert!((back.fov_y - 45.0).abs() < 1e-9);
    }

    #[test]
    fn orthographic_matrices_stay_fixed() {
        assert!(Orbit::from_matrix(DMat4::IDENTITY, DVec3::ZERO).is_none());
        let mut identity = [[0.0; 4]; 4];
        (0..4).for_each(|i| identity[i][i] = 1.0);
        let mut cam = ViewCamera::new(Some(&CameraSpec::Matrix(identity)), &[]);
        assert_eq!(cam.rows(2.0), identity);
        cam.moved().rotate(10.0, 0.0);
        assert_ne!(cam.rows(1.0), identity);
        cam.reset();
        assert_eq!(cam.rows(1.0), identity);
    }

    #[test]
    fn orbit_keeps_distance_and_clamps_at_the_poles() {
        let mut o = Orbit::fit(DVec3::ZERO, 1.0);
        let d = o.distance;
        o.rotate(50.0, 0.0);
        assert!((o.distance - d).abs() < 1e-12 && (o.dir.length() - 1.0).abs() < 1e-12);
        o.rotate(0.0, 1e5);
        assert!(o.dir.dot(o.up).abs() < 1.0);
        o.zoom(100.0);
        assert!(o.distance < d);
    }
}
