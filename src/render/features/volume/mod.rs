//! Strand density volumes on the GPU (`density_volume`, the twin of
//! `reference::volume`) and the volume tier that uses them (seed 002): far characters' hair
//! ray-marched through their volume (`volume_hair`), and volumetric ambient occlusion
//! of near hair (`glsl/volume_shading.glsl`).
//!
//! A volume is built in the frame after it is requested (after that frame's texture
//! rebuilds). The tier requests one for every character it needs, and rebuilds volumes whose
//! hair mesh changed pose since their build a few a frame, the longest stale first
//! ([`VolumeTier::rebuilds_per_frame`]): a far character's volume may lag its hair's motion by
//! a few frames, which nobody sees at its size.

pub mod density_volume;
pub mod volume_hair;

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, UVec3, Vec3};

use crate::reference::volume::{
    DensityVolume, VolumeSampling, cell_size, occupancy_words, volume_box,
};
use crate::render::core::ids::CharacterId;
use crate::render::core::shared::{
    CHARACTER_VISIBLE, CHARACTER_VOLUME_ONLY, CharacterRecord, DensityJob, FrameBlock,
    VOLUME_BUILT, VOLUME_DIMS_BITS, VOLUME_FIXED, VOLUME_OCCLUSION, VOLUME_SKIP_EMPTY, VolumeCell,
};
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult};

/// Most cells one density volume may have (128^3).
pub const MAX_VOLUME_CELLS: u32 = 1 << 21;
/// Most cells along one axis (what `CharacterRecord::volume.z` packs).
pub const MAX_VOLUME_SIDE: u32 = (1 << VOLUME_DIMS_BITS) - 1;

/// The volume tier of a view (seed 002): far hair drawn from density volumes, and their
/// ambient occlusion on near hair.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VolumeTier {
    /// Occlude the ambient light of every character's strands by its density volume.
    pub occlusion: bool,
    /// Draw far characters' hair as volumes: `Some((far, near))` in pixels of the hair box's
    /// bounding diameter on screen; below `far` the volume alone, above `near` the strands
    /// alone, between a screen-door blend whose volume share falls linearly.
    pub far: Option<(f32, f32)>,
    /// Volumes whose hair mesh moved since their build rebuilt per frame, at most.
    pub rebuilds_per_frame: u32,
    /// How the tier's volumes sample the hair.
    pub sampling: VolumeSampling,
    /// The far hair's march skips the volume's empty bricks
    /// (`reference::volume::DensityVolume::occupancy`): the same picture, 2.4x faster on the
    /// 1000-person crowd (lavapipe). Off only to check that.
    pub skip_empty: bool,
}

/// The volume tier's default switch band: hair boxes below this many pixels across are
/// volumes only.
pub const DEFAULT_FAR_PIXELS: f32 = 40.0;
/// Above this many pixels across they are strands only.
pub const DEFAULT_NEAR_PIXELS: f32 = 64.0;

impl VolumeTier {
    /// The tier off: no volumes, no occlusion.
    pub const OFF: VolumeTier = VolumeTier {
        occlusion: false,
        far: None,
        rebuilds_per_frame: 16,
        sampling: VolumeSampling {
            dims: UVec3::new(24, 24, 24),
            strands_sampled: 8,
            segments_log2: 3,
        },
        skip_empty: true,
    };

    /// Occlusion on, far hair as volumes over the default band.
    pub fn on() -> Self {
        VolumeTier {
            occlusion: true,
            far: Some((DEFAULT_FAR_PIXELS, DEFAULT_NEAR_PIXELS)),
            ..Self::OFF
        }
    }

    /// Whether any character needs a volume.
    pub fn enabled(&self) -> bool {
        self.occlusion || self.far.is_some()
    }

    /// Check the band and sampling.
    pub fn validate(&self) -> Result<(), String> {
        if let Some((far, near)) = self.far
            && !(far.is_finite() && near.is_finite() && far >= 0.0 && near >= far)
        {
            return Err(format!(
                "volume tier band {far}..{near} pixels: need 0 <= far <= near, both finite"
            ));
        }
        check_sampling(&self.sampling).map_err(|e| e.to_string())
    }

    /// The volume's share of a character whose hair box spans `pixels` on screen.
    pub fn weight(&self, pixels: f32) -> f32 {
        match self.far {
            None => 0.0,
            Some((far, near)) if near > far => ((near - pixels) / (near - far)).clamp(0.0, 1.0),
            Some((far, _)) => (pixels < far) as u32 as f32,
        }
    }
}

