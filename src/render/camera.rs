//! Camera, LoD settings and the per-view data of a frame ([`View`] -> [`FrameBlock`]).

use glam::{Mat4, Vec3, Vec4};

pub use super::core::camera::{
    Camera, MAX_CAMERA_COORDINATE, MAX_FOV_DEGREES, MIN_FOV_DEGREES, validate_camera,
};
use super::core::shared::{CountFields, FrameBlock, LodFields, ShadingFields};

/// Default viewing direction (target toward eye) of `render`, `bench` and the tests: a 3/4 view
/// from behind and above, where the sample heads show their hair.
pub const DEFAULT_VIEW_DIR: Vec3 = Vec3::new(0.7, 0.35, -1.0);

/// Check a light direction: finite and not zero.
pub fn validate_light(direction: Vec3) -> Result<(), String> {
    if !direction.is_finite() || direction.length() < 1e-12 {
        return Err(format!(
            "light direction {direction} must be finite and non-zero"
        ));
    }
    Ok(())
}

/// Strand alpha of [`LodSettings::crowd`].
pub const CROWD_ALPHA_STRANDS: f32 = 0.05;

/// The area term's extent of [`LodSettings::crowd`] (about pixels a bundle spans).
pub const CROWD_AREA_BELOW: f32 = 8.0;

/// The pixel cap of [`LodSettings::crowd`]: strands per square pixel of a bundle's extent.
pub const CROWD_STRANDS_PER_PIXEL: f32 = 0.5;

/// Level-of-detail settings (paper 003 sec. 3.6): separate alphas for strands and vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LodSettings {
    /// LoD on; off renders every bundle at full detail.
    pub enabled: bool,
    /// Alpha of eq. 7 for strand LoD.
    pub alpha_strands: f32,
    /// Below this extent (eq. 7's `h R / (d tan theta)`, about the pixels a bundle spans) the
    /// strand level falls with the bundle's area, not its width
    /// (`reference::lod::area_factor`); eq. 8's thickness keeps the coverage. 0: off, the
    /// paper's eq. 7. The light's views apply it in texels.
    pub area_below: f32,
    /// At most this many strands per square pixel of a bundle's extent (eq. 7's `h R / (d tan
    /// theta)`, squared; in texels for the light's views): at crowd distance the strands a
    /// bundle draws follow the pixels it covers, not its count at full detail, and eq. 8's
    /// thickness widens them to keep its coverage (`reference::lod::pixel_cap_level`). 0: off.
    pub strands_per_pixel: f32,
    /// Alpha of eq. 7 for vertex LoD.
    pub alpha_verts: f32,
    /// Geomorph transition window lambda of eq. 10-12, in `(0, 1]`.
    pub lambda: f32,
}

impl Default for LodSettings {
    fn default() -> Self {
        LodSettings {
            enabled: true,
            alpha_strands: 0.1,
            area_below: 0.0,
            strands_per_pixel: 0.0,
            alpha_verts: 0.1,
            lambda: 0.5,
        }
    }
}

impl LodSettings {
    /// Check alphas (positive, finite) and lambda (in `(0, 1]`).
    pub fn validate(&self) -> Result<(), String> {
        let alpha_ok = |a: f32| a > 0.0 && a.is_finite();
        if !alpha_ok(self.alpha_strands) || !alpha_ok(self.alpha_verts) {
            return Err("LoD alphas must be positive and finite".into());
        }
        if !(self.area_below >= 0.0 && self.area_below.is_finite()) {
            return Err(format!(
                "LoD area term below {} pixels: need a finite number >= 0",
                self.area_below
            ));
        }
        if !(self.strands_per_pixel >= 0.0 && self.strands_per_pixel.is_finite()) {
            return Err(format!(
                "LoD strands per pixel {}: need a finite number >= 0",
                self.strands_per_pixel
            ));
        }
        if !(self.lambda > 0.0 && self.lambda <= 1.0) {
            return Err(format!("LoD lambda {} is outside (0, 1]", self.lambda));
        }
        Ok(())
    }

