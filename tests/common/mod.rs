//! Shared helpers of the GPU tests. Every GPU test runs with validation layers on and fails on
//! any validation error. There is no skipping: without Vulkan the tests fail loudly (run
//! `tools/setup.sh` for lavapipe).
#![allow(dead_code)]

pub mod host;

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Mat4, Vec3};
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, StrandParams, View,
};
use hairmesh::vk::{Context, ContextDesc};
use hairmesh::{BakedHairMesh, HairStyle};

/// Path and LoD of a test render.
#[derive(Clone, Copy, Debug)]
pub struct RenderSettings {
    pub path: Option<RenderPath>,
    pub lod: LodSettings,
    pub shading: hairmesh::shade::ShadingModel,
    pub shadows: hairmesh::render::ShadowMode,
    pub transparency: hairmesh::render::Transparency,
    pub lod_appearance: bool,
}

/// What a test render produced.
pub struct RenderOutput {
    pub width: u32,
    pub height: u32,
    pub rgba: Vec<u8>,
    pub strands: u64,
    pub triangles: u64,
    pub path: RenderPath,
    pub mesh_primitives_query: Option<u64>,
    pub stats: hairmesh::render::FrameStats,
}

/// A renderer with a `size` x `size` target.
pub fn renderer(ctx: &Arc<Context>, size: u32) -> Renderer {
    Renderer::new(ctx, &RendererDesc::default().size(size, size)).unwrap()
}

/// Render one frame of everything in `r` and read it back.
pub fn render(r: &mut Renderer, cam: &Camera, settings: &RenderSettings) -> RenderOutput {
    let view = View {
        lod: settings.lod,
        shading: settings.shading,
        shadows: settings.shadows,
        transparency: settings.transparency,
        lod_appearance: settings.lod_appearance,
        ..View::new(*cam)
    };
    let report = r
        .render_one(
            &view,
            &FrameOptions {
                path: settings.path,
                read_image: true,
                ..Default::default()
            },
        )
        .unwrap();
    RenderOutput {
        width: report.width,
        height: report.height,
        rgba: report.rgba.unwrap(),
        strands: report.stats.strands_drawn as u64,
        triangles: report.stats.triangles_drawn as u64,
        path: report.path,
        mesh_primitives_query: report.mesh_primitives,
        stats: report.stats,
    }
}

pub fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

pub fn context() -> Arc<Context> {
    match Context::new(&ContextDesc::default().validation(true)) {
        Ok(c) => Arc::new(c),
        Err(e) => panic!("GPU tests need Vulkan with validation layers (run tools/setup.sh): {e}"),
    }
}

pub fn assert_no_validation_errors(ctx: &Context) {
    assert_eq!(
        ctx.validation_errors(),
        0,
        "validation errors: {:#?}",
        ctx.validation_messages()
    );
}

pub fn sample(name: &str) -> (BakedHairMesh, HairStyle) {
    load_mesh(
        &root().join("hairmeshes").join(name),
        None,
        Default::default(),
    )
    .unwrap()
}

/// Camera framing the mesh from a fixed 3/4 back view.
pub fn framing(baked: &BakedHairMesh) -> Camera {
    let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
    let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
    Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0)
}

/// An 8-bit sRGB value in linear light.
pub fn srgb_to_linear(c: u8) -> f64 {
    let c = c as f64 / 255.0;
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// Mean absolute difference of two equally sized 8-bit images, in [0, 1].
pub fn mean_abs_diff(a: &[u8], b: &[u8]) -> f64 {
    assert_eq!(a.len(), b.len(), "images of different sizes");
    let s: u64 = a
        .iter()
        .zip(b)
        .map(|(x, y)| (*x as i32 - *y as i32).unsigned_abs() as u64)
        .sum();
    s as f64 / a.len() as f64 / 255.0
}

/// FLIP (nv-flip) of RGBA image `test` against `reference`, both `w x h`: the error image,
/// its mean and 99th percentile.
pub fn flip_rgba(
    w: u32,
    h: u32,
    reference: &[u8],
    test: &[u8],
) -> (nv_flip::FlipImageFloat, f32, f32) {
    let rgb = |img: &[u8]| -> Vec<u8> { img.chunks(4).flat_map(|p| [p[0], p[1], p[2]]).collect() };
    let r = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(reference));
    let t = nv_flip::FlipImageRgb8::with_data(w, h, &rgb(test));
    let err = nv_flip::flip(r, t, nv_flip::DEFAULT_PIXELS_PER_DEGREE);
    let mut pool = nv_flip::FlipPool::from_image(&err);
    let (mean, p99) = (pool.mean(), pool.get_percentile(0.99, true));
    (err, mean, p99)
}