/// What the volume tier draws in a frame: its visible characters with a share of volume.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TierDraw {
    /// Character slots up to the last of them (0: none): the volume hair pass's instances.
    pub slots: u32,
    /// Drawn as their volume alone.
    pub alone: u32,
    /// Blended between strands and volume.
    pub blended: u32,
}

impl TierDraw {
    fn add(&mut self, slot: usize, alone: bool) {
        self.slots = self.slots.max(slot as u32 + 1);
        match alone {
            true => self.alone += 1,
            false => self.blended += 1,
        }
    }
}

/// Pixels the bounding sphere of the hair box of `r` spans on the screen of `block` (its
/// diameter; infinite with the eye inside it).
pub fn hair_pixels(r: &CharacterRecord, block: &FrameBlock) -> f32 {
    let lo = Vec3::from_slice(&r.mesh.pos_origin[..3]);
    let extent = Vec3::from_slice(&r.mesh.pos_extent[..3]);
    let model = Mat4::from_cols_array_2d(&r.model);
    let centre = model.transform_point3(lo + 0.5 * extent);
    let radius = 0.5 * extent.length() * r.model_scale;
    let height = block.pixels_high;
    let inv_tan = block.cot_half_fov;
    if inv_tan <= 0.0 {
        return 2.0 * radius / block.lod.ortho_height.max(1e-12) * height;
    }
    let distance = centre.distance(Vec3::from_array(block.eye));
    if distance <= radius {
        return f32::INFINITY;
    }
    radius * inv_tan * height / distance
}

/// Byte offset of the occupancy mask in a volume's buffer of `dims` cells: after the cells and
/// the one that gathers what fell outside (`volume_shading.glsl` `brick_occupied`).
fn mask_offset(dims: UVec3) -> u64 {
    (dims.x as u64 * dims.y as u64 * dims.z as u64 + 1) * size_of::<VolumeCell>() as u64
}

/// Refuse a sampling the GPU build cannot hold.
fn check_sampling(sampling: &VolumeSampling) -> GpuResult<()> {
    let d = sampling.dims;
    let cells = d.x as u64 * d.y as u64 * d.z as u64;
    if d.min_element() == 0 || d.max_element() > MAX_VOLUME_SIDE || cells > MAX_VOLUME_CELLS as u64
    {
        return Err(GpuError::Unsupported(format!(
            "density volume of {}x{}x{} cells (1 to {MAX_VOLUME_SIDE} a side, {MAX_VOLUME_CELLS} \
             cells in all)",
            d.x, d.y, d.z
        )));
    }
    if sampling.strands_sampled == 0 || sampling.segments_log2 > 8 {
        return Err(GpuError::Unsupported(format!(
            "density volume sampling of {} strands of 2^{} segments (at least 1 strand, at \
             most 2^8 segments)",
            sampling.strands_sampled, sampling.segments_log2
        )));
    }
    Ok(())
}

/// One character's volume: its sampling and cells, whether a frame has yet to build it,
/// whether its hair moved since, and the box (object units) and frame of its last build.
struct VolumeEntry {
    id: CharacterId,
    sampling: VolumeSampling,
    cells: Buffer,
    pending: bool,
    stale: bool,
    built: Option<(Vec3, Vec3)>,
    built_frame: u64,
}

/// Every character's density volume, by character slot.
#[derive(Default)]
pub struct DensityVolumes {
    entries: Vec<Option<VolumeEntry>>,
}

impl DensityVolumes {
    fn entry(&self, id: CharacterId) -> Option<&VolumeEntry> {
        self.entries
            .get(id.slot() as usize)?
            .as_ref()
            .filter(|e| e.id == id)
    }

