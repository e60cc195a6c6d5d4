//! A frame, from settings to submission: check the settings, size the buffers, write the frame
//! blocks, build the frame graph from the passes, run it, submit (the frames in flight are
//! [`super::core::slots`]).

use std::collections::VecDeque;
use std::sync::Arc;

use std::time::Instant;

use super::RenderPath;
use super::camera::View;
use super::core::graph::FrameGraph;
use super::core::graph::TransientPool;
use super::core::shared::{FrameBinding, SET_FRAME, SET_TEXTURES};
use super::core::shared::{FrameBlock, HairVertex, PropInstance};
use super::core::slots::FrameReport;
use super::core::slots::{
    FRAMES_IN_FLIGHT, FrameSlot, Pending, Retired, prop_instance_buffer, records_buffer,
};
use super::core::targets::{COLOR_FORMAT, DEPTH_FORMAT};
use super::core::targets::{RenderTargets, ShadowMaps};
use super::core::workspace::FrameBuffers;
use super::core::workspace::Workspace;
use super::crowd::Crowd;
use super::dynamics::pass::SimulatedCharacter;
use super::features::temporal::{
    FrameMotion, PreviousFrame, Temporal, TemporalFeature, TemporalWork,
};
use super::host::targets::HostTargetPasses;
use super::host::{DepthMapping, HostFrame, HostImage};
use super::passes::FramePasses;
use super::passes::output::FrameOutputs;
use super::passes::output::Overlay;
use super::passes::props::{PropDraw, PropList};
use super::passes::write_address_table;
use super::passes::{
    FrameInputs, FrameRes, FrameSources, FrameTransients, PassSets, TargetFormats,
};
use super::schedule::{Changes, HostStart, ScheduleInputs, add_frame};
use super::settings::{DeviceCaps, RendererDesc, check_msaa};
use super::settings::{FrameOptions, FrameTicket, LightRaster};
use super::shadow::{LightView, ShadowMode};
use super::soft::SoftBudget;
use super::soft::StrandRaster;
use super::transparency::Transparency;
use super::world::World;
use crate::vk::{
    Access, BindingDesc, Buffer, CommandRecorder, Context, DescriptorSetLayout, GpuError,
    GpuResult, PipelineLayout, Semaphore, SwapchainImage,
};

/// Where a windowed frame goes: a swapchain image, the semaphore its acquisition signals and
/// the one presentation waits for.
pub struct PresentTarget<'a> {
    /// The acquired image.
    pub image: &'a SwapchainImage,
    /// Signalled when the image may be written.
    pub wait: &'a Semaphore,
    /// Signalled when the frame is done (presentation waits for it).
    pub signal: &'a Semaphore,
    /// Drawn over the frame before it is presented (the control panel): called with the
    /// colour target in colour-attachment use.
    pub overlay: Option<&'a mut Overlay<'a>>,
}

/// The frames in flight and everything that draws them: the passes, the targets, the frame
/// slots, the working buffers, the state temporal accumulation and the static and LHS paths
/// keep between frames. What they draw is the [`World`].
pub struct Frames {
    pub(super) ctx: Arc<Context>,
    pub(super) desc: RendererDesc,
    pub(super) passes: FramePasses,
    pub(super) slots: Vec<FrameSlot>,
    pub(super) next: usize,
    pub(super) frame_number: u64,
    pub(super) targets: RenderTargets,
    pub(super) shadow: ShadowMaps,
    /// The frame graph's transient buffers and images, kept across frames.
    pub(super) transients: TransientPool,
    /// The software rasterizer's budgets.
    pub(super) soft_budget: SoftBudget,
    /// The crowd version whose strands the vertex pool holds (the last compute-path frame's),
    /// which static-path frames draw again.
    pub(super) static_version: Option<u64>,
    /// The crowd structure whose strand layout the draw arguments describe (the last compute
    /// frame's; a mesh frame clears them).
    pub(super) args_structure: Option<u64>,
    /// The LHS baseline's stored strands (`capture_lhs`), with the crowd version they are of.
    pub(super) lhs: Option<(u64, super::passes::lhs_skin::LhsState)>,
    pub(super) work: Workspace,
    /// The previous frame's matrices and the temporal history.
    pub(super) temporal: TemporalFeature,
    pub(super) completed: VecDeque<FrameReport>,
    /// The passes of host frames, made by the first one.
    pub(super) host_passes: Option<HostTargetPasses>,
}

impl Frames {
    /// Create pipelines, targets and frame slots for `crowd`'s textures; `soft_budget` as
    /// checked against the device.
    pub fn new(
        ctx: &Arc<Context>,
        desc: &RendererDesc,
        crowd: &Crowd,
        soft_budget: SoftBudget,
    ) -> GpuResult<Self> {
        let bindings: Vec<BindingDesc> = FrameBinding::ALL
            .iter()
            .map(|(b, _)| BindingDesc::single(*b as u32, b.kind()))
            .collect();
        let frame_layout = DescriptorSetLayout::new(ctx, &bindings)?;
        let mut set_layouts = vec![frame_layout.clone(); 2];
        set_layouts[SET_FRAME as usize] = frame_layout.clone();
        set_layouts[SET_TEXTURES as usize] = crowd.texture_layout().clone();
        let layout = PipelineLayout::new(ctx, &set_layouts)?;
        check_msaa(ctx, desc.msaa)
            .map_err(|why| GpuError::Unsupported(format!("{}x MSAA: {why}", desc.msaa)))?;
        let passes = FramePasses::new(ctx, &layout, desc.task_bundles, desc.msaa)?;
        let temporal = TemporalFeature::new(ctx, &layout)?;
        if desc.path == Some(RenderPath::Mesh) && !passes.has_mesh_path() {
            return Err(GpuError::Unsupported(format!(
                "{}: no usable VK_EXT_mesh_shader for the mesh path",
                ctx.info.name
            )));
        }
        let slots = (0..FRAMES_IN_FLIGHT)
            .map(|_| FrameSlot::new(ctx, &frame_layout))
            .collect::<GpuResult<_>>()?;
        Ok(Frames {
            ctx: ctx.clone(),
            desc: desc.clone(),
            passes,
            slots,
            next: 0,
            frame_number: 0,
            targets: RenderTargets::new(ctx, desc.width, desc.height, desc.msaa)?,
            shadow: ShadowMaps::new(ctx, desc.shadow_resolution)?,
            transients: TransientPool::new(ctx),
            soft_budget,
            static_version: None,
            args_structure: None,
            lhs: None,
            work: Workspace::new(ctx)?,
            temporal,
            completed: VecDeque::new(),
            host_passes: None,
        })
    }

