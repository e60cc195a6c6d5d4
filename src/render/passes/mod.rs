//! One file per pass. Each pass owns its pipelines and records itself with `record`, naming
//! what it reads and writes.

pub mod compute_generate;
pub mod hair_mesh_update;
pub mod lhs_skin;
pub mod props;
pub mod scalp;
pub mod shadow;
pub mod soft_raster;
pub mod strands;
pub mod transparency;

use std::sync::Arc;

use super::RenderPath;
use super::shared::GenerateArgs;
use super::targets::{COLOR_FORMAT, DEPTH_FORMAT, RenderTargets};
use crate::vk::{
    Access, Attachment, Buffer, CommandRecorder, Context, DescriptorSet, GpuResult,
    MeshPrimitivesQuery, PipelineLayout, Profiler,
    shader::{ShaderOptions, compile},
};
use compute_generate::{ComputeGenerate, GenerateView};
use props::{PropDraw, PropPass};
use scalp::ScalpPass;
use shadow::{ShadowDraw, ShadowPass};
use strands::StrandDraw;
use transparency::{TransparencyPass, TransparentDraw};

/// The two descriptor sets every pass binds: set 0 (frame and crowd tables) and set 1 (the
/// bindless textures).
#[derive(Clone, Copy)]
pub struct PassSets<'a> {
    /// Set 0.
    pub frame: &'a DescriptorSet,
    /// Set 1.
    pub textures: &'a DescriptorSet,
}

impl<'a> PassSets<'a> {
    /// As a slice for binding.
    pub fn both(&self) -> [&'a DescriptorSet; 2] {
        [self.frame, self.textures]
    }
}

/// Compile options of every hair shader: the generated `shared.glsl` and the task workgroup
/// width.
pub fn shader_options(task_bundles: u32) -> ShaderOptions {
    ShaderOptions::default()
        .include("shared.glsl", super::shared::glsl_header())
        .define("TASK_BUNDLES", task_bundles)
}

/// Formats and sample count of the targets the graphics passes draw into.
#[derive(Clone, Copy, Debug)]
pub struct TargetFormats {
    /// Colour format.
    pub color: ash::vk::Format,
    /// Depth format.
    pub depth: ash::vk::Format,
    /// Samples per pixel.
    pub samples: u32,
}

impl TargetFormats {
    /// An opaque, depth-tested graphics pipeline description for these targets.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        crate::vk::GraphicsDesc::new(name, self.color, self.depth).samples(self.samples)
    }
}

/// What a graphics pipeline draws into.
#[derive(Clone, Copy, Debug)]
pub enum DrawTarget {
    /// The camera view's colour and depth.
    Camera(TargetFormats),
    /// One of the light's depth maps: depth only, no fragment shader.
    ShadowDepth,
    /// The deep opacity layers: colour only, additive, no depth.
    ShadowOpacity,
    /// K-buffer insert: the camera's depth (tested, not written), no colour; fragments go to
    /// the per-pixel node buffers.
    OitInsert(TargetFormats),
    /// Depth peeling, first pass of a layer: depth only.
    PeelDepth,
    /// Depth peeling, second pass of a layer: depth test `EQUAL`; fragments go to the
    /// accumulation buffer.
    PeelColor,
}