    /// Build `id`'s volume with `sampling` in the next frame (its buffer reused when the size
    /// is unchanged); returns a replaced buffer, which frames in flight may still use.
    pub fn request(
        &mut self,
        ctx: &Arc<Context>,
        id: CharacterId,
        sampling: VolumeSampling,
    ) -> GpuResult<Option<Buffer>> {
        check_sampling(&sampling)?;
        let d = sampling.dims;
        let bytes = mask_offset(d) + occupancy_words(d) as u64 * 4;
        let slot = id.slot() as usize;
        if let Some(Some(e)) = self.entries.get_mut(slot)
            && e.id == id
            && e.cells.size == bytes
        {
            e.sampling = sampling;
            e.pending = true;
            return Ok(None);
        }
        let usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
            | vk::BufferUsageFlags::TRANSFER_DST
            | vk::BufferUsageFlags::TRANSFER_SRC;
        let cells = Buffer::new(ctx, &BufferDesc::new("density volume", bytes, usage))?;
        if self.entries.len() <= slot {
            self.entries.resize_with(slot + 1, || None);
        }
        let old = self.entries[slot].take().map(|e| e.cells);
        self.entries[slot] = Some(VolumeEntry {
            id,
            sampling,
            cells,
            pending: true,
            stale: false,
            built: None,
            built_frame: 0,
        });
        Ok(old)
    }

    /// Request `id`'s volume with `sampling` unless it has one (of any sampling).
    pub fn ensure(
        &mut self,
        ctx: &Arc<Context>,
        id: CharacterId,
        sampling: VolumeSampling,
    ) -> GpuResult<Option<Buffer>> {
        match self.entry(id) {
            Some(_) => Ok(None),
            None => self.request(ctx, id, sampling),
        }
    }

    /// Forget `id`'s volume; returns its buffer, which frames in flight may still use.
    pub fn remove(&mut self, id: CharacterId) -> Option<Buffer> {
        self.entry(id)?;
        self.entries[id.slot() as usize].take().map(|e| e.cells)
    }

    /// The character in `slot` changed pose this frame: its volume (if any) is stale.
    pub fn mark_stale(&mut self, slot: usize) {
        if let Some(Some(e)) = self.entries.get_mut(slot) {
            e.stale = true;
        }
    }

    /// The jobs of this frame's builds, from its `records`, now marked built: every volume
    /// waiting for its first build or a request, and up to `rebuilds` stale ones, the longest
    /// stale first. Returns the jobs, their character slots and the most bundles among them.
    pub fn take_jobs(
        &mut self,
        records: &[CharacterRecord],
        rebuilds: u32,
        frame: u64,
    ) -> (Vec<DensityJob>, Vec<usize>, u32) {
        let mut stale: Vec<(u64, usize)> = self
            .entries
            .iter()
            .enumerate()
            .filter_map(|(s, e)| e.as_ref().map(|e| (s, e)))
            .filter(|(_, e)| e.stale && !e.pending)
            .map(|(s, e)| (e.built_frame, s))
            .collect();
        stale.sort_unstable();
        for &(_, s) in stale.iter().take(rebuilds as usize) {
            if let Some(e) = self.entries[s].as_mut() {
                e.pending = true;
            }
        }
        let (mut jobs, mut slots, mut most) = (Vec::new(), Vec::new(), 0);
        for (s, e) in self.entries.iter_mut().enumerate() {
            let Some(e) = e.as_mut().filter(|e| e.pending) else {
                continue;
            };
            let Some(r) = records.get(s) else {
                continue;
            };
            e.pending = false;
            e.stale = false;
            e.built_frame = frame;
            let grid = volume_box(&r.mesh);
            e.built = Some(grid);
            jobs.push(job(e, r, grid));
            slots.push(s);
            most = most.max(r.bundle_count);
        }
        (jobs, slots, most)
    }

    /// The cells buffers of the volumes of `slots`.
    pub fn buffers(&self, slots: &[usize]) -> Vec<&Buffer> {
        slots
            .iter()
            .filter_map(|&s| self.entries[s].as_ref().map(|e| &e.cells))
            .collect()
    }

