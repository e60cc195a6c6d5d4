//! The volume tier (seed 002, `render::volume`): far hair drawn from its density volume
//! matches the strands it replaces at the switch distance, the blend between them has no
//! pop, and volumetric ambient occlusion darkens the inner hair and leaves the outer hair lit.
//! Validation on; the crowd's default look (Marschner, deep opacity shadows, opaque strands,
//! software strands and light passes where thin).

mod common;

use common::*;
use hairmesh::render::{Camera, LodSettings, Renderer, RendererDesc, View, VolumeTier};

/// Side of the test frames.
const SIZE: u32 = 128;

/// A camera from the default direction at which the hair box of `name` spans `pixels` pixels
/// of a `SIZE`-pixel frame (`render::volume::hair_pixels`).
fn camera_at(name: &str, pixels: f32) -> Camera {
    let (baked, _) = sample(name);
    hairmesh::render::camera::camera_spanning(&baked.info, pixels, SIZE)
}

/// One frame of `name` (64 strands per bundle, 16 segments) seen by `camera`, with `tier`.
fn frame(
    ctx: &std::sync::Arc<hairmesh::vk::Context>,
    name: &str,
    camera: Camera,
    (tier, lod): (VolumeTier, LodSettings),
) -> Vec<u8> {
    let (baked, style) = sample(name);
    let mut r = Renderer::new(
        ctx,
        &RendererDesc::default()
            .size(SIZE, SIZE)
            .shadow_resolution(512),
    )
    .unwrap();
    upload(&mut r, &baked, &style, 64, 4);
    let (view, opts) = hairmesh::render::camera::switch_look(camera, tier);
    let view = View { lod, ..view };
    let rgba = r.render_one(&view, &opts).unwrap().rgba.unwrap();
    assert_no_validation_errors(ctx);
    rgba
}

/// The tier with its band at `(far, near)` pixels, occlusion as given.
fn tier(far: f32, near: f32, occlusion: bool) -> VolumeTier {
    VolumeTier {
        occlusion,
        far: Some((far, near)),
        ..VolumeTier::on()
    }
}

/// The square of side `side` pixels at the centre of a `SIZE` x `SIZE` RGBA image.
fn centre_square(img: &[u8], side: u32) -> Vec<u8> {
    let o = (SIZE - side) / 2;
    (o..o + side)
        .flat_map(|y| {
            let row = ((y * SIZE + o) * 4) as usize;
            img[row..row + side as usize * 4].to_vec()
        })
        .collect()
}

/// FLIP of `test` against `reference` over the character's part of the screen: the square
/// its hair box's bounding sphere spans (`side` pixels, at the frame's centre). Saves both
/// crops and the error image under tests/output.
fn character_flip(name: &str, side: u32, reference: &[u8], test: &[u8]) -> (f32, f32) {
    let (r, t) = (centre_square(reference, side), centre_square(test, side));
    let (err, mean, p99) = flip_rgba(side, side, &r, &t);
    save_png(
        &output_dir().join(format!("volume-tier-{name}-strands.png")),
        side,
        side,
        &r,
    );
    save_failure(&format!("volume-tier-{name}-volume"), side, side, &t, &err);
    (mean, p99)
}

