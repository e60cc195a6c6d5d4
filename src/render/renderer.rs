//! The renderer: one frame serves every character. Its whole `impl` is here, a thin face over
//! two parts: the [`World`] it draws (characters, props, skinned bodies, density volumes) and
//! the [`Frames`] that draw it (pipelines, targets recreated on resize only, and
//! [`super::FRAMES_IN_FLIGHT`] frame slots). A frame is recorded with
//! [`Renderer::render_frame`] and its [`FrameReport`] collected with [`Renderer::wait`];
//! headless tools and tests do both with [`Renderer::render_one`]. What a frame runs is
//! [`super::schedule`]; how it is recorded and submitted, [`super::frame`]; inspection hooks,
//! [`super::debug`].

use std::sync::Arc;

use glam::Mat4;

use super::camera::View;
use super::core::shared::{HairVertex, PropInstance, SoftSegment, TextureBinding};
use super::core::slots::{FrameReport, Retired};
use super::crowd::{CharacterId, Crowd, StrandParams};
use super::debug;
use super::frame::Frames;
pub use super::frame::PresentTarget;
use super::host::HostFrame;
pub use super::passes::output::Overlay;
use super::prop_table::Props;
pub use super::settings::{
    DeviceCaps, FrameOptions, FrameSettings, FrameTicket, RenderPath, RendererDesc, check_msaa,
    software_raster_conflict, supported_msaa,
};
use super::soft::SoftBudget;
use super::world::World;
use crate::bake::BakedHairMesh;
use crate::model::style::HairStyle;
use crate::vk::{Context, GpuError, GpuResult};

/// Renders every character of the crowd in one frame: the public face over the [`World`] it
/// draws and the [`Frames`] that draw it.
pub struct Renderer {
    ctx: Arc<Context>,
    world: World,
    frames: Frames,
    /// Background colour (linear RGB).
    pub background: [f32; 3],
}

impl Renderer {
    /// Create pipelines, targets and frame slots; checks the device limits the settings need.
    pub fn new(ctx: &Arc<Context>, desc: &RendererDesc) -> GpuResult<Self> {
        let soft_budget = check_desc(ctx, desc)?;
        let crowd = Crowd::new(ctx, desc.max_characters)?;
        let frames = Frames::new(ctx, desc, &crowd, soft_budget)?;
        Ok(Renderer {
            ctx: ctx.clone(),
            world: World {
                crowd,
                props: Props::default(),
                skinned: Default::default(),
                volumes: Default::default(),
            },
            frames,
            background: [0.6, 0.65, 0.7],
        })
    }

    /// The path frames use unless told otherwise.
    pub fn default_path(&self) -> RenderPath {
        self.frames.default_path()
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.frames.passes.has_mesh_path()
    }

    /// Whether the software rasterizer is available (64-bit shared and buffer atomics).
    pub fn has_software_raster(&self) -> bool {
        self.frames.passes.has_software_raster()
    }

    /// What this renderer's device offers, for [`FrameSettings::validate`].
    pub fn caps(&self) -> DeviceCaps {
        self.frames.caps()
    }

    /// Forget the previous frame and the temporal history (a camera cut): the next frame has
    /// no motion and starts accumulating afresh.
    pub fn reset_temporal(&mut self) {
        self.frames.temporal.reset();
    }

    /// Samples per pixel of the targets.
    pub fn msaa(&self) -> u32 {
        self.frames.desc.msaa
    }

    /// The software rasterizer's budgets.
    pub fn soft_budget(&self) -> SoftBudget {
        self.frames.soft_budget
    }

    /// The software rasterizer's budgets and the `RendererDesc` choices it draws with.
    pub fn soft_tuning(&self) -> super::soft::SoftTuning {
        self.frames.soft_tuning()
    }

    /// The characters.
    pub fn crowd(&self) -> &Crowd {
        &self.world.crowd
    }

    /// Vertex slots of the compute path's pool.
    pub fn vertex_budget(&self) -> u32 {
        self.frames.vertex_budget()
    }