    /// Fill the volume fields of `records` (after [`Self::take_jobs`]): every character
    /// whose volume is built gets its grid, occlusion where `tier` asks for it, and its tier
    /// weight from `weights` (by slot; volume-only at 1). Returns what the tier draws.
    pub fn fill_records(
        &self,
        records: &mut [CharacterRecord],
        tier: &VolumeTier,
        weights: &[f32],
    ) -> TierDraw {
        let mut draw = TierDraw::default();
        for (slot, (r, e)) in records.iter_mut().zip(&self.entries).enumerate() {
            let Some((e, (lo, hi))) = e.as_ref().and_then(|e| Some((e, e.built?))) else {
                continue;
            };
            let dims = e.sampling.dims;
            let cell = cell_size(lo, hi, dims);
            let model = Mat4::from_cols_array_2d(&r.model);
            let to_grid = Mat4::from_scale(cell.recip()) * Mat4::from_translation(-lo);
            r.world_to_volume = (to_grid * model.inverse()).to_cols_array_2d();
            let address = e.cells.device_address();
            let packed = dims.x | dims.y << VOLUME_DIMS_BITS | dims.z << (2 * VOLUME_DIMS_BITS);
            let flags = VOLUME_BUILT
                | if tier.occlusion { VOLUME_OCCLUSION } else { 0 }
                | if tier.skip_empty {
                    VOLUME_SKIP_EMPTY
                } else {
                    0
                };
            r.volume = [address[0], address[1], packed, flags];
            let weight = weights.get(slot).copied().unwrap_or(0.0);
            let width = mean_strand_width(&r.style);
            r.volume_shading = [
                width / (VOLUME_FIXED * cell.x * cell.y * cell.z),
                cell.element_sum() / 3.0,
                weight,
                0.0,
            ];
            if weight >= 1.0 {
                r.flags |= CHARACTER_VOLUME_ONLY;
            }
            if weight > 0.0 && r.flags & CHARACTER_VISIBLE != 0 {
                draw.add(slot, weight >= 1.0);
            }
        }
        draw
    }

    /// `id`'s volume as last built (call after its frame completed).
    pub fn read(&self, ctx: &Arc<Context>, id: CharacterId) -> GpuResult<DensityVolume> {
        let (sampling, (lo, hi), bytes) = self.read_built(ctx, id)?;
        let cells: Vec<VolumeCell> = bytemuck::pod_collect_to_vec(&bytes);
        let mut volume = DensityVolume::empty(lo, hi, sampling.dims);
        let per_volume = 1.0 / (VOLUME_FIXED * volume.cell.x * volume.cell.y * volume.cell.z);
        let n = volume.density.len();
        for (i, c) in cells[..n].iter().enumerate() {
            volume.density[i] = c.len as f32 * per_volume;
            let flow = c.flow.map(|f| f as i32 as f32);
            volume.flow[i] = Vec3::from(flow) * per_volume;
        }
        volume.outside = cells[n].len as f32 / VOLUME_FIXED;
        Ok(volume)
    }

    /// Character `id`'s occupancy mask as the GPU wrote it (the twin of
    /// [`DensityVolume::occupancy`]), after the frames in flight (the caller waits for them).
    pub fn read_occupancy(&self, ctx: &Arc<Context>, id: CharacterId) -> GpuResult<Vec<u32>> {
        let (sampling, _, bytes) = self.read_built(ctx, id)?;
        let d = sampling.dims;
        let words: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let first = (mask_offset(d) / 4) as usize;
        Ok(words[first..first + occupancy_words(d) as usize].to_vec())
    }

    /// `id`'s sampling, box and whole buffer (cells, the one after them, the occupancy mask)
    /// as last built.
    fn read_built(
        &self,
        ctx: &Arc<Context>,
        id: CharacterId,
    ) -> GpuResult<(VolumeSampling, (Vec3, Vec3), Vec<u8>)> {
        let e = self
            .entry(id)
            .ok_or_else(|| GpuError::Unsupported("no density volume was requested".into()))?;
        let Some(built) = e.built.filter(|_| !e.pending) else {
            return Err(GpuError::Unsupported(
                "the density volume has not been built yet (render a frame first)".into(),
            ));
        };
        let bytes = crate::render::core::readback::read_device_buffer(ctx, &e.cells, e.cells.size)?;
        Ok((e.sampling, built, bytes))
    }
}

/// A strand's width averaged along it (`strand_width * mix(1, tip_width_ratio, s^p)` over
/// `s` in [0, 1]).
pub fn mean_strand_width(style: &crate::model::style::HairStyle) -> f32 {
    let taper = 1.0 / (style.taper_power.max(0.0) + 1.0);
    style.strand_width * (1.0 + (style.tip_width_ratio - 1.0) * taper)
}

