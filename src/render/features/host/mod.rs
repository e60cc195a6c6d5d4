//! Hair in a host engine's frame: the host's camera matrices ([`HostCamera`]), its colour and
//! depth targets ([`HostImage`]) and the frame it records ([`HostFrame`], drawn by
//! [`super::Renderer::record_host_frame`]).
//!
//! The renderer draws the hair into its own targets with its own camera, made from the host's
//! matrices so that both put every world point on the same pixel: the host's view and
//! projection are brought to one convention (right-handed view space, the image x not
//! mirrored), and the host's depth is converted pixel by pixel into the renderer's through the
//! view-space depth both projections encode ([`DepthMapping`], `glsl/host_depth.frag`). So any
//! depth convention works: standard or reversed, finite or infinite far plane, left- or
//! right-handed. The hair, premultiplied by its coverage, is then composited over the host's
//! colour (`glsl/host_composite.frag`).

use glam::{Mat4, Vec2, Vec3};

pub mod targets;

use crate::render::core::camera::Camera;
use crate::vk::{Access, Image};

/// A host's camera: its world-to-view and view-to-clip matrices, in Vulkan's clip space (x to
/// the right, depth in `[0, 1]`). View space may be right-handed (looking down -z) or
/// left-handed (+z); depth may be standard or reversed, with a finite or infinite far plane;
/// the projection may be off-centre (jitter). A projection with y up in clip space (OpenGL
/// style) is taken to be drawn with a flipped (negative-height) viewport, as Vulkan hosts with
/// such matrices do: the picture is upright either way.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostCamera {
    /// World to view.
    pub view: Mat4,
    /// View to clip.
    pub proj: Mat4,
}

/// The depth a projection stores for a view-space depth `z` (right-handed, negative ahead):
/// `d = (a z + b) / (c z + e)`, from the projection's z and w rows.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthRow {
    /// `a`, `b`, `c`, `e`.
    pub coefficients: [f32; 4],
}

impl DepthRow {
    /// The depth row of a right-handed projection.
    pub fn of(proj: Mat4) -> Self {
        DepthRow {
            coefficients: [proj.z_axis.z, proj.w_axis.z, proj.z_axis.w, proj.w_axis.w],
        }
    }

    /// The depth stored for view-space depth `z`.
    pub fn depth(&self, z: f32) -> f32 {
        let [a, b, c, e] = self.coefficients;
        (a * z + b) / (c * z + e)
    }

    /// The view-space depth stored as `d`; `None` where no finite point in front of the camera
    /// is (the far plane of an infinite projection: the host's background).
    pub fn view_z(&self, d: f32) -> Option<f32> {
        let [a, b, c, e] = self.coefficients;
        let den = d * c - a;
        let z = (b - d * e) / den;
        (den.abs() > f32::MIN_POSITIVE && z.is_finite() && z < 0.0).then_some(z)
    }
}

/// How a host's depth becomes the renderer's: through the view-space depth (CPU twin of
/// `glsl/host_depth.frag`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DepthMapping {
    /// The host's projection.
    pub host: DepthRow,
    /// The renderer's.
    pub ours: DepthRow,
    /// Metres the host's surfaces are moved away from the camera, along view-space depth
    /// ([`HostFrame::depth_slack`]).
    pub slack: f32,
}

impl DepthMapping {
    /// The renderer's depth for the host's depth `d` (1, the far plane, where the host's depth
    /// is its background; clamped to `[0, 1]`: host geometry nearer than the near plane hides
    /// everything behind it).
    pub fn convert(&self, d: f32) -> f32 {
        match self.moved_host().view_z(d) {
            Some(z) => self.ours.depth(z).clamp(0.0, 1.0),
            None => 1.0,
        }
    }

    /// The push constants of `glsl/host_depth.frag`.
    pub fn constants(&self) -> [[f32; 4]; 2] {
        [self.moved_host().coefficients, self.ours.coefficients]
    }

    /// The host's depth row with its surfaces `slack` farther away: `d(z + slack)` as a row in
    /// `z`, `(a z + (a s + b)) / (c z + (c s + e))`, so its inverse gives `z - slack`.
    fn moved_host(&self) -> DepthRow {
        let [a, b, c, e] = self.host.coefficients;
        let s = self.slack;
        DepthRow {
            coefficients: [a, a * s + b, c, c * s + e],
        }
    }
}

/// The renderer's view of a host camera.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct HostView {
    /// A camera that puts every point on the pixel the host's matrices put it on.
    pub camera: Camera,
    /// Its depth from the host's.
    pub depth: DepthMapping,
    /// The host's depth is reversed (1 near, 0 far).
    pub reversed: bool,
    /// The host's near and far planes (far: infinite for infinite projections).
    pub planes: (f32, f32),
}

/// Relative tolerance of the checks on a host's matrices.
const MATRIX_TOLERANCE: f32 = 1e-3;

