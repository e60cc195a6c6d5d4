//! The GPU side of moving hair meshes (`bake::deform`): per animated character, the static
//! basis (texel -> column map, styling terms, decode box) in buffers, one host-visible pose
//! buffer per frame in flight, and the packed texels `glsl/hair_mesh_update.comp` writes before
//! `passes::hair_mesh_update` copies them into the character's textures. Its position, u and
//! v textures exist twice: each pose update writes the set the last frame did not read, so
//! the previous pose stays for the motion vectors (`render::temporal`). A character whose hair
//! is simulated on the GPU (`render::dynamics`) also has a device-local pose buffer, which the
//! solver writes and the rebuild reads in the same frame.

use std::sync::Arc;

use ash::vk;
use glam::Vec3;

use super::core::shared::SimJob;
use super::core::shared::TextureBinding;
use super::core::shared::{DeformBinding, DeformParams};
use super::core::slots::FRAMES_IN_FLIGHT;
use super::dynamics::{HairSimulation, HeadMaps};
use crate::bake::deform::DeformBasis;
use crate::vk::{
    Buffer, BufferDesc, Context, DescriptorSet, DescriptorSetLayout, GpuError, GpuResult, Image,
};

/// The textures a pose update rewrites, in the order of the update's outputs.
pub const POSED_TEXTURES: [TextureBinding; 3] = [
    TextureBinding::Position,
    TextureBinding::U,
    TextureBinding::V,
];

pub use super::core::shared::DEFORM_GROUP_SIZE;

/// One animated character's update state.
pub struct DeformState {
    basis: DeformBasis,
    /// Per frame slot: the pose buffer and the set that reads it.
    poses: Vec<(Buffer, DescriptorSet)>,
    /// Packed output texels: hair mesh texture, u, v.
    pub outputs: [Buffer; 3],
    /// The other set of hair mesh, u and v textures.
    alternates: [Image; 3],
    /// Whether the alternates hold the current pose (else the character's own images).
    alternate_current: bool,
    /// Decode box, texel -> vertex map, styling offsets and terms.
    statics: [Buffer; 4],
    /// A pose given since the last frame, waiting for a frame slot.
    pending: Option<Vec<[f32; 4]>>,
    /// Bounds of the latest pose (character frame), for fitting the light's view.
    pose_bounds: Option<(Vec3, Vec3)>,
    /// Hair dynamics on the GPU, when started.
    simulation: Option<SimulatedPose>,
    /// Whether this frame's update reads the simulated pose.
    reads_simulation: bool,
}

/// GPU hair dynamics and the pose buffer it writes, with the update set that reads it.
pub struct SimulatedPose {
    sim: HairSimulation,
    pose: Buffer,
    set: DescriptorSet,
}

/// What a frame's update of one character rebuilds from.
pub enum PoseUpdate {
    /// A pose the CPU gave, uploaded.
    Uploaded,
    /// The GPU solver's pose after this step.
    Simulated(Box<SimJob>),
}

fn storage(
    ctx: &Arc<Context>,
    name: &str,
    bytes: u64,
    extra: vk::BufferUsageFlags,
) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(name, bytes, vk::BufferUsageFlags::STORAGE_BUFFER | extra),
    )
}

fn with_data(ctx: &Arc<Context>, name: &str, bytes: &[u8]) -> GpuResult<Buffer> {
    let mut padded = bytes.to_vec();
    padded.resize(bytes.len().max(16), 0);
    Buffer::device_local_with_data(ctx, name, vk::BufferUsageFlags::STORAGE_BUFFER, &padded)
}

/// The other set of posed textures, made like `own` (the character's [`POSED_TEXTURES`] as
/// made when it was added; zeroed: the first update writes them).
fn alternates(ctx: &Arc<Context>, own: [&Image; 3]) -> GpuResult<[Image; 3]> {
    let alternate =
        |own: &Image| Image::with_data(ctx, &own.desc, &vec![0; own.byte_size() as usize]);
    Ok([alternate(own[0])?, alternate(own[1])?, alternate(own[2])?])
}

