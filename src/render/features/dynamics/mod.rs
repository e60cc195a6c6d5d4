//! Hair dynamics on the GPU (`glsl/hair_dynamics.comp`, the twin of `dynamics::HairDynamics`):
//! per simulated character, its constraint structure and colliders (uploaded once), its state
//! (positions, velocities and the substep's scratch; only the GPU touches it after the upload)
//! and the step the next frame runs. A frame's steps are [`SimJob`]s: one table, one dispatch,
//! one workgroup per character, each reaching its character's buffers by device address.
//! Heads given by a radial map share one buffer per map ([`HeadMaps`]).

use std::sync::Arc;

use ash::vk;
use glam::{Mat4, Vec3};

pub mod pass;

use crate::dynamics::{
    Collider, DynamicsSettings, HairDynamics, HairState, RadialMap, StepClock, StepPlan,
};
use crate::render::core::shared::{
    COLLIDER_CAPSULE, COLLIDER_ELLIPSOID, COLLIDER_HEAD, MAX_SIM_COLLIDERS, SimCollider,
    SimConstraint, SimJob, SimState, SimVertex,
};
use crate::vk::{Buffer, BufferDesc, Context, GpuError, GpuResult};

/// Usage of the buffers the solver reaches by address.
fn addressed() -> vk::BufferUsageFlags {
    vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS
}

fn upload(ctx: &Arc<Context>, name: &str, bytes: &[u8]) -> GpuResult<Buffer> {
    let mut padded = bytes.to_vec();
    padded.resize(bytes.len().max(16), 0);
    Buffer::device_local_with_data(
        ctx,
        name,
        addressed() | vk::BufferUsageFlags::TRANSFER_SRC,
        &padded,
    )
}

/// The radial maps of head colliders on the GPU, one buffer per map.
#[derive(Default)]
pub struct HeadMaps {
    maps: Vec<(usize, Arc<Buffer>)>,
}

impl HeadMaps {
    /// The buffer of `map` (uploaded on first use).
    fn buffer(&mut self, ctx: &Arc<Context>, map: &'static RadialMap) -> GpuResult<Arc<Buffer>> {
        let key = map as *const RadialMap as usize;
        if let Some((_, b)) = self.maps.iter().find(|(k, _)| *k == key) {
            return Ok(b.clone());
        }
        if map.rows < 2 || map.cols < 1 || map.radius.len() != map.rows * map.cols {
            return Err(GpuError::Unsupported(format!(
                "head map of {} radii for {} x {}",
                map.radius.len(),
                map.rows,
                map.cols
            )));
        }
        let buffer = Arc::new(upload(ctx, "head map", bytemuck::cast_slice(&map.radius))?);
        self.maps.push((key, buffer.clone()));
        Ok(buffer)
    }
}

/// A collider as the solver reads it, and the radial map it needs (if a head).
fn sim_collider(c: &Collider) -> (SimCollider, Option<&'static RadialMap>) {
    let v4 = |v: Vec3, w: f32| v.extend(w).to_array();
    let (centre, radius) = c.bounding_sphere();
    let mut out = SimCollider {
        bound: v4(centre, radius),
        ..SimCollider::default()
    };
    match *c {
        Collider::Ellipsoid { centre, radii } => {
            out.shape[0] = COLLIDER_ELLIPSOID;
            out.a = v4(centre, 0.0);
            out.b = v4(radii, 0.0);
        }
        Collider::Capsule { a, b, radius } => {
            out.shape[0] = COLLIDER_CAPSULE;
            out.a = v4(a, radius);
            out.b = v4(b, 0.0);
        }
        Collider::Head {
            map,
            to_person,
            to_canonical,
            margin,
        } => {
            out.shape[0] = COLLIDER_HEAD;
            out.a = v4(Vec3::ZERO, margin);
            out.b = v4(map.centre, 0.0);
            out.to_canonical = to_canonical.to_cols_array_2d();
            out.to_person = to_person.to_cols_array_2d();
            return (out, Some(map));
        }
    }
    (out, None)
}