    /// Add a character (uploads its textures; blocks until they are on the GPU).
    pub fn add_character(
        &mut self,
        baked: &BakedHairMesh,
        style: &HairStyle,
        params: StrandParams,
        model: Mat4,
    ) -> GpuResult<CharacterId> {
        self.world.crowd.add(baked, style, params, model)
    }

    /// Remove a character; its textures are released after the frames using them.
    pub fn remove_character(&mut self, id: CharacterId) -> GpuResult<()> {
        let removed = self.world.crowd.remove(id)?;
        self.world.props.attached.retain(|(c, ..)| *c != id);
        self.world.skinned.remove(id);
        if let Some(cells) = self.world.volumes.remove(id) {
            self.retire(Retired::Resource(Box::new(cells)));
        }
        self.retire(Retired::Resource(Box::new(removed.textures)));
        self.retire(Retired::CharacterSlot(removed.slot));
        Ok(())
    }

    /// Move a character.
    pub fn set_model(&mut self, id: CharacterId, model: Mat4) -> GpuResult<()> {
        self.world.crowd.set_model(id, model)
    }

    /// Show or hide a character.
    pub fn set_visible(&mut self, id: CharacterId, visible: bool) -> GpuResult<()> {
        self.world.crowd.set_visible(id, visible)
    }

    /// Change a character's strand settings.
    pub fn set_params(&mut self, id: CharacterId, params: StrandParams) -> GpuResult<()> {
        self.world.crowd.set_params(id, params)
    }

    /// Let character `id`'s hair mesh move (`bake::deform`): `basis` from the mesh and bake it
    /// was added with (bake with a `motion_margin` so the motion stays inside the decode box).
    pub fn make_deformable(
        &mut self,
        id: CharacterId,
        basis: crate::bake::deform::DeformBasis,
    ) -> GpuResult<()> {
        let layout = self.frames.passes.deform_set_layout().clone();
        self.world.crowd.make_deformable(id, basis, &layout)
    }

    /// Set a deformable character's hair mesh pose (`layers x vertices` object-space positions,
    /// layer-major). The next frame rebuilds its hair mesh and u/v textures on the GPU before
    /// anything reads them.
    pub fn set_hair_mesh_pose(
        &mut self,
        id: CharacterId,
        positions: &[glam::Vec3],
    ) -> GpuResult<()> {
        self.world.crowd.set_pose(id, positions)
    }

    /// Simulate character `id`'s hair mesh on the GPU (`glsl/hair_dynamics.comp`), continuing
    /// from `sim`'s state, clock, constraints and colliders (the character must have been made
    /// deformable with the same mesh). Replaces an earlier GPU simulation of it. From then on
    /// [`Self::step_hair`] advances it and each step's pose is rebuilt into its textures
    /// without leaving the GPU.
    pub fn simulate_hair(
        &mut self,
        id: CharacterId,
        sim: &crate::dynamics::HairDynamics,
    ) -> GpuResult<()> {
        let layout = self.frames.passes.deform_set_layout().clone();
        if let Some(old) = self.world.crowd.simulate(id, sim, &layout)? {
            self.retire(Retired::Resource(Box::new(old)));
        }
        Ok(())
    }

    /// Advance character `id`'s GPU hair dynamics by `dt` seconds while it moves to `model`,
    /// with `settings` (the next frame runs the step, then rebuilds the textures from its
    /// pose). One step per frame: a second call before the frame replaces the first's step
    /// (its time is skipped). A pose given with [`Self::set_hair_mesh_pose`] after this call
    /// wins over the step, and the other way round.
    pub fn step_hair(
        &mut self,
        id: CharacterId,
        dt: f32,
        model: glam::Mat4,
        settings: &crate::dynamics::DynamicsSettings,
    ) -> GpuResult<()> {
        self.world.crowd.step_simulation(id, dt, model, settings)
    }