    /// The path frames use unless told otherwise.
    pub fn default_path(&self) -> RenderPath {
        match self.desc.path {
            Some(p) => p,
            None if self.passes.has_mesh_path() => RenderPath::Mesh,
            None => RenderPath::Compute,
        }
    }

    /// What this device offers, for [`super::FrameSettings::validate`].
    pub fn caps(&self) -> DeviceCaps {
        DeviceCaps {
            name: self.ctx.info.name.clone(),
            mesh_path: self.passes.has_mesh_path(),
            int64_atomics: self.passes.has_software_raster(),
        }
    }

    /// The software rasterizer's budgets and the `RendererDesc` choices it draws with.
    pub fn soft_tuning(&self) -> super::soft::SoftTuning {
        super::soft::SoftTuning {
            budget: self.soft_budget,
            auto_split_pixels: self.desc.auto_split_pixels,
        }
    }

    /// Vertex slots of the compute path's pool.
    pub fn vertex_budget(&self) -> u32 {
        (self.desc.vertex_pool_bytes / size_of::<HairVertex>() as u64).min(u32::MAX as u64) as u32
    }

    /// Recreate the targets at a new size (frames in flight keep the old ones until done).
    pub fn resize(&mut self, crowd: &mut Crowd, width: u32, height: u32) -> GpuResult<()> {
        super::settings::check_size(width, height)?;
        if self.targets.size() == (width, height) {
            return Ok(());
        }
        let old = std::mem::replace(
            &mut self.targets,
            RenderTargets::new(&self.ctx, width, height, self.desc.msaa)?,
        );
        self.retire(crowd, Retired::Resource(Box::new(old)));
        Ok(())
    }

    /// The index of the frame slot the newest submitted frame used.
    fn last_index(&self) -> usize {
        (self.next + FRAMES_IN_FLIGHT - 1) % FRAMES_IN_FLIGHT
    }

    /// The frame slot the newest submitted frame used.
    pub(super) fn last_slot(&self) -> &FrameSlot {
        &self.slots[self.last_index()]
    }

    /// Release `r` after the newest submitted frame completes (now if none is pending).
    pub(super) fn retire(&mut self, crowd: &mut Crowd, r: Retired) {
        let last = self.last_index();
        if self.slots[last].pending.is_some() {
            self.slots[last].retired.push(r);
        } else if let Retired::CharacterSlot(s) = r {
            crowd.free_slot(s);
        }
    }

    /// Wait for frame slot `i`, collect its report and release what was retired with it.
    pub(super) fn retire_slot(&mut self, crowd: &mut Crowd, i: usize) -> GpuResult<()> {
        let slot = &mut self.slots[i];
        slot.fence.wait()?;
        if let Some(p) = slot.pending.take() {
            self.completed.push_back(slot.report(p)?);
            while self.completed.len() > 2 * FRAMES_IN_FLIGHT {
                self.completed.pop_front();
            }
        }
        for r in std::mem::take(&mut self.slots[i].retired) {
            if let Retired::CharacterSlot(s) = r {
                crowd.free_slot(s);
            }
        }
        Ok(())
    }

    /// Wait for a submitted frame and return its report.
    pub fn wait(&mut self, crowd: &mut Crowd, ticket: FrameTicket) -> GpuResult<FrameReport> {
        // The frame pending in slot `i`, if any.
        let pending = |slots: &[FrameSlot], i: usize| slots[i].pending.as_ref().map(|p| p.frame);
        if let Some(i) = (0..FRAMES_IN_FLIGHT).find(|&i| pending(&self.slots, i) == Some(ticket.0))
        {
            // Frames complete in order: retire the older pending frame first.
            let other = (i + 1) % FRAMES_IN_FLIGHT;
            if pending(&self.slots, other).is_some_and(|f| f < ticket.0) {
                self.retire_slot(crowd, other)?;
            }
            self.retire_slot(crowd, i)?;
        }
        self.completed
            .iter()
            .position(|r| r.frame == ticket.0)
            .and_then(|k| self.completed.remove(k))
            .ok_or_else(|| {
                GpuError::Unsupported(format!("report of frame {} is no longer kept", ticket.0))
            })
    }

    /// Wait for every frame in flight.
    pub fn finish(&mut self, crowd: &mut Crowd) -> GpuResult<()> {
        for k in 1..=FRAMES_IN_FLIGHT {
            self.retire_slot(crowd, (self.next + k) % FRAMES_IN_FLIGHT)?;
        }
        Ok(())
    }
}

/// The density volumes of a frame.
struct DensityWork {
    /// The volumes built this frame: character slots, in the order of the slot's job table.
    built: Vec<usize>,
    /// The most bundles among their characters.
    most_bundles: u32,
    /// What the volume tier draws.
    draw: super::volume::TierDraw,
}

/// One frame's prop draws: the camera's, and the light's (the same props, bodies at the
/// far level the light's map needs).
pub(super) struct PropDraws {
    camera: Vec<PropDraw>,
    light: Vec<PropDraw>,
}

/// What one frame draws (beyond the options the caller gave).
pub(super) struct FrameWork<'a> {
    path: RenderPath,
    bundles: u32,
    props: &'a PropDraws,
    /// Skinning jobs this frame and the most vertices of one.
    skin: (u32, u32),
    /// Shadow mode, when shadows are on and there is hair to shadow.
    shadows: Option<ShadowMode>,
    /// How strands are composited.
    transparency: super::Transparency,
    /// How strands are rasterized.
    raster: StrandRaster,
    /// How the light's passes draw the hair.
    light_raster: LightRaster,
    /// k-buffer nodes per pixel (OIT budget, or the software rasterizer's K).
    kbuffer_budget: u32,
    /// Character slots whose hair mesh pose changed (rebuilt this frame).
    pose_updates: Vec<usize>,
    /// Character slots whose hair is simulated on the GPU this frame (their steps are in the
    /// slot's job table, in this order).
    simulated: Vec<usize>,
    /// The density volumes built and drawn this frame.
    density: DensityWork,
    /// Motion vectors and accumulation, when the frame has them.
    temporal: Option<TemporalWork>,
    /// The transient buffers and images the frame graph creates.
    transients: FrameTransients,
}

/// Where a frame is recorded and what it draws into.
pub(super) enum FrameTarget<'t, 'p> {
    /// The renderer's own command buffer, submitted here, and its own targets; the output is
    /// blitted onto a swapchain image when presented.
    Own(Option<&'t mut PresentTarget<'p>>),
    /// A host's command buffer (the host submits it), the hair composited over its colour and
    /// hidden behind its depth.
    Host(HostTargets<'t>),
}

impl FrameTarget<'_, '_> {
    /// The uses the host left its colour and depth in (`Nothing` for own frames).
    fn host_uses(&self) -> (Access, Access) {
        match self {
            FrameTarget::Host(h) => (
                h.color.before,
                h.depth.map_or(Access::Nothing, |d| d.before),
            ),
            FrameTarget::Own(_) => (Access::Nothing, Access::Nothing),
        }
    }
}

/// A host frame's command buffer and images.
pub(super) struct HostTargets<'t> {
    pub cmd: ash::vk::CommandBuffer,
    pub color: &'t HostImage<'t>,
    pub depth: Option<&'t HostImage<'t>>,
    /// The host's depth in the renderer's terms.
    pub mapping: DepthMapping,
}

