//! GPU working buffers shared by the frames: root samples, per-bundle LoD decisions and prefix
//! sums, scan scratch, indirect arguments + statistics, the compute path's vertex pool, and the
//! Marschner lookup texture.
//! Sized by the crowd's bundle count (grown by half again when too small, never shrunk); the
//! pool is allocated when the compute path is first used. These persist across frames (the
//! static and LHS paths draw the last compute frame's strands with its LoDs and offsets), so
//! they are imported into the frame graph, not created by it.

use std::sync::Arc;

use ash::vk;
use glam::Vec2;

use super::shared::{
    FrameBinding, GenerateArgs, SCAN_BLOCK, SHADING_LUT_HEIGHT, SHADING_LUT_WIDTH,
};
use crate::bake::blue_noise::{MAX_STRANDS_PER_BUNDLE, quad_samples_for, triangle_samples_for};
use crate::vk::{Buffer, BufferDesc, Context, DescriptorSet, GpuResult, Image, ImageDesc, Sampler};

fn storage(ctx: &Arc<Context>, name: &str, bytes: u64) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(name, bytes, vk::BufferUsageFlags::STORAGE_BUFFER),
    )
}

/// The buffers of set 0 that are not the workspace's own.
pub struct FrameBuffers<'a> {
    /// The frame slot's `FrameBlock`.
    pub frame_ubo: &'a Buffer,
    /// The frame slot's character records.
    pub records: &'a Buffer,
    /// The frame slot's prop instances.
    pub prop_instances: &'a Buffer,
    /// The crowd's bundle table, once there are characters.
    pub bundle_table: Option<&'a Buffer>,
    /// The prop meshes, once set.
    pub prop_vertices: Option<&'a Buffer>,
    /// Skinned meshes' rest vertices, once set; the frame slot's skin matrices, skinning jobs
    /// and posed vertices.
    pub skin: [Option<&'a Buffer>; 4],
    /// The frame slot's root probe output.
    pub root_probe: &'a Buffer,
    /// The light's maps.
    pub shadow: &'a super::targets::ShadowMaps,
    /// The temporal history this frame reads and writes, once made.
    pub history: Option<(&'a Buffer, &'a Buffer)>,
}

/// One level of the scan: `count` elements at `input` (level 0: the bundles), block sums at
/// `sums` in the scratch buffer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct ScanLevel {
    /// Elements scanned.
    pub count: u32,
    /// Offset of the elements in the scratch buffer (level > 0).
    pub input: u32,
    /// Offset of the block sums in the scratch buffer.
    pub sums: u32,
}

/// The levels that scan `bundles` elements (up to one block sum at the top, the grand
/// total), and the scratch elements they need.
pub fn scan_plan(bundles: u32) -> (Vec<ScanLevel>, u32) {
    let mut levels = Vec::new();
    let (mut count, mut input, mut next) = (bundles.max(1), 0, 0);
    loop {
        let blocks = count.div_ceil(SCAN_BLOCK);
        levels.push(ScanLevel {
            count,
            input,
            sums: next,
        });
        input = next;
        next += blocks;
        if blocks == 1 {
            return (levels, next);
        }
        count = blocks;
    }
}

/// The working buffers as the frame graph imports them.
pub struct WorkBuffers<'a> {
    /// `GenerateArgs`.
    pub args: &'a Buffer,
    /// The vertex pool (or its placeholder).
    pub pool: &'a Buffer,
    /// Bundle LoDs.
    pub lods: &'a Buffer,
    /// Bundle offsets.
    pub offsets: &'a Buffer,
    /// Scan scratch.
    pub scan: &'a Buffer,
}

/// The working buffers.
pub struct Workspace {
    ctx: Arc<Context>,
    root_samples: Buffer,
    /// Samples of each set in `root_samples` (a tier of `bake::blue_noise`).
    root_sample_count: usize,
    lods: Buffer,
    offsets: Buffer,
    scan: Buffer,
    /// `GenerateArgs`: indirect arguments and statistics.
    pub args: Buffer,
    /// The compute path's vertex pool, once used.
    pub pool: Option<Buffer>,
    placeholder: Buffer,
    bundles: u32,
    /// The Marschner lookup texture (`shade::lut`), built at start-up.
    shading_lut: Image,
    lut_sampler: Sampler,
}

