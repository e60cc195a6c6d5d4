//! The camera: a perspective look-at view, checked before use (every view of the renderer and
//! every host camera ends as one).

use glam::{Mat4, Vec2, Vec3, Vec4};

/// A perspective look-at camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    /// Eye position.
    pub eye: Vec3,
    /// Point looked at.
    pub target: Vec3,
    /// Up direction.
    pub up: Vec3,
    /// Vertical field of view, radians.
    pub fov_y: f32,
    /// Near plane distance.
    pub near: f32,
    /// Far plane distance.
    pub far: f32,
    /// Where the view axis meets the image, in normalised device coordinates (0: the centre;
    /// off-centre and jittered projections of host engines, `render::HostCamera`).
    pub shift: Vec2,
    /// Image x mirrored: the view is a reflection (a host whose world and view space differ in
    /// handedness, `render::HostCamera`); every pipeline is two-sided, so only the
    /// picture flips.
    pub mirror: bool,
}

/// Check a camera: finite eye and target, eye != target, vertical field of view in degrees in
/// `(0, 180)`. Used by `render`, scene files and the renderer alike.
pub fn validate_camera(eye: Vec3, target: Vec3, fov_y_degrees: f32) -> Result<(), String> {
    if !eye.is_finite() || !target.is_finite() {
        return Err(format!(
            "camera eye {eye} and target {target} must be finite"
        ));
    }
    if eye.abs().max(target.abs()).max_element() > MAX_CAMERA_COORDINATE {
        return Err(format!(
            "camera eye {eye} and target {target} must lie within {MAX_CAMERA_COORDINATE:e} of the origin (32-bit floats are 2 mm apart there)"
        ));
    }
    if eye.distance(target) <= 1e-6 * eye.length().max(1.0) {
        return Err(format!("camera eye and target are the same point {eye}"));
    }
    if !(MIN_FOV_DEGREES..=MAX_FOV_DEGREES).contains(&fov_y_degrees) {
        return Err(format!(
            "field of view {fov_y_degrees} degrees is outside {MIN_FOV_DEGREES}..={MAX_FOV_DEGREES}"
        ));
    }
    Ok(())
}

/// Narrowest vertical field of view accepted, degrees.
pub const MIN_FOV_DEGREES: f32 = 0.1;
/// Widest vertical field of view accepted, degrees.
pub const MAX_FOV_DEGREES: f32 = 179.0;
/// Largest camera coordinate accepted, metres: the world is rendered in 32-bit floats, whose
/// spacing at 2e4 is 2 mm (characters stand within `scene::MAX_TRANSLATION`).
pub const MAX_CAMERA_COORDINATE: f32 = 2e4;

impl Camera {
    /// [`Camera::look_at`] after [`validate_camera`].
    pub fn checked(eye: Vec3, target: Vec3, fov_y_degrees: f32) -> Result<Self, String> {
        validate_camera(eye, target, fov_y_degrees)?;
        Ok(Camera::look_at(eye, target, fov_y_degrees))
    }

    /// Look from `eye` at `target` with a vertical field of view in degrees.
    pub fn look_at(eye: Vec3, target: Vec3, fov_y_degrees: f32) -> Self {
        let dist = eye.distance(target).max(1e-3);
        Camera {
            eye,
            target,
            up: Vec3::Y,
            fov_y: fov_y_degrees.to_radians(),
            near: dist * 0.01,
            far: dist * 20.0,
            shift: Vec2::ZERO,
            mirror: false,
        }
    }

    /// Frame a bounding box from direction `dir` (from the target toward the eye).
    pub fn framing(lo: Vec3, hi: Vec3, dir: Vec3, fov_y_degrees: f32) -> Self {
        let centre = (lo + hi) * 0.5;
        let radius = ((hi - lo) * 0.5).length().max(1e-3);
        let dist = radius / (fov_y_degrees.to_radians() * 0.5).tan() * 1.1;
        Camera::look_at(
            centre + dir.normalize_or(Vec3::Z) * dist,
            centre,
            fov_y_degrees,
        )
    }

    /// Vulkan clip-space view-projection (y down, depth 0..1).
    pub fn view_proj(&self, aspect: f32) -> Mat4 {
        // Right-handed view, Vulkan projection: y down in clip space, depth in [0, 1].
        let f = (self.target - self.eye).normalize_or(Vec3::NEG_Z);
        let s = f.cross(self.up).normalize_or(Vec3::X);
        let u = s.cross(f);
        let view = Mat4::from_cols(
            Vec4::new(s.x, u.x, -f.x, 0.0),
            Vec4::new(s.y, u.y, -f.y, 0.0),
            Vec4::new(s.z, u.z, -f.z, 0.0),
            Vec4::new(-s.dot(self.eye), -u.dot(self.eye), f.dot(self.eye), 1.0),
        );
        let g = 1.0 / (self.fov_y * 0.5).tan();
        let (n, fa) = (self.near, self.far);
        let sx = if self.mirror { -g / aspect } else { g / aspect };
        let proj = Mat4::from_cols(
            Vec4::new(sx, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -g, 0.0, 0.0),
            // The view axis lands on `shift` (w = -z).
            Vec4::new(-self.shift.x, -self.shift.y, fa / (n - fa), -1.0),
            Vec4::new(0.0, 0.0, n * fa / (n - fa), 0.0),
        );
        proj * view
    }
}
