//! Temporal stability (`render::temporal`): the motion vectors are the surfaces' true motion
//! (checked against the CPU twin and by moving the previous frame's image onto the current
//! one), in every draw and transparency mode; temporal accumulation converges to the frame
//! it accumulates and runs clean under validation.

mod common;

use common::*;
use glam::{Mat4, Vec2, Vec3};
use hairmesh::render::temporal::{PixelMotion, clip_to_prev, motion_at, reprojected_change};
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, StrandRaster, Temporal,
    Transparency, View,
};

const SIZE: u32 = 96;

/// A camera around the sample head, `step` small turns from the framing.
fn turned(base: &Camera, step: f32) -> Camera {
    let offset = base.eye - base.target;
    let rot = Mat4::from_rotation_y(0.02 * step);
    Camera {
        eye: base.target + rot.transform_vector3(offset),
        ..*base
    }
}

fn view(camera: Camera, transparency: Transparency, temporal: Temporal) -> View {
    View {
        lod: LodSettings::off(),
        transparency,
        temporal,
        ..View::new(camera)
    }
}

/// Frames at cameras `cams` in order; the images and motion of the last two.
fn sequence(
    r: &mut Renderer,
    cams: &[Camera],
    (transparency, raster): (Transparency, StrandRaster),
) -> [(Vec<u8>, Vec<PixelMotion>); 2] {
    let mut out = Vec::new();
    for cam in cams {
        let opts = FrameOptions {
            path: Some(RenderPath::Compute),
            read_image: true,
            read_motion: true,
            raster,
            ..Default::default()
        };
        let report = r
            .render_one(&view(*cam, transparency, Temporal::Off), &opts)
            .unwrap();
        out.push((report.rgba.unwrap(), report.motion.unwrap()));
    }
    let last = out.pop().unwrap();
    [out.pop().unwrap(), last]
}

fn hair_mask(motion: &[PixelMotion]) -> Vec<bool> {
    motion.iter().map(PixelMotion::is_hair).collect()
}

/// The GPU's motion equals the CPU twin's for the camera's move, pixel by pixel, for hair,
/// scalp and background alike, in every draw and transparency mode (hardware strips opaque,
/// through the k-buffer and depth peeling; the software rasterizer). With the previous
/// frame's matrices used twice (the motion of a frame after itself) it would be zero and
/// fail.
#[test]
fn motion_vectors_are_the_camera_motion() {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let base = framing(&baked);
    let cams = [turned(&base, 0.0), turned(&base, 1.0)];
    let vp = |c: &Camera| c.view_proj(1.0);
    let m = clip_to_prev(vp(&cams[0]), Mat4::IDENTITY, vp(&cams[1]));
    let size = Vec2::splat(SIZE as f32);
    let modes = [
        (Transparency::Opaque, StrandRaster::Hardware),
        (Transparency::KBuffer { budget: 4 }, StrandRaster::Hardware),
        (
            Transparency::DepthPeeling { layers: 2 },
            StrandRaster::Hardware,
        ),
        (Transparency::Opaque, StrandRaster::Software { k: 4 }),
    ];
    for mode in modes {
        let mut r = renderer(&ctx, SIZE);
        upload(&mut r, &baked, &style, 16, 4);
        let [_, (_, motion)] = sequence(&mut r, &cams, mode);
        let (mut hair, mut worst, mut largest) = (0, 0.0f32, 0.0f32);
        for (i, p) in motion.iter().enumerate() {
            let centre = Vec2::new((i as u32 % SIZE) as f32, (i as u32 / SIZE) as f32) + 0.5;
            let expected = motion_at(m, centre, p.depth, size);
            worst = worst.max((p.motion - expected).length());
            largest = largest.max(expected.length());
            hair += p.is_hair() as usize;
        }
        assert!(hair > 500, "{mode:?}: hair pixels {hair}");
        assert!(largest > 1.0, "the camera moved {largest} px at most");
        assert!(
            worst < 0.01,
            "{mode:?}: motion off the CPU twin's by {worst} px"
        );
    }
    assert_no_validation_errors(&ctx);
}