impl Frames {
    /// [`super::Renderer::render_frame`], then blit the image onto `present.image` (scaled to its
    /// size) after `present.wait`, signalling `present.signal` for presentation.
    pub(in crate::render) fn render_frame_to(
        &mut self,
        world: &mut World,
        background: [f32; 3],
        view: &View,
        opts: &FrameOptions,
        mut present: Option<PresentTarget>,
    ) -> GpuResult<FrameTicket> {
        let target = FrameTarget::Own(present.as_mut());
        self.draw_frame(world, background, self.next, view, opts, target)
    }

    /// Draw one frame in frame slot `i` (waited for first) into `target`: check the settings,
    /// write the slot's tables, build and run the frame graph, and submit it (the renderer's
    /// own command buffer) or leave it to the host.
    pub(super) fn draw_frame(
        &mut self,
        world: &mut World,
        background: [f32; 3],
        i: usize,
        view: &View,
        opts: &FrameOptions,
        mut target: FrameTarget,
    ) -> GpuResult<FrameTicket> {
        let (path, kbuffer_budget) = self.check_frame(world, view, opts)?;
        let temporal = self.temporal_work(view, opts, path)?;
        // What draws the frame's bundles, decided once (`auto` with k-buffer OIT is all
        // software): the passes, buffers and frame blocks all follow it.
        let raster = super::settings::raster_under(opts.raster, view.transparency);
        self.retire_slot(&mut world.crowd, i)?;
        self.prepare_history(i, temporal)?;
        self.prepare_workspace(world, i, path)?;
        let updates = world.crowd.write_pending_poses(i)?;
        let simulated = self.write_sim_jobs(i, &updates.simulated)?;
        let pose_updates = updates.updated;
        let (mut block, light_block) =
            self.frame_blocks(world, view, opts, (raster, kbuffer_budget));
        let motion = self
            .temporal
            .write_block(&mut block, temporal, self.targets.size());
        // Software light passes only where there is a light view this frame.
        let light_raster = light_block.map_or(LightRaster::Hardware, |_| opts.light_raster);
        let soft_light = (light_raster == LightRaster::Software).then_some(view.shadows);
        let transients = self.frame_transients(
            (view.transparency, raster),
            soft_light,
            kbuffer_budget,
            temporal,
        )?;
        // Motion matrices only where the frame's temporal pass reads them.
        let moving = temporal.map(|_| &motion);
        let mut records = self.frame_records(world, &pose_updates, moving);
        let density = self.write_density_jobs(
            world,
            i,
            &mut records,
            (&view.volumes, &block),
            &pose_updates,
        )?;
        let work_draw = density.draw;
        let blocks = (&block, light_block.as_ref());
        let (prop_draws, skin) = self.write_slot(world, i, blocks, &records, moving, opts)?;
        let start = Instant::now();
        let work = FrameWork {
            path,
            bundles: world.crowd.bundle_count(),
            props: &prop_draws,
            skin,
            shadows: light_block.map(|_| view.shadows),
            transparency: view.transparency,
            raster,
            light_raster,
            kbuffer_budget,
            pose_updates,
            simulated,
            density,
            temporal,
            transients,
        };
        let (frame_graph, unscoped_commands) =
            self.record((world, background), i, work, opts, &mut target)?;
        let record_ms = start.elapsed().as_secs_f64() * 1e3;
        let recorded = (frame_graph, unscoped_commands, record_ms);
        let bundles = world.crowd.bundle_count();
        let pending = self.pending((path, opts), recorded, (work_draw, bundles), &block);
        self.hand_over(i, pending, target)?;
        self.remember_frame(&records, &motion, temporal);
        self.after_submit(world, path, raster);
        self.next = (i + 1) % FRAMES_IN_FLIGHT;
        Ok(FrameTicket(self.frame_number - 1))
    }

    /// What the report of this frame (drawn on `path` with `opts`) needs once it completes:
    /// the graph's description, the commands outside every scope and the CPU ms it took to
    /// record, the volume tier's draw and the bundles, the frame block.
    fn pending(
        &self,
        (path, opts): (RenderPath, &FrameOptions),
        (frame_graph, unscoped_commands, record_ms): (Option<String>, u32, f64),
        (tier, bundles): (super::volume::TierDraw, u32),
        block: &FrameBlock,
    ) -> Pending {
        let (width, height) = self.targets.size();
        Pending {
            frame: self.frame_number,
            path,
            width,
            height,
            record_ms,
            read_image: opts.read_image,
            read_motion: opts.read_motion,
            frame_graph,
            volume_characters: (tier.alone, tier.blended),
            probe_roots: opts.probe_roots.then_some(bundles),
            unscoped_commands,
            budgets: self.view_budgets(path, block),
        }
    }

    /// This frame's temporal work (`None`: no motion vectors), or why this device cannot do
    /// it: the compute path's vertices carry deformation residuals.
    fn temporal_work(
        &self,
        view: &View,
        opts: &FrameOptions,
        path: RenderPath,
    ) -> GpuResult<Option<TemporalWork>> {
        let vertex_slots = match path {
            RenderPath::Compute => self.desc.vertex_pool_bytes / size_of::<HairVertex>() as u64,
            _ => 0,
        };
        self.temporal
            .work(view.temporal, opts.read_motion, vertex_slots)
    }

    /// The temporal history for this frame's size where it accumulates; history buffers it
    /// replaces are retired with frame slot `i`.
    fn prepare_history(&mut self, i: usize, temporal: Option<TemporalWork>) -> GpuResult<()> {
        if let Some(old) = self
            .temporal
            .prepare(&self.ctx, temporal, self.targets.size())?
        {
            self.slots[i].retired.push(Retired::Resource(Box::new(old)));
        }
        Ok(())
    }

    /// The buffers the views' LoD had to fit this frame (the LoD pressure's budgets).
    fn view_budgets(
        &self,
        path: RenderPath,
        block: &FrameBlock,
    ) -> super::core::slots::ViewBudgets {
        super::core::slots::ViewBudgets {
            segments: self.soft_budget.segments,
            pool: match path {
                RenderPath::Compute => block.counts.vertex_budget,
                _ => 0,
            },
        }
    }

