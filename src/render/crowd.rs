//! The characters on the GPU: each character's five textures in one element of the bindless
//! texture arrays (descriptor indexing), its [`CharacterRecord`] (placement, style, strand
//! settings) and its bundles in the crowd's bundle table. Adding or removing a character never
//! waits for frames in flight: a removed character's textures and texture slot are retired
//! with the frame that last used them.

use std::sync::Arc;

use ash::vk;
use glam::Mat4;

pub use super::core::ids::CharacterId;
use super::core::shared::{
    CHARACTER_VISIBLE, CharacterRecord, GpuBundle, MAX_VERTS_LOG2, SimJob, TextureBinding,
};
use super::deform::PoseUpdate;
use crate::bake::blue_noise::MAX_STRANDS_PER_BUNDLE;
use crate::bake::{BakedHairMesh, MeshInfo};
use crate::model::style::HairStyle;
use crate::reference::root_surface::RootCell;
use crate::vk::{
    BindingDesc, Buffer, Context, DescriptorKind, DescriptorSet, DescriptorSetLayout, GpuError,
    GpuResult, Image, ImageDesc, Sampler,
};

/// The formats of the five textures, in Table 1 order (as [`TextureBinding::ALL`]).
pub const TEXTURE_FORMATS: [vk::Format; 5] = [
    vk::Format::R16G16B16A16_UNORM,
    vk::Format::R16G16_UNORM,
    vk::Format::R16_UNORM,
    vk::Format::R16G16B16A16_SNORM,
    vk::Format::R16G16B16A16_SNORM,
];

/// What to generate for a character.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StrandParams {
    /// Strands per (average) bundle, `1..=MAX_STRANDS_PER_BUNDLE` (32,768); a bundle of
    /// larger root area than the mean grows more (`HairStyle::density_by_area`), and no bundle
    /// may grow more than that either.
    pub strands_per_bundle: u32,
    /// Vertices per strand are `2^verts_log2 + 1`, `verts_log2 <= 6`.
    pub verts_log2: u32,
}

impl StrandParams {
    /// Check the ranges the shaders rely on.
    pub fn validate(&self) -> GpuResult<()> {
        if self.strands_per_bundle == 0
            || self.strands_per_bundle > MAX_STRANDS_PER_BUNDLE as u32
            || self.verts_log2 > MAX_VERTS_LOG2
        {
            return Err(GpuError::Unsupported(format!(
                "strands per bundle must be 1..={MAX_STRANDS_PER_BUNDLE} and verts-log2 <= {MAX_VERTS_LOG2} (got {} and {})",
                self.strands_per_bundle, self.verts_log2
            )));
        }
        Ok(())
    }
}

/// Strand triangles of a character at full detail (2 per segment).
fn max_triangles(
    bundles: &[crate::bake::BundleDesc],
    style: &HairStyle,
    params: StrandParams,
) -> u64 {
    let strands: u64 = bundles
        .iter()
        .map(|b| {
            crate::reference::generate::strands_in_bundle(b, style, params.strands_per_bundle)
                as u64
        })
        .sum();
    strands * (1u64 << params.verts_log2) * 2
}

/// Strands of a character's fullest bundle at full detail, before any limit.
fn most_in_a_bundle(bundles: &[crate::bake::BundleDesc], style: &HairStyle, n: u32) -> f32 {
    bundles
        .iter()
        .map(|b| match style.density_by_area {
            0 => n as f32,
            _ => (n as f32 * b.density).round(),
        })
        .fold(0.0, f32::max)
}

/// Refuse strand settings under which a bundle of `bundles` would grow more strands than a
/// bundle holds (they would be cut to it).
fn check_fullest_bundle(
    bundles: &[crate::bake::BundleDesc],
    style: &HairStyle,
    params: StrandParams,
) -> GpuResult<()> {
    let most = most_in_a_bundle(bundles, style, params.strands_per_bundle);
    if most > MAX_STRANDS_PER_BUNDLE as f32 {
        return Err(GpuError::Unsupported(format!(
            "{} strands per bundle: the character's largest bundle would grow {most} strands, more than a bundle holds ({MAX_STRANDS_PER_BUNDLE})",
            params.strands_per_bundle
        )));
    }
    Ok(())
}