/// Moving the previous frame's image along the motion vectors lands it on the current one:
/// the opaque hair's change of luminance falls well below the change without moving it.
/// Measured on lavapipe (96 px, 4.6 degree turn about the head): 0.026 moved, 0.050 unmoved;
/// the bound is 0.7 of unmoved. (Semi-transparent hair blends strands with what is behind
/// them, which moves differently, so the nearest surface's motion moves only part of a
/// pixel's colour: the test above checks those modes' vectors directly.)
#[test]
fn motion_vectors_move_the_previous_frame_onto_the_current_one() {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let base = framing(&baked);
    let cams = [turned(&base, 0.0), turned(&base, 4.0)];
    let mut r = renderer(&ctx, SIZE);
    upload(&mut r, &baked, &style, 16, 4);
    let mode = (Transparency::Opaque, StrandRaster::Hardware);
    let [(before, _), (now, motion)] = sequence(&mut r, &cams, mode);
    let mask = hair_mask(&motion);
    let size = (SIZE, SIZE);
    let (moved, n) = reprojected_change(&before, &now, &motion, &mask, size);
    let still = vec![PixelMotion::default(); motion.len()];
    let (unmoved, _) = reprojected_change(&before, &now, &still, &mask, size);
    println!("moved {moved:.4} unmoved {unmoved:.4} over {n} px");
    assert!(n > 300, "{n} hair pixels");
    assert!(
        moved < 0.7 * unmoved,
        "change {moved:.4} along the motion vectors, {unmoved:.4} without"
    );
    assert_no_validation_errors(&ctx);
}

/// A character that moves with the camera stays put on screen: its motion is ~0 where the
/// camera's alone would be large (each character's own clip_to_prev).
#[test]
fn a_character_moving_with_the_camera_has_no_motion() {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let mut r = renderer(&ctx, SIZE);
    let id = upload(&mut r, &baked, &style, 16, 4);
    let base = framing(&baked);
    let shift = Vec3::new(0.02, 0.0, 0.0);
    let (mut motion, mut cams) = (Vec::new(), Vec::new());
    for k in 0..2 {
        let t = shift * k as f32;
        r.set_model(id, Mat4::from_translation(t)).unwrap();
        let cam = Camera {
            eye: base.eye + t,
            target: base.target + t,
            ..base
        };
        cams.push(cam);
        let opts = FrameOptions {
            read_motion: true,
            ..Default::default()
        };
        let report = r
            .render_one(&view(cam, Transparency::Opaque, Temporal::Off), &opts)
            .unwrap();
        motion = report.motion.unwrap();
    }
    let vp = |c: &Camera| c.view_proj(1.0);
    let camera_only = clip_to_prev(vp(&cams[0]), Mat4::IDENTITY, vp(&cams[1]));
    let size = Vec2::splat(SIZE as f32);
    let (mut hair, mut most, mut camera_sum) = (0, 0.0f32, 0.0f32);
    for (i, p) in motion.iter().enumerate().filter(|(_, p)| p.is_hair()) {
        let centre = Vec2::new((i as u32 % SIZE) as f32, (i as u32 / SIZE) as f32) + 0.5;
        hair += 1;
        most = most.max(p.motion.length());
        camera_sum += motion_at(camera_only, centre, p.depth, size).length();
    }
    assert!(hair > 500, "hair pixels {hair}");
    assert!(most < 0.01, "hair moved {most} px on screen");
    let camera_mean = camera_sum / hair as f32;
    assert!(
        camera_mean > 0.5,
        "the camera's motion alone: {camera_mean} px"
    );
    assert_no_validation_errors(&ctx);
}

