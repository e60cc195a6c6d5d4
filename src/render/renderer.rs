//! The renderer: one frame serves every character. It owns the pipelines, the render targets
//! (recreated on resize only), the crowd's GPU tables and [`FRAMES_IN_FLIGHT`] frame slots.
//! A frame is recorded with [`Renderer::render_frame`] and its [`FrameReport`] collected with
//! [`Renderer::wait`]; headless tools and tests do both with [`Renderer::render_one`].

use std::collections::VecDeque;
use std::sync::Arc;
use std::time::Instant;

use ash::vk;
use glam::Mat4;

use super::camera::View;
use super::crowd::{CharacterId, Crowd, StrandParams};
use super::frame::{
    FRAMES_IN_FLIGHT, FrameReport, FrameSlot, Pending, Retired, prop_instance_buffer,
    records_buffer,
};
use super::passes::props::PropDraw;
use super::passes::{FrameInputs, FramePasses, PassSets};
pub use super::settings::{FrameOptions, FrameTicket, RenderPath, RendererDesc};
use super::shadow::{LightView, ShadowMode};
use super::shared::{FrameBinding, GenerateArgs, HairVertex, SET_FRAME, SET_TEXTURES};
use super::shared::{PropInstance, PropVertex};
use super::soft::{SoftBudget, SoftBuffers, StrandRaster};
use super::targets::{RenderTargets, ShadowMaps};
use super::transparency::{Transparency, TransparencyBuffers};
use super::workspace::FrameBuffers;
use super::workspace::Workspace;
use crate::bake::BakedHairMesh;
use crate::model::style::HairStyle;
use crate::vk::{
    Access, BindingDesc, Buffer, BufferDesc, CommandRecorder, Context, DescriptorSetLayout,
    GpuError, GpuResult, Image, PipelineLayout, Semaphore, SwapchainImage,
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

/// Something drawn over a frame's colour target before it is presented.
pub type Overlay<'a> = dyn FnMut(&mut CommandRecorder, &Image) -> GpuResult<()> + 'a;

/// Prop meshes on the GPU and the instances placed for the next frames.
#[derive(Default)]
struct Props {
    vertices: Option<Buffer>,
    meshes: Vec<(u32, u32)>,
    instances: Vec<(usize, PropInstance)>,
    /// Props that move with a character: `(character, mesh, instance in its frame)`.
    attached: Vec<(CharacterId, usize, PropInstance)>,
}

impl Props {
    /// This frame's instance records (sorted by mesh) and one draw per mesh: the world props
    /// and, placed by `model_of` (`None`: not drawn), the characters' own.
    fn frame_lists(
        &self,
        model_of: impl Fn(CharacterId) -> Option<Mat4>,
    ) -> (Vec<PropInstance>, Vec<PropDraw>) {
        let mut all = self.instances.clone();
        all.extend(self.attached.iter().filter_map(|(id, mesh, inst)| {
            let model = model_of(*id)? * Mat4::from_cols_array_2d(&inst.model);
            Some((
                *mesh,
                PropInstance {
                    model: model.to_cols_array_2d(),
                    color: inst.color,
                },
            ))
        }));
        all.sort_by_key(|(m, _)| *m);
        let records = all.iter().map(|(_, i)| *i).collect();
        let mut draws: Vec<PropDraw> = Vec::new();
        for (k, (mesh, _)) in all.iter().enumerate() {
            let (first_vertex, vertex_count) = self.meshes[*mesh];
            match draws.last_mut() {
                Some(d) if d.first_vertex == first_vertex => d.instance_count += 1,
                _ => draws.push(PropDraw {
                    first_vertex,
                    vertex_count,
                    first_instance: k as u32,
                    instance_count: 1,
                }),
            }
        }
        (records, draws)
    }
}

/// Renders every character of the crowd in one frame.
pub struct Renderer {
    ctx: Arc<Context>,
    desc: RendererDesc,
    crowd: Crowd,
    passes: FramePasses,
    frames: Vec<FrameSlot>,
    props: Props,
    next: usize,
    frame_number: u64,
    targets: RenderTargets,
    shadow: ShadowMaps,
    /// Per-pixel buffers of the transparent modes.
    transparency: TransparencyBuffers,
    /// The software rasterizer's buffers and budgets.
    soft: SoftBuffers,
    soft_budget: SoftBudget,
    /// The crowd version whose strands the vertex pool holds (the last compute-path frame's),
    /// which static-path frames draw again.
    static_version: Option<u64>,
    /// The crowd structure whose strand layout the draw arguments describe (the last compute
    /// frame's; a mesh frame clears them).
    args_structure: Option<u64>,
    /// The LHS baseline's stored strands (`capture_lhs`), with the crowd version they are of.
    lhs: Option<(u64, super::passes::lhs_skin::LhsState)>,
    work: Workspace,
    completed: VecDeque<FrameReport>,
    /// Background colour (linear RGB).
    pub background: [f32; 3],
}

/// What one frame draws (beyond the options the caller gave).
struct FrameWork<'a> {
    path: RenderPath,
    bundles: u32,
    props: &'a [PropDraw],
    /// Shadow mode, when shadows are on and there is hair to shadow.
    shadows: Option<ShadowMode>,
    /// How strands are composited.
    transparency: super::Transparency,
    /// How strands are rasterized.
    raster: StrandRaster,
    /// k-buffer nodes per pixel (OIT budget, or the software rasterizer's K).
    kbuffer_budget: u32,
    /// Character slots whose hair mesh pose changed (rebuilt this frame).
    pose_updates: Vec<usize>,
}