    /// The crowd's trade (`crowd`'s default): strands at half the default alpha, vertices at
    /// the default. Paper 003 sec. 3.6 leaves alpha to the user: at 0.1 a bundle 10 pixels
    /// across already draws every strand, several to a pixel, which the thickness term of eq. 8
    /// makes up for at 0.05 with half as many. Measured on lavapipe (2-core VM, 1280x720,
    /// `crowd --headless --frames 4 --orbit off`, frame 3): 100 people 163,711 -> 92,845
    /// strands, 2667 -> 1859 ms, FLIP 0.0077 against 0.1; 1000 people 377,519 -> 193,777
    /// strands, 5443 -> 4164 ms, FLIP 0.0079. A bundle 20 pixels across or more (a portrait's)
    /// draws every strand either way. Below 8 pixels ([`CROWD_AREA_BELOW`]) strands fall with a
    /// bundle's area: 1000 people 193,656 -> 92,166 strands, FLIP 0.0108 (2026-12-07).
    pub fn crowd() -> Self {
        LodSettings {
            alpha_strands: CROWD_ALPHA_STRANDS,
            area_below: CROWD_AREA_BELOW,
            strands_per_pixel: CROWD_STRANDS_PER_PIXEL,
            ..Default::default()
        }
    }

    /// Every bundle at full detail.
    pub fn off() -> Self {
        LodSettings {
            enabled: false,
            ..Default::default()
        }
    }
}

/// The 8 corners of the box `lo..hi`.
pub fn box_corners(lo: Vec3, hi: Vec3) -> [Vec3; 8] {
    std::array::from_fn(|k| {
        Vec3::new(
            if k & 1 == 0 { lo.x } else { hi.x },
            if k & 2 == 0 { lo.y } else { hi.y },
            if k & 4 == 0 { lo.z } else { hi.z },
        )
    })
}

/// Whether the box `lo..hi` is not entirely outside one of `planes` (CPU twin of `box_visible`
/// in `bundle_lod.glsl`: the corner furthest along each plane's normal is tested).
pub fn box_in_frustum(planes: &[[f32; 4]; 6], lo: Vec3, hi: Vec3) -> bool {
    planes.iter().all(|pl| {
        let n = Vec3::from_slice(&pl[..3]);
        n.dot(Vec3::select(n.cmpge(Vec3::ZERO), hi, lo)) + pl[3] >= 0.0
    })
}

/// Frustum planes of a Vulkan view-projection matrix (Gribb-Hartmann), normalised.
pub fn frustum_planes(m: Mat4) -> [[f32; 4]; 6] {
    let row = |i: usize| Vec4::new(m.x_axis[i], m.y_axis[i], m.z_axis[i], m.w_axis[i]);
    let (r0, r1, r2, r3) = (row(0), row(1), row(2), row(3));
    [r3 + r0, r3 - r0, r3 + r1, r3 - r1, r2, r3 - r2].map(|p| {
        let n = p.truncate().length().max(1e-20);
        (p / n).to_array()
    })
}

/// Direction toward the light of [`View::new`] (normalised by the frame).
pub const DEFAULT_LIGHT_DIR: Vec3 = Vec3::new(0.4, 1.0, 0.6);

/// Direction toward the light of the crowd's look ([`View::crowd_look`]).
pub const CROWD_LIGHT_DIR: Vec3 = Vec3::new(0.4, 1.0, 0.3);

/// A portrait's key light for `camera` (unit, toward the light): from the camera's left,
/// [`PORTRAIT_KEY_AZIMUTH`] round from the view axis and [`PORTRAIT_KEY_ELEVATION`] up, the
/// classic three-quarter key that models a face (one side lit, the other in form shadow, the
/// eyes catching the light below their upper lids).
pub fn portrait_light(camera: &Camera) -> Vec3 {
    let back = (camera.eye - camera.target).normalize_or(Vec3::Z);
    let left = camera.up.cross(back).normalize_or(Vec3::X) * -1.0;
    let up = back.cross(left) * -1.0;
    let (az, el) = (PORTRAIT_KEY_AZIMUTH, PORTRAIT_KEY_ELEVATION);
    (back * (az.cos() * el.cos()) + left * (az.sin() * el.cos()) + up * el.sin()).normalize()
}

/// Azimuth of [`portrait_light`] from the view axis, radians (40 degrees).
pub const PORTRAIT_KEY_AZIMUTH: f32 = 0.70;
/// Elevation of [`portrait_light`], radians (28 degrees).
pub const PORTRAIT_KEY_ELEVATION: f32 = 0.49;

