//! Synchronization validation (`VK_VALIDATION_FEATURE_ENABLE_SYNCHRONIZATION_VALIDATION_EXT`)
//! over every frame the renderer can draw: each valid combination of generation path x strand
//! raster x shadows x transparency x MSAA (as `FrameSettings::validate` decides), with the
//! volume tier off, occluding, blending and alone in turn, two frames in
//! flight each on small images, every frame with skinned bodies (the skinning pass) and every
//! other one probing roots, then the static and LHS paths and an animated hair mesh (posed
//! from the CPU, then simulated on the GPU). Any
//! validation message fails. The frame graph derives every barrier from the passes' declared
//! uses; the last test removes one declared read and shows validation catches it.

mod common;

use std::sync::Arc;

use common::*;
use glam::{Mat4, Vec3};
use hairmesh::bake::deform::DeformBasis;
use hairmesh::render::{
    FrameOptions, FrameSettings, LightRaster, LodSettings, RenderPath, Renderer, RendererDesc,
    ShadowMode, StrandParams, StrandRaster, Temporal, Transparency, View, VolumeTier,
};
use hairmesh::shade::ShadingModel;
use hairmesh::vk::{Access, Context, ContextDesc};

fn sync_context() -> Arc<Context> {
    match Context::new(&ContextDesc::default().sync_validation(true)) {
        Ok(c) => Arc::new(c),
        Err(e) => panic!("GPU tests need Vulkan with validation layers (run tools/setup.sh): {e}"),
    }
}

fn params() -> StrandParams {
    StrandParams {
        strands_per_bundle: 6,
        verts_log2: 3,
    }
}

/// Two characters of `head_long` side by side, and a view of them.
fn scene(ctx: &Arc<Context>, desc: RendererDesc) -> (Renderer, View) {
    let (baked, style) = sample("head_long.obj");
    let mut r = Renderer::new(ctx, &desc.size(40, 32)).unwrap();
    // Each character also wears the man's skinned body in the walk (the skinning pass, read
    // by the camera's and the light's prop passes), small and beside its hair.
    let meshes = hairmesh::characters::people::skinned_meshes().unwrap();
    r.set_skinned_meshes(&meshes).unwrap();
    let man = &hairmesh::characters::people::figures().unwrap()[0];
    let walk = man.clip("walk").unwrap();
    let pose = man.skeleton.skin_matrices(&walk.sample(&man.skeleton, 0.3));
    let parts: Vec<(usize, [f32; 4])> = (0..5).map(|k| (k, [0.5, 0.4, 0.3, 1.0])).collect();
    for x in [-0.15f32, 0.15] {
        let model = Mat4::from_translation(Vec3::new(x, 0.0, 0.0));
        let id = r.add_character(&baked, &style, params(), model).unwrap();
        r.set_character_skin(id, &parts, pose.len()).unwrap();
        let body = model * Mat4::from_scale(Vec3::splat(0.2));
        r.set_character_pose(id, body, &pose).unwrap();
    }
    let view = View {
        shading: ShadingModel::Marschner,
        multiple_scattering: true,
        ..View::new(framing(&baked))
    };
    (r, view)
}

/// Two frames in flight, then wait; fails on any validation message naming `what`.
fn two_frames(ctx: &Context, r: &mut Renderer, view: &View, opts: &FrameOptions, what: &str) {
    let a = r
        .render_frame(view, opts)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    let b = r
        .render_frame(view, opts)
        .unwrap_or_else(|e| panic!("{what}: {e}"));
    r.wait(a).unwrap();
    r.wait(b).unwrap();
    assert!(
        ctx.validation_errors() == 0,
        "{what}: {:#?}",
        ctx.validation_messages()
    );
}

