//! Pictures of strand sets for comparing a fitted hair mesh with its input: both drawn the
//! same way by the software rasterizer (`Renderer::rasterize_segments`), Kajiya-Kay shaded at
//! the vertices, from one camera.

use glam::{Mat4, Vec3};

use crate::render::core::shared::SoftSegment;
use crate::render::{Camera, Renderer};
use crate::vk::GpuResult;

/// How the strands are drawn.
#[derive(Clone, Copy, Debug)]
pub struct StrandLook {
    /// Camera.
    pub camera: Camera,
    /// Base colour (linear RGB).
    pub color: Vec3,
    /// Direction toward the light.
    pub light: Vec3,
    /// Drawn width in pixels.
    pub width_px: f32,
}

/// The segments of `strands` seen by `look` on a `width x height` image (segments with an
/// end behind the camera or outside the depth range are left out).
pub fn strand_segments(
    strands: &[Vec<Vec3>],
    look: &StrandLook,
    width: u32,
    height: u32,
) -> Vec<SoftSegment> {
    let vp: Mat4 = look.camera.view_proj(width as f32 / height as f32);
    let l = look.light.normalize_or(Vec3::Y);
    let size = glam::Vec2::new(width as f32, height as f32);
    let mut out = Vec::new();
    for s in strands {
        let shade = |k: usize| -> (Option<Vec3>, [f32; 3]) {
            let t = if k + 1 < s.len() {
                s[k + 1] - s[k]
            } else {
                s[k] - s[k - 1]
            }
            .normalize_or(Vec3::Y);
            let e = (look.camera.eye - s[k]).normalize_or(Vec3::Z);
            let (diffuse, spec) = crate::shade::kajiya_kay(t, l, e);
            let c = look.color * (0.25 + 0.75 * diffuse) + Vec3::splat(0.3 * spec);
            let clip = vp * s[k].extend(1.0);
            let ok = clip.w > 1e-6 && clip.z >= 0.0 && clip.z <= clip.w;
            let ndc = clip.truncate() / clip.w.max(1e-6);
            let screen = (ndc.truncate() * 0.5 + 0.5) * size;
            (ok.then(|| screen.extend(ndc.z)), c.to_array())
        };
        let mut prev = shade(0);
        for k in 1..s.len() {
            let next = shade(k);
            if let (Some(a), Some(b)) = (prev.0, next.0)
                && a.truncate().distance(b.truncate()) > 1e-4
            {
                out.push(SoftSegment::shaded(a, b, look.width_px, [prev.1, next.1]));
            }
            prev = next;
        }
    }
    out
}

/// Draw `strands` with `look` over black; RGBA8 (sRGB) of the renderer's target size.
pub fn draw_strands(
    renderer: &mut Renderer,
    strands: &[Vec<Vec3>],
    look: &StrandLook,
) -> GpuResult<Vec<u8>> {
    let (w, h) = renderer.size();
    let segments = strand_segments(strands, look, w, h);
    if segments.is_empty() {
        return Err(crate::vk::GpuError::Unsupported(
            "no strand segment is in view".into(),
        ));
    }
    renderer.rasterize_segments(&segments, 8, 0.7)
}