    /// Character `id`'s GPU hair dynamics state (world positions and velocities) and clock,
    /// read back after the frames in flight (tests, and switching to the CPU solver).
    pub fn read_hair_state(
        &mut self,
        id: CharacterId,
    ) -> GpuResult<(crate::dynamics::HairState, crate::dynamics::StepClock)> {
        self.finish()?;
        let sim = self.world.crowd.simulation(id)?.sim();
        let bytes = super::core::readback::read_device_buffer(
            &self.ctx,
            sim.state_buffer(),
            sim.state_bytes(),
        )?;
        Ok((super::dynamics::hair_state(&bytes), *sim.clock()))
    }

    /// Build character `id`'s strand density volume (seed 002; `reference::volume` is its
    /// twin) over its hair's box, sampled as `sampling`, in the next frame.
    pub fn request_density_volume(
        &mut self,
        id: CharacterId,
        sampling: crate::reference::volume::VolumeSampling,
    ) -> GpuResult<()> {
        if !self.world.crowd.contains(id) {
            return Err(GpuError::Unsupported("no such character".into()));
        }
        if let Some(old) = self.world.volumes.request(&self.ctx, id, sampling)? {
            self.retire(Retired::Resource(Box::new(old)));
        }
        Ok(())
    }

    /// Character `id`'s density volume as last built, read back after the frames in flight.
    pub fn read_density_volume(
        &mut self,
        id: CharacterId,
    ) -> GpuResult<crate::reference::volume::DensityVolume> {
        self.finish()?;
        self.world.volumes.read(&self.ctx, id)
    }

    /// Character `id`'s density volume's occupancy mask as the GPU wrote it (its bricks with
    /// strands: [`crate::reference::volume::DensityVolume::occupancy`]), after the frames in
    /// flight.
    pub fn read_density_occupancy(&mut self, id: CharacterId) -> GpuResult<Vec<u32>> {
        self.finish()?;
        self.world.volumes.read_occupancy(&self.ctx, id)
    }

    /// The pose character `id`'s GPU hair dynamics last wrote (`layers x vertices`,
    /// character frame), read back after the frames in flight.
    pub fn read_hair_pose(&mut self, id: CharacterId) -> GpuResult<Vec<glam::Vec3>> {
        self.finish()?;
        let s = self.world.crowd.simulation(id)?;
        let bytes = super::core::readback::read_device_buffer(&self.ctx, s.pose(), s.pose().size)?;
        let poses: Vec<[f32; 4]> = bytemuck::pod_collect_to_vec(&bytes);
        let n = s.sim().vertex_count();
        Ok(poses
            .iter()
            .take(n)
            .map(|p| glam::Vec3::from_slice(&p[..3]))
            .collect())
    }

    /// The posed vertices the last frame's skinning pass wrote (its jobs in order: characters
    /// by slot, each one's parts as given to [`Self::set_character_skin`]), read back after
    /// the frames in flight; `vertices` of them.
    pub fn read_posed_vertices(
        &mut self,
        vertices: usize,
    ) -> GpuResult<Vec<super::core::shared::SkinnedVertex>> {
        self.finish()?;
        let buffer = &self.frames.last_slot().skinned;
        let bytes = vertices as u64 * size_of::<super::core::shared::SkinnedVertex>() as u64;
        if bytes > buffer.size {
            return Err(GpuError::Unsupported(format!(
                "{vertices} posed vertices asked for, the frame holds {}",
                buffer.size / size_of::<super::core::shared::SkinnedVertex>() as u64
            )));
        }
        let data = super::core::readback::read_device_buffer(&self.ctx, buffer, bytes)?;
        Ok(bytemuck::pod_collect_to_vec(&data))
    }