impl DrawTarget {
    /// The pipeline description (formats, depth, blending) for this target.
    pub fn graphics_desc<'a>(&self, name: &'a str) -> crate::vk::GraphicsDesc<'a> {
        use crate::vk::{BlendMode, DepthMode, GraphicsDesc};
        use ash::vk::Format;
        match self {
            DrawTarget::Camera(t) => t.graphics_desc(name),
            DrawTarget::ShadowDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::ShadowOpacity => GraphicsDesc::new(
                name,
                super::targets::SHADOW_LAYERS_FORMAT,
                Format::UNDEFINED,
            )
            .depth(DepthMode::Off)
            .blend(BlendMode::Additive),
            DrawTarget::OitInsert(t) => GraphicsDesc::new(name, Format::UNDEFINED, t.depth)
                .samples(t.samples)
                .depth(DepthMode::TestOnly),
            DrawTarget::PeelDepth => GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT),
            DrawTarget::PeelColor => {
                GraphicsDesc::new(name, Format::UNDEFINED, DEPTH_FORMAT).depth(DepthMode::Equal)
            }
        }
    }

    /// The fragment shader strands drawn into this target use (`None`: depth only).
    pub fn strand_fragment_shader(&self) -> Option<&'static str> {
        match self {
            DrawTarget::Camera(_) => Some("strands.frag"),
            DrawTarget::ShadowDepth => None,
            DrawTarget::ShadowOpacity => Some("shadow.frag"),
            DrawTarget::OitInsert(_) => Some("oit.frag"),
            DrawTarget::PeelDepth => Some("peel_depth.frag"),
            DrawTarget::PeelColor => Some("peel_color.frag"),
        }
    }
}

/// A vertex (+ fragment, where given) pipeline drawing into `target`.
pub fn vertex_pipeline(
    ctx: &Arc<Context>,
    layout: &Arc<PipelineLayout>,
    name: &str,
    shaders: (&str, Option<&str>),
    target: DrawTarget,
) -> GpuResult<crate::vk::Pipeline> {
    let opts = shader_options(1);
    let v = compile(shaders.0, &opts)?;
    let f = shaders.1.map(|f| compile(f, &opts)).transpose()?;
    let mut desc = target
        .graphics_desc(name)
        .stage(ash::vk::ShaderStageFlags::VERTEX, &v);
    if let Some(f) = &f {
        desc = desc.stage(ash::vk::ShaderStageFlags::FRAGMENT, f);
    }
    crate::vk::Pipeline::graphics(ctx, layout, &desc)
}

/// A compute pipeline over its own set 0 of `bindings` storage buffers (passes outside the
/// frame's sets: the hair mesh update, LHS skinning): the set layout and the pipeline.
pub fn own_set_compute(
    ctx: &Arc<Context>,
    name: &str,
    shader: &str,
    bindings: impl IntoIterator<Item = u32>,
) -> GpuResult<(Arc<crate::vk::DescriptorSetLayout>, crate::vk::Pipeline)> {
    let bindings: Vec<crate::vk::BindingDesc> = bindings
        .into_iter()
        .map(|b| crate::vk::BindingDesc::single(b, crate::vk::DescriptorKind::StorageBuffer))
        .collect();
    let set_layout = crate::vk::DescriptorSetLayout::new(ctx, &bindings)?;
    let layout = PipelineLayout::new(ctx, std::slice::from_ref(&set_layout))?;
    let spirv = compile(shader, &shader_options(1))?;
    let pipeline = crate::vk::Pipeline::compute(ctx, name, &layout, &spirv)?;
    Ok((set_layout, pipeline))
}

/// `(x, y)` workgroup counts for `groups` workgroups with at most `DISPATCH_ROW` per row.
pub fn dispatch_2d(groups: u32) -> (u32, u32) {
    let row = super::shared::DISPATCH_ROW;
    (groups.min(row), groups.div_ceil(row))
}

/// What one frame's passes read and write.
pub struct FrameInputs<'a> {
    /// Descriptor sets.
    pub sets: PassSets<'a>,
    /// Bundles of all characters.
    pub bundles: u32,
    /// Generation path.
    pub path: RenderPath,
    /// `GenerateArgs` (cleared here, then written by generation).
    pub args: &'a Buffer,
    /// Colour and depth targets.
    pub targets: &'a mut RenderTargets,
    /// Clear colour, or `None` to draw over the previous contents.
    pub clear: Option<[f32; 4]>,
    /// Props to draw (bodies, ground).
    pub props: &'a [PropDraw],
    /// The light's passes.
    pub shadow: ShadowInputs<'a>,
    /// How the strands are composited.
    pub transparency: super::Transparency,
    /// The transparent modes' per-pixel buffers (sized for this frame's mode).
    pub transparency_buffers: &'a mut super::transparency::TransparencyBuffers,
    /// How strands are rasterized.
    pub raster: super::soft::StrandRaster,
    /// The software rasterizer's buffers (sized for this frame when it is used).
    pub soft_buffers: &'a super::soft::SoftBuffers,
    /// k-buffer nodes per pixel of this frame (the OIT budget, or the software
    /// rasterizer's K in opaque frames).
    pub kbuffer_budget: u32,
}

