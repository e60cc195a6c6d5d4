//! The render world's half: the renderer on Bevy's device, kept in step with the main world's
//! hair (extract, prepare), and one host frame per 3D camera recorded between Bevy's opaque
//! and transparent passes, into a command buffer of its own that Bevy submits in order.

// wgpu textures key the image cache: they hash and compare by identity, not by the interior
// state clippy sees.
#![allow(clippy::mutable_key_type)]

use std::collections::HashMap;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use bevy::core_pipeline::core_3d::{main_opaque_pass_3d, main_transparent_pass_3d};
use bevy::core_pipeline::schedule::{Core3d, Core3dSystems};
use bevy::prelude::*;
use bevy::render::renderer::{RenderContext, RenderDevice, RenderQueue, ViewQuery};
use bevy::render::view::{ExtractedView, ViewDepthTexture, ViewTarget};
use bevy::render::{Extract, ExtractSchedule, Render, RenderApp, RenderSystems};
use hairmesh::render::{
    CharacterId, FRAMES_IN_FLIGHT, FrameOptions, FrameTicket, HostCamera, HostFrame, HostImage,
    Renderer, RendererDesc, View,
};
use hairmesh::vk::wgpu_host::wgpu;
use hairmesh::vk::{Access, Image, WgpuDevice, wgpu_host};

use crate::library::{LoadedHair, PlacedHair};
use crate::{HairSettings, to_glam};

/// What the hair frames did, readable from both worlds (a clone of one shared record).
#[derive(Resource, Clone, Default)]
pub struct HairFrames(Arc<Mutex<FrameRecord>>);

/// See [`HairFrames`].
#[derive(Clone, Debug, Default)]
pub struct FrameRecord {
    /// Hair frames recorded (one per camera per Bevy frame).
    pub recorded: u64,
    /// Hair frames whose GPU work completed and was read back.
    pub completed: u64,
    /// Strands drawn by the last completed frame.
    pub strands_drawn: u32,
    /// GPU milliseconds of the last completed frame (0 where the device cannot time).
    pub gpu_ms: f64,
    /// Characters the renderer holds.
    pub characters: usize,
    /// Vulkan validation messages so far (the renderer's and Bevy's, on the shared device).
    pub validation_errors: u32,
    /// The last error, one line (a refused camera, a failed upload).
    pub last_error: Option<String>,
}

impl HairFrames {
    /// A copy of the record.
    pub fn record(&self) -> FrameRecord {
        self.0.lock().map(|r| r.clone()).unwrap_or_default()
    }

    fn update(&self, f: impl FnOnce(&mut FrameRecord)) {
        if let Ok(mut r) = self.0.lock() {
            f(&mut r);
        }
    }

    fn fail(&self, what: String) {
        self.update(|r| {
            if r.last_error.as_ref() != Some(&what) {
                error!("hair: {what}");
            }
            r.last_error = Some(what);
        });
    }
}

/// The main world's hair, light and settings, copied for this frame.
#[derive(Resource, Default)]
struct ExtractedHair {
    hairs: Vec<(Entity, Arc<LoadedHair>, glam::Mat4)>,
    toward_light: Option<glam::Vec3>,
    settings: HairSettings,
}

/// A Bevy texture as a host image, kept while Bevy uses it.
struct CachedImage {
    image: Image,
    /// Keeps the `VkImage` alive as long as `image` refers to it.
    _texture: wgpu::Texture,
    last_used: u64,
}

/// A frame slot's last frame: its ticket, and whether Bevy's submission of it has completed.
struct SlotUse {
    ticket: FrameTicket,
    done: Arc<AtomicBool>,
    submitted: bool,
}

/// The renderer and what it draws; fields drop in order, the device last.
struct HairState {
    renderer: Option<Renderer>,
    images: HashMap<wgpu::Texture, CachedImage>,
    characters: HashMap<Entity, (CharacterId, Arc<LoadedHair>)>,
    slots: Vec<Option<SlotUse>>,
    next_slot: usize,
    frame: u64,
    device: WgpuDevice,
}

#[derive(Resource)]
struct HairRenderState(Mutex<HairState>);

/// Add the render world's systems, with the renderer's device.
pub(crate) fn build(app: &mut App, device: WgpuDevice) {
    let frames = HairFrames::default();
    app.insert_resource(frames.clone());
    let Some(render_app) = app.get_sub_app_mut(RenderApp) else {
        error!("HairPlugin: no render app (add it after DefaultPlugins)");
        return;
    };
    let state = HairState {
        renderer: None,
        images: HashMap::new(),
        characters: HashMap::new(),
        slots: (0..FRAMES_IN_FLIGHT).map(|_| None).collect(),
        next_slot: 0,
        frame: 0,
        device,
    };
    render_app
        .insert_resource(frames)
        .insert_resource(HairRenderState(Mutex::new(state)))
        .init_resource::<ExtractedHair>()
        .add_systems(ExtractSchedule, extract_hair)
        .add_systems(Render, sync_renderer.in_set(RenderSystems::Prepare))
        .add_systems(Render, mark_submitted.in_set(RenderSystems::Cleanup))
        .add_systems(
            Core3d,
            draw_hair
                .in_set(Core3dSystems::MainPass)
                .after(main_opaque_pass_3d)
                .before(main_transparent_pass_3d),
        );
}