fn check_size(width: u32, height: u32) -> GpuResult<()> {
    if width == 0 || height == 0 || width > 8192 || height > 8192 {
        return Err(GpuError::Unsupported(format!(
            "bad target size {width}x{height}: 1..=8192 per side"
        )));
    }
    Ok(())
}

/// Why the software rasterizer cannot draw with `path`, `msaa` samples and `transparency`
/// (`None`: it can); tools check this before any work to name their flags.
pub fn software_raster_conflict(
    path: RenderPath,
    msaa: u32,
    transparency: Transparency,
) -> Option<String> {
    if !matches!(path, RenderPath::Mesh | RenderPath::Compute) {
        return Some(
            "the software rasterizer draws generated strands: use the mesh or compute path".into(),
        );
    }
    if msaa > 1 {
        return Some(
            "the software rasterizer antialiases strands analytically and reads single-sample depth: use it without MSAA".into(),
        );
    }
    if matches!(transparency, Transparency::DepthPeeling { .. }) {
        return Some(
            "the software rasterizer composites through the k-buffer: use it with opaque or oit transparency, not depth peeling".into(),
        );
    }
    None
}

/// Sample counts `ctx`'s device supports for the renderer's colour and depth targets.
pub fn supported_msaa(ctx: &Context) -> Vec<u32> {
    (0..7)
        .map(|b| 1u32 << b)
        .filter(|c| ctx.info.attachment_sample_counts & c != 0)
        .collect()
}

/// `samples` per pixel on `ctx`'s device, or why not (naming the device and what it offers);
/// tools prefix the flag that set it.
pub fn check_msaa(ctx: &Context, samples: u32) -> Result<(), String> {
    let supported = supported_msaa(ctx);
    if supported.contains(&samples) {
        return Ok(());
    }
    let list: Vec<String> = supported.iter().map(|c| c.to_string()).collect();
    Err(format!(
        "{} supports {} samples per pixel for colour and depth",
        ctx.info.name,
        list.join(", ")
    ))
}