    /// Write this frame's GPU hair dynamics steps into frame slot `i`'s job table (grown as
    /// needed: its earlier frame has completed); their character slots, in table order.
    fn write_sim_jobs(
        &mut self,
        i: usize,
        steps: &[(usize, super::core::shared::SimJob)],
    ) -> GpuResult<Vec<usize>> {
        if steps.is_empty() {
            return Ok(Vec::new());
        }
        let jobs: Vec<super::core::shared::SimJob> = steps.iter().map(|(_, j)| *j).collect();
        let bytes = bytemuck::cast_slice(&jobs);
        let table = &mut self.slots[i].sim_jobs;
        write_address_table(&self.ctx, table, "hair dynamics jobs", bytes)?;
        Ok(steps.iter().map(|(s, _)| *s).collect())
    }

    /// The density volumes of this frame: request those the view's volume `tier` needs, mark
    /// those of the characters in `pose_updates` stale, write the jobs of the volumes built
    /// this frame into frame slot `i`'s job table (grown as needed: its earlier frame has
    /// completed), and fill the volume fields of `records`.
    fn write_density_jobs(
        &mut self,
        world: &mut World,
        i: usize,
        records: &mut [super::core::shared::CharacterRecord],
        (tier, block): (&super::volume::VolumeTier, &FrameBlock),
        pose_updates: &[usize],
    ) -> GpuResult<DensityWork> {
        // Each character's share of volume, from its size on screen (0 with the far tier off).
        let weights: Vec<f32> = records
            .iter()
            .map(|r| match tier.far {
                Some(_) => tier.weight(super::volume::hair_pixels(r, block)),
                None => 0.0,
            })
            .collect();
        if tier.enabled() {
            for id in world.crowd.ids() {
                let slot = id.slot() as usize;
                let visible = records[slot].flags & super::core::shared::CHARACTER_VISIBLE != 0;
                let needed = tier.occlusion || weights[slot] > 0.0;
                if visible
                    && needed
                    && let Some(old) = world.volumes.ensure(&self.ctx, id, tier.sampling)?
                {
                    self.slots[i].retired.push(Retired::Resource(Box::new(old)));
                }
            }
        }
        for &slot in pose_updates {
            world.volumes.mark_stale(slot);
        }
        // Stale volumes are rebuilt for the tier; with it off only requests are built.
        let rebuilds = if tier.enabled() {
            tier.rebuilds_per_frame
        } else {
            0
        };
        let (jobs, built, most_bundles) =
            world
                .volumes
                .take_jobs(records, rebuilds, self.frame_number);
        let draw = world.volumes.fill_records(records, tier, &weights);
        if !jobs.is_empty() {
            let bytes = bytemuck::cast_slice(&jobs);
            let table = &mut self.slots[i].density_jobs;
            write_address_table(&self.ctx, table, "density volume jobs", bytes)?;
        }
        Ok(DensityWork {
            built,
            most_bundles,
            draw,
        })
    }

    /// The character records of this frame: those in `pose_updates` with their previous
    /// pose's textures, all with their motion where the frame has motion vectors.
    fn frame_records(
        &self,
        world: &World,
        pose_updates: &[usize],
        motion: Option<&FrameMotion>,
    ) -> Vec<super::core::shared::CharacterRecord> {
        let mut records = world.crowd.records(pose_updates);
        if let Some(motion) = motion {
            for (slot, r) in records.iter_mut().enumerate() {
                let model = glam::Mat4::from_cols_array_2d(&r.model);
                r.clip_to_prev = motion.character(slot, model).to_cols_array_2d();
            }
        }
        records
    }

    /// After a frame is submitted: its matrices become the next frame's previous ones, and
    /// with accumulation its history the next frame's to read.
    fn remember_frame(
        &mut self,
        records: &[super::core::shared::CharacterRecord],
        motion: &FrameMotion,
        temporal: Option<TemporalWork>,
    ) {
        let models = records.iter().map(|r| {
            (r.flags & super::core::shared::CHARACTER_VISIBLE != 0)
                .then(|| glam::Mat4::from_cols_array_2d(&r.model))
        });
        let previous = PreviousFrame {
            view_proj: motion.view_proj,
            models: models.collect(),
            size: self.targets.size(),
        };
        self.temporal.remember(previous, temporal);
    }

    /// Refuse a frame this renderer cannot draw (path state, 32-bit counters, settings);
    /// returns its path and k-buffer budget.
    fn check_frame(
        &self,
        world: &World,
        view: &View,
        opts: &FrameOptions,
    ) -> GpuResult<(RenderPath, u32)> {
        view.validate().map_err(GpuError::Unsupported)?;
        let path = opts.path.unwrap_or(self.default_path());
        if path == RenderPath::Static && self.static_version != Some(world.crowd.version()) {
            return Err(GpuError::Unsupported(
                "the static path draws the strands of the last compute-path frame: render one first, and again after the characters change".into(),
            ));
        }
        let structure = Some(world.crowd.structure_version());
        if path == RenderPath::Lhs
            && (self.lhs.as_ref().map(|l| l.0) != structure || self.args_structure != structure)
        {
            return Err(GpuError::Unsupported(
                "the LHS path needs strands stored by capture_lhs for the current characters, and a compute-path frame since the last mesh-path one".into(),
            ));
        }
        // Statistics are 32-bit: refuse a frame without LoD whose crowd could wrap them (with
        // LoD a real head's strands follow its pixels; the buffers' sums are held to their
        // budgets by the LoD pressure either way).
        let worst = world.crowd.max_triangles();
        if !view.lod.enabled && worst > u32::MAX as u64 {
            return Err(GpuError::Unsupported(format!(
                "the crowd has {worst} strand triangles at full detail, more than 32-bit frame counters hold; lower strands per bundle or vertex level"
            )));
        }
        let settings = super::settings::FrameSettings {
            path,
            raster: opts.raster,
            transparency: view.transparency,
            msaa: self.desc.msaa,
            light_raster: opts.light_raster,
        };
        let budget = settings
            .validate(&self.caps())
            .map_err(GpuError::Unsupported)?;
        Ok((path, budget))
    }