/// An update set reading `pose`.
fn update_set(
    ctx: &Arc<Context>,
    layout: &Arc<DescriptorSetLayout>,
    statics: &[Buffer; 4],
    pose: &Buffer,
    outputs: &[Buffer; 3],
) -> GpuResult<DescriptorSet> {
    let set = DescriptorSet::new(ctx, "hair mesh update", layout)?;
    for (b, _) in DeformBinding::ALL {
        let buffer = match b {
            DeformBinding::Params => &statics[0],
            DeformBinding::Positions => pose,
            DeformBinding::TexelVertex => &statics[1],
            DeformBinding::StylingOffsets => &statics[2],
            DeformBinding::StylingTerms => &statics[3],
            DeformBinding::PositionTexels => &outputs[0],
            DeformBinding::UTexels => &outputs[1],
            DeformBinding::VTexels => &outputs[2],
        };
        set.write_buffer(b as u32, buffer)?;
    }
    Ok(set)
}

impl SimulatedPose {
    /// The solver's state.
    pub fn sim(&self) -> &HairSimulation {
        &self.sim
    }

    /// The pose buffer (`layers x vertices` vec4, character frame).
    pub fn pose(&self) -> &Buffer {
        &self.pose
    }
}

impl DeformState {
    /// Buffers for `basis`; sets from `layout` (the update pass's); the other texture set
    /// made like `own` (the character's [`POSED_TEXTURES`] as made when it was added).
    pub fn new(
        ctx: &Arc<Context>,
        basis: DeformBasis,
        layout: &Arc<DescriptorSetLayout>,
        own: [&Image; 3],
    ) -> GpuResult<Self> {
        let alternates = alternates(ctx, own)?;
        let info = &basis.info;
        let slice = info.slice_texels() as u64;
        let layers = info.layers as u64;
        let params = DeformParams {
            origin: info.pos_origin,
            extent: info.pos_extent,
            counts: [slice as u32, info.layers, basis.vertices, 0],
        };
        let statics = [
            with_data(ctx, "deform params", bytemuck::bytes_of(&params))?,
            with_data(
                ctx,
                "texel vertex",
                bytemuck::cast_slice(&basis.texel_vertex),
            )?,
            with_data(
                ctx,
                "styling offsets",
                bytemuck::cast_slice(&basis.styling.offsets),
            )?,
            with_data(
                ctx,
                "styling terms",
                bytemuck::cast_slice(&basis.styling.terms),
            )?,
        ];
        let src = vk::BufferUsageFlags::TRANSFER_SRC;
        let outputs = [
            storage(
                ctx,
                "deformed positions",
                slice * info.position_depth() as u64 * 8,
                src,
            )?,
            storage(ctx, "deformed u", slice * layers * 8, src)?,
            storage(ctx, "deformed v", slice * layers * 8, src)?,
        ];
        let pose_bytes = layers * basis.vertices as u64 * 16;
        let mut poses = Vec::with_capacity(FRAMES_IN_FLIGHT);
        for _ in 0..FRAMES_IN_FLIGHT {
            let pose = Buffer::new(
                ctx,
                &BufferDesc::new(
                    "hair mesh pose",
                    pose_bytes,
                    vk::BufferUsageFlags::STORAGE_BUFFER,
                )
                .host_visible(),
            )?;
            let set = update_set(ctx, layout, &statics, &pose, &outputs)?;
            poses.push((pose, set));
        }
        Ok(DeformState {
            basis,
            poses,
            outputs,
            alternates,
            alternate_current: false,
            statics,
            pending: None,
            pose_bounds: None,
            simulation: None,
            reads_simulation: false,
        })
    }

    /// Simulate the hair on the GPU from `sim`'s state (replacing an earlier GPU simulation,
    /// which is returned for retiring); `layout`: the update pass's.
    pub fn simulate(
        &mut self,
        ctx: &Arc<Context>,
        layout: &Arc<DescriptorSetLayout>,
        sim: &crate::dynamics::HairDynamics,
        maps: &mut HeadMaps,
    ) -> GpuResult<Option<SimulatedPose>> {
        let n = self.basis.vertices as usize * self.basis.info.layers as usize;
        if sim.vertex_count() != n {
            return Err(GpuError::Unsupported(format!(
                "hair dynamics of {} vertices for a hair mesh of {n}",
                sim.vertex_count()
            )));
        }
        let gpu = HairSimulation::new(ctx, sim, &self.basis.root_thinning, maps)?;
        let pose = super::dynamics::pose_buffer(ctx, n as u64)?;
        let set = update_set(ctx, layout, &self.statics, &pose, &self.outputs)?;
        Ok(self.simulation.replace(SimulatedPose {
            sim: gpu,
            pose,
            set,
        }))
    }

    /// The GPU simulation, if started.
    pub fn simulation(&self) -> Option<&SimulatedPose> {
        self.simulation.as_ref()
    }