    /// Store the strands of the last compute-path frame for the LHS baseline (`RenderPath::Lhs`):
    /// its first `vertices` pool vertices (`FrameStats::vertex_slots_written` of that frame,
    /// rendered with LoD off), `verts_per_strand` each, with `fraction` of them as guides
    /// (`reference::lhs`). Waits for the frames in flight.
    pub fn capture_lhs(
        &mut self,
        vertices: u32,
        verts_per_strand: usize,
        fraction: f32,
    ) -> GpuResult<&crate::reference::lhs::LhsModel> {
        if self.frames.static_version != Some(self.world.crowd.version()) {
            return Err(GpuError::Unsupported(
                "capture_lhs needs the strands of a compute-path frame of the current characters"
                    .into(),
            ));
        }
        let rest = self.read_vertices(vertices)?;
        if rest.len() != vertices as usize {
            return Err(GpuError::Unsupported(format!(
                "capture_lhs: {vertices} vertices asked for, the pool holds {}",
                rest.len()
            )));
        }
        let positions = rest
            .iter()
            .map(|v| glam::Vec3::from_slice(&v.pos_width[..3]))
            .collect();
        let model = crate::reference::lhs::LhsModel::new(positions, verts_per_strand, fraction)
            .map_err(|e| GpuError::Unsupported(e.to_string()))?;
        let pool = self
            .frames
            .work
            .pool
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("no vertex pool".into()))?;
        let state = self.frames.passes.lhs_skin().upload(model, &rest, pool)?;
        let version = self.world.crowd.structure_version();
        Ok(self.frames.lhs.insert((version, state)).1.model())
    }

    /// Set the LHS guides' vertices for the next `RenderPath::Lhs` frame (guide-major, as
    /// `LhsModel::guide_rest`).
    pub fn set_lhs_guides(&mut self, now: &[glam::Vec3]) -> GpuResult<()> {
        self.frames
            .lhs
            .as_mut()
            .ok_or_else(|| GpuError::Unsupported("no LHS strands captured".into()))?
            .1
            .set_guides(now)
    }

    /// Upload the prop meshes (triangle lists); instances refer to them by index. Replaces
    /// earlier meshes and clears the instances.
    pub fn set_prop_meshes(
        &mut self,
        meshes: &[Vec<super::core::shared::PropVertex>],
    ) -> GpuResult<()> {
        if let Some(old) = self.world.props.set_meshes(&self.ctx, meshes)? {
            self.retire(Retired::Resource(Box::new(old)));
        }
        Ok(())
    }

    /// Give prop meshes far versions: an instance whose bounding sphere spans fewer than
    /// `below_pixels` of the camera's image is drawn with the far mesh in every view of the
    /// frame (camera, light, motion). Replaces earlier far versions; cleared by
    /// [`Self::set_prop_meshes`].
    pub fn set_prop_lods(&mut self, lods: &[super::prop_table::PropLod]) -> GpuResult<()> {
        self.world.props.set_lods(lods)
    }

    /// Place world props for the next frames: `(mesh index, instance)`.
    pub fn set_prop_instances(&mut self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        self.world.props.set_instances(instances)
    }

    /// Give character `id` props that move with it (its head and body): `(mesh index,
    /// instance in the character's frame)`, drawn every frame at the character's current
    /// model, and not at all while it is hidden or after it is removed. Replaces its earlier
    /// props.
    pub fn set_character_props(
        &mut self,
        id: CharacterId,
        instances: &[(usize, PropInstance)],
    ) -> GpuResult<()> {
        if !self.world.crowd.contains(id) {
            return Err(GpuError::Unsupported(format!("no character {id:?}")));
        }
        self.world.props.set_attached(id, instances)
    }

    /// Where character `id`'s props are drawn this frame (world transforms, in the order
    /// given to [`Self::set_character_props`]); empty while it is hidden.
    pub fn character_prop_models(&self, id: CharacterId) -> Vec<Mat4> {
        match self.world.crowd.drawn_model(id) {
            Some(model) => self.world.props.attached_models(id, model),
            None => Vec::new(),
        }
    }

    /// Upload the skinned meshes (bodies, clothes); characters wear them by index
    /// ([`Self::set_character_skin`]). Replaces earlier ones and what characters wore.
    pub fn set_skinned_meshes(&mut self, meshes: &[crate::skin::SkinnedMesh]) -> GpuResult<()> {
        for old in self.world.skinned.set_meshes(&self.ctx, meshes)? {
            self.retire(Retired::Resource(Box::new(old)));
        }
        Ok(())
    }

    /// Far versions of skinned meshes (as [`Self::set_prop_lods`]).
    pub fn set_skinned_lods(&mut self, lods: &[super::prop_table::PropLod]) -> GpuResult<()> {
        self.world.skinned.set_lods(lods)
    }

    /// Character `id` wears skinned meshes `parts` (`(mesh, linear colour)`, the colour
    /// multiplying the mesh's own) over a skeleton of `joints`, placed and posed by
    /// [`Self::set_character_pose`] and skinned on the GPU every frame the character is drawn
    /// (hidden with it, removed with it).
    pub fn set_character_skin(
        &mut self,
        id: CharacterId,
        parts: &[(usize, [f32; 4])],
        joints: usize,
    ) -> GpuResult<()> {
        if !self.world.crowd.contains(id) {
            return Err(GpuError::Unsupported(format!("no character {id:?}")));
        }
        self.world.skinned.set_wearer(id, parts, joints)
    }

    /// Character `id`'s body for the next frames: its placement (`body`, the skinned
    /// meshes' frame to world, independent of the hair's model) and skin matrices (bind pose
    /// to that frame, one per joint: `skin::Skeleton::skin_matrices`).
    pub fn set_character_pose(
        &mut self,
        id: CharacterId,
        body: Mat4,
        matrices: &[Mat4],
    ) -> GpuResult<()> {
        self.world.skinned.set_pose(id, body, matrices)
    }

    /// Character `id`'s body placement and skin matrices as last set.
    pub fn character_pose(&self, id: CharacterId) -> Option<(Mat4, &[Mat4])> {
        self.world.skinned.pose(id)
    }

    /// Where character `id` is drawn this frame (`None`: hidden or removed).
    pub fn drawn_model(&self, id: CharacterId) -> Option<Mat4> {
        self.world.crowd.drawn_model(id)
    }

    /// Target size.
    pub fn size(&self) -> (u32, u32) {
        self.frames.targets.size()
    }

    /// Recreate the targets at a new size (frames in flight keep the old ones until done).
    pub fn resize(&mut self, width: u32, height: u32) -> GpuResult<()> {
        self.frames.resize(&mut self.world.crowd, width, height)
    }

    /// Release `r` after the newest submitted frame completes (now if none is pending).
    fn retire(&mut self, r: Retired) {
        self.frames.retire(&mut self.world.crowd, r);
    }

    /// [`Renderer::render_frame`], then blit the image onto `present.image` (scaled to its
    /// size) after `present.wait`, signalling `present.signal` for presentation.
    pub fn render_frame_to(
        &mut self,
        view: &View,
        opts: &FrameOptions,
        present: Option<PresentTarget>,
    ) -> GpuResult<FrameTicket> {
        let world = &mut self.world;
        self.frames
            .render_frame_to(world, self.background, view, opts, present)
    }

    /// Record the hair of one frame into a host's command buffer: seen through the host's
    /// camera, hidden behind the host's depth, composited over the host's colour, with `look`
    /// for everything else (light, shading, shadows, LoD; its camera is replaced). The host
    /// submits the buffer, and once that submission has completed, [`Renderer::wait`] with the
    /// ticket returns the frame's report without waiting (host frames complete when the host
    /// says so). The renderer's targets follow the host colour's size. `opts.clear` does not
    /// apply (the hair is drawn over a transparent layer, which `opts.read_image` reads back).
    /// Refused: temporal accumulation (the host's own anti-aliasing jitters its projection,
    /// which host frames follow), a slot out of range, images the host wants back unused.
    pub fn record_host_frame(
        &mut self,
        look: &View,
        opts: &FrameOptions,
        frame: HostFrame,
    ) -> GpuResult<FrameTicket> {
        let world = &mut self.world;
        self.frames
            .record_host_frame(world, self.background, look, opts, frame)
    }

    /// Draw `segments` (screen space and shaded, as generation appends them) with the
    /// software rasterizer alone, over a black image with nothing in front, keeping `k`
    /// fragments per pixel sorted, each with opacity `opacity` times its coverage; returns
    /// the image (RGBA8, sRGB). Waits for the frames in flight. For tests and tools that
    /// check the rasterizer apart from generation (single-sample targets only).
    pub fn rasterize_segments(
        &mut self,
        segments: &[SoftSegment],
        k: u32,
        opacity: f32,
    ) -> GpuResult<Vec<u8>> {
        debug::rasterize_segments(&mut self.frames, &mut self.world, segments, k, opacity)
    }

    /// The first `count` vertices of the compute path's pool, as the last frame wrote them
    /// (waits for every frame in flight).
    pub fn read_vertices(&mut self, count: u32) -> GpuResult<Vec<HairVertex>> {
        debug::read_vertices(&mut self.frames, &mut self.world, count)
    }

    /// Read back character `id`'s texture `binding` (tightly packed texels, as in the bake).
    /// Waits for every frame in flight; for tests and tools.
    pub fn read_texture(&mut self, id: CharacterId, binding: TextureBinding) -> GpuResult<Vec<u8>> {
        debug::read_texture(&mut self.frames, &mut self.world, id, binding)
    }

    /// Record and submit one frame of every visible character seen from `view`. Waits only
    /// for the frame submitted [`FRAMES_IN_FLIGHT`] frames ago.
    pub fn render_frame(&mut self, view: &View, opts: &FrameOptions) -> GpuResult<FrameTicket> {
        self.render_frame_to(view, opts, None)
    }

    /// Wait until the frame slot the next frame will use is free (its previous frame
    /// completed); a window loop calls this before acquiring a swapchain image, so the
    /// semaphores it passes are no longer in use.
    pub fn wait_for_free_slot(&mut self) -> GpuResult<()> {
        self.frames
            .retire_slot(&mut self.world.crowd, self.frames.next)
    }

    /// Wait for a submitted frame and return its report.
    pub fn wait(&mut self, ticket: FrameTicket) -> GpuResult<FrameReport> {
        self.frames.wait(&mut self.world.crowd, ticket)
    }

    /// Wait for every frame in flight.
    pub fn finish(&mut self) -> GpuResult<()> {
        self.frames.finish(&mut self.world.crowd)
    }

    /// Render one frame and wait for it (headless tools and tests).
    pub fn render_one(&mut self, view: &View, opts: &FrameOptions) -> GpuResult<FrameReport> {
        let t = self.render_frame(view, opts)?;
        self.wait(t)
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // Every frame's resources are released after the GPU is done with them.
        self.ctx.wait_idle();
    }
}