    /// The transient resources of this frame's passes (after [`Self::prepare_workspace`]
    /// has updated the bundle table), checked against the device before anything is
    /// recorded; compiles the transparency pipelines it needs.
    pub(super) fn frame_transients(
        &mut self,
        (transparency, raster): (Transparency, StrandRaster),
        soft_light: Option<ShadowMode>,
        kbuffer_budget: u32,
        temporal: Option<TemporalWork>,
    ) -> GpuResult<FrameTransients> {
        let size = self.targets.size();
        // The software rasterizer composites through the k-buffer, in opaque frames too.
        let buffers_for = match (raster.uses_software(), transparency) {
            (true, Transparency::Opaque) => Transparency::KBuffer {
                budget: kbuffer_budget,
            },
            (_, t) => t,
        };
        self.passes.prepare_transparency(buffers_for)?;
        if raster.uses_software() || soft_light.is_some() {
            let range = self.ctx.info.max_storage_buffer_range;
            self.soft_budget
                .validate(range)
                .map_err(GpuError::Unsupported)?;
        }
        let soft = raster.uses_software().then_some(self.soft_budget);
        let light = soft_light.map(|mode| (self.soft_budget, self.shadow.resolution(), mode));
        let t = super::passes::frame_transients(buffers_for, (soft, light), size, temporal);
        for b in t.buffers() {
            self.transients.check(b)?;
        }
        Ok(t)
    }

    /// The camera's frame block and, with shadows and hair in view, the light's, for a frame
    /// drawn with `raster` and a k-buffer of `kbuffer_budget` nodes.
    fn frame_blocks(
        &self,
        world: &World,
        view: &View,
        opts: &FrameOptions,
        (raster, kbuffer_budget): (StrandRaster, u32),
    ) -> (FrameBlock, Option<FrameBlock>) {
        let (width, height) = self.targets.size();
        let bundles = world.crowd.bundle_count();
        let slots = world.crowd.slot_count();
        let mut block = view.frame_block(width, height, bundles, slots, self.vertex_budget());
        block.transparency = view.transparency.frame_fields(self.desc.msaa);
        if raster.uses_software() {
            block.transparency.kbuffer_nodes = kbuffer_budget;
            let opacity = match view.transparency {
                Transparency::Opaque => 1.0,
                _ => super::transparency::STRAND_OPACITY,
            };
            super::soft::frame_fields(&mut block, raster, opacity, self.soft_tuning());
        }
        let light = self.light_view(world, view, &block);
        if let Some(l) = &light {
            (block.light_view_proj, block.shadow) = l.shadow_fields(view.shadows);
        }
        if let Some(b) = self.body_light_view(world, view, &block) {
            (block.body_view_proj, block.body_shadow) = b.body_fields();
        }
        let soft_light = (opts.light_raster == LightRaster::Software).then_some(self.soft_budget);
        let light_block = light.map(|l| l.frame_block(&block, &view.lod, soft_light));
        (block, light_block)
    }

    /// Write slot `i`'s frame blocks, `records`, prop instances (with their motion where
    /// the frame has motion vectors) and skinning jobs and matrices, and size its readbacks;
    /// returns this frame's prop draws (the camera's and the light's) and its skinning jobs
    /// and widest job.
    fn write_slot(
        &mut self,
        world: &mut World,
        i: usize,
        (block, light_block): (&FrameBlock, Option<&FrameBlock>),
        records: &[super::core::shared::CharacterRecord],
        motion: Option<&FrameMotion>,
        opts: &FrameOptions,
    ) -> GpuResult<(PropDraws, (u32, u32))> {
        let crowd = &world.crowd;
        let still = glam::Mat4::IDENTITY;
        let moved = |id: super::crowd::CharacterId| {
            let model = crowd.drawn_model(id)?;
            Some((
                model,
                motion.map_or(still, |m| m.character(id.slot() as usize, model)),
            ))
        };
        let camera_motion = motion.map_or(still, FrameMotion::camera);
        let camera = super::prop_table::Projection {
            eye: glam::Vec3::from_array(block.eye),
            height: block.pixels_high,
            cot_half_fov: block.cot_half_fov,
            texel: 0.0,
        };
        // The bodies' light map sees far bodies at its own texel size, a pixel being as many
        // texels as its filter blurs together.
        let body_texel = block.body_shadow.texel;
        let light = (body_texel > 0.0).then(|| {
            super::prop_table::Projection::orthographic(
                body_texel * super::shadow::LIGHT_FAR_TEXELS_PER_PIXEL,
            )
        });
        let (mut prop_instances, mut prop_draws) =
            world.props.frame_lists(&moved, camera_motion, &camera);
        let mut light_draws = prop_draws.clone();
        let skin = world.skinned.frame_lists(
            moved,
            (&camera, light.as_ref()),
            &mut prop_instances,
            (&mut prop_draws, &mut light_draws),
        );
        // Bodies before the static props (the ground above all): what they hide of the ground
        // is then never shaded.
        prop_draws.sort_by_key(|d| !d.skinned);
        light_draws.sort_by_key(|d| !d.skinned);
        let slot = &mut self.slots[i];
        slot.frame_ubo.write(0, bytemuck::bytes_of(block))?;
        if let Some(lb) = light_block {
            slot.light_ubo.write(0, bytemuck::bytes_of(lb))?;
        }
        slot.records.write(0, bytemuck::cast_slice(records))?;
        slot.prop_instances
            .write(0, bytemuck::cast_slice(&prop_instances))?;
        let posed_bytes =
            skin.vertices as u64 * size_of::<super::core::shared::SkinnedVertex>() as u64;
        if posed_bytes > slot.skinned.size {
            return Err(GpuError::Unsupported(format!(
                "this frame poses {} body vertices ({posed_bytes} bytes), more than one storage \
                 buffer of this device holds ({} bytes): fewer or farther characters",
                skin.vertices, slot.skinned.size
            )));
        }
        if !skin.jobs.is_empty() {
            slot.skin_jobs.write(0, bytemuck::cast_slice(&skin.jobs))?;
            slot.skin_matrices
                .write(0, bytemuck::cast_slice(&skin.matrices))?;
        }
        self.size_readbacks(i, opts)?;
        let draws = PropDraws {
            camera: prop_draws,
            light: light_draws,
        };
        Ok((draws, (skin.jobs.len() as u32, skin.widest)))
    }

    /// Size frame slot `i`'s image and motion readbacks for what `opts` reads back.
    fn size_readbacks(&mut self, i: usize, opts: &FrameOptions) -> GpuResult<()> {
        let (width, height) = self.targets.size();
        let pixels = width as u64 * height as u64;
        let slot = &mut self.slots[i];
        size_readback(
            &self.ctx,
            &mut slot.image_readback,
            opts.read_image,
            pixels * 4,
        )?;
        size_readback(
            &self.ctx,
            &mut slot.motion_readback,
            opts.read_motion,
            pixels * 16,
        )
    }