    /// Step the GPU simulation by `dt` while the character moves to `model` (the next frame
    /// runs it and rebuilds the textures from its pose; it replaces a pose given since).
    pub fn step_simulation(
        &mut self,
        dt: f32,
        model: glam::Mat4,
        settings: &crate::dynamics::DynamicsSettings,
    ) -> GpuResult<()> {
        let Some(s) = self.simulation.as_mut() else {
            return Err(GpuError::Unsupported(
                "hair dynamics were not started on the GPU".into(),
            ));
        };
        s.sim.step(dt, model, settings, &s.pose)?;
        self.pending = None;
        // The pose stays on the GPU: the light's view falls back to the decode box (the
        // rebuild clamps every pose to it).
        self.pose_bounds = None;
        Ok(())
    }

    /// The other set's image of texture `binding` (`None`: uv and w, which poses keep).
    pub fn alternate(&self, binding: TextureBinding) -> Option<&Image> {
        let i = POSED_TEXTURES.iter().position(|b| *b == binding)?;
        Some(&self.alternates[i])
    }

    /// Whether the other set holds the current pose.
    pub fn alternate_current(&self) -> bool {
        self.alternate_current
    }

    /// The basis (decode box, layout, styling terms).
    pub fn basis(&self) -> &DeformBasis {
        &self.basis
    }

    /// Set the next frame's pose: `layers x vertices` object-space positions, layer-major.
    /// Every value must be finite; points outside the decode box are clamped to it.
    pub fn set_pose(&mut self, positions: &[Vec3]) -> GpuResult<()> {
        let n = self.basis.vertices as usize * self.basis.info.layers as usize;
        if positions.len() != n {
            return Err(GpuError::Unsupported(format!(
                "hair mesh pose: {} positions for {n} layer vertices",
                positions.len()
            )));
        }
        if let Some(i) = positions.iter().position(|p| !p.is_finite()) {
            return Err(GpuError::Unsupported(format!(
                "hair mesh pose: position {i} is not finite"
            )));
        }
        // The root layer's w carries the root thinning into the root slice's alpha (as its cube
        // root, like the bake's encode_columns).
        let thinning = &self.basis.root_thinning;
        self.pending = Some(
            positions
                .iter()
                .enumerate()
                .map(|(i, p)| {
                    p.extend(thinning.get(i).map_or(0.0, |t| t.cbrt()))
                        .to_array()
                })
                .collect(),
        );
        self.pose_bounds = Some(crate::model::hair_mesh::bounds(positions.iter().copied()));
        if let Some(s) = self.simulation.as_mut() {
            s.sim.take_job();
        }
        Ok(())
    }

    /// Bounds of the latest pose in the character's frame (`None` before the first pose, and
    /// while the pose comes from the GPU dynamics).
    pub fn pose_bounds(&self) -> Option<(Vec3, Vec3)> {
        self.pose_bounds
    }

    /// Write a pending pose into frame slot `slot`'s buffer (its earlier frame has completed),
    /// or take the pending GPU step, and make the other texture set current (this frame's
    /// update writes it); what this frame's update rebuilds from, if anything.
    pub fn write_pending(&mut self, slot: usize) -> GpuResult<Option<PoseUpdate>> {
        let job = self.simulation.as_mut().and_then(|s| s.sim.take_job());
        let update = match (self.pending.take(), job) {
            (Some(pose), _) => {
                self.poses[slot].0.write(0, bytemuck::cast_slice(&pose))?;
                PoseUpdate::Uploaded
            }
            (None, Some(job)) => PoseUpdate::Simulated(Box::new(job)),
            (None, None) => {
                self.reads_simulation = false;
                return Ok(None);
            }
        };
        self.reads_simulation = matches!(update, PoseUpdate::Simulated(_));
        self.alternate_current = !self.alternate_current;
        Ok(Some(update))
    }

    /// The set frame slot `slot` dispatches with, and the workgroup count.
    pub fn dispatch(&self, slot: usize) -> (&DescriptorSet, u32) {
        let invocations = self.basis.info.slice_texels() as u32 * self.basis.info.layers;
        let set = match (&self.simulation, self.reads_simulation) {
            (Some(s), true) => &s.set,
            _ => &self.poses[slot].1,
        };
        (set, invocations.div_ceil(DEFORM_GROUP_SIZE))
    }

    /// This frame's simulated state and pose buffers, when its update reads the simulation.
    pub fn simulated_buffers(&self) -> Option<(&Buffer, &Buffer)> {
        let s = self.simulation.as_ref().filter(|_| self.reads_simulation)?;
        Some((s.sim.state_buffer(), &s.pose))
    }
}