impl Renderer {
    /// Create pipelines, targets and frame slots; checks the device limits the settings need.
    pub fn new(ctx: &Arc<Context>, desc: &RendererDesc) -> GpuResult<Self> {
        check_size(desc.width, desc.height)?;
        let range = ctx.info.max_storage_buffer_range;
        if desc.vertex_pool_bytes < size_of::<HairVertex>() as u64 || desc.vertex_pool_bytes > range
        {
            return Err(GpuError::Unsupported(format!(
                "vertex pool of {} bytes: must be {}..={range} (maxStorageBufferRange of {})",
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
        let crowd = Crowd::new(ctx, desc.max_characters)?;
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
        if desc.path == Some(RenderPath::Mesh) && !passes.has_mesh_path() {
            return Err(GpuError::Unsupported(format!(
                "{}: no usable VK_EXT_mesh_shader for the mesh path",
                ctx.info.name
            )));
        }
        let frames = (0..FRAMES_IN_FLIGHT)
            .map(|_| FrameSlot::new(ctx, &frame_layout))
            .collect::<GpuResult<_>>()?;
        let work = Workspace::new(ctx)?;
        Ok(Renderer {
            ctx: ctx.clone(),
            desc: desc.clone(),
            crowd,
            passes,
            frames,
            props: Props::default(),
            next: 0,
            frame_number: 0,
            targets: RenderTargets::new(ctx, desc.width, desc.height, desc.msaa)?,
            shadow: ShadowMaps::new(ctx, desc.shadow_resolution)?,
            transparency: TransparencyBuffers::new(ctx)?,
            soft: SoftBuffers::new(ctx)?,
            soft_budget,
            static_version: None,
            args_structure: None,
            lhs: None,
            work,
            completed: VecDeque::new(),
            background: [0.6, 0.65, 0.7],
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

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.passes.has_mesh_path()
    }

    /// Whether the software rasterizer is available (64-bit shared and buffer atomics).
    pub fn has_software_raster(&self) -> bool {
        self.passes.has_software_raster()
    }

    /// The software rasterizer's budgets.
    pub fn soft_budget(&self) -> SoftBudget {
        self.soft_budget
    }

    /// The characters.
    pub fn crowd(&self) -> &Crowd {
        &self.crowd
    }

    /// Vertex slots of the compute path's pool.
    pub fn vertex_budget(&self) -> u32 {
        (self.desc.vertex_pool_bytes / size_of::<HairVertex>() as u64).min(u32::MAX as u64) as u32
    }

    /// Add a character (uploads its textures; blocks until they are on the GPU).
    pub fn add_character(
        &mut self,
        baked: &BakedHairMesh,
        style: &HairStyle,
        params: StrandParams,
        model: Mat4,
    ) -> GpuResult<CharacterId> {
        self.crowd.add(baked, style, params, model)
    }

    /// Remove a character; its textures are released after the frames using them.
    pub fn remove_character(&mut self, id: CharacterId) -> GpuResult<()> {
        let removed = self.crowd.remove(id)?;
        self.props.attached.retain(|(c, ..)| *c != id);
        self.retire(Retired::Resource(Box::new(removed.textures)));
        self.retire(Retired::CharacterSlot(removed.slot));
        Ok(())
    }

    /// Move a character.
    pub fn set_model(&mut self, id: CharacterId, model: Mat4) -> GpuResult<()> {
        self.crowd.set_model(id, model)
    }

    /// Show or hide a character.
    pub fn set_visible(&mut self, id: CharacterId, visible: bool) -> GpuResult<()> {
        self.crowd.set_visible(id, visible)
    }

    /// Change a character's strand settings.
    pub fn set_params(&mut self, id: CharacterId, params: StrandParams) -> GpuResult<()> {
        self.crowd.set_params(id, params)
    }

    /// Let character `id`'s hair mesh move (`bake::deform`): `basis` from the mesh and bake it
    /// was added with (bake with a `motion_margin` so the motion stays inside the decode box).
    pub fn make_deformable(
        &mut self,
        id: CharacterId,
        basis: crate::bake::deform::DeformBasis,
    ) -> GpuResult<()> {
        let layout = self.passes.deform_set_layout().clone();
        self.crowd.make_deformable(id, basis, &layout)
    }

    /// Set a deformable character's hair mesh pose (`layers x vertices` object-space positions,
    /// layer-major). The next frame rebuilds its hair mesh and u/v textures on the GPU before
    /// anything reads them.
    pub fn set_hair_mesh_pose(
        &mut self,
        id: CharacterId,
        positions: &[glam::Vec3],
    ) -> GpuResult<()> {
        self.crowd.set_pose(id, positions)
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
        if self.static_version != Some(self.crowd.version()) {
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
            .work
            .pool
            .as_ref()
            .ok_or_else(|| GpuError::Unsupported("no vertex pool".into()))?;
        let state = self.passes.lhs_skin.upload(model, &rest, pool)?;
        let version = self.crowd.structure_version();
        Ok(self.lhs.insert((version, state)).1.model())
    }

    /// Set the LHS guides' vertices for the next `RenderPath::Lhs` frame (guide-major, as
    /// `LhsModel::guide_rest`).
    pub fn set_lhs_guides(&mut self, now: &[glam::Vec3]) -> GpuResult<()> {
        self.lhs
            .as_mut()
            .ok_or_else(|| GpuError::Unsupported("no LHS strands captured".into()))?
            .1
            .set_guides(now)
    }

    /// Read back character `id`'s texture `binding` (tightly packed texels, as in the bake).
    /// Waits for every frame in flight; for tests and tools.
    pub fn read_texture(
        &mut self,
        id: CharacterId,
        binding: super::shared::TextureBinding,
    ) -> GpuResult<Vec<u8>> {
        self.finish()?;
        let image = self.crowd.texture(id, binding)?;
        let mut readback = Buffer::new(
            &self.ctx,
            &BufferDesc::new(
                "texture readback",
                image.byte_size(),
                vk::BufferUsageFlags::TRANSFER_DST,
            )
            .readback(),
        )?;
        self.ctx.submit_and_wait(|rec| {
            rec.image_barrier(image, Access::SampledRead, Access::TransferRead);
            rec.copy_image_to_buffer(image, &readback);
            rec.image_barrier(image, Access::TransferRead, Access::SampledRead);
            rec.barrier(&[Access::TransferWrite], &[Access::HostRead]);
        })?;
        readback.read()
    }

    /// Upload the prop meshes (triangle lists); instances refer to them by index. Replaces
    /// earlier meshes and clears the instances.
    pub fn set_prop_meshes(&mut self, meshes: &[Vec<PropVertex>]) -> GpuResult<()> {
        let mut all = Vec::new();
        let mut ranges = Vec::new();
        for m in meshes {
            if m.len() % 3 != 0 || m.iter().any(|v| !v.position.iter().all(|x| x.is_finite())) {
                return Err(GpuError::Unsupported(
                    "prop meshes are finite triangle lists".into(),
                ));
            }
            ranges.push((all.len() as u32, m.len() as u32));
            all.extend_from_slice(m);
        }
        let vertices = if all.is_empty() {
            None
        } else {
            Some(Buffer::device_local_with_data(
                &self.ctx,
                "prop vertices",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytemuck::cast_slice(&all),
            )?)
        };
        if let Some(old) = std::mem::replace(&mut self.props.vertices, vertices) {
            self.retire(Retired::Resource(Box::new(old)));
        }
        self.props.meshes = ranges;
        self.props.instances.clear();
        self.props.attached.clear();
        Ok(())
    }

    /// Refuse instances of meshes that do not exist or with non-finite values.
    fn check_prop_instances(&self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        if let Some((m, _)) = instances
            .iter()
            .find(|(m, _)| *m >= self.props.meshes.len())
        {
            return Err(GpuError::Unsupported(format!("no prop mesh {m}")));
        }
        if instances.iter().any(|(_, i)| {
            !i.model
                .iter()
                .flatten()
                .chain(&i.color)
                .all(|x| x.is_finite())
        }) {
            return Err(GpuError::Unsupported("prop transform is not finite".into()));
        }
        Ok(())
    }

    /// Place world props for the next frames: `(mesh index, instance)`.
    pub fn set_prop_instances(&mut self, instances: &[(usize, PropInstance)]) -> GpuResult<()> {
        self.check_prop_instances(instances)?;
        self.props.instances = instances.to_vec();
        Ok(())
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
        if !self.crowd.contains(id) {
            return Err(GpuError::Unsupported(format!("no character {id:?}")));
        }
        self.check_prop_instances(instances)?;
        self.props.attached.retain(|(c, ..)| *c != id);
        self.props
            .attached
            .extend(instances.iter().map(|(m, i)| (id, *m, *i)));
        Ok(())
    }

    /// Where character `id`'s props are drawn this frame (world transforms, in the order
    /// given to [`Self::set_character_props`]); empty while it is hidden.
    pub fn character_prop_models(&self, id: CharacterId) -> Vec<Mat4> {
        let Some(model) = self.crowd.drawn_model(id) else {
            return Vec::new();
        };
        self.props
            .attached
            .iter()
            .filter(|(c, ..)| *c == id)
            .map(|(_, _, i)| model * Mat4::from_cols_array_2d(&i.model))
            .collect()
    }

    /// Where character `id` is drawn this frame (`None`: hidden or removed).
    pub fn drawn_model(&self, id: CharacterId) -> Option<Mat4> {
        self.crowd.drawn_model(id)
    }

    /// Target size.
    pub fn size(&self) -> (u32, u32) {
        self.targets.size()
    }

    /// Recreate the targets at a new size (frames in flight keep the old ones until done).
    pub fn resize(&mut self, width: u32, height: u32) -> GpuResult<()> {
        check_size(width, height)?;
        if self.targets.size() == (width, height) {
            return Ok(());
        }
        let old = std::mem::replace(
            &mut self.targets,
            RenderTargets::new(&self.ctx, width, height, self.desc.msaa)?,
        );
        self.retire(Retired::Resource(Box::new(old)));
        Ok(())
    }

    /// Release `r` after the newest submitted frame completes (now if none is pending).
    fn retire(&mut self, r: Retired) {
        let last = (self.next + FRAMES_IN_FLIGHT - 1) % FRAMES_IN_FLIGHT;
        if self.frames[last].pending.is_some() {
            self.frames[last].retired.push(r);
        } else if let Retired::CharacterSlot(s) = r {
            self.crowd.free_slot(s);
        }
    }

    /// Wait for frame slot `i`, collect its report and release what was retired with it.
    fn retire_slot(&mut self, i: usize) -> GpuResult<()> {
        let slot = &mut self.frames[i];
        slot.fence.wait()?;
        if let Some(p) = slot.pending.take() {
            let args: GenerateArgs = bytemuck::pod_read_unaligned(&slot.stats_readback.read()?);
            let rgba = match (&mut slot.image_readback, p.read_image) {
                (Some(b), true) => Some(b.read_range(0, (p.width * p.height * 4) as usize)?),
                _ => None,
            };
            let mesh_primitives = match (&slot.mesh_query, p.path) {
                (Some(q), RenderPath::Mesh) => q.result()?,
                _ => None,
            };
            self.completed.push_back(FrameReport {
                frame: p.frame,
                path: p.path,
                width: p.width,
                height: p.height,
                stats: args.stats,
                pass_ms: slot.profiler.results()?,
                mesh_primitives,
                record_ms: p.record_ms,
                rgba,
            });
            while self.completed.len() > 2 * FRAMES_IN_FLIGHT {
                self.completed.pop_front();
            }
        }
        for r in std::mem::take(&mut self.frames[i].retired) {
            if let Retired::CharacterSlot(s) = r {
                self.crowd.free_slot(s);
            }
        }
        Ok(())
    }

    /// Grow the working buffers for the crowd's bundles and allocate the vertex pool when the
    /// compute path first needs it. Replaced buffers are retired with frame slot `i`.
    fn prepare_workspace(&mut self, i: usize, path: RenderPath) -> GpuResult<()> {
        if let Some(old) = self.crowd.update_bundle_table()? {
            self.frames[i]
                .retired
                .push(Retired::Resource(Box::new(old)));
        }
        if let Some(old) = self.work.grow(self.crowd.bundle_count())? {
            self.frames[i]
                .retired
                .push(Retired::Resource(Box::new(old)));
        }
        if path.pulls_vertices() {
            self.work.ensure_pool(self.desc.vertex_pool_bytes)?;
        }
        let slots = self.crowd.slot_count();
        let slot = &mut self.frames[i];
        if slot.records.size < slots as u64 * size_of::<super::shared::CharacterRecord>() as u64 {
            slot.records = records_buffer(&self.ctx, slots.next_power_of_two())?;
        }
        let instances = (self.props.instances.len() + self.props.attached.len()) as u32;
        if slot.prop_instances.size < instances as u64 * size_of::<PropInstance>() as u64 {
            slot.prop_instances = prop_instance_buffer(&self.ctx, instances.next_power_of_two())?;
        }
        let slot = &self.frames[i];
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
                    bundle_table: self.crowd.bundle_table(),
                    prop_vertices: self.props.vertices.as_ref(),
                    shadow: &self.shadow,
                    transparency: &self.transparency,
                    soft: &self.soft,
                },
            )?;
        }
        Ok(())
    }

    /// The light's view for `view`: fitted around the visible characters whose hair is in the
    /// camera's frustum. `None` when shadows are off or no hair is in view.
    fn light_view(&self, view: &View, block: &super::shared::FrameBlock) -> Option<LightView> {
        if view.shadows == ShadowMode::Off {
            return None;
        }
        let bounds: Vec<_> = self
            .crowd
            .hair_bounds()
            .into_iter()
            .filter(|(lo, hi)| super::camera::box_in_frustum(&block.planes, *lo, *hi))
            .collect();
        LightView::fit(&bounds, view.light_dir, self.shadow.resolution())
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
        self.retire_slot(self.next)
    }

    /// [`Renderer::render_frame`], then blit the image onto `present.image` (scaled to its
    /// size) after `present.wait`, signalling `present.signal` for presentation.
    pub fn render_frame_to(
        &mut self,
        view: &View,
        opts: &FrameOptions,
        mut present: Option<PresentTarget>,
    ) -> GpuResult<FrameTicket> {
        view.validate().map_err(GpuError::Unsupported)?;
        let path = opts.path.unwrap_or(self.default_path());
        if path == RenderPath::Mesh && !self.passes.has_mesh_path() {
            return Err(GpuError::Unsupported(format!(
                "{}: no usable VK_EXT_mesh_shader for the mesh path",
                self.ctx.info.name
            )));
        }
        if path == RenderPath::Static && self.static_version != Some(self.crowd.version()) {
            return Err(GpuError::Unsupported(
                "the static path draws the strands of the last compute-path frame: render one first, and again after the characters change".into(),
            ));
        }
        let structure = Some(self.crowd.structure_version());
        if path == RenderPath::Lhs
            && (self.lhs.as_ref().map(|l| l.0) != structure || self.args_structure != structure)
        {
            return Err(GpuError::Unsupported(
                "the LHS path needs strands stored by capture_lhs for the current characters, and a compute-path frame since the last mesh-path one".into(),
            ));
        }
        // Prefix sums and statistics are 32-bit: refuse a crowd that could wrap them (LoD
        // usually needs far less, but a frame without LoD must not produce garbage).
        let worst = self.crowd.max_draw_vertices();
        if worst > u32::MAX as u64 {
            return Err(GpuError::Unsupported(format!(
                "the crowd needs up to {worst} strand draw vertices at full detail, more than 32-bit frame counters hold; lower strands per bundle or vertex level"
            )));
        }
        let raster = opts.raster;
        let kbuffer_budget = self.check_raster(raster, path, view.transparency)?;
        let i = self.next;
        self.retire_slot(i)?;
        let (width, height) = self.targets.size();
        // The software rasterizer composites through the k-buffer, in opaque frames too.
        let buffers_for = match (raster.uses_software(), view.transparency) {
            (true, Transparency::Opaque) => Transparency::KBuffer {
                budget: kbuffer_budget,
            },
            (_, t) => t,
        };
        self.passes.prepare_transparency(buffers_for)?;
        for old in self.transparency.ensure(buffers_for, width, height)? {
            self.frames[i].retired.push(Retired::Resource(old));
        }
        if raster.uses_software() {
            for old in self.soft.ensure(self.soft_budget, width, height)? {
                self.frames[i].retired.push(Retired::Resource(old));
            }
        }
        self.prepare_workspace(i, path)?;
        let pose_updates = self.crowd.write_pending_poses(i)?;
        let bundles = self.crowd.bundle_count();
        let mut block = view.frame_block(
            width,
            height,
            bundles,
            self.crowd.slot_count(),
            self.vertex_budget(),
        );
        block.transparency = view.transparency.frame_fields(self.desc.msaa);
        if raster.uses_software() {
            block.transparency[1] = kbuffer_budget;
            let opacity = match view.transparency {
                Transparency::Opaque => 1.0,
                _ => super::transparency::STRAND_OPACITY,
            };
            super::soft::frame_fields(
                &mut block,
                raster,
                self.soft_budget,
                opacity,
                self.desc.auto_split_pixels,
            );
        }
        let light = self.light_view(view, &block);
        if let Some(l) = &light {
            (block.light_view_proj, block.shadow, block.shadow_params) =
                l.shadow_fields(view.shadows);
        }
        let light_block = light.map(|l| l.frame_block(&block, &view.lod));
        let records = self.crowd.records();
        let crowd = &self.crowd;
        let (prop_instances, prop_draws) = self.props.frame_lists(|id| crowd.drawn_model(id));
        {
            let slot = &mut self.frames[i];
            slot.frame_ubo.write(0, bytemuck::bytes_of(&block))?;
            if let Some(lb) = &light_block {
                slot.light_ubo.write(0, bytemuck::bytes_of(lb))?;
            }
            slot.records.write(0, bytemuck::cast_slice(&records))?;
            slot.prop_instances
                .write(0, bytemuck::cast_slice(&prop_instances))?;
            let image_bytes = width as u64 * height as u64 * 4;
            if opts.read_image
                && slot
                    .image_readback
                    .as_ref()
                    .is_none_or(|b| b.size != image_bytes)
            {
                slot.image_readback = Some(Buffer::new(
                    &self.ctx,
                    &BufferDesc::new(
                        "image readback",
                        image_bytes,
                        vk::BufferUsageFlags::TRANSFER_DST,
                    )
                    .readback(),
                )?);
            }
        }
        let start = Instant::now();
        let shadows = light_block.map(|_| view.shadows);
        let work = FrameWork {
            path,
            bundles,
            props: &prop_draws,
            shadows,
            transparency: view.transparency,
            raster,
            kbuffer_budget,
            pose_updates,
        };
        self.record(i, work, opts, present.as_mut())?;
        let record_ms = start.elapsed().as_secs_f64() * 1e3;
        let slot = &mut self.frames[i];
        slot.fence.reset()?;
        let (wait, signal) = match &present {
            Some(p) => (Some(p.wait), Some(p.signal)),
            None => (None, None),
        };
        if let Err(e) = self.ctx.submit_with(&slot.cmd, &slot.fence, wait, signal) {
            // Keep the slot usable: a fence that will never be signalled would hang the next wait.
            slot.fence = crate::vk::Fence::new(&self.ctx, true)?;
            return Err(e);
        }
        let frame = self.frame_number;
        slot.pending = Some(Pending {
            frame,
            path,
            width,
            height,
            record_ms,
            read_image: opts.read_image,
        });
        self.frame_number += 1;
        // The pool and draw arguments now hold this frame's strands (compute path), or the mesh
        // path has overwritten the arguments.
        match path {
            // Software bundles leave no strands in the pool.
            RenderPath::Compute if raster.uses_software() => {
                self.static_version = None;
                self.args_structure = None;
            }
            RenderPath::Compute => {
                self.static_version = Some(self.crowd.version());
                self.args_structure = Some(self.crowd.structure_version());
            }
            RenderPath::Mesh => {
                self.static_version = None;
                self.args_structure = None;
            }
            RenderPath::Static | RenderPath::Lhs => {}
        }
        self.next = (i + 1) % FRAMES_IN_FLIGHT;
        Ok(FrameTicket(frame))
    }

    /// Check that `raster` can draw a frame of `path` with `transparency`; returns the k-buffer
    /// budget of the frame (the OIT budget, or the software rasterizer's K in opaque frames).
    fn check_raster(
        &self,
        raster: StrandRaster,
        path: RenderPath,
        transparency: Transparency,
    ) -> GpuResult<u32> {
        raster.validate().map_err(GpuError::Unsupported)?;
        let budget = match transparency {
            Transparency::KBuffer { budget } => budget,
            _ => raster.k(),
        };
        if !raster.uses_software() {
            return Ok(budget);
        }
        let refuse = |why: String| Err(GpuError::Unsupported(why));
        if !self.passes.has_software_raster() {
            return refuse(format!(
                "{}: the software rasterizer needs shaderInt64 and 64-bit buffer and shared atomics",
                self.ctx.info.name
            ));
        }
        if let Some(why) = software_raster_conflict(path, self.desc.msaa, transparency) {
            return refuse(why);
        }
        Ok(budget)
    }

    /// Draw `segments` (screen space and shaded, as generation appends them) with the
    /// software rasterizer alone, over a black image with nothing in front, keeping `k`
    /// fragments per pixel sorted, each with opacity `opacity` times its coverage; returns
    /// the image (RGBA8, sRGB). Waits for the frames in flight. For tests and tools that
    /// check the rasterizer apart from generation (single-sample targets only).
    pub fn rasterize_segments(
        &mut self,
        segments: &[super::shared::SoftSegment],
        k: u32,
        opacity: f32,
    ) -> GpuResult<Vec<u8>> {
        let raster = StrandRaster::Software { k };
        let kbuffer = Transparency::KBuffer { budget: k };
        self.check_raster(raster, RenderPath::Compute, kbuffer)?;
        if segments.is_empty() || segments.len() as u64 > self.soft_budget.segments as u64 {
            return Err(GpuError::Unsupported(format!(
                "rasterize_segments: 1..={} segments",
                self.soft_budget.segments
            )));
        }
        if !(0.0..=1.0).contains(&opacity) {
            return Err(GpuError::Unsupported(format!(
                "rasterize_segments: opacity {opacity} outside 0..=1"
            )));
        }
        self.finish()?;
        let i = self.next;
        let (width, height) = self.targets.size();
        self.passes.prepare_transparency(kbuffer)?;
        // Nothing is in flight: replaced buffers can go now.
        drop(self.transparency.ensure(kbuffer, width, height)?);
        drop(self.soft.ensure(self.soft_budget, width, height)?);
        self.prepare_workspace(i, RenderPath::Mesh)?;
        let mut block: super::shared::FrameBlock = bytemuck::Zeroable::zeroed();
        block.viewport = [
            width as f32,
            height as f32,
            1.0 / width as f32,
            1.0 / height as f32,
        ];
        block.transparency = kbuffer.frame_fields(1);
        let split = self.desc.auto_split_pixels;
        super::soft::frame_fields(&mut block, raster, self.soft_budget, opacity, split);
        self.frames[i]
            .frame_ubo
            .write(0, bytemuck::bytes_of(&block))?;
        let upload = Buffer::with_data(
            &self.ctx,
            "soft segments upload",
            vk::BufferUsageFlags::TRANSFER_SRC,
            bytemuck::cast_slice(segments),
        )?;
        let bytes = width as u64 * height as u64 * 4;
        let mut readback = Buffer::new(
            &self.ctx,
            &BufferDesc::new("image readback", bytes, vk::BufferUsageFlags::TRANSFER_DST)
                .readback(),
        )?;
        let ctx = self.ctx.clone();
        let slot = &mut self.frames[i];
        let (passes, targets) = (&self.passes, &mut self.targets);
        let sets = PassSets {
            frame: &slot.set,
            textures: self.crowd.texture_set(),
        };
        let result = ctx.submit_and_wait(|rec| {
            slot.profiler.reset(rec);
            rec.barrier(
                &[Access::ComputeReadWrite, Access::FragmentReadWrite],
                &[Access::TransferWrite],
            );
            rec.copy_buffer(&upload, 0, &self.soft.segments, 0, upload.size);
            let counts = (segments.len() as u32, k);
            let r = passes.record_soft_only(
                rec,
                &mut slot.profiler,
                sets,
                &self.work.args,
                &self.soft,
                &self.transparency,
                targets,
                counts,
            );
            let output = targets.output();
            rec.image_barrier(output, Access::ColorAttachment, Access::TransferRead);
            rec.copy_image_to_buffer(output, &readback);
            targets.set_output_access(Access::TransferRead);
            rec.barrier(&[Access::TransferWrite], &[Access::HostRead]);
            r
        });
        result??;
        readback.read()
    }

    /// Record frame slot `i`: the passes, then the statistics and (optionally) image readback.
    fn record(
        &mut self,
        i: usize,
        work: FrameWork,
        opts: &FrameOptions,
        present: Option<&mut PresentTarget>,
    ) -> GpuResult<()> {
        let FrameWork {
            path,
            bundles,
            props,
            shadows,
            transparency,
            raster,
            kbuffer_budget,
            pose_updates,
        } = work;
        let slot = &mut self.frames[i];
        let bg = self.background;
        let mut rec = slot.cmd.begin()?;
        slot.profiler.reset(&mut rec);
        if let Some(q) = &mut slot.mesh_query {
            q.reset(&mut rec);
        }
        let jobs = self.crowd.update_jobs(i, &pose_updates);
        self.passes
            .record_updates(&mut rec, &mut slot.profiler, &jobs);
        if path == RenderPath::Lhs
            && let Some((_, lhs)) = self.lhs.as_mut()
        {
            self.passes
                .lhs_skin
                .record(&mut rec, &mut slot.profiler, lhs, i)?;
        }
        let inputs = FrameInputs {
            sets: PassSets {
                frame: &slot.set,
                textures: self.crowd.texture_set(),
            },
            bundles,
            path,
            args: &self.work.args,
            targets: &mut self.targets,
            clear: opts.clear.then_some([bg[0], bg[1], bg[2], 1.0]),
            props,
            shadow: super::passes::ShadowInputs {
                mode: shadows,
                light_sets: PassSets {
                    frame: &slot.light_set,
                    textures: self.crowd.texture_set(),
                },
                maps: &mut self.shadow,
            },
            transparency,
            transparency_buffers: &mut self.transparency,
            raster,
            soft_buffers: &self.soft,
            kbuffer_budget,
        };
        self.passes.record(
            &mut rec,
            &mut slot.profiler,
            slot.mesh_query.as_mut(),
            inputs,
        )?;
        let mut present = present;
        if let Some(overlay) = present.as_mut().and_then(|p| p.overlay.as_mut()) {
            overlay(&mut rec, self.targets.output())?;
        }
        rec.barrier(
            &[Access::ComputeReadWrite, Access::TaskReadWrite],
            &[Access::TransferRead],
        );
        let args_bytes = size_of::<GenerateArgs>() as u64;
        rec.copy_buffer(&self.work.args, 0, &slot.stats_readback, 0, args_bytes);
        if opts.read_image
            && let Some(readback) = &slot.image_readback
        {
            let output = self.targets.output();
            rec.image_barrier(output, Access::ColorAttachment, Access::TransferRead);
            rec.copy_image_to_buffer(output, readback);
            self.targets.set_output_access(Access::TransferRead);
        }
        if let Some(p) = present {
            let output = self.targets.output();
            if self.targets.output_access != Access::TransferRead {
                rec.image_barrier(output, Access::ColorAttachment, Access::TransferRead);
            }
            self.targets.set_output_access(Access::TransferRead);
            let color = self.targets.output();
            rec.swapchain_barrier(p.image, Access::Nothing, Access::TransferWrite);
            rec.blit_to_swapchain(color, p.image);
            rec.swapchain_barrier(p.image, Access::TransferWrite, Access::Present);
        }
        rec.barrier(&[Access::TransferWrite], &[Access::HostRead]);
        drop(rec);
        slot.cmd.end()
    }

    /// Wait for a submitted frame and return its report.
    pub fn wait(&mut self, ticket: FrameTicket) -> GpuResult<FrameReport> {
        if let Some(i) = (0..FRAMES_IN_FLIGHT).find(|&i| {
            self.frames[i]
                .pending
                .as_ref()
                .is_some_and(|p| p.frame == ticket.0)
        }) {
            // Frames complete in order: retire the older pending frame first.
            let other = (i + 1) % FRAMES_IN_FLIGHT;
            if self.frames[other]
                .pending
                .as_ref()
                .is_some_and(|p| p.frame < ticket.0)
            {
                self.retire_slot(other)?;
            }
            self.retire_slot(i)?;
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
    pub fn finish(&mut self) -> GpuResult<()> {
        for k in 1..=FRAMES_IN_FLIGHT {
            self.retire_slot((self.next + k) % FRAMES_IN_FLIGHT)?;
        }
        Ok(())
    }

    /// Render one frame and wait for it (headless tools and tests).
    pub fn render_one(&mut self, view: &View, opts: &FrameOptions) -> GpuResult<FrameReport> {
        let t = self.render_frame(view, opts)?;
        self.wait(t)
    }

    /// The first `count` vertices of the compute path's pool, as the last frame wrote them
    /// (waits for every frame in flight).
    pub fn read_vertices(&mut self, count: u32) -> GpuResult<Vec<HairVertex>> {
        self.finish()?;
        let Some(pool) = &self.work.pool else {
            return Ok(Vec::new());
        };
        let bytes = (count as u64 * size_of::<HairVertex>() as u64).min(pool.size);
        if bytes == 0 {
            return Ok(Vec::new());
        }
        let mut readback = Buffer::new(
            &self.ctx,
            &BufferDesc::new("vertex readback", bytes, vk::BufferUsageFlags::TRANSFER_DST)
                .readback(),
        )?;
        self.ctx.submit_and_wait(|rec| {
            rec.barrier(
                &[Access::VertexRead, Access::ComputeReadWrite],
                &[Access::TransferRead],
            );
            rec.copy_buffer(pool, 0, &readback, 0, bytes);
            rec.barrier(&[Access::TransferWrite], &[Access::HostRead]);
        })?;
        Ok(bytemuck::pod_collect_to_vec(&readback.read()?))
    }
}

impl Drop for Renderer {
    fn drop(&mut self) {
        // Every frame's resources are released after the GPU is done with them.
        self.ctx.wait_idle();
    }
}