/// A character transform must be finite.
fn check_model(model: &Mat4) -> GpuResult<()> {
    if model.is_finite() {
        Ok(())
    } else {
        Err(GpuError::Unsupported(
            "character transform is not finite".into(),
        ))
    }
}

/// Uniform scale of a character transform: the length of its x axis (widths and styling
/// margins scale by it; characters are expected to be scaled uniformly).
fn model_scale(model: &Mat4) -> f32 {
    model.x_axis.truncate().length()
}

/// What [`Crowd::write_pending_poses`] found for a frame.
#[derive(Default)]
pub struct PoseUpdates {
    /// Character slots whose textures are rebuilt.
    pub updated: Vec<usize>,
    /// Character slots simulated on the GPU first, with their steps.
    pub simulated: Vec<(usize, SimJob)>,
}

/// The GPU resources of one character: its five textures and, when its hair mesh moves, the
/// update state (with the other set of position, u and v textures).
pub struct CharacterTextures {
    images: Vec<Image>,
    bytes: u64,
    deform: Option<super::deform::DeformState>,
}

impl CharacterTextures {
    /// The image of texture `binding` made when the character was added.
    pub(super) fn own_image(&self, binding: TextureBinding) -> &Image {
        &self.images[binding as usize]
    }

    /// The current image of texture `binding`.
    fn image(&self, binding: TextureBinding) -> &Image {
        self.deform
            .as_ref()
            .filter(|d| d.alternate_current())
            .and_then(|d| d.alternate(binding))
            .unwrap_or(self.own_image(binding))
    }
}

struct Character {
    generation: u32,
    max_triangles: u64,
    /// Largest root offset of a bundle at rest ([`RootCell::bulge_bound`]), object units.
    root_bulge: f32,
    info: MeshInfo,
    style: HairStyle,
    params: StrandParams,
    model: Mat4,
    visible: bool,
    bundles: Vec<crate::bake::BundleDesc>,
    first_bundle: u32,
    textures: CharacterTextures,
}

/// Something a removed character leaves for the frame retirement list.
pub struct RemovedCharacter {
    /// Its textures (drop after the frames using them retired).
    pub textures: CharacterTextures,
    /// Its slot (reuse after the frames using it retired, [`Crowd::free_slot`]).
    pub slot: u32,
}

/// All characters and their GPU tables.
pub struct Crowd {
    ctx: Arc<Context>,
    sampler: Sampler,
    texture_layout: Arc<DescriptorSetLayout>,
    texture_set: DescriptorSet,
    slots: Vec<Option<Character>>,
    generations: Vec<u32>,
    free: Vec<u32>,
    capacity: u32,
    bundle_table: Option<Buffer>,
    bundle_count: u32,
    dirty: bool,
    /// Bumped by every change to the characters (static strands are valid for one version).
    version: u64,
    /// Bumped when the strands that exist change (characters added, removed, shown, hidden or
    /// restyled), not when they move: stored LHS strands are valid for one structure.
    structure_version: u64,
    /// Radial maps of GPU-simulated heads.
    head_maps: super::dynamics::HeadMaps,
}