/// Everything per-view a frame needs: camera, light, image size and LoD settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct View {
    /// The camera.
    pub camera: Camera,
    /// Direction toward the light.
    pub light_dir: Vec3,
    /// LoD settings.
    pub lod: LodSettings,
    /// Shading model of the strands.
    pub shading: crate::shade::ShadingModel,
    /// Shadows from the light (hair on hair, hair and bodies on each other).
    pub shadows: super::settings::ShadowMode,
    /// How strands are composited: opaque, k-buffer OIT or depth peeling.
    pub transparency: super::transparency::Transparency,
    /// Seed 000's aggregated appearance for LoD-thickened strands (opacity and multiple
    /// scattering scaled by the strands a thick strand stands for).
    pub lod_appearance: bool,
    /// Multiple scattering between strands under the Marschner model: dual scattering
    /// (`shade::scattering`; Zinke et al. 2008, seed 000 eqs. 3-4).
    pub multiple_scattering: bool,
    /// Temporal accumulation (jitter, motion vectors, history).
    pub temporal: super::temporal::Temporal,
    /// The volume tier: far hair drawn from density volumes, volumetric ambient occlusion.
    pub volumes: super::volume::VolumeTier,
}

impl View {
    /// `camera` with the defaults: light from above and in front (`DEFAULT_LIGHT_DIR`), LoD
    /// on, the placeholder look, no shadows, opaque strands, seed 000's LoD appearance on,
    /// multiple scattering off, the volume tier off.
    /// Change fields with struct update syntax: `View { shadows, ..View::new(camera) }`.
    pub fn new(camera: Camera) -> View {
        View {
            camera,
            light_dir: DEFAULT_LIGHT_DIR,
            lod: LodSettings::default(),
            shading: Default::default(),
            shadows: Default::default(),
            transparency: Default::default(),
            lod_appearance: true,
            multiple_scattering: false,
            temporal: Default::default(),
            volumes: super::volume::VolumeTier::OFF,
        }
    }

    /// The look `crowd` shows by default, for every tool and test that means it: light from
    /// [`CROWD_LIGHT_DIR`], LoD on with the thick-strand term, Marschner with multiple
    /// scattering, deep opacity shadows, opaque strands, the volume tier on, no temporal
    /// accumulation.
    pub fn crowd_look(camera: Camera) -> View {
        View {
            light_dir: CROWD_LIGHT_DIR,
            shading: crate::shade::ShadingModel::Marschner,
            shadows: super::settings::ShadowMode::DeepOpacity,
            multiple_scattering: true,
            volumes: super::volume::VolumeTier::on(),
            ..View::new(camera)
        }
    }

    /// Check camera, light and LoD settings (finite, in range).
    pub fn validate(&self) -> Result<(), String> {
        let c = &self.camera;
        validate_camera(c.eye, c.target, c.fov_y.to_degrees())?;
        let planes_ok = c.near > 0.0
            && c.far > c.near
            && c.far.is_finite()
            && c.up.is_finite()
            && c.shift.is_finite()
            && c.shift.abs().max_element() < 1e3;
        if !planes_ok {
            return Err(format!(
                "camera near {} / far {} planes or lens shift {} are invalid",
                c.near, c.far, c.shift
            ));
        }
        validate_light(self.light_dir)?;
        self.volumes.validate()?;
        self.lod.validate()
    }

    /// The frame block for `width x height` pixels, `bundles` bundles in `characters`
    /// character slots and a vertex pool of `vertex_budget` slots.
    pub fn frame_block(
        &self,
        width: u32,
        height: u32,
        bundles: u32,
        characters: u32,
        vertex_budget: u32,
    ) -> FrameBlock {
        let camera = &self.camera;
        let vp = camera.view_proj(width as f32 / height as f32);
        FrameBlock {
            view_proj: vp.to_cols_array_2d(),
            eye: camera.eye.to_array(),
            pixels_high: height as f32,
            to_light: self.light_dir.normalize_or(Vec3::Y).to_array(),
            cot_half_fov: 1.0 / (camera.fov_y * 0.5).tan(),
            viewport: [
                width as f32,
                height as f32,
                1.0 / width as f32,
                1.0 / height as f32,
            ],
            planes: frustum_planes(vp),
            lod: LodFields {
                alpha_strands: self.lod.alpha_strands,
                alpha_verts: self.lod.alpha_verts,
                lambda: self.lod.lambda,
                tan_fov: camera.fov_y.tan(),
                ortho_height: 0.0,
                area_below: self.lod.area_below,
                strands_per_pixel: self.lod.strands_per_pixel,
                _pad: 0.0,
            },
            counts: CountFields {
                bundles,
                slots: characters,
                lod_on: self.lod.enabled as u32,
                vertex_budget,
            },
            shading: ShadingFields {
                model: self.shading as u32,
                lod_appearance: self.lod_appearance as u32,
                multiple_scattering: self.multiple_scattering as u32,
                _pad: 0,
            },
            // Filled in by the renderer once the light view is fitted.
            light_view_proj: Mat4::IDENTITY.to_cols_array_2d(),
            shadow: Default::default(),
            // Samples filled in by the renderer.
            transparency: self.transparency.frame_fields(1),
            // Filled in by the renderer for frames with motion vectors.
            temporal: Default::default(),
            clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
            unjittered_view_proj: vp.to_cols_array_2d(),
            // Filled in by the renderer for frames that use the software rasterizer.
            soft: Default::default(),
            // Filled in by the renderer once the bodies' light view is fitted.
            body_view_proj: Mat4::IDENTITY.to_cols_array_2d(),
            body_shadow: Default::default(),
        }
    }
}