impl HostCamera {
    /// The renderer's camera for a `width x height` target seeing what this camera sees: its
    /// near plane is the host's; its far plane the host's, or `far` when that is nearer (the
    /// renderer's depth is standard and finite: `far` should enclose the hair). Errors name what
    /// is wrong with the matrices.
    pub fn view(&self, (width, height): (u32, u32), far: f32) -> Result<HostView, String> {
        let (view, proj) = self.right_handed()?;
        let (sx, sy) = (proj.x_axis.x, proj.y_axis.y);
        let skew = [proj.x_axis.y, proj.y_axis.x, proj.x_axis.z, proj.y_axis.z];
        if sx == 0.0 || sy == 0.0 || skew.iter().any(|v| v.abs() > MATRIX_TOLERANCE * sy.abs()) {
            return Err(format!(
                "the projection {proj} scales x by {sx} and y by {sy} with skew {skew:?}: not a perspective projection"
            ));
        }
        let g = sy.abs();
        let aspect = width as f32 / height as f32;
        if ((g / sx.abs()) / aspect - 1.0).abs() > MATRIX_TOLERANCE {
            return Err(format!(
                "the projection's aspect ratio {} is not the {width}x{height} target's {aspect}",
                g / sx.abs()
            ));
        }
        // Off-centre: the view axis lands at ndc = -(z column), with y as the picture shows it.
        let (ox, oy) = (proj.z_axis.x, proj.z_axis.y);
        let shift = Vec2::new(-ox, if sy < 0.0 { -oy } else { oy });
        let (near, host_far, reversed) = planes(&proj)?;
        let mut camera = rigid_camera(view, sx < 0.0)?;
        camera.fov_y = 2.0 * (1.0 / g).atan();
        camera.shift = shift;
        camera.near = near;
        camera.far = host_far.min(far.max(near * 2.0));
        let ours = DepthRow::of(camera_projection(&camera, aspect));
        Ok(HostView {
            camera,
            depth: DepthMapping {
                host: DepthRow::of(proj),
                ours,
                slack: 0.0,
            },
            reversed,
            planes: (near, host_far),
        })
    }

    /// Where the camera is, in world space (a handedness flip of view space leaves it there).
    pub fn eye(&self) -> Vec3 {
        self.view.inverse().transform_point3(Vec3::ZERO)
    }

    /// The host's matrices with a right-handed view space (w = -z, scaled to exactly that):
    /// a left-handed pair is reflected in z on both sides, which leaves clip space unchanged.
    fn right_handed(&self) -> Result<(Mat4, Mat4), String> {
        let (view, mut proj) = (self.view, self.proj);
        if !view.is_finite() || !proj.is_finite() {
            return Err("the view and projection matrices must be finite".into());
        }
        let w = proj.row(3);
        let s = w.z;
        if s.abs() < f32::MIN_POSITIVE
            || w.x.abs().max(w.y.abs()).max(w.w.abs()) > MATRIX_TOLERANCE * s.abs()
        {
            return Err(format!(
                "the projection's w row {w} is not (0, 0, +-1, 0): only perspective projections are drawn"
            ));
        }
        proj *= 1.0 / s.abs();
        if s < 0.0 {
            return Ok((view, proj));
        }
        let flip = Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0));
        Ok((flip * view, proj * flip))
    }
}

/// Near and far planes and whether depth is reversed, from a right-handed projection whose
/// depth is `-a + b / t` at distance `t`.
fn planes(proj: &Mat4) -> Result<(f32, f32, bool), String> {
    let (a, b) = (proj.z_axis.z, proj.w_axis.z);
    let reversed = b > 0.0;
    let over = |num: f32, den: f32| match den {
        0.0 => f32::INFINITY,
        d => num / d,
    };
    // Standard: 0 at the near plane, 1 at the far one; reversed the other way round.
    let (near, far) = match reversed {
        false => (over(b, a), over(b, 1.0 + a)),
        true => (over(b, 1.0 + a), over(b, a)),
    };
    let far = if far > 0.0 { far } else { f32::INFINITY };
    if !(near > 0.0 && near.is_finite() && far > near) {
        return Err(format!(
            "the projection's depth rows give a near plane at {near} and a far one at {far}"
        ));
    }
    Ok((near, far, reversed))
}