/// With a still camera, accumulation converges to (nearly) the frame it accumulates: every
/// jittered frame is a sample of the same picture. FLIP mean against the unjittered frame,
/// measured 0.02-0.03 on lavapipe at 96 px (strands thinner than a pixel land on other pixels
/// under jitter; the average is the smoother picture); bound 0.08. Every draw and
/// transparency mode runs clean under validation.
#[test]
fn accumulation_converges_on_a_still_frame() {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let cam = framing(&baked);
    let modes = [
        (
            Transparency::Opaque,
            StrandRaster::Hardware,
            RenderPath::Mesh,
        ),
        (
            Transparency::KBuffer { budget: 4 },
            StrandRaster::Hardware,
            RenderPath::Compute,
        ),
        (
            Transparency::DepthPeeling { layers: 2 },
            StrandRaster::Hardware,
            RenderPath::Compute,
        ),
        (
            Transparency::Opaque,
            StrandRaster::Auto { k: 4 },
            RenderPath::Compute,
        ),
    ];
    for (transparency, raster, path) in modes {
        let mut r = Renderer::new(&ctx, &RendererDesc::default().size(SIZE, SIZE)).unwrap();
        upload(&mut r, &baked, &style, 16, 4);
        let opts = |read_image| FrameOptions {
            path: Some(path),
            raster,
            read_image,
            ..Default::default()
        };
        let plain = r
            .render_one(&view(cam, transparency, Temporal::Off), &opts(true))
            .unwrap()
            .rgba
            .unwrap();
        let mut last = Vec::new();
        for f in 0..10 {
            let report = r
                .render_one(&view(cam, transparency, Temporal::Taa), &opts(f == 9))
                .unwrap();
            if let Some(rgba) = report.rgba {
                last = rgba;
            }
        }
        let (err, mean, p99) = flip_rgba(SIZE, SIZE, &plain, &last);
        println!("{transparency:?} {raster:?} {path:?}: FLIP mean {mean:.4} p99 {p99:.4}");
        if mean > 0.08 {
            save_failure("temporal_accumulation", SIZE, SIZE, &last, &err);
        }
        assert!(
            mean <= 0.08,
            "{transparency:?} {raster:?}: FLIP mean {mean}"
        );
    }
    assert_no_validation_errors(&ctx);
}

/// After `reset_temporal` (a camera cut) the next frame has no previous frame: no motion,
/// however far the camera jumped; the frame after it moves again.
#[test]
fn a_cut_has_no_motion() {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let mut r = renderer(&ctx, SIZE);
    upload(&mut r, &baked, &style, 16, 4);
    let base = framing(&baked);
    let motion_at_step = |r: &mut Renderer, step: f32| {
        let opts = FrameOptions {
            read_motion: true,
            ..Default::default()
        };
        let v = view(turned(&base, step), Transparency::Opaque, Temporal::Off);
        let motion = r.render_one(&v, &opts).unwrap().motion.unwrap();
        motion
            .iter()
            .map(|p| p.motion.length())
            .fold(0.0f32, f32::max)
    };
    motion_at_step(&mut r, 0.0);
    assert!(motion_at_step(&mut r, 5.0) > 1.0, "a turn moves the pixels");
    r.reset_temporal();
    assert!(
        motion_at_step(&mut r, 10.0) < 1e-3,
        "no motion across a cut"
    );
    assert!(
        motion_at_step(&mut r, 15.0) > 1.0,
        "motion again after the cut"
    );
    assert_no_validation_errors(&ctx);
}

/// A hair mesh swung sideways and back, more toward the tips, and its rest pose (layer-major).
fn swing(mesh: &hairmesh::model::hair_mesh::HairMesh) -> [Vec<Vec3>; 2] {
    let rest: Vec<Vec3> = mesh.layers.iter().flatten().copied().collect();
    let n = mesh.vertices_per_layer();
    let swung = rest
        .iter()
        .enumerate()
        .map(|(j, p)| {
            let d = p.distance(mesh.layers[0][j % n]);
            *p + Vec3::new(0.4 * d, 0.0, -0.15 * d)
        })
        .collect();
    [rest, swung]
}

