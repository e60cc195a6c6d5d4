//! One character's hair on the GPU: the five textures, bundle table, style, root samples,
//! per-bundle counts and the generated-vertex buffer, bound as descriptor set 0.

use std::sync::Arc;

use ash::vk;
use bytemuck::{Pod, Zeroable};
use glam::Mat4;

use crate::bake::blue_noise::{quad_samples, triangle_samples};
use crate::bake::{BakedHairMesh, MeshInfo};
use crate::model::style::HairStyle;
use crate::reference::generate::strands_in_bundle;
use crate::vk::descriptor::{Binding, DescriptorSet};
use crate::vk::image::Sampler;
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult, Image, ImageDesc};

/// Largest vertex level on the GPU paths (`2^6 = 64` segments = `MAX_SEGMENTS` = 2 vertices
/// per thread of a 32-thread workgroup in strand_build.glsl).
pub const MAX_VERTS_LOG2: u32 = 6;

/// Bytes of the `Indirect` block of bindings.glsl.
pub const INDIRECT_BYTES: u64 = 48;

/// Bytes of one generated vertex (`HairVertex` in bindings.glsl).
pub const HAIR_VERTEX_BYTES: u64 = 32;

#[repr(C)]
#[derive(Clone, Copy, Pod, Zeroable)]
struct MeshAndStyle {
    mesh: MeshInfo,
    style: HairStyle,
}

/// What to generate for a character.
#[derive(Clone, Copy, Debug)]
pub struct StrandParams {
    /// Strands per (average) bundle.
    pub strands_per_bundle: u32,
    /// Vertices per strand are `2^verts_log2 + 1`.
    pub verts_log2: u32,
}

/// GPU resources of one character.
pub struct HairGpu {
    /// Decode constants.
    pub info: MeshInfo,
    /// Object-to-world transform.
    pub model: Mat4,
    /// Generation parameters.
    pub params: StrandParams,
    /// Per-frame uniforms.
    pub frame: Buffer,
    /// Generated vertices (`HairVertex`).
    pub vertices: Buffer,
    /// Indirect dispatch + draw arguments.
    pub indirect: Buffer,
    /// Descriptor set 0.
    pub set: DescriptorSet,
    _keep: Vec<Buffer>,
    _images: Vec<Image>,
}

/// The formats of the five textures, in Table 1 order.
pub const TEXTURE_FORMATS: [vk::Format; 5] = [
    vk::Format::R16G16B16A16_UNORM,
    vk::Format::R16G16_UNORM,
    vk::Format::R16_UNORM,
    vk::Format::R16G16B16A16_SNORM,
    vk::Format::R16G16B16A16_SNORM,
];

impl HairGpu {
    /// Upload `baked` with `style` and allocate buffers for `params`.
    pub fn new(
        ctx: &Arc<Context>,
        sampler: &Sampler,
        baked: &BakedHairMesh,
        style: &HairStyle,
        params: StrandParams,
        model: Mat4,
    ) -> GpuResult<Self> {
        if params.verts_log2 > MAX_VERTS_LOG2 || params.strands_per_bundle == 0 {
            return Err(GpuError::Unsupported(format!(
                "strands per bundle must be >= 1 and verts-log2 <= {MAX_VERTS_LOG2}"
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
        let images: Vec<Image> = baked
            .textures()
            .iter()
            .zip(TEXTURE_FORMATS)
            .map(|(t, format)| {
                let desc = if t.name == "uv-texture" {
                    ImageDesc::new_2d(t.name, format, t.extent[0], t.extent[1])
                } else {
                    ImageDesc::new_3d(t.name, format, t.extent)
                };
                Image::with_data(ctx, &desc, t.bytes)
            })
            .collect::<GpuResult<_>>()?;
        let storage = vk::BufferUsageFlags::STORAGE_BUFFER;
        let mesh = Buffer::with_data(
            ctx,
            "mesh+style",
            storage,
            bytemuck::bytes_of(&MeshAndStyle {
                mesh: baked.info,
                style: *style,
            }),
        )?;
        let bundles = Buffer::with_data(
            ctx,
            "bundles",
            storage,
            bytemuck::cast_slice(&baked.bundles),
        )?;
        let samples: Vec<glam::Vec2> = quad_samples()
            .iter()
            .chain(triangle_samples())
            .copied()
            .collect();
        let samples =
            Buffer::with_data(ctx, "root samples", storage, bytemuck::cast_slice(&samples))?;
        let bundle_count = baked.bundles.len() as u64;
        let counts = Buffer::new(
            ctx,
            &BufferDesc::new("bundle lods", 16 * bundle_count, storage),
        )?;
        let offsets = Buffer::new(
            ctx,
            &BufferDesc::new("bundle offsets", 16 * bundle_count, storage),
        )?;
        let indirect = Buffer::new(
            ctx,
            &BufferDesc::new(
                "indirect",
                INDIRECT_BYTES,
                storage
                    | vk::BufferUsageFlags::INDIRECT_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_SRC
                    | vk::BufferUsageFlags::TRANSFER_DST,
            ),
        )?;
        let max_strands: u64 = baked
            .bundles
            .iter()
            .map(|b| strands_in_bundle(b, style, params.strands_per_bundle) as u64)
            .sum();
        let vertex_bytes = max_strands * ((1u64 << params.verts_log2) + 1) * HAIR_VERTEX_BYTES;
        let vertices = Buffer::new(
            ctx,
            &BufferDesc::new(
                "hair vertices",
                vertex_bytes,
                storage | vk::BufferUsageFlags::TRANSFER_SRC,
            ),
        )?;
        let frame = Buffer::new(
            ctx,
            &BufferDesc::new(
                "frame",
                size_of::<super::frame::FrameParams>() as u64,
                vk::BufferUsageFlags::UNIFORM_BUFFER,
            )
            .host_visible(),
        )?;
        let set = DescriptorSet::new(
            ctx,
            "hair set",
            &[
                Binding::Uniform(&frame),
                Binding::Storage(&mesh),
                Binding::Storage(&bundles),
                Binding::Texture(&images[0], sampler.raw),
                Binding::Texture(&images[1], sampler.raw),
                Binding::Texture(&images[2], sampler.raw),
                Binding::Texture(&images[3], sampler.raw),
                Binding::Texture(&images[4], sampler.raw),
                Binding::Storage(&samples),
                Binding::Storage(&counts),
                Binding::Storage(&offsets),
                Binding::Storage(&indirect),
                Binding::Storage(&vertices),
            ],
        )?;
        Ok(HairGpu {
            info: baked.info,
            model,
            params,
            frame,
            vertices,
            indirect,
            set,
            _keep: vec![mesh, bundles, samples, counts, offsets],
            _images: images,
        })
    }

    /// Number of bundles.
    pub fn bundle_count(&self) -> u32 {
        self.info.bundle_count
    }

    /// The model transform as push-constant data.
    pub fn model_cols(&self) -> [f32; 16] {
        self.model.to_cols_array()
    }
}