/// What the light's passes need.
pub struct ShadowInputs<'a> {
    /// Shadow mode of this frame; `None` when off (or nothing to shadow).
    pub mode: Option<super::shadow::ShadowMode>,
    /// Set 0 with the light's frame block, and the texture set.
    pub light_sets: PassSets<'a>,
    /// The maps.
    pub maps: &'a mut super::targets::ShadowMaps,
}

/// The passes of a frame, in order: statistics reset; with shadows, the light's generation
/// (compute path) and passes, then a second reset; generation (compute path); the opaque pass
/// (props, scalps, and opaque strands; the mesh path generates inside it); with transparency,
/// the transparent strand passes and their resolve.
pub struct FramePasses {
    generate: ComputeGenerate,
    shadow: ShadowPass,
    props: PropPass,
    scalp: ScalpPass,
    strands: StrandDraw,
    transparency: TransparencyPass,
    /// The software rasterizer, on devices with 64-bit shared and buffer atomics.
    soft: Option<soft_raster::SoftRasterPass>,
    hair_mesh_update: hair_mesh_update::HairMeshUpdate,
    /// The LHS baseline's skinning pass.
    pub lhs_skin: lhs_skin::LhsSkin,
}

/// Zero `args` (indirect arguments and statistics) after earlier generation used it.
pub(crate) fn clear_args(rec: &mut CommandRecorder, args: &Buffer) {
    rec.barrier(
        &[
            Access::ComputeReadWrite,
            Access::TaskReadWrite,
            Access::IndirectRead,
            Access::TransferRead,
        ],
        &[Access::TransferWrite],
    );
    rec.fill_buffer(args, 0, size_of::<GenerateArgs>() as u64, 0);
    rec.barrier(
        &[Access::TransferWrite],
        &[Access::ComputeReadWrite, Access::TaskReadWrite],
    );
}

impl FramePasses {
    /// Compile every pipeline; the mesh path with `task_bundles` bundles per task workgroup.
    pub fn new(
        ctx: &Arc<Context>,
        layout: &Arc<PipelineLayout>,
        task_bundles: u32,
        samples: u32,
    ) -> GpuResult<Self> {
        let targets = TargetFormats {
            color: COLOR_FORMAT,
            depth: DEPTH_FORMAT,
            samples,
        };
        let camera = DrawTarget::Camera(targets);
        Ok(FramePasses {
            generate: ComputeGenerate::new(ctx, layout)?,
            shadow: ShadowPass::new(ctx, layout, task_bundles)?,
            props: PropPass::new(ctx, layout, camera)?,
            scalp: ScalpPass::new(ctx, layout, targets)?,
            strands: StrandDraw::new(ctx, layout, camera, task_bundles)?,
            transparency: TransparencyPass::new(ctx, layout, targets, task_bundles),
            soft: if ctx.info.int64_atomics {
                Some(soft_raster::SoftRasterPass::new(ctx, layout, task_bundles)?)
            } else {
                None
            },
            hair_mesh_update: hair_mesh_update::HairMeshUpdate::new(ctx)?,
            lhs_skin: lhs_skin::LhsSkin::new(ctx)?,
        })
    }

    /// Layout of the animated characters' update sets.
    pub fn deform_set_layout(&self) -> &Arc<crate::vk::DescriptorSetLayout> {
        self.hair_mesh_update.set_layout()
    }

    /// Record this frame's hair mesh texture rebuilds (before [`Self::record`]).
    pub fn record_updates(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        jobs: &[hair_mesh_update::UpdateJob],
    ) {
        self.hair_mesh_update.record(rec, profiler, jobs);
    }