/// The look-at camera of a rigid right-handed `view`, seen through a projection that mirrors
/// x when `mirrored`; errors when the view matrix scales or shears. A view that is a
/// reflection (the host's world and view space differ in handedness) is reflected in x once
/// more, and the picture mirrored instead: clip space stays the same.
fn rigid_camera(view: Mat4, mirrored: bool) -> Result<Camera, String> {
    let r = glam::Mat3::from_mat4(view);
    let gram = r.transpose() * r;
    let off = (gram - glam::Mat3::IDENTITY).to_cols_array();
    if off.iter().any(|x| x.abs() > MATRIX_TOLERANCE) {
        return Err(format!(
            "the view matrix {view} is not a rotation and a translation (scale or shear)"
        ));
    }
    let reflection = r.determinant() < 0.0;
    let v = match reflection {
        true => Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0)) * view,
        false => view,
    };
    let inverse = v.inverse();
    let eye = inverse.transform_point3(Vec3::ZERO);
    let forward = inverse.transform_vector3(Vec3::NEG_Z).normalize();
    let up = inverse.transform_vector3(Vec3::Y).normalize();
    Ok(Camera {
        eye,
        target: eye + forward,
        up,
        fov_y: 1.0,
        near: 0.1,
        far: 100.0,
        shift: Vec2::ZERO,
        mirror: mirrored != reflection,
    })
}

/// The projection part of `camera`'s view-projection for `aspect`.
fn camera_projection(camera: &Camera, aspect: f32) -> Mat4 {
    let at_origin = Camera {
        eye: Vec3::ZERO,
        target: Vec3::NEG_Z,
        up: Vec3::Y,
        ..*camera
    };
    at_origin.view_proj(aspect)
}

/// One of the host's images in a host frame: the host says in which use it is and in which use
/// it wants it back; the frame graph orders the renderer's uses after the first and ends in the
/// second.
pub struct HostImage<'a> {
    /// The image ([`Image::from_host`]).
    pub image: &'a Image,
    /// Its use when the frame's commands start (the host's last use).
    pub before: Access,
    /// The use it is left in.
    pub after: Access,
}