/// The camera from [`DEFAULT_VIEW_DIR`] (vertical field of view 40 degrees) at which
/// the bounding sphere of the hair box of `info` spans `pixels` pixels of a frame `height`
/// pixels tall: the inverse of [`hair_pixels`](super::volume::hair_pixels) for a character at the origin, where the switch
/// is measured (tests/volume_tier.rs) and shown (`bench crowd --band-strip`).
pub fn camera_spanning(info: &crate::bake::MeshInfo, pixels: f32, height: u32) -> Camera {
    let lo = Vec3::from_slice(&info.pos_origin[..3]);
    let extent = Vec3::from_slice(&info.pos_extent[..3]);
    let (centre, radius, fov) = (lo + 0.5 * extent, 0.5 * extent.length(), 40.0f32);
    let distance = radius / (fov.to_radians() * 0.5).tan() * height as f32 / pixels;
    let dir = DEFAULT_VIEW_DIR.normalize();
    Camera::look_at(centre + dir * distance, centre, fov)
}

/// The look the switch between strands and volume is measured and shown with, for `camera`
/// and `tier`: Marschner, deep opacity shadows, software strands (`auto:8`) and light passes,
/// the image read back.
pub fn switch_look(camera: Camera, tier: super::VolumeTier) -> (View, super::FrameOptions) {
    let view = View {
        shading: crate::shade::ShadingModel::Marschner,
        shadows: super::ShadowMode::DeepOpacity,
        volumes: tier,
        ..View::new(camera)
    };
    let opts = super::FrameOptions {
        read_image: true,
        raster: super::StrandRaster::Auto { k: 8 },
        light_raster: super::LightRaster::Software,
        ..Default::default()
    };
    (view, opts)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The portrait key light comes from in front of the subject, above and from the camera's
    /// left (the subject's right), at the stated angles.
    #[test]
    fn the_portrait_light_is_a_three_quarter_key() {
        let cam = Camera::look_at(Vec3::new(0.0, 1.6, 0.8), Vec3::new(0.0, 1.52, 0.0), 35.0);
        let l = portrait_light(&cam);
        assert!((l.length() - 1.0).abs() < 1e-5);
        assert!(l.z > 0.5 && l.x < -0.3 && l.y > 0.3, "{l}");
        let back = (cam.eye - cam.target).normalize();
        let off_axis = l.dot(back).acos();
        let expected = (PORTRAIT_KEY_AZIMUTH.cos() * PORTRAIT_KEY_ELEVATION.cos()).acos();
        assert!(
            (off_axis - expected).abs() < 0.05,
            "{off_axis} vs {expected}"
        );
    }

    #[test]
    fn frustum_contains_target_not_behind() {
        let cam = Camera::look_at(Vec3::new(0.0, 0.0, 5.0), Vec3::ZERO, 45.0);
        let planes = frustum_planes(cam.view_proj(1.0));
        let inside = |p: Vec3| {
            planes
                .iter()
                .all(|pl| Vec3::from_slice(&pl[..3]).dot(p) + pl[3] >= 0.0)
        };
        assert!(inside(Vec3::ZERO));
        assert!(!inside(Vec3::new(0.0, 0.0, 10.0)), "behind the camera");
        assert!(!inside(Vec3::new(100.0, 0.0, 0.0)), "far to the side");
        let unit = Vec3::splat(0.5);
        assert!(box_in_frustum(&planes, -unit, unit));
        assert!(box_in_frustum(
            &planes,
            Vec3::new(-50.0, -0.5, -0.5),
            Vec3::new(50.0, 0.5, 0.5)
        ));
        assert!(!box_in_frustum(
            &planes,
            Vec3::new(99.0, -0.5, -0.5),
            Vec3::new(101.0, 0.5, 0.5)
        ));
        assert!(!box_in_frustum(
            &planes,
            Vec3::new(-0.5, -0.5, 9.0),
            Vec3::new(0.5, 0.5, 11.0)
        ));
        let c = box_corners(Vec3::ZERO, Vec3::ONE);
        assert_eq!(
            (c[0], c[7], c[5]),
            (Vec3::ZERO, Vec3::ONE, Vec3::new(1.0, 0.0, 1.0))
        );
        assert_eq!(size_of::<FrameBlock>(), 672);
    }

    /// The ray length to a depth (`shade::volume`) is the distance of the point that projects to it: points at
    /// known distances along slanted rays through a perspective view come back within 1e-3
    /// relative (measured 4.6e-6 at 0.7, 6.3e-6 at 3.9 and 7.2e-5 at 57 world units, where a
    /// float depth near 1 has few steps left); the cleared depth is infinitely far.
    #[test]
    fn ray_length_to_depth_inverts_the_projection() {
        let eye = Vec3::new(0.3, 1.6, 4.0);
        // The renderer's own camera (Vulkan depth 0..1, y down).
        let camera = Camera::look_at(eye, Vec3::new(0.0, 1.0, 0.0), 45.0);
        let view_proj = camera.view_proj(16.0 / 9.0);
        for (dir, t) in [
            (Vec3::new(-0.1, -0.2, -1.0), 0.7),
            (Vec3::new(0.3, 0.1, -1.0), 3.9),
            (Vec3::new(0.0, -0.05, -1.0), 57.0),
        ] {
            let dir = dir.normalize();
            let c = view_proj * (eye + dir * t).extend(1.0);
            let back = crate::shade::volume::ray_length_to_depth(view_proj, eye, dir, c.z / c.w);
            assert!((back - t).abs() < 1e-3 * t, "{t} -> {back}");
        }
        let forward = (Vec3::new(0.0, 1.0, 0.0) - eye).normalize();
        assert_eq!(
            crate::shade::volume::ray_length_to_depth(view_proj, eye, forward, 1.0),
            f32::INFINITY
        );
    }

    /// The switch is measured with the look its doc names (what `bench volume-tier` and
    /// `tests/volume_tier.rs` compare).
    #[test]
    fn the_switch_look_is_the_documented_one() {
        let camera = Camera::look_at(Vec3::Z, Vec3::ZERO, 40.0);
        let (view, opts) = switch_look(camera, crate::render::VolumeTier::on());
        assert_eq!(view.shading, crate::shade::ShadingModel::Marschner);
        assert_eq!(view.shadows, crate::render::ShadowMode::DeepOpacity);
        assert_eq!(view.volumes, crate::render::VolumeTier::on());
        assert_eq!(opts.raster, crate::render::StrandRaster::Auto { k: 8 });
        assert_eq!(opts.light_raster, crate::render::LightRaster::Software);
        assert!(opts.read_image);
    }

    /// `camera_spanning` is the inverse of `hair_pixels` for a character at the origin: its
    /// camera looks at the hair box's centre along the default view direction, from where the
    /// box's sphere spans the pixels asked for, at the 40-degree field of view.
    #[test]
    fn camera_spanning_is_the_inverse_of_hair_pixels() {
        let mut r: crate::render::core::shared::CharacterRecord = bytemuck::Zeroable::zeroed();
        r.model = glam::Mat4::IDENTITY.to_cols_array_2d();
        r.mesh.pos_origin = [1.0, 2.0, -3.0, 0.0];
        r.mesh.pos_extent = [4.0, 2.0, 1.0, 0.0];
        r.model_scale = 1.0;
        let centre = Vec3::new(3.0, 3.0, -2.5);
        for (pixels, height) in [(20.0, 720), (64.0, 720), (300.0, 1080)] {
            let cam = camera_spanning(&r.mesh, pixels, height);
            assert!((cam.fov_y - 40f32.to_radians()).abs() < 1e-6);
            assert!(cam.target.distance(centre) < 1e-5, "{}", cam.target);
            let dir = (cam.eye - centre).normalize();
            assert!(dir.dot(DEFAULT_VIEW_DIR.normalize()) > 0.99999);
            let mut block: crate::render::core::shared::FrameBlock = bytemuck::Zeroable::zeroed();
            (block.eye, block.pixels_high) = (cam.eye.to_array(), height as f32);
            block.cot_half_fov = 1.0 / (cam.fov_y * 0.5).tan();
            let spans = crate::render::volume::hair_pixels(&r, &block);
            assert!((spans / pixels - 1.0).abs() < 1e-4, "{pixels}: {spans}");
        }
    }
}