    /// Check and compile what `mode` needs, before a frame uses it.
    pub fn prepare_transparency(&mut self, mode: super::Transparency) -> GpuResult<()> {
        self.transparency.prepare(mode)
    }

    /// Whether the mesh path is available.
    pub fn has_mesh_path(&self) -> bool {
        self.strands.has_mesh_path()
    }

    /// Whether the software rasterizer is available.
    pub fn has_software_raster(&self) -> bool {
        self.soft.is_some()
    }

    /// The software rasterizer alone over `targets` (cleared to black first): `segments`
    /// segments already in the soft buffers, nothing in front (the soft depth is filled with
    /// 1), composited through a k-buffer of `budget` nodes (`Renderer::rasterize_segments`).
    #[allow(clippy::too_many_arguments)]
    pub fn record_soft_only(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        sets: PassSets,
        args: &Buffer,
        soft_buffers: &super::soft::SoftBuffers,
        transparency_buffers: &super::transparency::TransparencyBuffers,
        targets: &mut RenderTargets,
        (segments, budget): (u32, u32),
    ) -> GpuResult<()> {
        let pass = self.soft.as_ref().ok_or_else(|| {
            crate::vk::GpuError::Unsupported("no software rasterizer on this device".into())
        })?;
        let (w, h) = targets.size();
        clear_args(rec, args);
        rec.barrier(&[Access::ComputeReadWrite], &[Access::TransferWrite]);
        let offset = GenerateArgs::SEGMENTS_DEMANDED_OFFSET;
        rec.fill_buffer(args, offset, 4, segments);
        rec.fill_buffer(
            &soft_buffers.depth,
            0,
            w as u64 * h as u64 * 4,
            1.0f32.to_bits(),
        );
        rec.image_barrier(&targets.color, Access::Nothing, Access::ColorAttachment);
        rec.image_barrier(&targets.depth, Access::Nothing, Access::DepthAttachment);
        rec.begin_rendering(
            Attachment {
                image: &targets.color,
                clear: Some([0.0, 0.0, 0.0, 1.0]),
                resolve: None,
            },
            Attachment {
                image: &targets.depth,
                clear: Some([1.0; 4]),
                resolve: None,
            },
        );
        rec.end_rendering();
        targets.color_access = Access::ColorAttachment;
        targets.depth_access = Access::DepthAttachment;
        TransparencyPass::clear_kbuffer(rec, transparency_buffers, budget, w as u64 * h as u64);
        let draw = soft_raster::SoftDraw {
            sets,
            args,
            buffers: soft_buffers,
            targets: None,
            size: (w, h),
        };
        pass.record(rec, profiler, draw);
        self.transparency
            .record_resolve(rec, profiler, false, sets, targets)?;
        targets.set_output_access(Access::ColorAttachment);
        Ok(())
    }

