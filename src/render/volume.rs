//! Strand density volumes on the GPU (`passes::density_volume`, the twin of
//! `reference::volume`): a volume per character that asked for one, built in the frame after
//! the request (after that frame's texture rebuilds), read back on demand.

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::crowd::CharacterId;
use super::shared::{CharacterRecord, DensityJob, VOLUME_FIXED};
use crate::reference::volume::{DensityVolume, VolumeSampling, cell_size, volume_box};
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult};

/// Most cells one density volume may have (128^3).
pub const MAX_VOLUME_CELLS: u32 = 1 << 21;

/// One character's volume: its sampling and cells, whether a frame has yet to build it, and
/// the box (object units) of its last build.
struct VolumeEntry {
    id: CharacterId,
    sampling: VolumeSampling,
    cells: Buffer,
    pending: bool,
    built: Option<(Vec3, Vec3)>,
}

/// Every requested density volume.
#[derive(Default)]
pub struct DensityVolumes {
    entries: Vec<VolumeEntry>,
}

impl DensityVolumes {
    /// Build `id`'s volume with `sampling` in the next frame (its buffer reused when the size
    /// is unchanged); returns a replaced buffer, which frames in flight may still use.
    pub fn request(
        &mut self,
        ctx: &Arc<Context>,
        id: CharacterId,
        sampling: VolumeSampling,
    ) -> GpuResult<Option<Buffer>> {
        let d = sampling.dims;
        let cells = d.x as u64 * d.y as u64 * d.z as u64;
        if d.min_element() == 0 || cells > MAX_VOLUME_CELLS as u64 {
            return Err(GpuError::Unsupported(format!(
                "density volume of {}x{}x{} cells (1 to {MAX_VOLUME_CELLS} cells)",
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
        let bytes = (cells + 1) * 4;
        if let Some(e) = self.entries.iter_mut().find(|e| e.id == id)
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
        let old = self.remove(id);
        self.entries.push(VolumeEntry {
            id,
            sampling,
            cells,
            pending: true,
            built: None,
        });
        Ok(old)
    }

    /// Forget `id`'s volume; returns its buffer, which frames in flight may still use.
    pub fn remove(&mut self, id: CharacterId) -> Option<Buffer> {
        let i = self.entries.iter().position(|e| e.id == id)?;
        Some(self.entries.swap_remove(i).cells)
    }

    /// The jobs of the volumes waiting to be built, from this frame's `records`, now marked
    /// built; with the entries they belong to and the most bundles among them.
    pub fn take_jobs(&mut self, records: &[CharacterRecord]) -> (Vec<DensityJob>, Vec<usize>, u32) {
        let mut jobs = Vec::new();
        let mut entries = Vec::new();
        let mut most = 0;
        for (i, e) in self.entries.iter_mut().enumerate() {
            let Some(r) = records.get(e.id.slot() as usize).filter(|_| e.pending) else {
                continue;
            };
            e.pending = false;
            let grid = volume_box(&r.mesh);
            e.built = Some(grid);
            jobs.push(job(e, r, grid));
            entries.push(i);
            most = most.max(r.bundle_count);
        }
        (jobs, entries, most)
    }

    /// The cells buffers of `entries`.
    pub fn buffers(&self, entries: &[usize]) -> Vec<&Buffer> {
        entries.iter().map(|&i| &self.entries[i].cells).collect()
    }

    /// `id`'s volume as last built (call after its frame completed).
    pub fn read(&self, ctx: &Arc<Context>, id: CharacterId) -> GpuResult<DensityVolume> {
        let e = self
            .entries
            .iter()
            .find(|e| e.id == id)
            .ok_or_else(|| GpuError::Unsupported("no density volume was requested".into()))?;
        let Some((lo, hi)) = e.built.filter(|_| !e.pending) else {
            return Err(GpuError::Unsupported(
                "the density volume has not been built yet (render a frame first)".into(),
            ));
        };
        let bytes = super::debug::read_device_buffer(ctx, &e.cells, e.cells.size)?;
        let fixed: Vec<u32> = bytemuck::pod_collect_to_vec(&bytes);
        let mut volume = DensityVolume::empty(lo, hi, e.sampling.dims);
        let cell_volume = volume.cell.x * volume.cell.y * volume.cell.z;
        let n = volume.density.len();
        for (d, f) in volume.density.iter_mut().zip(&fixed[..n]) {
            *d = *f as f32 / VOLUME_FIXED / cell_volume;
        }
        volume.outside = fixed[n] as f32 / VOLUME_FIXED;
        Ok(volume)
    }
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