impl Crowd {
    /// Room for `capacity` characters; fails with a clear message when the device's
    /// descriptor-indexing limits cannot hold two sets of five textures per character (the
    /// second: an animated character's other pose, elements `capacity..2 capacity`).
    pub fn new(ctx: &Arc<Context>, capacity: u32) -> GpuResult<Self> {
        let limit = ctx.info.max_bindless_sampled_images / 10;
        if capacity == 0 || capacity > limit {
            return Err(GpuError::Unsupported(format!(
                "{}: room for {capacity} characters needs {} bindless sampled images; the device allows {} ({limit} characters)",
                ctx.info.name,
                capacity as u64 * 10,
                ctx.info.max_bindless_sampled_images
            )));
        }
        for f in TEXTURE_FORMATS {
            if !ctx.supports_linear_filter(f) {
                return Err(GpuError::Unsupported(format!(
                    "{}: {f:?} cannot be sampled with linear filtering",
                    ctx.info.name
                )));
            }
        }
        let bindings: Vec<BindingDesc> = TextureBinding::ALL
            .iter()
            .map(|(b, _)| {
                BindingDesc::bindless(*b as u32, DescriptorKind::SampledImage, 2 * capacity)
            })
            .collect();
        let texture_layout = DescriptorSetLayout::new(ctx, &bindings)?;
        let texture_set = DescriptorSet::new(ctx, "character textures", &texture_layout)?;
        Ok(Crowd {
            ctx: ctx.clone(),
            sampler: Sampler::linear_clamp(ctx)?,
            texture_layout,
            texture_set,
            slots: Vec::new(),
            generations: Vec::new(),
            free: Vec::new(),
            capacity,
            bundle_table: None,
            bundle_count: 0,
            dirty: false,
            version: 0,
            structure_version: 0,
            head_maps: Default::default(),
        })
    }

    /// Layout of the texture set (set 1 of every pipeline).
    pub fn texture_layout(&self) -> &Arc<DescriptorSetLayout> {
        &self.texture_layout
    }

    /// The texture set.
    pub fn texture_set(&self) -> &DescriptorSet {
        &self.texture_set
    }

    /// Upload `baked` and add a character. Blocks until its textures are uploaded.
    pub fn add(
        &mut self,
        baked: &BakedHairMesh,
        style: &HairStyle,
        params: StrandParams,
        model: Mat4,
    ) -> GpuResult<CharacterId> {
        params.validate()?;
        check_fullest_bundle(&baked.bundles, style, params)?;
        self.version += 1;
        self.structure_version += 1;
        check_model(&model)?;
        let slot = match self.free.pop() {
            Some(s) => s,
            None if (self.slots.len() as u32) < self.capacity => {
                self.slots.push(None);
                self.generations.push(0);
                self.slots.len() as u32 - 1
            }
            None => {
                return Err(GpuError::Unsupported(format!(
                    "the crowd is full ({} characters; raise RendererDesc::max_characters)",
                    self.capacity
                )));
            }
        };
        let textures = match self.upload(slot, baked) {
            Ok(t) => t,
            Err(e) => {
                self.free.push(slot);
                return Err(e);
            }
        };
        self.generations[slot as usize] += 1;
        let generation = self.generations[slot as usize];
        self.slots[slot as usize] = Some(Character {
            generation,
            max_triangles: max_triangles(&baked.bundles, style, params),
            root_bulge: baked
                .bundles
                .iter()
                .map(|b| RootCell::from_baked(baked, b).bulge_bound())
                .fold(0.0, f32::max),
            info: baked.info,
            style: *style,
            params,
            model,
            visible: true,
            bundles: baked.bundles.clone(),
            first_bundle: 0,
            textures,
        });
        self.dirty = true;
        Ok(CharacterId::new(slot, generation))
    }

    fn upload(&self, slot: u32, baked: &BakedHairMesh) -> GpuResult<CharacterTextures> {
        let mut images = Vec::new();
        let mut bytes = 0;
        for ((t, format), (binding, _)) in baked
            .textures()
            .iter()
            .zip(TEXTURE_FORMATS)
            .zip(TextureBinding::ALL)
        {
            let desc = if binding == TextureBinding::Uv {
                ImageDesc::new_2d(t.name, format, t.extent[0], t.extent[1])
            } else {
                ImageDesc::new_3d(t.name, format, t.extent)
            };
            // Transfer source: `Renderer::read_texture` reads them back.
            let desc = desc.usage(vk::ImageUsageFlags::TRANSFER_SRC);
            let image = Image::with_data(&self.ctx, &desc, t.bytes)?;
            bytes += image.byte_size();
            images.push(image);
        }
        // The slot is free: no pending frame reads it (freed slots retire with their frames).
        for (image, (binding, _)) in images.iter().zip(TextureBinding::ALL) {
            self.texture_set
                .write_image(binding as u32, slot, image, &self.sampler)?;
        }
        Ok(CharacterTextures {
            images,
            bytes,
            deform: None,
        })
    }