/// The root samples of bundles of up to `strands` strands, as the shaders read them
/// (`strand_eval.glsl`): the quad set from 0, the triangle set from `MAX_STRANDS_PER_BUNDLE`,
/// each as large as the sample tier holding `strands` (the rest zero, never read).
fn root_samples(ctx: &Arc<Context>, strands: usize) -> GpuResult<Buffer> {
    let mut samples = vec![Vec2::ZERO; 2 * MAX_STRANDS_PER_BUNDLE];
    let (quad, triangle) = (quad_samples_for(strands), triangle_samples_for(strands));
    samples[..quad.len()].copy_from_slice(quad);
    samples[MAX_STRANDS_PER_BUNDLE..][..triangle.len()].copy_from_slice(triangle);
    Buffer::with_data(
        ctx,
        "root samples",
        vk::BufferUsageFlags::STORAGE_BUFFER,
        bytemuck::cast_slice(&samples),
    )
}

/// Buffers replaced by a resize, to retire with the current frame.
pub type ReplacedBuffers = [Buffer; 3];

impl Workspace {
    /// Minimal buffers (nothing to draw yet).
    pub fn new(ctx: &Arc<Context>) -> GpuResult<Self> {
        Ok(Workspace {
            ctx: ctx.clone(),
            root_samples: root_samples(ctx, 1)?,
            root_sample_count: quad_samples_for(1).len(),
            lods: storage(ctx, "bundle lods", 16)?,
            offsets: storage(ctx, "bundle offsets", 16)?,
            scan: storage(ctx, "scan scratch", 16)?,
            args: Buffer::new(
                ctx,
                &BufferDesc::new(
                    "generate args",
                    size_of::<GenerateArgs>() as u64,
                    vk::BufferUsageFlags::STORAGE_BUFFER
                        | vk::BufferUsageFlags::INDIRECT_BUFFER
                        | vk::BufferUsageFlags::TRANSFER_SRC
                        | vk::BufferUsageFlags::TRANSFER_DST,
                ),
            )?,
            pool: None,
            placeholder: storage(ctx, "vertex pool (unused)", 16)?,
            bundles: 0,
            shading_lut: Image::with_data(
                ctx,
                &ImageDesc::new_2d(
                    "shading lut",
                    vk::Format::R16G16B16A16_UNORM,
                    SHADING_LUT_WIDTH,
                    SHADING_LUT_HEIGHT,
                ),
                bytemuck::cast_slice(crate::shade::lut::shading_lut()),
            )?,
            lut_sampler: Sampler::linear_clamp(ctx)?,
        })
    }

    /// Make room for `bundles` bundles; returns the replaced buffers, which frames in flight
    /// may still use.
    pub fn grow(&mut self, bundles: u32) -> GpuResult<Option<ReplacedBuffers>> {
        if bundles <= self.bundles {
            return Ok(None);
        }
        let n = bundles.max(self.bundles + self.bundles / 2);
        let (_, scratch) = scan_plan(n);
        let lods = storage(&self.ctx, "bundle lods", 16 * n as u64)?;
        let offsets = storage(&self.ctx, "bundle offsets", 16 * n as u64)?;
        let scan = storage(&self.ctx, "scan scratch", 16 * scratch as u64)?;
        self.bundles = n;
        Ok(Some([
            std::mem::replace(&mut self.lods, lods),
            std::mem::replace(&mut self.offsets, offsets),
            std::mem::replace(&mut self.scan, scan),
        ]))
    }

    /// Hold the root samples of bundles of up to `strands` strands; returns the replaced buffer,
    /// which frames in flight may still use.
    pub fn ensure_root_samples(&mut self, strands: u32) -> GpuResult<Option<Buffer>> {
        if strands as usize <= self.root_sample_count {
            return Ok(None);
        }
        let buffer = root_samples(&self.ctx, strands as usize)?;
        self.root_sample_count = quad_samples_for(strands as usize).len();
        Ok(Some(std::mem::replace(&mut self.root_samples, buffer)))
    }