/// The state buffer's contents for `state`: a `SimState` per vertex, then room for the
/// substep's positions (a `vec4` per vertex; kept apart so that the phases that solve them
/// touch four vertices per cache line).
fn sim_state_bytes(state: &HairState) -> Vec<u8> {
    let states: Vec<SimState> = state
        .x
        .iter()
        .zip(&state.v)
        .map(|(x, v)| SimState {
            x: x.extend(0.0).to_array(),
            v: v.extend(0.0).to_array(),
        })
        .collect();
    let mut bytes = bytemuck::cast_slice(&states).to_vec();
    bytes.resize(bytes.len() + state.x.len() * size_of::<[f32; 4]>(), 0);
    bytes
}

/// One character's hair dynamics on the GPU.
pub struct HairSimulation {
    vertices: Buffer,
    spacing: Buffer,
    colours: Buffer,
    colliders: Buffer,
    state: Buffer,
    head_map: Option<(Arc<Buffer>, [u32; 2])>,
    /// Vertices per layer, layers, spacing colours, colliders.
    counts: [u32; 4],
    clock: StepClock,
    pending: Option<SimJob>,
}

impl HairSimulation {
    /// Upload `sim`'s structure, colliders, state and clock; `thinning`: the root layer's
    /// thinning (the pose's w, as `DeformState::set_pose` writes it).
    pub fn new(
        ctx: &Arc<Context>,
        sim: &HairDynamics,
        thinning: &[f32],
        maps: &mut HeadMaps,
    ) -> GpuResult<Self> {
        let t = sim.topology();
        let vertices: Vec<SimVertex> = (0..t.rest.len())
            .map(|j| SimVertex {
                rest: t.rest[j]
                    .extend(thinning.get(j).map_or(0.0, |x| x.cbrt()))
                    .to_array(),
                lengths: [t.edge[j], t.bend[j], 0.0, 0.0],
            })
            .collect();
        let spacing: Vec<SimConstraint> = t
            .spacing
            .iter()
            .map(|&(a, b, rest)| SimConstraint {
                a,
                b,
                rest,
                _pad: 0,
            })
            .collect();
        let colliders: Vec<(SimCollider, Option<&'static RadialMap>)> =
            sim.colliders().iter().map(sim_collider).collect();
        let mut map = None;
        for m in colliders.iter().filter_map(|(_, m)| *m) {
            if map.is_some_and(|seen: &RadialMap| !std::ptr::eq(seen, m)) {
                return Err(GpuError::Unsupported(
                    "GPU hair dynamics: a character's head colliders must share one radial map"
                        .into(),
                ));
            }
            map = Some(m);
        }
        let records: Vec<SimCollider> = colliders.iter().map(|(c, _)| *c).collect();
        if records.len() > MAX_SIM_COLLIDERS as usize {
            return Err(GpuError::Unsupported(format!(
                "GPU hair dynamics: {} colliders; at most {MAX_SIM_COLLIDERS}",
                records.len()
            )));
        }
        // Checked: now upload, the shared head map first.
        let head_map = match map {
            Some(m) => Some((maps.buffer(ctx, m)?, [m.rows as u32, m.cols as u32])),
            None => None,
        };
        Ok(HairSimulation {
            vertices: upload(ctx, "sim vertices", bytemuck::cast_slice(&vertices))?,
            spacing: upload(ctx, "sim spacing", bytemuck::cast_slice(&spacing))?,
            colours: upload(ctx, "sim colours", bytemuck::cast_slice(&t.spacing_colours))?,
            colliders: upload(ctx, "sim colliders", bytemuck::cast_slice(&records))?,
            state: upload(ctx, "sim state", &sim_state_bytes(sim.state()))?,
            head_map,
            counts: [
                t.n as u32,
                t.layers as u32,
                t.spacing_colours.len() as u32 - 1,
                records.len() as u32,
            ],
            clock: *sim.clock(),
            pending: None,
        })
    }

    /// The state buffer (the frame graph orders its uses).
    pub fn state_buffer(&self) -> &Buffer {
        &self.state
    }

    /// The clock: simulated time and the placement of the last step.
    pub fn clock(&self) -> &StepClock {
        &self.clock
    }

    /// Advance by `dt` seconds while the character moves to `model`, with `settings`, writing
    /// the pose into `pose` (the next frame runs it; a second call before then replaces its
    /// placement and adds nothing: the clock has moved on).
    pub fn step(
        &mut self,
        dt: f32,
        model: Mat4,
        settings: &DynamicsSettings,
        pose: &Buffer,
    ) -> GpuResult<()> {
        settings.validate().map_err(GpuError::Unsupported)?;
        if !model.is_finite() {
            return Err(GpuError::Unsupported(
                "character transform is not finite".into(),
            ));
        }
        let plan = self.clock.advance(dt, model, settings);
        self.pending = Some(self.job(plan, settings, pose, &model));
        Ok(())
    }

    /// The job of `plan` (`None`: no time passed; only the pose at `model`).
    fn job(
        &self,
        plan: Option<StepPlan>,
        s: &DynamicsSettings,
        pose: &Buffer,
        model: &Mat4,
    ) -> SimJob {
        let to = crate::dynamics::Placement::of(model);
        let plan = plan.unwrap_or(StepPlan {
            from: to,
            to,
            substeps: 0,
            h: 0.0,
            time: self.clock.time,
        });
        let keep = (-s.damping * plan.h).exp();
        let v4 = |v: Vec3, w: f32| v.extend(w).to_array();
        let (map, size) = match &self.head_map {
            Some((b, size)) => (b.device_address(), *size),
            None => ([0; 2], [0; 2]),
        };
        SimJob {
            vertices: self.vertices.device_address(),
            spacing: self.spacing.device_address(),
            spacing_colours: self.colours.device_address(),
            colliders: self.colliders.device_address(),
            state: self.state.device_address(),
            pose: pose.device_address(),
            head_map: map,
            solve: address_plus(self.state.device_address(), self.state_bytes()),
            counts: [
                self.counts[0],
                self.counts[1],
                plan.substeps,
                self.counts[3],
            ],
            colours: [self.counts[2], size[0], size[1], 0],
            from_rotation: plan.from.rotation.to_array(),
            to_rotation: plan.to.rotation.to_array(),
            from_translation: v4(plan.from.translation, plan.time),
            to_translation: v4(plan.to.translation, plan.h),
            from_scale: v4(plan.from.scale, keep),
            to_scale: v4(plan.to.scale, 0.0),
            gravity: v4(s.gravity, s.wind.gustiness),
            wind: v4(s.wind.direction.normalize_or(Vec3::X), s.wind.strength),
            stiffness: [
                s.shape_stiffness,
                s.spacing_compliance,
                s.bend_compliance,
                s.ftl_damping,
            ],
        }
    }

    /// The step waiting for the next frame, taken.
    pub fn take_job(&mut self) -> Option<SimJob> {
        self.pending.take()
    }

    /// Vertices simulated (all layers).
    pub fn vertex_count(&self) -> usize {
        self.counts[0] as usize * self.counts[1] as usize
    }

    /// Bytes of the state buffer's first part, the state (then come the substep's positions).
    pub fn state_bytes(&self) -> u64 {
        (self.vertex_count() * size_of::<SimState>()) as u64
    }
}

/// `address` (low word first) advanced by `bytes`.
fn address_plus(address: [u32; 2], bytes: u64) -> [u32; 2] {
    let a = (address[0] as u64 | (address[1] as u64) << 32) + bytes;
    [a as u32, (a >> 32) as u32]
}

/// Positions and velocities from the state buffer's bytes.
pub fn hair_state(bytes: &[u8]) -> HairState {
    let states: Vec<SimState> = bytemuck::pod_collect_to_vec(bytes);
    HairState {
        x: states.iter().map(|s| Vec3::from_slice(&s.x[..3])).collect(),
        v: states.iter().map(|s| Vec3::from_slice(&s.v[..3])).collect(),
    }
}

/// A device-local pose buffer the solver writes and the texture rebuild reads.
pub fn pose_buffer(ctx: &Arc<Context>, vertices: u64) -> GpuResult<Buffer> {
    Buffer::new(
        ctx,
        &BufferDesc::new(
            "simulated pose",
            vertices * 16,
            addressed() | vk::BufferUsageFlags::TRANSFER_SRC,
        ),
    )
}