    /// Record frame slot `i` into `target`'s command buffer: the frame graph of
    /// [`super::schedule::add_frame`], run between the frame's outer timestamps. Returns the
    /// graph's description when `opts` asks for it, and the commands recorded outside every
    /// timing scope.
    fn record(
        &mut self,
        (world, background): (&World, [f32; 3]),
        i: usize,
        work: FrameWork,
        opts: &FrameOptions,
        target: &mut FrameTarget,
    ) -> GpuResult<(Option<String>, u32)> {
        let FrameSlot {
            cmd,
            profiler,
            mesh_query,
            set,
            light_set,
            stats_readback,
            image_readback,
            motion_readback,
            retired,
            sim_jobs,
            density_jobs,
            skinned,
            root_probe,
            ..
        } = &mut self.slots[i];
        let mut rec = match target {
            FrameTarget::Host(h) => CommandRecorder::host(&self.ctx, h.cmd),
            FrameTarget::Own(_) => cmd.begin()?,
        };
        begin_timing(&mut rec, profiler, mesh_query.as_mut());
        let jobs = world.crowd.update_jobs(i, &work.pose_updates);
        let simulated = simulated_characters(&world.crowd, &work.simulated);
        let (mut host_color_use, mut host_depth_use) = target.host_uses();
        let mut g = new_graph(opts, &self.desc);
        let sources = FrameSources {
            work: &self.work,
            targets: &mut self.targets,
            shadow: &mut self.shadow,
            history: self.temporal.history(),
            skinned,
        };
        let size = sources.targets.size();
        let r = FrameRes::new(&mut g, sources, &work.transients);
        g.bind_transients(set);
        g.bind_transients(light_set);
        let changes = Changes {
            jobs: &jobs,
            dynamics: sim_jobs.as_ref().map(|t| (t, simulated.as_slice())),
            lhs: match (work.path, self.lhs.as_mut()) {
                (RenderPath::Lhs, Some((_, lhs))) => Some((lhs, i)),
                _ => None,
            },
            volume_builds: volume_builds(density_jobs.as_ref(), &world.volumes, &work.density),
        };
        let host_uses = (&mut host_color_use, &mut host_depth_use);
        let host = host_start(&*target, self.host_passes.as_ref(), host_uses, i);
        let clear = (opts.clear && host.is_none()).then_some(opaque(background));
        let sets = PassSets::camera_and_light((set, light_set), world.crowd.texture_set());
        let props = prop_lists(work.props, world.skinned.indices.as_ref());
        let query = (mesh_query.as_mut(), &self.temporal);
        let mut draw = frame_inputs(&work, (sets, props), clear, size, query);
        if opts.probe_roots {
            draw.probe = Some((g.import_buffer("root probe", root_probe), work.bundles));
        }
        draw.motion_readback = motion_readback.as_ref().filter(|_| opts.read_motion);
        let image_readback = image_readback.as_ref().filter(|_| opts.read_image);
        let plan = ScheduleInputs {
            changes,
            host,
            draw,
            outputs: outputs(target, stats_readback, image_readback),
        };
        add_frame(&mut g, &self.passes, &r, plan)?;
        let (description, unscoped) =
            run_graph(g, &mut rec, profiler, &mut self.transients, retired)?;
        drop(rec);
        if let FrameTarget::Own(_) = target {
            cmd.end()?;
        }
        Ok((description, unscoped))
    }

    /// Submit slot `i` (own frames), or leave it to the host: the slot's fence stays
    /// signalled, and the host vouches for the frame's completion before it reuses the slot.
    fn hand_over(&mut self, i: usize, pending: Pending, target: FrameTarget) -> GpuResult<()> {
        match target {
            FrameTarget::Own(present) => self.submit(i, pending, present.as_deref()),
            FrameTarget::Host(_) => {
                self.slots[i].pending = Some(pending);
                self.frame_number += 1;
                Ok(())
            }
        }
    }

    /// Submit slot `i` (after `present.wait`, signalling `present.signal`).
    fn submit(
        &mut self,
        i: usize,
        pending: Pending,
        present: Option<&PresentTarget>,
    ) -> GpuResult<()> {
        let slot = &mut self.slots[i];
        slot.fence.reset()?;
        let (wait, signal) = match present {
            Some(p) => (Some(p.wait), Some(p.signal)),
            None => (None, None),
        };
        if let Err(e) = self.ctx.submit_with(&slot.cmd, &slot.fence, wait, signal) {
            // Keep the slot usable: a fence that will never be signalled would hang the next wait.
            slot.fence = crate::vk::Fence::new(&self.ctx, true)?;
            return Err(e);
        }
        slot.pending = Some(pending);
        self.frame_number += 1;
        Ok(())
    }

    /// The pool and draw arguments now hold this frame's strands (compute path), or the mesh
    /// path has overwritten the arguments.
    fn after_submit(&mut self, world: &mut World, path: RenderPath, raster: StrandRaster) {
        match path {
            // Software bundles leave no strands in the pool.
            RenderPath::Compute if !raster.uses_software() => {
                self.static_version = Some(world.crowd.version());
                self.args_structure = Some(world.crowd.structure_version());
            }
            RenderPath::Compute | RenderPath::Mesh => {
                self.static_version = None;
                self.args_structure = None;
            }
            RenderPath::Static | RenderPath::Lhs => {}
        }
    }

    /// Grow the working buffers for the crowd's bundles and allocate the vertex pool when the
    /// compute path first needs it. Replaced buffers are retired with frame slot `i`.
    pub(super) fn prepare_workspace(
        &mut self,
        world: &mut World,
        i: usize,
        path: RenderPath,
    ) -> GpuResult<()> {
        if let Some(old) = world.crowd.update_bundle_table()? {
            self.slots[i].retired.push(Retired::Resource(Box::new(old)));
        }
        if let Some(old) = self.work.grow(world.crowd.bundle_count())? {
            self.slots[i].retired.push(Retired::Resource(Box::new(old)));
        }
        if let Some(old) = self
            .work
            .ensure_root_samples(world.crowd.most_in_a_bundle())?
        {
            self.slots[i].retired.push(Retired::Resource(Box::new(old)));
        }
        if path.pulls_vertices() {
            self.work.ensure_pool(self.desc.vertex_pool_bytes)?;
        }
        let slots = world.crowd.slot_count();
        let slot = &mut self.slots[i];
        if slot.records.size
            < slots as u64 * size_of::<super::core::shared::CharacterRecord>() as u64
        {
            slot.records = records_buffer(&self.ctx, slots.next_power_of_two())?;
        }
        let skin = world.skinned.capacity();
        let instances =
            (world.props.instances.len() + world.props.attached.len()) as u32 + skin.instances;
        if slot.prop_instances.size < instances as u64 * size_of::<PropInstance>() as u64 {
            slot.prop_instances = prop_instance_buffer(&self.ctx, instances.next_power_of_two())?;
        }
        grow_skin_buffers(&self.ctx, slot, skin)?;
        let probe_bytes = world.crowd.bundle_count() as u64 * 16;
        if slot.root_probe.size < probe_bytes {
            slot.root_probe = super::core::slots::host_table(
                &self.ctx,
                "root probe",
                probe_bytes.next_power_of_two(),
            )?;
        }
        let slot = &self.slots[i];
        for (set, ubo) in [
            (&slot.set, &slot.frame_ubo),
            (&slot.light_set, &slot.light_ubo),
        ] {
            self.work.write_set(
                set,
                FrameBuffers {
                    frame_ubo: ubo,
                    records: &slot.records,
                    prop_instances: &slot.prop_instances,
                    bundle_table: world.crowd.bundle_table(),
                    prop_vertices: world.props.vertices.as_ref(),
                    skin: [
                        world.skinned.rest.as_ref(),
                        Some(&slot.skin_matrices),
                        Some(&slot.skin_jobs),
                        Some(&slot.skinned),
                    ],
                    root_probe: &slot.root_probe,
                    shadow: &self.shadow,
                    history: self.temporal.history(),
                },
            )?;
        }
        Ok(())
    }