    /// Record the frame's passes. Leaves the targets as colour / depth attachments and
    /// `args` written by the last generating stage.
    pub fn record(
        &self,
        rec: &mut CommandRecorder,
        profiler: &mut Profiler,
        mesh_query: Option<&mut MeshPrimitivesQuery>,
        inp: FrameInputs,
    ) -> GpuResult<()> {
        // Statistics accumulate from zero every frame; the static path keeps the last compute
        // frame's draw arguments (and statistics).
        let keep_args = matches!(inp.path, RenderPath::Static | RenderPath::Lhs);
        if !keep_args {
            clear_args(rec, inp.args);
        }
        let compute = inp.bundles > 0 && inp.path == RenderPath::Compute;
        let shadow = inp.shadow;
        match shadow.mode {
            Some(mode) => {
                if compute {
                    let sets = shadow.light_sets;
                    self.generate.record(
                        rec,
                        profiler,
                        sets,
                        inp.bundles,
                        inp.args,
                        GenerateView::Light,
                    );
                }
                let draw = ShadowDraw {
                    mode,
                    sets: shadow.light_sets,
                    bundles: inp.bundles,
                    path: inp.path,
                    args: inp.args,
                    props: inp.props,
                };
                self.shadow.record(rec, profiler, shadow.maps, draw)?;
                // The camera's statistics start from zero again.
                if !keep_args {
                    clear_args(rec, inp.args);
                }
            }
            None => ShadowPass::keep_readable(rec, shadow.maps),
        }
        if compute {
            self.generate.record(
                rec,
                profiler,
                inp.sets,
                inp.bundles,
                inp.args,
                GenerateView::Camera,
            );
        }
        let targets = inp.targets;
        let (color_from, depth_from) = match inp.clear {
            Some(_) => (Access::Nothing, Access::Nothing),
            None => (targets.color_access, targets.depth_access),
        };
        rec.image_barrier(&targets.color, color_from, Access::ColorAttachment);
        rec.image_barrier(&targets.depth, depth_from, Access::DepthAttachment);
        if let Some(r) = &targets.resolved {
            // The resolve overwrites every pixel: earlier contents are not needed.
            rec.image_barrier(r, Access::Nothing, Access::ColorAttachment);
        }
        let mesh = inp.path == RenderPath::Mesh;
        let transparent = inp.bundles > 0 && inp.transparency != super::Transparency::Opaque;
        let soft = inp.bundles > 0 && inp.raster.uses_software();
        profiler.begin(rec, if mesh { "mesh draw" } else { "draw" });
        rec.begin_rendering(
            Attachment {
                image: &targets.color,
                clear: inp.clear,
                // With transparency or software strands the resolve pass ends the frame's
                // colour.
                resolve: targets.resolved.as_ref().filter(|_| !transparent && !soft),
            },
            Attachment {
                image: &targets.depth,
                clear: inp.clear.map(|_| [1.0; 4]),
                resolve: None,
            },
        );
        let mut result = Ok(());
        self.props.record(rec, inp.sets, inp.props);
        let mut query = mesh_query;
        if inp.bundles > 0 {
            self.scalp.record(rec, inp.sets, inp.bundles);
            if transparent {
                // Drawn by the transparent passes below.
            } else if mesh {
                if let Some(q) = query.as_deref_mut() {
                    q.begin(rec);
                }
                result = self.strands.record_mesh(rec, inp.sets, inp.bundles);
                if let Some(q) = query.as_deref_mut() {
                    q.end(rec);
                }
            } else {
                self.strands.record_pulled(rec, inp.sets, inp.args);
            }
        }
        rec.end_rendering();
        profiler.end(rec);
        targets.color_access = Access::ColorAttachment;
        targets.depth_access = Access::DepthAttachment;
        result?;
        if transparent {
            let draw = TransparentDraw {
                mode: inp.transparency,
                sets: inp.sets,
                bundles: inp.bundles,
                path: inp.path,
                args: inp.args,
                targets: &mut *targets,
                buffers: inp.transparency_buffers,
                mesh_query: query,
            };
            self.transparency.record_layers(rec, profiler, draw)?;
        } else if soft {
            let (w, h) = targets.size();
            TransparencyPass::clear_kbuffer(
                rec,
                inp.transparency_buffers,
                inp.kbuffer_budget,
                w as u64 * h as u64,
            );
        }
        if soft {
            let pass = self.soft.as_ref().ok_or_else(|| {
                crate::vk::GpuError::Unsupported("no software rasterizer on this device".into())
            })?;
            let size = targets.size();
            if mesh {
                pass.record_mesh_segments(rec, profiler, inp.sets, inp.bundles, size)?;
            }
            let draw = soft_raster::SoftDraw {
                sets: inp.sets,
                args: inp.args,
                buffers: inp.soft_buffers,
                targets: Some(&mut *targets),
                size,
            };
            pass.record(rec, profiler, draw);
        }
        if transparent || soft {
            let peel = matches!(inp.transparency, super::Transparency::DepthPeeling { .. });
            self.transparency
                .record_resolve(rec, profiler, peel, inp.sets, targets)?;
        }
        targets.set_output_access(Access::ColorAttachment);
        Ok(())
    }
}