    /// Allocate the vertex pool of `bytes` if it is not there yet.
    pub fn ensure_pool(&mut self, bytes: u64) -> GpuResult<()> {
        if self.pool.is_none() {
            self.pool = Some(Buffer::new(
                &self.ctx,
                &BufferDesc::new(
                    "vertex pool",
                    bytes,
                    vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_SRC,
                ),
            )?);
        }
        Ok(())
    }

    /// The buffers the frame graph imports (the placeholder stands in for a pool not yet
    /// allocated).
    pub fn buffers(&self) -> WorkBuffers<'_> {
        WorkBuffers {
            args: &self.args,
            pool: self.pool.as_ref().unwrap_or(&self.placeholder),
            lods: &self.lods,
            offsets: &self.offsets,
            scan: &self.scan,
        }
    }

    /// Point every binding of a frame's set 0 at its buffer, except the frame graph's
    /// transient buffers (it binds them when it runs).
    pub fn write_set(&self, set: &DescriptorSet, frame: FrameBuffers) -> GpuResult<()> {
        let bundles = frame.bundle_table.unwrap_or(&self.placeholder);
        let prop_vertices = frame.prop_vertices.unwrap_or(&self.placeholder);
        let pool = self.pool.as_ref().unwrap_or(&self.placeholder);
        for (b, _) in FrameBinding::ALL {
            let buffer = match b {
                FrameBinding::Frame => frame.frame_ubo,
                FrameBinding::Characters => frame.records,
                FrameBinding::Bundles => bundles,
                FrameBinding::RootSamples => &self.root_samples,
                FrameBinding::BundleLods => &self.lods,
                FrameBinding::BundleOffsets => &self.offsets,
                FrameBinding::ScanScratch => &self.scan,
                FrameBinding::Args => &self.args,
                FrameBinding::Vertices => pool,
                FrameBinding::PropVertices => prop_vertices,
                FrameBinding::PropInstances => frame.prop_instances,
                FrameBinding::SkinRest => frame.skin[0].unwrap_or(&self.placeholder),
                FrameBinding::SkinMatrices => frame.skin[1].unwrap_or(&self.placeholder),
                FrameBinding::SkinJobs => frame.skin[2].unwrap_or(&self.placeholder),
                FrameBinding::SkinnedVertices => frame.skin[3].unwrap_or(&self.placeholder),
                FrameBinding::RootProbe => frame.root_probe,
                FrameBinding::OitNodes
                | FrameBinding::OitTail
                | FrameBinding::PeelDepth
                | FrameBinding::PeelAccum
                | FrameBinding::SoftSegments
                | FrameBinding::SoftTiles
                | FrameBinding::SoftEntries
                | FrameBinding::SoftDepth
                | FrameBinding::SoftShadowDepth
                | FrameBinding::SoftShadowLayers
                | FrameBinding::Visibility
                | FrameBinding::Motion
                | FrameBinding::FrameColor
                | FrameBinding::VertexMotion
                | FrameBinding::SegmentMotion => continue,
                FrameBinding::HistoryIn => frame.history.map_or(&self.placeholder, |h| h.0),
                FrameBinding::HistoryOut => frame.history.map_or(&self.placeholder, |h| h.1),
                FrameBinding::ShadowHairDepth
                | FrameBinding::ShadowPropDepth
                | FrameBinding::ShadowLayers => {
                    let maps = frame.shadow;
                    let image = match b {
                        FrameBinding::ShadowHairDepth => &maps.hair_depth,
                        FrameBinding::ShadowPropDepth => &maps.prop_depth,
                        _ => &maps.layers,
                    };
                    set.write_image(b as u32, 0, image, &maps.sampler)?;
                    continue;
                }
                FrameBinding::ShadingLut => {
                    set.write_image(b as u32, 0, &self.shading_lut, &self.lut_sampler)?;
                    continue;
                }
            };
            set.write_buffer(b as u32, buffer)?;
        }
        Ok(())
    }
}