    /// The light's view for `view`: fitted around the visible characters whose hair is in the
    /// camera's frustum. `None` when shadows are off or no hair is in view.
    fn light_view(
        &self,
        world: &World,
        view: &View,
        block: &super::core::shared::FrameBlock,
    ) -> Option<LightView> {
        if view.shadows == ShadowMode::Off {
            return None;
        }
        let bounds: Vec<_> = world
            .crowd
            .hair_bounds()
            .into_iter()
            .filter(|(lo, hi)| super::camera::box_in_frustum(&block.planes, *lo, *hi))
            .collect();
        LightView::fit(&bounds, view.light_dir, self.shadow.resolution())
    }

    /// The bodies' light view for `view`: fitted to the bodies in the camera's frustum. `None`
    /// when shadows are off or no body is in view.
    fn body_light_view(
        &self,
        world: &World,
        view: &View,
        block: &super::core::shared::FrameBlock,
    ) -> Option<LightView> {
        if view.shadows == ShadowMode::Off {
            return None;
        }
        let model_of = |id| world.crowd.drawn_model(id);
        let mut bodies = world.props.character_spheres(&model_of);
        bodies.extend(world.skinned.character_spheres(&model_of));
        let camera = (
            glam::Mat4::from_cols_array_2d(&block.unjittered_view_proj),
            glam::Vec3::from_array(block.eye),
        );
        LightView::fit_bodies(
            &bodies,
            camera,
            view.light_dir,
            self.shadow.body_resolution(),
        )
    }
}

/// Where the frame's results go: the statistics and `image_readback` for the report, and an
/// own frame's overlay and swapchain image.
fn outputs<'a, 'o>(
    target: &'a mut FrameTarget<'_, 'o>,
    stats_readback: &'a Buffer,
    image_readback: Option<&'a Buffer>,
) -> FrameOutputs<'a, 'o> {
    let (overlay, present) = match target {
        FrameTarget::Own(Some(p)) => (p.overlay.as_deref_mut(), Some(p.image)),
        _ => (None, None),
    };
    FrameOutputs {
        overlay,
        stats_readback,
        image_readback,
        present,
    }
}

/// `rgb` as an opaque colour.
fn opaque([r, g, b]: [f32; 3]) -> [f32; 4] {
    [r, g, b, 1.0]
}

/// A host frame's start for the schedule: its images, the uses the host left them in, its
/// depth mapping. `None` for the renderer's own frames.
fn host_start<'a>(
    target: &FrameTarget<'a, '_>,
    passes: Option<&'a HostTargetPasses>,
    uses: (&'a mut Access, &'a mut Access),
    slot: usize,
) -> Option<HostStart<'a>> {
    let (FrameTarget::Host(h), Some(passes)) = (target, passes) else {
        return None;
    };
    Some(HostStart {
        passes,
        color: h.color,
        depth: h.depth,
        mapping: h.mapping,
        uses,
        slot,
    })
}

/// Grow frame slot `slot`'s skinning buffers for `(instances, matrices, posed vertices)`
/// (its earlier frame has completed, so they may be replaced).
fn grow_skin_buffers(
    ctx: &Arc<Context>,
    slot: &mut FrameSlot,
    skin: super::skinned_props::SkinCapacity,
) -> GpuResult<()> {
    use super::core::shared::{SkinJob, SkinnedVertex};
    use super::core::slots::{host_table, skinned_buffer};
    let (jobs, matrices) = (skin.jobs, skin.matrices);
    let job_bytes = jobs as u64 * size_of::<SkinJob>() as u64;
    if slot.skin_jobs.size < job_bytes {
        slot.skin_jobs = host_table(ctx, "skin jobs", job_bytes.next_power_of_two())?;
    }
    let matrix_bytes = matrices as u64 * 64;
    if slot.skin_matrices.size < matrix_bytes {
        slot.skin_matrices = host_table(ctx, "skin matrices", matrix_bytes.next_power_of_two())?;
    }
    // The bound assumes every part near; a crowd's frame poses far fewer. The buffer is one
    // storage binding, so it stops at the device's range (write_slot refuses a frame that
    // needs more).
    let vertex = size_of::<SkinnedVertex>() as u64;
    let most = (ctx.info.max_storage_buffer_range / vertex).min(u32::MAX as u64) as u32;
    let posed = skin.vertices.next_power_of_two().min(most);
    if slot.skinned.size < posed as u64 * vertex {
        slot.skinned = skinned_buffer(ctx, posed)?;
    }
    Ok(())
}

/// Make `readback` a buffer of `bytes` when the frame `wants` it and it is not one already.
fn size_readback(
    ctx: &Arc<Context>,
    readback: &mut Option<Buffer>,
    wants: bool,
    bytes: u64,
) -> GpuResult<()> {
    if wants && readback.as_ref().is_none_or(|b| b.size != bytes) {
        *readback = Some(super::core::readback::readback(
            ctx,
            "image readback",
            bytes,
        )?);
    }
    Ok(())
}

/// A frame's graph, described where `opts` asks, with the use `desc` omits on purpose (the
/// tests that check the graph's validation).
fn new_graph<'a>(opts: &FrameOptions, desc: &'a super::settings::RendererDesc) -> FrameGraph<'a> {
    let mut g = FrameGraph::new(opts.describe_frame);
    if let Some((pass, resource, access)) = &desc.omit_use {
        g.omit_use(pass, resource, *access);
    }
    g
}