#[test]
fn every_pass_combination_is_free_of_hazards() {
    let ctx = sync_context();
    let mut valid = 0;
    let mut soft_lights = 0;
    for msaa in [1, 4] {
        let (mut r, base) = scene(&ctx, RendererDesc::default().msaa(msaa));
        for path in [RenderPath::Mesh, RenderPath::Compute] {
            for raster in [
                StrandRaster::Hardware,
                StrandRaster::Software { k: 4 },
                StrandRaster::Auto { k: 4 },
            ] {
                for shadows in [
                    ShadowMode::Off,
                    ShadowMode::Approximate,
                    ShadowMode::DeepOpacity,
                ] {
                    for transparency in [
                        Transparency::Opaque,
                        Transparency::KBuffer { budget: 4 },
                        Transparency::DepthPeeling { layers: 2 },
                    ] {
                        // The light's passes alternate between the hardware and the
                        // software ones, so each path, shadow mode and draw meets both.
                        let light_raster = match shadows != ShadowMode::Off && valid % 2 == 1 {
                            true => LightRaster::Software,
                            false => LightRaster::Hardware,
                        };
                        let settings = FrameSettings {
                            path,
                            raster,
                            transparency,
                            msaa,
                            light_raster,
                        };
                        if settings.validate(&r.caps()).is_err() {
                            continue;
                        }
                        valid += 1;
                        soft_lights += (light_raster == LightRaster::Software) as u32;
                        // Every third combination accumulates (its second frame blends the
                        // first's history), the next reads motion vectors back.
                        let temporal = match valid % 3 {
                            0 => Temporal::Taa,
                            _ => Temporal::Off,
                        };
                        // The volume tier in turn: off, occlusion only, most of the hair
                        // blended toward the volume, the volume alone.
                        let volumes = match valid % 4 {
                            0 => VolumeTier::OFF,
                            1 => VolumeTier {
                                far: None,
                                ..VolumeTier::on()
                            },
                            2 => VolumeTier {
                                far: Some((0.0, 1e6)),
                                ..VolumeTier::on()
                            },
                            _ => VolumeTier {
                                far: Some((1e6, 1e6)),
                                ..VolumeTier::on()
                            },
                        };
                        let view = View {
                            shadows,
                            transparency,
                            temporal,
                            volumes,
                            ..base
                        };
                        let opts = FrameOptions {
                            path: Some(path),
                            raster,
                            light_raster,
                            read_image: valid % 2 == 0,
                            read_motion: valid % 3 == 1,
                            probe_roots: valid % 2 == 1,
                            ..Default::default()
                        };
                        let what = format!(
                            "{path:?} {raster} {shadows:?} (light {light_raster}) {transparency} {msaa}x temporal {temporal} volumes {:?}",
                            volumes.far
                        );
                        two_frames(&ctx, &mut r, &view, &opts, &what);
                    }
                }
            }
        }
    }
    // Per path: 9 hardware + 6 soft + 6 auto single-sample combinations, 6 with 4x MSAA.
    assert_eq!(valid, 2 * (9 + 6 + 6 + 6), "combinations drawn");
    assert!(
        soft_lights >= 12,
        "software light passes drawn {soft_lights} times"
    );
}