    fn get(&self, id: CharacterId) -> GpuResult<&Character> {
        self.slots
            .get(id.slot() as usize)
            .and_then(|c| c.as_ref())
            .filter(|c| c.generation == id.generation())
            .ok_or_else(|| GpuError::Unsupported(format!("no character {id:?}")))
    }

    fn get_mut(&mut self, id: CharacterId) -> GpuResult<&mut Character> {
        self.slots
            .get_mut(id.slot() as usize)
            .and_then(|c| c.as_mut())
            .filter(|c| c.generation == id.generation())
            .ok_or_else(|| GpuError::Unsupported(format!("no character {id:?}")))
    }

    /// Whether `id` names a character of the crowd.
    pub fn contains(&self, id: CharacterId) -> bool {
        self.slots
            .get(id.slot() as usize)
            .and_then(|c| c.as_ref())
            .is_some_and(|c| c.generation == id.generation())
    }

    /// Where character `id` is drawn this frame: its model, or `None` if it is hidden or gone.
    pub fn drawn_model(&self, id: CharacterId) -> Option<Mat4> {
        self.slots
            .get(id.slot() as usize)
            .and_then(|c| c.as_ref())
            .filter(|c| c.generation == id.generation() && c.visible)
            .map(|c| c.model)
    }

    /// Remove a character; its textures and slot must be retired with the last frame that
    /// may use them.
    pub fn remove(&mut self, id: CharacterId) -> GpuResult<RemovedCharacter> {
        self.version += 1;
        self.structure_version += 1;
        self.get_mut(id)?;
        let c = self.slots[id.slot() as usize]
            .take()
            .expect("checked by get_mut");
        self.dirty = true;
        Ok(RemovedCharacter {
            textures: c.textures,
            slot: id.slot(),
        })
    }

    /// Let character `id`'s hair mesh move: `basis` must come from the mesh and bake it was
    /// added with (same root layout and layers); `layout` is the update pass's set layout.
    pub fn make_deformable(
        &mut self,
        id: CharacterId,
        basis: crate::bake::deform::DeformBasis,
        layout: &Arc<DescriptorSetLayout>,
    ) -> GpuResult<()> {
        self.get_mut(id)?;
        let c = self.slots[id.slot() as usize]
            .as_mut()
            .expect("checked by get_mut");
        if basis.info != c.info {
            return Err(GpuError::Unsupported(
                "the deform basis belongs to another bake (decode box or layout differ)".into(),
            ));
        }
        if c.textures.deform.is_some() {
            return Err(GpuError::Unsupported(format!(
                "character {id:?} is already deformable"
            )));
        }
        let own = super::deform::POSED_TEXTURES.map(|b| c.textures.own_image(b));
        let state = super::deform::DeformState::new(&self.ctx, basis, layout, own)?;
        // The other texture set: its own position, u and v; the shared uv and w. No frame
        // reads those elements before the first pose update.
        let other = id.slot() + self.capacity;
        for (binding, _) in TextureBinding::ALL {
            let image = state
                .alternate(binding)
                .unwrap_or(c.textures.own_image(binding));
            self.texture_set
                .write_image(binding as u32, other, image, &self.sampler)?;
        }
        c.textures.deform = Some(state);
        Ok(())
    }

    /// Set the hair mesh pose of a deformable character for the next frame.
    pub fn set_pose(&mut self, id: CharacterId, positions: &[glam::Vec3]) -> GpuResult<()> {
        self.version += 1;
        match &mut self.get_mut(id)?.textures.deform {
            Some(d) => d.set_pose(positions),
            None => Err(GpuError::Unsupported(format!(
                "character {id:?} was not made deformable"
            ))),
        }
    }