/// Run the frame graph into `rec` and close the frame's outer timing pair; the transients
/// the pool released are retired with the frame. The graph's description (when asked for)
/// and the commands recorded outside every timing scope.
fn run_graph(
    g: FrameGraph,
    rec: &mut CommandRecorder,
    profiler: &mut crate::vk::Profiler,
    transients: &mut super::core::graph::TransientPool,
    retired: &mut Vec<Retired>,
) -> GpuResult<(Option<String>, u32)> {
    let result = g.run(rec, profiler, transients);
    profiler.end_frame(rec);
    let unscoped = rec.unscoped_commands();
    let released = transients.take_released();
    retired.extend(released.into_iter().map(Retired::Resource));
    Ok((result?, unscoped))
}

/// The density volumes this frame builds (`density.built`), from the slot's job `table`:
/// the table, their cells in its order, the most bundles among their characters.
fn volume_builds<'a>(
    table: Option<&'a Buffer>,
    volumes: &'a super::features::volume::DensityVolumes,
    density: &DensityWork,
) -> Option<(&'a Buffer, Vec<&'a Buffer>, u32)> {
    let table = table.filter(|_| !density.built.is_empty())?;
    Some((table, volumes.buffers(&density.built), density.most_bundles))
}

/// Reset the frame's timestamp and mesh queries and open its outer timing pair.
fn begin_timing(
    rec: &mut CommandRecorder,
    profiler: &mut crate::vk::Profiler,
    mesh_query: Option<&mut crate::vk::MeshPrimitivesQuery>,
) {
    profiler.reset(rec);
    if let Some(q) = mesh_query {
        q.reset(rec);
    }
    profiler.begin_frame(rec);
}

/// The GPU-simulated characters' state and pose buffers, for the dynamics pass.
fn simulated_characters<'a>(
    crowd: &'a super::crowd::Crowd,
    simulated: &[usize],
) -> Vec<SimulatedCharacter<'a>> {
    crowd
        .simulated_buffers(simulated)
        .into_iter()
        .map(|(state, pose)| SimulatedCharacter { state, pose })
        .collect()
}

/// The camera's and the light's prop lists, with the skinned bodies' index buffer.
fn prop_lists<'a>(props: &'a PropDraws, skin_indices: Option<&'a Buffer>) -> [PropList<'a>; 2] {
    [&props.camera, &props.light].map(|draws| PropList {
        draws,
        skin_indices,
    })
}

/// What the frame's passes draw: the frame's work, its sets and props, and the slot's query.
fn frame_inputs<'a>(
    work: &FrameWork<'a>,
    ((sets, light_sets), [props, light_props]): ((PassSets<'a>, PassSets<'a>), [PropList<'a>; 2]),
    clear: Option<[f32; 4]>,
    size: (u32, u32),
    (mesh_query, temporal_feature): (
        Option<&'a mut crate::vk::MeshPrimitivesQuery>,
        &'a TemporalFeature,
    ),
) -> FrameInputs<'a> {
    FrameInputs {
        sets,
        light_sets,
        bundles: work.bundles,
        path: work.path,
        clear,
        props,
        light_props,
        skin: work.skin,
        probe: None,
        shadow: work.shadows,
        transparency: work.transparency,
        raster: work.raster,
        light_raster: work.light_raster,
        kbuffer_budget: work.kbuffer_budget,
        size,
        mesh_query,
        temporal: work.temporal,
        temporal_feature,
        motion_readback: None,
        volume_slots: work.density.draw.slots,
    }
}

impl Frames {
    /// Record the hair of one frame into a host's command buffer: seen through the host's
    /// camera, hidden behind the host's depth, composited over the host's colour, with `look`
    /// for everything else (light, shading, shadows, LoD; its camera is replaced). The host
    /// submits the buffer, and once that submission has completed, [`super::Renderer::wait`] with the
    /// ticket returns the frame's report without waiting (host frames complete when the host
    /// says so). The renderer's targets follow the host colour's size. `opts.clear` does not
    /// apply (the hair is drawn over a transparent layer, which `opts.read_image` reads back).
    /// Refused: temporal accumulation (the host's own anti-aliasing jitters its projection,
    /// which host frames follow), a slot out of range, images the host wants back unused.
    pub(in crate::render) fn record_host_frame(
        &mut self,
        world: &mut World,
        background: [f32; 3],
        look: &View,
        opts: &FrameOptions,
        frame: HostFrame,
    ) -> GpuResult<FrameTicket> {
        let refuse = |what: String| GpuError::Unsupported(format!("host frame: {what}"));
        if frame.slot >= FRAMES_IN_FLIGHT {
            return Err(refuse(format!(
                "slot {} is not below {FRAMES_IN_FLIGHT}",
                frame.slot
            )));
        }
        if look.temporal == Temporal::Taa {
            return Err(refuse(
                "temporal accumulation is the host's (host frames follow its jittered projection)"
                    .into(),
            ));
        }
        if !(0.0..1e3).contains(&frame.depth_slack) {
            return Err(refuse(format!(
                "depth slack {} is not a distance in 0..1000",
                frame.depth_slack
            )));
        }
        let images = std::iter::once(&frame.color).chain(frame.depth.as_ref());
        if images.into_iter().any(|i| i.after == Access::Nothing) {
            return Err(refuse("an image cannot be handed back unused".into()));
        }
        let [width, height, _] = frame.color.image.desc.extent;
        self.resize(&mut world.crowd, width, height)?;
        if self.host_passes.is_none() {
            let targets = TargetFormats {
                color: COLOR_FORMAT,
                depth: DEPTH_FORMAT,
                samples: self.desc.msaa,
            };
            self.host_passes = Some(HostTargetPasses::new(&self.ctx, targets)?);
        }
        let depth_image = frame.depth.as_ref().map(|d| d.image);
        let passes = self.host_passes.as_mut().expect("made above");
        passes.prepare(frame.color.image, depth_image)?;
        passes.bind(frame.slot, depth_image, self.targets.output())?;
        // The renderer's depth range: the host's near plane, and far enough for the hair.
        let size = (width, height);
        let mut host = frame
            .camera
            .view(size, self.hair_far(world, frame.camera.eye()))
            .map_err(refuse)?;
        host.depth.slack = frame.depth_slack;
        let view = View {
            camera: host.camera,
            ..*look
        };
        let target = FrameTarget::Host(HostTargets {
            cmd: frame.cmd,
            color: &frame.color,
            depth: frame.depth.as_ref(),
            mapping: host.depth,
        });
        self.draw_frame(world, background, frame.slot, &view, opts, target)
    }

    /// A far plane beyond every character's hair seen from `eye` (with a tenth to spare).
    fn hair_far(&self, world: &World, eye: glam::Vec3) -> f32 {
        let far = world
            .crowd
            .hair_bounds()
            .into_iter()
            .flat_map(|(lo, hi)| super::camera::box_corners(lo, hi))
            .map(|c| c.distance(eye))
            .fold(0.0f32, f32::max);
        (far * 1.1).max(1e-3)
    }
}