/// Mean brightness (0-255, mean of RGB) of the pixels of `img` that are not the background
/// colour of its first pixel.
fn covered_brightness(img: &[u8]) -> f64 {
    let (mut sum, mut n) = (0.0, 0);
    for p in img.chunks(4) {
        if p != &img[..4] {
            sum += (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
            n += 1;
        }
    }
    sum / n.max(1) as f64
}

/// At the middle of the default band (52 pixels), FLIP means over the character's square
/// (lavapipe, 128x128 frames, 24^3 cells, steps of two cells, the march ending at the opaque
/// depth): head_long 0.129, sintel 0.092 between the volume alone and the strands alone
/// (0.133 and 0.085 before 2026-12-07, when the software rasterizer's thick strands stopped
/// being drawn at least sqrt(k) pixels wide where one strand is thinner than a pixel: sintel's
/// LoD strands came closer to its full detail, 0.027 -> 0.016, and darker, 66.7 -> 62.7 of
/// the volume's 85.0).
/// Inside the hair the two agree (mean colour within 1% for head_long, 10% for sintel); most
/// of the error is the volume's edge, which the trilinear cells blur about a cell (2 pixels
/// here) beyond the strands. For scale, the strands with LoD against the strands at full
/// detail (both the renderer's own strands) already differ by 0.079 (sintel 0.016). Bounds:
/// head_long the measurement plus about 15%; sintel's lies under 0.095, what a march through
/// the scalp to the box's far side measured (the hair behind the head counted in front of
/// it). Issue 26 asked 0.05, which these cells do not reach (guide, volume chapter).
const SWITCH_FLIP_MEAN: [(&str, f32); 2] = [("head_long.obj", 0.15), ("sintel.obj", 0.094)];
/// The middle of the default band (`render::volume`).
const SWITCH_PIXELS: f32 = 0.5
    * (hairmesh::render::volume::DEFAULT_FAR_PIXELS
        + hairmesh::render::volume::DEFAULT_NEAR_PIXELS);

#[test]
fn the_volume_matches_the_strands_at_the_switch_distance() {
    let ctx = context();
    let side = SWITCH_PIXELS.round() as u32;
    let lod = LodSettings::default();
    for (name, bound) in SWITCH_FLIP_MEAN {
        let short = name.trim_end_matches(".obj");
        let camera = camera_at(name, SWITCH_PIXELS);
        // Strands alone (the band below the character), the volume alone (above it), and
        // the strands at full detail.
        let strands = frame(&ctx, name, camera, (tier(0.0, 0.0, true), lod));
        let volume = frame(&ctx, name, camera, (tier(1e6, 1e6, true), lod));
        // Skipping the volume's empty bricks changes no pixel (their samples are exactly 0).
        let every_brick = VolumeTier {
            skip_empty: false,
            ..tier(1e6, 1e6, true)
        };
        let marched_whole = frame(&ctx, name, camera, (every_brick, lod));
        let changed = volume
            .chunks(4)
            .zip(marched_whole.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        assert_eq!(
            changed, 0,
            "{short}: skipping empty bricks changed {changed} pixels"
        );
        let full = frame(
            &ctx,
            name,
            camera,
            (tier(0.0, 0.0, true), LodSettings::off()),
        );
        // Halfway across a band around the character's size.
        let (far, near) = (SWITCH_PIXELS - 10.0, SWITCH_PIXELS + 10.0);
        let half = frame(&ctx, name, camera, (tier(far, near, true), lod));
        for (tag, img) in [
            ("strands", &strands),
            ("volume", &volume),
            ("halfway", &half),
        ] {
            save_png(
                &output_dir().join(format!("volume-band-{short}-{tag}.png")),
                SIZE,
                SIZE,
                img,
            );
        }
        let (mean, p99) = character_flip(short, side, &strands, &volume);
        let (lod_mean, _) = flip_rgba(
            side,
            side,
            &centre_square(&full, side),
            &centre_square(&strands, side),
        )
        .map_rest();
        println!(
            "{name}: volume vs strands FLIP mean {mean:.4}, p99 {p99:.4} over the character's {side}x{side} pixels (LoD strands vs full detail: {lod_mean:.4}); hair brightness strands {:.1} volume {:.1}",
            covered_brightness(&strands),
            covered_brightness(&volume)
        );
        assert!(
            mean <= bound,
            "{name}: the volume differs from the strands by FLIP mean {mean:.4} (LoD alone {lod_mean:.4}, bound {bound}); tests/output/volume-tier-*"
        );
        // Across the band the strands thin out over the volume: halfway, the picture lies
        // between them (nearer each than they are to each other), so nothing pops. Measured
        // FLIP to strands / to volume 0.079 / 0.115 (head_long), 0.064 / 0.079 (sintel); a
        // volume whose depth hid the software-rasterized strands behind it failed at 0.211 /
        // 0.249. The band strip (guide, volume chapter) shows it without accumulation.
        let crop = |img: &[u8]| centre_square(img, side);
        let (to_strands, _) = flip_rgba(side, side, &crop(&strands), &crop(&half)).map_rest();
        let (to_volume, _) = flip_rgba(side, side, &crop(&volume), &crop(&half)).map_rest();
        println!("{name}: halfway blend vs strands {to_strands:.4}, vs volume {to_volume:.4}");
        assert!(
            to_strands < mean && to_volume < mean,
            "{name}: the halfway blend is not between strands and volume ({to_strands:.4}, {to_volume:.4} vs {mean:.4})"
        );
    }
}

/// `flip_rgba`'s mean and 99th percentile without the error image.
trait MapRest {
    fn map_rest(self) -> (f32, f32);
}

impl MapRest for (nv_flip::FlipImageFloat, f32, f32) {
    fn map_rest(self) -> (f32, f32) {
        (self.1, self.2)
    }
}

/// Volumetric ambient occlusion (seed 002) darkens the hair where it is dense and leaves the
/// outer hair nearly as lit. The same frame with occlusion off and on: no hair pixel gets
/// brighter, the hair gets darker on average (measured: keeps 0.879 of its brightness), and
/// the darkest quarter (the inner hair) loses more than the brightest (0.680 against 0.991).
#[test]
fn volumetric_occlusion_darkens_the_inner_hair() {
    let ctx = context();
    let name = "head_long.obj";
    let (baked, _) = sample(name);
    let camera = framing(&baked);
    let lod = LodSettings::default();
    let off = frame(&ctx, name, camera, (VolumeTier::OFF, lod));
    let on = frame(
        &ctx,
        name,
        camera,
        (
            VolumeTier {
                occlusion: true,
                ..VolumeTier::OFF
            },
            lod,
        ),
    );
    save_png(&output_dir().join("volume-ao-off.png"), SIZE, SIZE, &off);
    save_png(&output_dir().join("volume-ao-on.png"), SIZE, SIZE, &on);
    let luma = |p: &[u8]| (p[0] as f64 + p[1] as f64 + p[2] as f64) / 3.0;
    let bg = &off[..4];
    let mut pairs: Vec<(f64, f64)> = off
        .chunks(4)
        .zip(on.chunks(4))
        .filter(|(a, _)| *a != bg)
        .map(|(a, b)| (luma(a), luma(b)))
        .collect();
    assert!(pairs.len() > 2000, "only {} hair pixels", pairs.len());
    let brighter = pairs.iter().filter(|(a, b)| b > &(a + 1.0)).count();
    assert_eq!(brighter, 0, "{brighter} pixels got brighter with occlusion");
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    let q = pairs.len() / 4;
    let ratio = |s: &[(f64, f64)]| {
        s.iter().map(|p| p.1).sum::<f64>() / s.iter().map(|p| p.0).sum::<f64>().max(1e-9)
    };
    let (dark, bright, all) = (
        ratio(&pairs[..q]),
        ratio(&pairs[pairs.len() - q..]),
        ratio(&pairs),
    );
    println!(
        "occlusion keeps {all:.3} of the hair's brightness: darkest quarter {dark:.3}, brightest {bright:.3}"
    );
    // Measured 0.879 (darkest quarter 0.680): the bound asks for a visible 3% at least.
    assert!(all < 0.97, "occlusion kept {all:.3} of the brightness");
    assert!(
        dark < bright,
        "darkest quarter kept {dark:.3}, brightest {bright:.3}"
    );
}