/// A frame the host records: its command buffer, the frame slot it has in flight, its camera
/// and targets.
pub struct HostFrame<'a> {
    /// The host's command buffer: recording, outside any render pass. The host submits it.
    pub cmd: ash::vk::CommandBuffer,
    /// The frame slot (`0..FRAMES_IN_FLIGHT`) this frame uses. The host guarantees that the
    /// last frame recorded with this slot has completed on the GPU.
    pub slot: usize,
    /// The host's camera.
    pub camera: HostCamera,
    /// The colour target the hair is composited over (any colour format the device can
    /// render and blend; linear values are written, so an sRGB or float target is exact).
    pub color: HostImage<'a>,
    /// The depth the hair is hidden behind (sampled: created with `SAMPLED` usage, one sample
    /// per pixel); `None`: nothing hides the hair.
    pub depth: Option<HostImage<'a>>,
    /// Metres (world units) the host's depth is pushed away from the camera before it hides
    /// hair: hair that lies on a host's scalp closer than its triangles' sag (hair grown on a
    /// smooth head sits a fraction of a millimetre above it; the mesh's flat triangles cut
    /// through that) is not hidden by it. 0: exact; the Bevy plugin uses 4 mm.
    pub depth_slack: f32,
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec4;

    /// A right-handed look-at and Vulkan projections (y down) of every depth convention.
    fn host_matrices(reversed: bool, infinite: bool) -> HostCamera {
        let (eye, target) = (Vec3::new(1.0, 1.5, 3.0), Vec3::new(0.0, 1.4, 0.0));
        let f = (target - eye).normalize();
        let s = f.cross(Vec3::Y).normalize();
        let u = s.cross(f);
        let view = Mat4::from_cols(
            s.extend(0.0),
            u.extend(0.0),
            (-f).extend(0.0),
            eye.extend(1.0),
        )
        .inverse();
        let (g, aspect, n, far) = (1.0 / 0.4f32.tan(), 1.5, 0.1f32, 50.0f32);
        // Depth -a + b / t at distance t.
        let (a, b) = match (reversed, infinite) {
            (false, false) => (far / (n - far), n * far / (n - far)),
            (false, true) => (-1.0, -n),
            (true, false) => (n / (far - n), n * far / (far - n)),
            (true, true) => (0.0, n),
        };
        let proj = Mat4::from_cols(
            Vec4::new(g / aspect, 0.0, 0.0, 0.0),
            Vec4::new(0.0, -g, 0.0, 0.0),
            Vec4::new(0.0, 0.0, a, -1.0),
            Vec4::new(0.0, 0.0, b, 0.0),
        );
        HostCamera { view, proj }
    }

    fn clip_to_pixel(m: Mat4, p: Vec3) -> Vec2 {
        let c = m * p.extend(1.0);
        Vec2::new(c.x, c.y) / c.w
    }

    #[test]
    fn slack_moves_host_surfaces_away_along_view_depth() {
        let host = host_matrices(true, true);
        let mut v = host.view((1500, 1000), 20.0).unwrap();
        let p = Vec3::new(0.0, 1.4, 0.0);
        let c = host.proj * host.view * p.extend(1.0);
        let d = c.z / c.w;
        let exact = v.depth.convert(d);
        v.depth.slack = 0.01;
        let z = host.view.transform_point3(p).z;
        // The renderer's depth of the point 1 cm farther along view-space depth.
        let moved = v.depth.ours.depth(z - 0.01);
        assert!((v.depth.convert(d) - moved).abs() < 1e-6);
        assert!(v.depth.convert(d) > exact);
        let row = DepthRow {
            coefficients: v.depth.constants()[0],
        };
        assert!(
            (row.view_z(d).unwrap() - (z - 0.01)).abs() < 1e-5,
            "the shader gets it"
        );
    }

    #[test]
    fn every_depth_convention_maps_points_and_depth_alike() {
        let points = [
            Vec3::new(0.1, 1.3, 0.2),
            Vec3::new(-0.4, 1.8, -2.0),
            Vec3::new(0.0, 1.4, 0.0),
        ];
        for reversed in [false, true] {
            for infinite in [false, true] {
                let host = host_matrices(reversed, infinite);
                let v = host.view((1500, 1000), 20.0).unwrap();
                assert_eq!(v.reversed, reversed);
                assert!((v.planes.0 - 0.1).abs() < 1e-4, "{:?}", v.planes);
                assert_eq!(v.planes.1.is_infinite(), infinite);
                let ours = v.camera.view_proj(1.5);
                for p in points {
                    let (a, b) = (
                        clip_to_pixel(host.proj * host.view, p),
                        clip_to_pixel(ours, p),
                    );
                    assert!((a - b).length() < 1e-4, "{reversed} {infinite}: {a} vs {b}");
                    // Depth through the mapping is our depth of the same point.
                    let hc = host.proj * host.view * p.extend(1.0);
                    let oc = ours * p.extend(1.0);
                    let d = v.depth.convert(hc.z / hc.w);
                    assert!((d - oc.z / oc.w).abs() < 1e-4, "{d} vs {}", oc.z / oc.w);
                }
                // The host's background is our far plane.
                let background = if reversed { 0.0 } else { 1.0 };
                assert_eq!(v.depth.convert(background), 1.0);
            }
        }
    }

    #[test]
    fn left_handed_off_centre_and_flipped_hosts_land_on_the_same_pixels() {
        let rh = host_matrices(true, true);
        let p = Vec3::new(0.3, 1.2, -0.5);
        // The same camera in a left-handed world (z negated) with left-handed matrices.
        let z = Mat4::from_scale(Vec3::new(1.0, 1.0, -1.0));
        let lh = HostCamera {
            view: z * rh.view * z,
            proj: rh.proj * z,
        };
        let v = lh.view((1500, 1000), 20.0).unwrap();
        let host_pixel = clip_to_pixel(lh.proj * lh.view, z.transform_point3(p));
        let ours = clip_to_pixel(v.camera.view_proj(1.5), z.transform_point3(p));
        assert!(
            (host_pixel - ours).length() < 1e-4,
            "{host_pixel} vs {ours}"
        );
        // Jitter: an off-centre projection moves the picture by the same amount.
        let mut jittered = rh;
        jittered.proj.z_axis.x += 0.01;
        jittered.proj.z_axis.y -= 0.02;
        let v = jittered.view((1500, 1000), 20.0).unwrap();
        let a = clip_to_pixel(jittered.proj * jittered.view, p);
        let b = clip_to_pixel(v.camera.view_proj(1.5), p);
        assert!((a - b).length() < 1e-4, "{a} vs {b}");
        // OpenGL-style y up: drawn with a flipped viewport, so the picture's y is negated.
        let mut gl = rh;
        gl.proj.y_axis.y = -gl.proj.y_axis.y;
        let v = gl.view((1500, 1000), 20.0).unwrap();
        let a = clip_to_pixel(gl.proj * gl.view, p);
        let b = clip_to_pixel(v.camera.view_proj(1.5), p);
        assert!((a * Vec2::new(1.0, -1.0) - b).length() < 1e-4, "{a} vs {b}");
    }

    #[test]
    fn bad_matrices_are_refused() {
        let good = host_matrices(false, false);
        let cases = [
            (
                HostCamera {
                    proj: Mat4::from_scale(Vec3::new(0.5, -0.5, 0.1)),
                    ..good
                },
                "perspective",
            ),
            (
                HostCamera {
                    view: good.view * Mat4::from_scale(Vec3::splat(2.0)),
                    ..good
                },
                "scale",
            ),
            (
                HostCamera {
                    view: Mat4::NAN,
                    ..good
                },
                "finite",
            ),
        ];
        for (host, says) in cases {
            let e = host.view((1500, 1000), 20.0).unwrap_err();
            assert!(e.contains(says), "{e}");
        }
        let e = good.view((1000, 1000), 20.0).unwrap_err();
        assert!(e.contains("aspect"), "{e}");
    }
}