#[test]
fn static_lhs_and_animated_frames_are_free_of_hazards() {
    let ctx = sync_context();
    let (mut r, base) = scene(&ctx, RendererDesc::default());
    let view = View {
        shadows: ShadowMode::DeepOpacity,
        transparency: Transparency::KBuffer { budget: 4 },
        lod: LodSettings::off(),
        ..base
    };
    let compute = FrameOptions {
        path: Some(RenderPath::Compute),
        ..Default::default()
    };
    let first = r.render_one(&view, &compute).unwrap();
    for path in [RenderPath::Static, RenderPath::Lhs] {
        if path == RenderPath::Lhs {
            let vertices = first.stats.vertex_slots_written;
            r.capture_lhs(vertices, 9, 0.05).unwrap();
        }
        // Hardware strips, then the stored strands through the software rasterizer.
        for raster in [StrandRaster::Hardware, StrandRaster::Software { k: 4 }] {
            let opts = FrameOptions {
                path: Some(path),
                raster,
                ..Default::default()
            };
            two_frames(&ctx, &mut r, &view, &opts, &format!("{path:?} {raster}"));
        }
    }
    // An animated hair mesh: its textures are rebuilt on the GPU before the frame reads them.
    let dir = root().join("hairmeshes");
    let mesh = hairmesh::model::obj_io::load_hair_mesh_obj(&dir.join("triangle_tuft.obj")).unwrap();
    let style = hairmesh::HairStyle::load(&dir.join("triangle_tuft.toml")).unwrap();
    let options = hairmesh::BakeOptions {
        motion_margin: 0.2,
        ..Default::default()
    };
    let baked = hairmesh::bake(&mesh, &style, options, |_, _| {}).unwrap();
    let basis = DeformBasis::new(&mesh, &baked, options).unwrap();
    let id = r
        .add_character(&baked, &style, params(), Mat4::IDENTITY)
        .unwrap();
    r.make_deformable(id, basis).unwrap();
    let rest: Vec<Vec3> = mesh.layers.iter().flatten().copied().collect();
    for (k, path) in [RenderPath::Mesh, RenderPath::Compute]
        .into_iter()
        .enumerate()
    {
        let pose: Vec<Vec3> = rest
            .iter()
            .map(|p| *p + Vec3::new(0.01 * (k + 1) as f32, 0.0, 0.0))
            .collect();
        r.set_hair_mesh_pose(id, &pose).unwrap();
        let opts = FrameOptions {
            path: Some(path),
            raster: StrandRaster::Auto { k: 4 },
            ..Default::default()
        };
        two_frames(&ctx, &mut r, &view, &opts, &format!("animated {path:?}"));
    }
    // Its hair dynamics on the GPU: the solver writes the pose the rebuild reads, two frames
    // in flight sharing the state buffer.
    let settings = hairmesh::dynamics::DynamicsSettings::default();
    let sim = hairmesh::dynamics::HairDynamics::new(&mesh, Vec::new(), settings, Mat4::IDENTITY);
    r.simulate_hair(id, &sim).unwrap();
    let opts = FrameOptions {
        path: Some(RenderPath::Compute),
        ..Default::default()
    };
    let mut tickets = Vec::new();
    for f in 1..=2 {
        let model = Mat4::from_rotation_y(0.2 * f as f32);
        r.set_model(id, model).unwrap();
        r.step_hair(id, 1.0 / 60.0, model, &settings).unwrap();
        tickets.push(r.render_frame(&view, &opts).unwrap());
    }
    for t in tickets {
        r.wait(t).unwrap();
    }
    assert!(
        ctx.validation_errors() == 0,
        "GPU dynamics: {:#?}",
        ctx.validation_messages()
    );
}

#[test]
fn a_missing_declared_read_is_caught() {
    // The compute path's strand workgroups are dispatched indirectly from the arguments that
    // finalize wrote: leave out that declared read and nothing orders the indirect read after
    // the write (the bug that once reached main between the tile scan and the scatter).
    let ctx = sync_context();
    let desc = RendererDesc {
        omit_use: Some(("generate".into(), "args".into(), Some(Access::IndirectRead))),
        ..RendererDesc::default()
    };
    let (mut r, view) = scene(&ctx, desc);
    let opts = FrameOptions {
        path: Some(RenderPath::Compute),
        ..Default::default()
    };
    r.render_one(&view, &opts).unwrap();
    let messages = ctx.validation_messages();
    assert!(
        messages.iter().any(|m| m.contains("SYNC-HAZARD")),
        "no hazard reported: {messages:#?}"
    );
}

#[test]
fn a_missing_skinned_read_is_caught() {
    // The opaque pass draws the bodies the skinning pass posed this frame: leave out its
    // declared read of the posed vertices and nothing orders the vertex reads after the
    // compute writes.
    let ctx = sync_context();
    let desc = RendererDesc {
        omit_use: Some((
            "opaque".into(),
            "skinned vertices".into(),
            Some(Access::VertexRead),
        )),
        ..RendererDesc::default()
    };
    let (mut r, view) = scene(&ctx, desc);
    r.render_one(&view, &FrameOptions::default()).unwrap();
    let messages = ctx.validation_messages();
    assert!(
        messages.iter().any(|m| m.contains("SYNC-HAZARD")),
        "no hazard reported: {messages:#?}"
    );
}