/// Check `desc` against itself and `ctx`'s device limits before anything is created; the
/// software rasterizer's budgets it asks for.
fn check_desc(ctx: &Context, desc: &RendererDesc) -> GpuResult<SoftBudget> {
    super::settings::check_size(desc.width, desc.height)?;
    let range = ctx.info.max_storage_buffer_range;
    if desc.vertex_pool_bytes < size_of::<HairVertex>() as u64 || desc.vertex_pool_bytes > range {
        return Err(GpuError::Unsupported(format!(
            "--vertex-pool-mib: a vertex pool of {} bytes must be {}..={range} bytes, the largest storage buffer {} holds",
            desc.vertex_pool_bytes,
            size_of::<HairVertex>(),
            ctx.info.name
        )));
    }
    if !(16..=8192).contains(&desc.shadow_resolution) {
        return Err(GpuError::Unsupported(format!(
            "shadow map resolution {} outside 16..=8192",
            desc.shadow_resolution
        )));
    }
    let soft_budget = desc
        .soft_budget
        .unwrap_or_else(|| SoftBudget::for_range(range));
    soft_budget.validate(range).map_err(GpuError::Unsupported)?;
    if !(desc.auto_split_pixels > 0.0 && desc.auto_split_pixels.is_finite()) {
        return Err(GpuError::Unsupported(format!(
            "auto split width {} pixels must be finite and positive",
            desc.auto_split_pixels
        )));
    }
    // Visibility ids carry the character slot in 16 bits (temporal.glsl).
    let most = super::core::shared::VISIBILITY_INDEX + 1;
    if desc.max_characters > most {
        return Err(GpuError::Unsupported(format!(
            "room for {} characters: at most {most} (motion vectors name a character in 16 bits)",
            desc.max_characters
        )));
    }
    Ok(soft_budget)
}