fn extract_hair(
    mut out: ResMut<ExtractedHair>,
    hairs: Extract<Query<(Entity, &PlacedHair)>>,
    lights: Extract<Query<&GlobalTransform, With<DirectionalLight>>>,
    settings: Extract<Res<HairSettings>>,
) {
    out.hairs = hairs
        .iter()
        .map(|(e, p)| (e, p.hair.clone(), p.model))
        .collect();
    // A directional light shines along its forward axis: toward it is its back.
    out.toward_light = lights.iter().next().map(|t| {
        let b = t.back();
        glam::Vec3::new(b.x, b.y, b.z)
    });
    out.settings = **settings;
}

/// Add, move and remove the renderer's characters to match the main world's hair.
fn sync_renderer(
    state: Res<HairRenderState>,
    extracted: Res<ExtractedHair>,
    frames: Res<HairFrames>,
) {
    let Ok(mut guard) = state.0.lock() else {
        return;
    };
    let state = &mut *guard;
    if let Err(e) = sync(state, &extracted) {
        frames.fail(e.to_string());
    }
    let count = state.characters.len();
    let errors = state.device.context.validation_errors();
    frames.update(|r| {
        r.characters = count;
        r.validation_errors = errors;
    });
}

fn sync(state: &mut HairState, extracted: &ExtractedHair) -> hairmesh::vk::GpuResult<()> {
    if extracted.hairs.is_empty() && state.renderer.is_none() {
        return Ok(());
    }
    let renderer = match &mut state.renderer {
        Some(r) => r,
        none => none.insert(Renderer::new(
            &state.device.context,
            &RendererDesc::default().size(64, 64),
        )?),
    };
    let wanted: HashMap<Entity, _> = extracted.hairs.iter().map(|h| (h.0, h)).collect();
    let gone: Vec<Entity> = state
        .characters
        .iter()
        .filter(|(e, (_, hair))| wanted.get(e).is_none_or(|w| !Arc::ptr_eq(&w.1, hair)))
        .map(|(e, _)| *e)
        .collect();
    for entity in gone {
        if let Some((id, _)) = state.characters.remove(&entity) {
            renderer.remove_character(id)?;
        }
    }
    for (entity, hair, model) in &extracted.hairs {
        match state.characters.get(entity) {
            Some((id, _)) => renderer.set_model(*id, *model)?,
            None => {
                let id = renderer.add_character(&hair.baked, &hair.style, hair.params, *model)?;
                state.characters.insert(*entity, (id, hair.clone()));
            }
        }
    }
    Ok(())
}

/// Draw the hair into one camera's colour, hidden behind its depth.
fn draw_hair(
    view: ViewQuery<(&ExtractedView, &ViewTarget, &ViewDepthTexture)>,
    extracted: Res<ExtractedHair>,
    state: Res<HairRenderState>,
    frames: Res<HairFrames>,
    device: Res<RenderDevice>,
    mut ctx: RenderContext,
) {
    let (view, target, depth) = view.into_inner();
    if !extracted.settings.enabled || extracted.hairs.is_empty() {
        return;
    }
    if target.sampled_main_texture().is_some() {
        frames.fail("a camera with MSAA: hair needs `Msaa::Off` (see hair_camera)".into());
        return;
    }
    let Ok(mut guard) = state.0.lock() else {
        return;
    };
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("hair"),
    });
    let drawn = record(
        &mut guard,
        &extracted,
        &frames,
        (view, target, depth),
        &mut encoder,
    );
    match drawn {
        Ok(()) => ctx.add_command_buffer(encoder.finish()),
        Err(e) => frames.fail(e.to_string()),
    }
}