    /// Write every pending pose into frame slot `frame`'s buffers and take the pending GPU
    /// steps: the character slots that have an update this frame, and the steps (with their
    /// slots) the hair dynamics pass runs before the updates.
    pub fn write_pending_poses(&mut self, frame: usize) -> GpuResult<PoseUpdates> {
        let mut out = PoseUpdates::default();
        for (slot, c) in self.slots.iter_mut().enumerate() {
            let Some(d) = c.as_mut().and_then(|c| c.textures.deform.as_mut()) else {
                continue;
            };
            match d.write_pending(frame)? {
                Some(PoseUpdate::Uploaded) => out.updated.push(slot),
                Some(PoseUpdate::Simulated(job)) => {
                    out.updated.push(slot);
                    out.simulated.push((slot, *job));
                }
                None => {}
            }
        }
        Ok(out)
    }

    /// The deform state of character `id`, which must be deformable.
    fn deform_mut(&mut self, id: CharacterId) -> GpuResult<&mut super::deform::DeformState> {
        self.get_mut(id)?.textures.deform.as_mut().ok_or_else(|| {
            GpuError::Unsupported(format!("character {id:?} was not made deformable"))
        })
    }

    /// Simulate character `id`'s hair on the GPU from `sim`'s state (it must have been made
    /// deformable); an earlier GPU simulation of it is returned for retiring.
    pub fn simulate(
        &mut self,
        id: CharacterId,
        sim: &crate::dynamics::HairDynamics,
        layout: &Arc<DescriptorSetLayout>,
    ) -> GpuResult<Option<super::deform::SimulatedPose>> {
        let ctx = self.ctx.clone();
        let mut maps = std::mem::take(&mut self.head_maps);
        let result = self
            .deform_mut(id)
            .and_then(|d| d.simulate(&ctx, layout, sim, &mut maps));
        self.head_maps = maps;
        result
    }

    /// Step character `id`'s GPU hair dynamics (see `DeformState::step_simulation`).
    pub fn step_simulation(
        &mut self,
        id: CharacterId,
        dt: f32,
        model: Mat4,
        settings: &crate::dynamics::DynamicsSettings,
    ) -> GpuResult<()> {
        self.version += 1;
        self.deform_mut(id)?.step_simulation(dt, model, settings)
    }

    /// Character `id`'s GPU simulation, if started.
    pub fn simulation(&self, id: CharacterId) -> GpuResult<&super::deform::SimulatedPose> {
        self.get(id)?
            .textures
            .deform
            .as_ref()
            .and_then(|d| d.simulation())
            .ok_or_else(|| {
                GpuError::Unsupported(format!("character {id:?} has no GPU hair dynamics"))
            })
    }

    /// The state and pose buffers of the simulated characters in `slots` (this frame's).
    pub fn simulated_buffers(&self, slots: &[usize]) -> Vec<(&Buffer, &Buffer)> {
        slots
            .iter()
            .filter_map(|&s| self.slots.get(s)?.as_ref()?.textures.deform.as_ref())
            .filter_map(|d| d.simulated_buffers())
            .collect()
    }