/// Write `rgba` and the magma FLIP `err` image as `tests/output/<name>-actual.png` and
/// `<name>-diff.png`.
pub fn save_failure(name: &str, w: u32, h: u32, rgba: &[u8], err: &nv_flip::FlipImageFloat) {
    let dir = output_dir();
    save_png(&dir.join(format!("{name}-actual.png")), w, h, rgba);
    let diff = err.apply_color_lut(&nv_flip::magma_lut());
    image::RgbImage::from_raw(w, h, diff.to_vec())
        .unwrap()
        .save(dir.join(format!("{name}-diff.png")))
        .unwrap();
}

pub fn light() -> Vec3 {
    hairmesh::render::camera::DEFAULT_LIGHT_DIR
}

/// Compute path, LoD off: the settings the golden images were made with.
pub fn compute_full() -> RenderSettings {
    RenderSettings {
        path: Some(RenderPath::Compute),
        lod: LodSettings::off(),
        shading: hairmesh::shade::ShadingModel::Placeholder,
        shadows: hairmesh::render::ShadowMode::Off,
        transparency: hairmesh::render::Transparency::Opaque,
        lod_appearance: true,
    }
}

/// Render one sample mesh on the compute path without LoD.
pub fn render_sample(
    ctx: &Arc<Context>,
    name: &str,
    n: u32,
    e: u32,
    size: u32,
    camera: Option<Camera>,
) -> RenderOutput {
    render_sample_with(ctx, name, n, e, size, camera, &compute_full())
}

/// Render one sample mesh with explicit settings.
pub fn render_sample_with(
    ctx: &Arc<Context>,
    name: &str,
    n: u32,
    e: u32,
    size: u32,
    camera: Option<Camera>,
    settings: &RenderSettings,
) -> RenderOutput {
    let (baked, style) = sample(name);
    let mut r = renderer(ctx, size);
    upload(&mut r, &baked, &style, n, e);
    let cam = camera.unwrap_or_else(|| framing(&baked));
    render(&mut r, &cam, settings)
}

pub fn output_dir() -> PathBuf {
    let d = root().join("tests").join("output");
    std::fs::create_dir_all(&d).unwrap();
    d
}

pub fn save_png(path: &Path, w: u32, h: u32, rgba: &[u8]) {
    image::RgbaImage::from_raw(w, h, rgba.to_vec())
        .unwrap()
        .save(path)
        .unwrap();
}

/// Add a mesh with `n` strands per bundle and `2^e + 1` vertices, identity transform.
pub fn upload(
    r: &mut Renderer,
    baked: &BakedHairMesh,
    style: &HairStyle,
    n: u32,
    e: u32,
) -> hairmesh::render::CharacterId {
    let params = StrandParams {
        strands_per_bundle: n,
        verts_log2: e,
    };
    r.add_character(baked, style, params, Mat4::IDENTITY)
        .unwrap()
}

/// The LoD inputs the shaders see for `cam` at `size` pixels with default LoD settings.
pub fn lod_view(cam: &Camera, size: u32) -> hairmesh::reference::lod::LodView {
    lod_view_with(cam, size, &LodSettings::default())
}

/// The LoD inputs the shaders see for `cam` at `size` pixels with `lod`.
pub fn lod_view_with(
    cam: &Camera,
    size: u32,
    lod: &LodSettings,
) -> hairmesh::reference::lod::LodView {
    hairmesh::reference::lod::LodView {
        eye: cam.eye,
        resolution: size as f32,
        fov_y: cam.fov_y,
        alpha_strands: lod.alpha_strands,
        area_below: lod.area_below,
        strands_per_pixel: lod.strands_per_pixel,
        alpha_verts: lod.alpha_verts,
        lambda: lod.lambda,
        strand_share: 1.0,
        pressure: 1.0,
    }
}