/// The host frame of one camera, into `encoder`.
fn record(
    state: &mut HairState,
    extracted: &ExtractedHair,
    frames: &HairFrames,
    (view, target, depth): (&ExtractedView, &ViewTarget, &ViewDepthTexture),
    encoder: &mut wgpu::CommandEncoder,
) -> hairmesh::vk::GpuResult<()> {
    let slot = state.next_slot;
    free_slot(state, slot, frames)?;
    state.frame += 1;
    let frame = state.frame;
    // Before recording: a view destroyed while a command buffer is recording invalidates it.
    evict_images(state);
    let color = cached_image(state, target.main_texture(), "bevy colour", frame)?;
    let depth_image = match extracted.settings.depth_test {
        true => Some(cached_image(state, &depth.texture, "bevy depth", frame)?),
        false => None,
    };
    let camera = HostCamera {
        view: to_glam(view.world_from_view.to_matrix().inverse()),
        proj: to_glam(view.clip_from_view),
    };
    let mut look = View::crowd_look(hairmesh::render::Camera::look_at(
        glam::Vec3::Z,
        glam::Vec3::ZERO,
        40.0,
    ));
    // The crowd's level of detail: grown hair is a real head's count, which the pixel cap
    // thins at distance.
    look.lod = hairmesh::render::LodSettings::crowd();
    if let Some(dir) = extracted.toward_light {
        look.light_dir = dir;
    }
    if !extracted.settings.shadows {
        look.shadows = hairmesh::render::ShadowMode::Off;
    }
    let images = &state.images;
    let renderer = state.renderer.as_mut().expect("a renderer with hair");
    let ticket = wgpu_host::record_into(encoder, |cmd| {
        let host_image = |t: &wgpu::Texture, access| HostImage {
            image: &images[t].image,
            before: access,
            after: access,
        };
        renderer.record_host_frame(
            &look,
            &FrameOptions::default(),
            HostFrame {
                cmd,
                slot,
                camera,
                color: host_image(&color, Access::ColorAttachment),
                depth: depth_image.map(|d| host_image(&d, Access::DepthAttachment)),
                depth_slack: extracted.settings.depth_slack,
            },
        )
    })??;
    state.slots[slot] = Some(SlotUse {
        ticket,
        done: Arc::new(AtomicBool::new(false)),
        submitted: false,
    });
    state.next_slot = (slot + 1) % FRAMES_IN_FLIGHT;
    frames.update(|r| r.recorded += 1);
    Ok(())
}

/// The host image of Bevy's texture `t` (made the first time it is seen); its key.
fn cached_image(
    state: &mut HairState,
    t: &wgpu::Texture,
    name: &str,
    frame: u64,
) -> hairmesh::vk::GpuResult<wgpu::Texture> {
    if !state.images.contains_key(t) {
        let image = Image::from_wgpu(&state.device.context, &state.device, t, name)?;
        let cached = CachedImage {
            image,
            _texture: t.clone(),
            last_used: frame,
        };
        state.images.insert(t.clone(), cached);
    }
    if let Some(c) = state.images.get_mut(t) {
        c.last_used = frame;
    }
    Ok(t.clone())
}

/// Forget host images of textures Bevy stopped drawing to (resized, or a camera gone) once
/// every frame that may have used them has completed.
fn evict_images(state: &mut HairState) {
    let keep_after = state.frame.saturating_sub(FRAMES_IN_FLIGHT as u64 + 1);
    state.images.retain(|_, c| c.last_used > keep_after);
}

/// Wait until the last frame recorded in `slot` has completed on the GPU, and take its report.
fn free_slot(
    state: &mut HairState,
    slot: usize,
    frames: &HairFrames,
) -> hairmesh::vk::GpuResult<()> {
    let Some(last) = state.slots[slot].take() else {
        return Ok(());
    };
    if !last.submitted {
        // Recorded this frame by another camera, not yet submitted: its resources are busy.
        state.slots[slot] = Some(last);
        return Err(hairmesh::vk::GpuError::Unsupported(format!(
            "more than {FRAMES_IN_FLIGHT} cameras draw hair in one frame"
        )));
    }
    while !last.done.load(Ordering::Acquire) {
        let waited = state
            .device
            .device
            .poll(wgpu::PollType::wait_indefinitely());
        if let Err(e) = waited {
            return Err(hairmesh::vk::GpuError::Unsupported(format!(
                "wgpu poll: {e}"
            )));
        }
    }
    let renderer = state.renderer.as_mut().expect("a renderer with frames");
    let report = renderer.wait(last.ticket)?;
    frames.update(|r| {
        r.completed += 1;
        r.strands_drawn = report.stats.strands_drawn;
        r.gpu_ms = report.gpu_ms();
    });
    Ok(())
}

/// After Bevy's submission: each slot recorded this frame completes with it.
fn mark_submitted(state: Res<HairRenderState>, queue: Res<RenderQueue>) {
    let Ok(mut guard) = state.0.lock() else {
        return;
    };
    for used in guard.slots.iter_mut().flatten() {
        if !used.submitted {
            used.submitted = true;
            let done = used.done.clone();
            queue.on_submitted_work_done(move || done.store(true, Ordering::Release));
        }
    }
}