    /// The update jobs of character slots `updated` for frame slot `frame`.
    pub fn update_jobs(
        &self,
        frame: usize,
        updated: &[usize],
    ) -> Vec<super::passes::hair_mesh_update::UpdateJob<'_>> {
        updated
            .iter()
            .filter_map(|&slot| self.slots.get(slot)?.as_ref())
            .filter_map(|c| {
                let d = c.textures.deform.as_ref()?;
                let (set, groups) = d.dispatch(frame);
                let img = |b: TextureBinding| c.textures.image(b);
                Some(super::passes::hair_mesh_update::UpdateJob {
                    set,
                    groups,
                    outputs: &d.outputs,
                    images: [
                        img(TextureBinding::Position),
                        img(TextureBinding::U),
                        img(TextureBinding::V),
                    ],
                })
            })
            .collect()
    }

    /// The image of character `id`'s texture `binding` (tests and tools read it back).
    pub fn texture(&self, id: CharacterId, binding: TextureBinding) -> GpuResult<&Image> {
        self.slots
            .get(id.slot() as usize)
            .and_then(|c| c.as_ref())
            .filter(|c| c.generation == id.generation())
            .map(|c| c.textures.image(binding))
            .ok_or_else(|| GpuError::Unsupported(format!("no character {id:?}")))
    }

    /// Make a retired slot available again.
    pub fn free_slot(&mut self, slot: u32) {
        self.free.push(slot);
    }

    /// Move a character.
    pub fn set_model(&mut self, id: CharacterId, model: Mat4) -> GpuResult<()> {
        self.version += 1;
        check_model(&model)?;
        self.get_mut(id)?.model = model;
        Ok(())
    }

    /// Show or hide a character.
    pub fn set_visible(&mut self, id: CharacterId, visible: bool) -> GpuResult<()> {
        self.version += 1;
        self.structure_version += 1;
        self.get_mut(id)?.visible = visible;
        Ok(())
    }

    /// Change a character's strand settings.
    pub fn set_params(&mut self, id: CharacterId, params: StrandParams) -> GpuResult<()> {
        self.version += 1;
        self.structure_version += 1;
        params.validate()?;
        let c = self.get_mut(id)?;
        check_fullest_bundle(&c.bundles, &c.style, params)?;
        c.params = params;
        c.max_triangles = max_triangles(&c.bundles, &c.style, params);
        Ok(())
    }

    /// Strands the fullest bundle of any character grows at full detail (the root samples the
    /// GPU needs).
    pub fn most_in_a_bundle(&self) -> u32 {
        self.slots
            .iter()
            .flatten()
            .map(|c| most_in_a_bundle(&c.bundles, &c.style, c.params.strands_per_bundle) as u32)
            .max()
            .unwrap_or(0)
    }

    /// Strand triangles (2 per segment) of every character at full detail: the largest value
    /// a frame's 32-bit statistics can reach without LoD (the compute path's vertex and
    /// draw-vertex sums are held to its pool by the LoD pressure, `lod_pressure.comp`; the
    /// triangle statistics are not).
    pub fn max_triangles(&self) -> u64 {
        self.slots.iter().flatten().map(|c| c.max_triangles).sum()
    }

    /// World-space bounds of every visible character's hair: the box of its latest pose for
    /// animated characters, else of its hair mesh texture, transformed, grown by the styling
    /// offsets and the curved roots (as `bundle_lod.glsl` grows bundle bounds).
    pub fn hair_bounds(&self) -> Vec<(glam::Vec3, glam::Vec3)> {
        use glam::Vec3;
        self.slots
            .iter()
            .flatten()
            .filter(|c| c.visible)
            .map(|c| {
                let texture_box = || {
                    let lo = Vec3::from_slice(&c.info.pos_origin[..3]);
                    (lo, lo + Vec3::from_slice(&c.info.pos_extent[..3]))
                };
                let (lo, hi) = c
                    .textures
                    .deform
                    .as_ref()
                    .and_then(|d| d.pose_bounds())
                    .unwrap_or_else(texture_box);
                let (mut wlo, mut whi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
                for corner in super::camera::box_corners(lo, hi) {
                    let p = c.model.transform_point3(corner);
                    wlo = wlo.min(p);
                    whi = whi.max(p);
                }
                let st = &c.style;
                // Animated roots follow the scalp rigidly, so the bulge at rest bounds theirs.
                let margin = model_scale(&c.model)
                    * (st.curl_radius
                        + st.wave_amplitude
                        + st.frizz_amplitude
                        + st.strand_width
                        + c.root_bulge);
                (wlo - margin, whi + margin)
            })
            .collect()
    }

    /// A number that changes whenever the characters change.
    pub fn version(&self) -> u64 {
        self.version
    }

    /// A number that changes whenever the set of strands changes (not when characters move).
    pub fn structure_version(&self) -> u64 {
        self.structure_version
    }

    /// Handles of every live character.
    pub fn ids(&self) -> Vec<CharacterId> {
        self.slots
            .iter()
            .enumerate()
            .filter_map(|(slot, c)| {
                c.as_ref()
                    .map(|c| CharacterId::new(slot as u32, c.generation))
            })
            .collect()
    }

    /// Live characters.
    pub fn len(&self) -> usize {
        self.slots.iter().flatten().count()
    }

    /// Whether there are no characters.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Character slots in use (the record table's length).
    pub fn slot_count(&self) -> u32 {
        self.slots.len() as u32
    }

    /// Bundles of all characters.
    pub fn bundle_count(&self) -> u32 {
        self.bundle_count
    }

    /// Texture bytes of all characters.
    pub fn texture_bytes(&self) -> u64 {
        self.slots.iter().flatten().map(|c| c.textures.bytes).sum()
    }

    /// The bundle table (after [`Crowd::update_bundle_table`]).
    pub fn bundle_table(&self) -> Option<&Buffer> {
        self.bundle_table.as_ref()
    }

    /// Rebuild the bundle table if characters were added or removed; returns the old table,
    /// which frames in flight may still read (retire it).
    pub fn update_bundle_table(&mut self) -> GpuResult<Option<Buffer>> {
        if !self.dirty {
            return Ok(None);
        }
        let mut table = Vec::new();
        for (slot, c) in self.slots.iter_mut().enumerate() {
            if let Some(c) = c {
                c.first_bundle = table.len() as u32;
                table.extend(
                    c.bundles
                        .iter()
                        .enumerate()
                        .map(|(i, b)| GpuBundle::new(b, slot as u32, i as u32)),
                );
            }
        }
        let old = self.bundle_table.take();
        self.bundle_count = table.len() as u32;
        self.dirty = false;
        if !table.is_empty() {
            let buffer = Buffer::device_local_with_data(
                &self.ctx,
                "bundle table",
                vk::BufferUsageFlags::STORAGE_BUFFER,
                bytemuck::cast_slice(&table),
            )?;
            self.bundle_table = Some(buffer);
        }
        Ok(old)
    }

    /// The character records of every slot (empty slots are invisible, with no bundles);
    /// those in `deforming` (their pose changed this frame) with the previous pose's texture
    /// set.
    pub fn records(&self, deforming: &[usize]) -> Vec<CharacterRecord> {
        let mut records: Vec<CharacterRecord> = self
            .slots
            .iter()
            .enumerate()
            .map(|(slot, c)| match c {
                Some(c) => {
                    let texture_slot = self.texture_element(slot, c, false);
                    CharacterRecord {
                        model: c.model.to_cols_array_2d(),
                        mesh: c.info,
                        style: c.style,
                        texture_slot,
                        first_bundle: c.first_bundle,
                        bundle_count: c.bundles.len() as u32,
                        strands_per_bundle: c.params.strands_per_bundle,
                        verts_log2: c.params.verts_log2,
                        flags: if c.visible { CHARACTER_VISIBLE } else { 0 },
                        model_scale: model_scale(&c.model),
                        prev_texture_slot: texture_slot,
                        clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
                        // Filled in by the frame for characters with a density volume.
                        world_to_volume: Mat4::IDENTITY.to_cols_array_2d(),
                        volume: [0; 4],
                        volume_shading: [0.0; 4],
                    }
                }
                None => bytemuck::Zeroable::zeroed(),
            })
            .collect();
        for &slot in deforming {
            if let (Some(r), Some(Some(c))) = (records.get_mut(slot), self.slots.get(slot)) {
                r.prev_texture_slot = self.texture_element(slot, c, true);
            }
        }
        records
    }

    /// The texture array element of slot `slot`'s current texture set (`previous`: the other
    /// one, which holds the pose before the last update).
    fn texture_element(&self, slot: usize, c: &Character, previous: bool) -> u32 {
        let other = c
            .textures
            .deform
            .as_ref()
            .is_some_and(|d| d.alternate_current() != previous);
        slot as u32 + if other { self.capacity } else { 0 }
    }
}
