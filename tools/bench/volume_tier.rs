//! `bench crowd --volume-tier`: the crowd with the look `crowd` shows by default (Marschner,
//! deep opacity shadows, LoD on, the fastest rasterizers the device allows) with the volume
//! tier off and on (`render::VolumeTier::on`), for every count, in one run: median GPU ms per
//! pass and of the frame, characters drawn as volumes, and each setting's cost of the largest
//! crowd over the smallest.

use anyhow::Result;
use hairmesh::outln;
use hairmesh::render::{FrameOptions, FrameSettings, LightRaster, StrandRaster, View, VolumeTier};

/// Print a row per count and tier setting, then the ratio lines. With `picture`, returns the
/// largest crowd's frame with the tier on.
pub fn compare(run: &super::CrowdRun, counts: &[usize], picture: bool) -> Result<Option<Vec<u8>>> {
    outln!(
        "| N | volume tier | strands drawn | volumes alone + blended | GPU ms per pass | GPU ms | frame wall ms |\n|---|---|---|---|---|---|---|"
    )?;
    let mut gpu = [Vec::new(), Vec::new()];
    let mut image = None;
    for &count in counts {
        let mut r = run.renderer(hairmesh::render::shared::TASK_PAYLOAD_BUNDLES)?;
        run.add_crowd(&mut r, count)?;
        let settings = FrameSettings {
            path: r.default_path(),
            raster: StrandRaster::Hardware,
            transparency: Default::default(),
            msaa: r.msaa(),
            light_raster: LightRaster::Hardware,
        }
        .with_fastest((None, None), &r.caps());
        let opts = FrameOptions {
            path: Some(settings.path),
            raster: settings.raster,
            light_raster: settings.light_raster,
            ..Default::default()
        };
        for (i, tier) in [VolumeTier::OFF, VolumeTier::on()].into_iter().enumerate() {
            let view = View {
                volumes: tier,
                ..View::crowd_look(run.camera)
            };
            // The first frame builds every volume; the timed ones rebuild stale ones only.
            let read_image = picture && i == 1 && count == *counts.last().unwrap_or(&0);
            let first = r.render_one(&view, &FrameOptions { read_image, ..opts })?;
            let (reports, wall) = super::timed_frames(&mut r, &view, &opts, run.runs)?;
            let passes: Vec<String> = super::median_passes(&first, &reports)
                .iter()
                .map(|(n, ms)| format!("{n} {ms:.1}"))
                .collect();
            let ms = super::median(reports.iter().map(|r| r.gpu_ms()).collect());
            let (alone, blended) = reports.last().map_or((0, 0), |r| r.volume_characters);
            outln!(
                "| {count} | {} | {} | {alone} + {blended} | {} | {ms:.1} | {wall:.1} |",
                if i == 1 { "on" } else { "off" },
                reports.last().map_or(0, |r| r.stats.strands_drawn),
                passes.join(", "),
            )?;
            gpu[i].push(ms);
            if read_image {
                image = first.rgba;
            }
        }
    }
    if let (Some(&small), Some(&large)) = (counts.first(), counts.last()) {
        for (i, name) in ["off", "on"].iter().enumerate() {
            let (a, b) = (gpu[i][0], gpu[i][counts.len() - 1]);
            outln!(
                "volume tier {name}: {large} characters cost {:.2}x the GPU time of {small} ({b:.1} / {a:.1} ms)",
                b / a
            )?;
        }
    }
    Ok(image)
}

/// Hair-box sizes (pixels across) of the band strip's columns: above, inside and below the
/// default band.
const STRIP_PIXELS: [f32; 7] = [80.0, 64.0, 58.0, 52.0, 46.0, 40.0, 32.0];
/// Side of one strip frame, and of the centre square each column shows (upscaled twice).
const STRIP_FRAME: u32 = 128;
const STRIP_CROP: u32 = 72;

/// The band strip (`--band-strip`): one character (`mesh`) shrinking across the volume
/// tier's default band, tier on (top row: strands, screen-door blend, volume) and off
/// (bottom row: strands only), each column the centre of a frame at one size, twice enlarged.
pub fn band_strip(
    ctx: &std::sync::Arc<hairmesh::vk::Context>,
    (baked, style): &(hairmesh::BakedHairMesh, hairmesh::HairStyle),
) -> Result<(Vec<u8>, (u32, u32))> {
    let mut rows = Vec::new();
    for tier in [VolumeTier::on(), VolumeTier::OFF] {
        let mut row = Vec::new();
        for pixels in STRIP_PIXELS {
            let desc = hairmesh::render::RendererDesc::default()
                .size(STRIP_FRAME, STRIP_FRAME)
                .shadow_resolution(512);
            let mut r = hairmesh::render::Renderer::new(ctx, &desc)?;
            let params = hairmesh::render::StrandParams {
                strands_per_bundle: 64,
                verts_log2: 4,
            };
            r.add_character(baked, style, params, glam::Mat4::IDENTITY)?;
            let camera =
                hairmesh::render::camera::camera_spanning(&baked.info, pixels, STRIP_FRAME);
            let (view, opts) = hairmesh::render::camera::switch_look(camera, tier);
            let rgba = r.render_one(&view, &opts)?.rgba.unwrap_or_default();
            let full = image::RgbaImage::from_raw(STRIP_FRAME, STRIP_FRAME, rgba)
                .ok_or_else(|| anyhow::anyhow!("frame size"))?;
            let o = (STRIP_FRAME - STRIP_CROP) / 2;
            let crop = image::imageops::crop_imm(&full, o, o, STRIP_CROP, STRIP_CROP).to_image();
            let big = image::imageops::resize(
                &crop,
                2 * STRIP_CROP,
                2 * STRIP_CROP,
                image::imageops::FilterType::Nearest,
            );
            row.push(big.into_raw());
        }
        rows.push(row);
    }
    let tile = (2 * STRIP_CROP, 2 * STRIP_CROP);
    let image = super::side_by_side(&rows, tile)?;
    let size = (image.width(), image.height());
    Ok((image.into_raw(), size))
}