/// The job of `e` for the character of `r`, over the box `lo..hi`.
fn job(e: &VolumeEntry, r: &CharacterRecord, (lo, hi): (Vec3, Vec3)) -> DensityJob {
    let dims = e.sampling.dims;
    let cell = cell_size(lo, hi, dims);
    let v4 = |v: Vec3| v.extend(0.0).to_array();
    DensityJob {
        cells: e.cells.device_address(),
        _pad: [0; 2],
        origin: v4(lo),
        cell: v4(cell),
        dims: [dims.x, dims.y, dims.z, e.id.slot()],
        bundles: [
            r.first_bundle,
            r.bundle_count,
            e.sampling.strands_sampled,
            e.sampling.segments_log2,
        ],
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A frame's tier draw counts each character once, as alone or blended, and its instance
    /// range reaches one past the last slot drawn (the volume hair pass's instance count).
    #[test]
    fn tier_draw_counts_and_spans_its_characters() {
        let mut d = TierDraw::default();
        d.add(4, true);
        d.add(1, false);
        d.add(9, true);
        assert_eq!(
            d,
            TierDraw {
                slots: 10,
                alone: 2,
                blended: 1
            }
        );
    }

    /// The mean width is the taper's integral: checked against a midpoint sum of
    /// `strand_width * mix(1, tip_width_ratio, s^p)` (returning a constant survived the
    /// 2026-12-06 sample).
    #[test]
    fn mean_strand_width_integrates_the_taper() {
        let style = crate::model::style::HairStyle {
            strand_width: 0.002,
            tip_width_ratio: 0.25,
            taper_power: 2.0,
            ..Default::default()
        };
        let n = 10_000;
        let (w, tip, p) = (0.002f64, 0.25f64, 2.0f64);
        let sum: f64 = (0..n)
            .map(|i| {
                let s = (i as f64 + 0.5) / n as f64;
                w * (1.0 + (tip - 1.0) * s.powf(p))
            })
            .sum();
        let numeric = sum / n as f64;
        // 0.002 * (1 - 0.75 / 3) = 0.0015; the midpoint sum's error is below 1e-9 of it.
        let relative = (mean_strand_width(&style) as f64 - numeric).abs() / numeric;
        assert!(relative < 1e-5, "{relative}");
        assert!((numeric - 0.0015).abs() < 1e-9);
    }

    /// A character's hair spans its bounding sphere's projected diameter: `2 r / (2 d tan)`
    /// of the screen height in perspective, `2 r / view height` of it in orthographic views.
    #[test]
    fn hair_pixels_is_the_projected_sphere() {
        let mut r: CharacterRecord = bytemuck::Zeroable::zeroed();
        r.model = Mat4::IDENTITY.to_cols_array_2d();
        r.mesh.pos_extent = [4.0, 0.0, 0.0, 0.0];
        r.model_scale = 1.0;
        let mut block: FrameBlock = bytemuck::Zeroable::zeroed();
        // Sphere at (2, 0, 0), radius 2, eye 10 away, 720 px high, inv_tan 1.
        (block.eye, block.pixels_high) = ([2.0, 0.0, 10.0], 720.0);
        block.cot_half_fov = 1.0;
        assert!((hair_pixels(&r, &block) - 144.0).abs() < 1e-3);
        (block.eye, block.pixels_high) = ([2.0, 0.0, 1.5], 720.0);
        assert_eq!(hair_pixels(&r, &block), f32::INFINITY);
        // Orthographic (inv_tan 0): a 4-unit-high view.
        block.cot_half_fov = 0.0;
        block.lod.ortho_height = 4.0;
        assert!((hair_pixels(&r, &block) - 720.0).abs() < 1e-3);
    }

    #[test]
    fn the_tier_weight_falls_across_the_band() {
        let tier = VolumeTier::on();
        let (far, near) = tier.far.unwrap();
        assert_eq!(tier.weight(far - 1.0), 1.0);
        assert_eq!(tier.weight(near + 1.0), 0.0);
        assert!((tier.weight(0.5 * (far + near)) - 0.5).abs() < 1e-6);
        assert_eq!(VolumeTier::OFF.weight(0.0), 0.0);
        // Either half of the tier needs volumes; neither, none (the fourth mutation sample's
        // survivor was `enabled` always true).
        assert!(!VolumeTier::OFF.enabled() && tier.enabled());
        let occlusion_only = VolumeTier {
            occlusion: true,
            ..VolumeTier::OFF
        };
        let far_only = VolumeTier {
            occlusion: false,
            ..tier
        };
        assert!(occlusion_only.enabled() && far_only.enabled());
        let bad = VolumeTier {
            far: Some((50.0, 10.0)),
            ..tier
        };
        assert!(bad.validate().is_err());
        assert!(tier.validate().is_ok());
    }
}