/// Compare `motion` at every strand vertex of `after` (world space, projected by `vp`) that is
/// the nearest surface of its pixel with the vertex's move from `before`: the medians of the
/// error and of the move, and how many vertices were compared.
fn strand_motion_error(
    motion: &[PixelMotion],
    (before, after): (&[Vec3], &[Vec3]),
    vp: Mat4,
) -> (f32, f32, usize) {
    let size = Vec2::splat(SIZE as f32);
    let project = |p: Vec3| {
        let c = vp * p.extend(1.0);
        let ndc = c.truncate() / c.w;
        ((Vec2::new(ndc.x, ndc.y) + 1.0) * 0.5 * size, ndc.z)
    };
    let (mut errors, mut moves) = (Vec::new(), Vec::new());
    for (b, a) in after.iter().zip(before) {
        let ((pb, zb), (pa, _)) = (project(*b), project(*a));
        if pb.min_element() < 0.0 || pb.max_element() >= size.x {
            continue;
        }
        let p = motion[pb.y as usize * SIZE as usize + pb.x as usize];
        // Only where this vertex's strand is the pixel's nearest surface.
        let ratio = (1.0 - p.depth) / (1.0 - zb).max(1e-9);
        if p.is_hair() && (0.98..1.02).contains(&ratio) {
            errors.push((p.motion - (pb - pa)).length());
            moves.push((pb - pa).length());
        }
    }
    let median = |mut v: Vec<f32>| {
        v.sort_by(f32::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(f32::NAN)
    };
    let count = errors.len();
    (median(errors), median(moves), count)
}

/// Hair that deforms relative to its head (a new hair mesh pose, still camera) has the motion
/// of its own strands: at every strand vertex of the new pose that is the nearest surface of
/// its pixel, the GPU's motion equals the vertex's screen position minus its position in the
/// previous pose (CPU oracle: both poses rebuilt and generated on the CPU, same seed), on the
/// mesh path, the compute path and through the software rasterizer. Rigid motion vectors
/// alone (what the renderer had before the previous pose was evaluated) are zero here.
/// Measured on lavapipe (96 px): median error 0.12 px (software: 0.14) against a median move
/// of 2.95 px; the bound is 0.2 of the move and 0.5 px.
#[test]
fn deforming_hair_has_the_motion_of_its_strands() {
    use hairmesh::bake::deform::DeformBasis;
    use hairmesh::bake::{BakeOptions, BakedHairMesh, bake};
    use hairmesh::model::obj_io::load_hair_mesh_obj;
    use hairmesh::model::style::HairStyle;
    use hairmesh::reference::generate::CpuGenerator;

    let ctx = context();
    let dir = root().join("hairmeshes");
    let mesh = load_hair_mesh_obj(&dir.join("head_long.obj")).unwrap();
    let style = HairStyle::load(&dir.join("head_long.toml")).unwrap();
    let options = BakeOptions {
        motion_margin: 0.2,
        ..Default::default()
    };
    let baked = bake(&mesh, &style, options, |_, _| {}).unwrap();
    let basis = DeformBasis::new(&mesh, &baked, options).unwrap();
    let poses = swing(&mesh);
    let strands = |pose: &[Vec3]| {
        let t = basis.rebuild(pose);
        let posed = BakedHairMesh {
            position: t.position,
            u_dir: t.u_dir,
            v_dir: t.v_dir,
            ..baked.clone()
        };
        CpuGenerator::new(&posed, style).generate(16, 4).positions
    };
    let (before, after) = (strands(&poses[0]), strands(&poses[1]));
    let cam = framing(&baked);
    let modes = [
        (RenderPath::Mesh, StrandRaster::Hardware),
        (RenderPath::Compute, StrandRaster::Hardware),
        (RenderPath::Compute, StrandRaster::Software { k: 4 }),
    ];
    for (path, raster) in modes {
        let mut r = renderer(&ctx, SIZE);
        let id = upload(&mut r, &baked, &style, 16, 4);
        r.make_deformable(id, basis.clone()).unwrap();
        let mut motion = Vec::new();
        for pose in &poses {
            r.set_hair_mesh_pose(id, pose).unwrap();
            let opts = FrameOptions {
                path: Some(path),
                read_motion: true,
                raster,
                ..Default::default()
            };
            let v = view(cam, Transparency::Opaque, Temporal::Off);
            motion = r.render_one(&v, &opts).unwrap().motion.unwrap();
        }
        let pair = (before.as_slice(), after.as_slice());
        let (error, moved, count) = strand_motion_error(&motion, pair, cam.view_proj(1.0));
        println!(
            "{path:?} {raster:?}: {count} vertices, median error {error:.3} px, median move {moved:.3} px"
        );
        assert!(count > 200, "{path:?} {raster:?}: {count} vertices seen");
        assert!(moved > 1.5, "the pose moved the hair {moved} px");
        assert!(
            error < 0.2 * moved && error < 0.5,
            "{path:?} {raster:?}: motion off the strands' by {error} px (median)"
        );
    }
    assert_no_validation_errors(&ctx);
}

/// Mean reprojected change of the hair's luminance from frame to frame (the flicker measure
/// of `bench temporal`, `render::temporal::reprojected_change`) over a slow orbit of the head
/// (0.25 degrees a frame), after `warmup` frames, with `temporal` on or off.
fn orbit_flicker(temporal: Temporal, frames: u32, warmup: usize) -> f64 {
    let ctx = context();
    let (baked, style) = sample("head_long.obj");
    let base = framing(&baked);
    let mut r = Renderer::new(&ctx, &RendererDesc::default().size(SIZE, SIZE)).unwrap();
    upload(&mut r, &baked, &style, 16, 4);
    let mut images = Vec::new();
    let mut motion = Vec::new();
    for f in 0..frames {
        let turn = Mat4::from_rotation_y(0.25f32.to_radians() * f as f32);
        let camera = Camera {
            eye: base.target + turn.transform_vector3(base.eye - base.target),
            ..base
        };
        let opts = FrameOptions {
            path: Some(RenderPath::Compute),
            read_image: true,
            read_motion: true,
            ..Default::default()
        };
        let report = r
            .render_one(&view(camera, Transparency::Opaque, temporal), &opts)
            .unwrap();
        images.push(report.rgba.unwrap());
        motion.push(report.motion.unwrap());
    }
    assert_no_validation_errors(&ctx);
    let mut changes = Vec::new();
    for f in warmup.max(1)..images.len() {
        let mask = hair_mask(&motion[f]);
        let (change, n) =
            reprojected_change(&images[f - 1], &images[f], &motion[f], &mask, (SIZE, SIZE));
        assert!(n > 100, "frame {f}: {n} hair pixels");
        changes.push(change);
    }
    changes.iter().sum::<f64>() / changes.len() as f64
}

/// Temporal accumulation steadies sub-pixel strands: over a slow orbit the hair's luminance
/// changes from frame to frame (along the true motion) much less with `taa` than without:
/// measured on lavapipe 0.00446 against 0.01035, a ratio of 0.431; the bound, 0.6, sits
/// between that and the ratio near 1 that accumulation switched off, or history that never
/// blends, reads (`bench temporal` quantifies the same measure at full size).
#[test]
fn accumulation_reduces_flicker() {
    let off = orbit_flicker(Temporal::Off, 14, 6);
    let taa = orbit_flicker(Temporal::Taa, 14, 6);
    println!(
        "orbit flicker: {off:.5} off, {taa:.5} with taa (ratio {:.3})",
        taa / off
    );
    assert!(taa < 0.6 * off, "taa {taa} against {off} without");
}
