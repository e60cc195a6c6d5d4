//! A crowd in motion: every character follows its [`CharacterMotion`]; characters with a
//! simulated hair mesh step their hair dynamics every frame, on the GPU by default
//! ([`DynamicsPath::Gpu`]: the renderer runs `glsl/hair_dynamics.comp` and rebuilds the
//! textures from its pose without the pose leaving the device) or on the CPU
//! ([`DynamicsPath::Cpu`]: [`HairDynamics`] on all cores, the pose uploaded). Switching path
//! carries the state across. With the screen-size schedule on, characters small on screen
//! simulate less often: by the height in pixels of their hair (the projected size eq. 7 of
//! paper 003 uses), every frame above 96 px, every 2nd above 48, every 4th above 24, else
//! every 8th frame (phases staggered by crowd slot, [`due_on`]), with the time they skipped (up to
//! [`MAX_FRAME_STEP`](crate::dynamics::MAX_FRAME_STEP)) in one step.

use std::time::Instant;

use glam::Vec3;

use super::motion::CharacterMotion;
use crate::dynamics::{Collider, DynamicsSettings, HairDynamics, Wind};
use crate::model::hair_mesh::HairMesh;
use crate::render::{Camera, CharacterId, Renderer};
use crate::vk::GpuResult;

/// One character of an animated crowd.
pub struct AnimatedCharacter {
    id: CharacterId,
    motion: CharacterMotion,
    dynamics: Option<HairDynamics>,
    /// Centre and radius of its hair at rest, character frame.
    bounds: (Vec3, f32),
    /// Seconds since its hair was last simulated.
    pending_dt: f32,
    /// Its hair roots as last handed to the renderer (character frame).
    roots: Vec<Vec3>,
    /// Whether the renderer holds its hair dynamics' current state (GPU path).
    on_gpu: bool,
    /// A skinned person: placed by their path and clip instead of `motion`.
    walker: Option<super::walk::Walker>,
}

/// What the last [`CrowdAnimation::advance`] did.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct AnimationStats {
    /// CPU milliseconds simulating hair meshes (CPU path) or handing the GPU its steps.
    pub simulate_ms: f64,
    /// Where they were simulated.
    pub path: DynamicsPath,
    /// Characters whose hair was simulated (and textures rebuilt).
    pub simulated: usize,
    /// Hair mesh vertices simulated.
    pub vertices: usize,
}

/// The crowd's motion and hair dynamics.
pub struct CrowdAnimation {
    characters: Vec<AnimatedCharacter>,
    time: f32,
    frame: u64,
    /// Characters move (walk, turn, sway).
    pub moving: bool,
    /// Hair meshes are simulated (otherwise they stay at rest, moving rigidly).
    pub simulating: bool,
    /// Where hair meshes are simulated (switch any time: the state is carried across).
    pub path: DynamicsPath,
    /// Simulate characters small on screen less often (see the module doc); off: every
    /// character every frame.
    pub schedule: bool,
    /// Wind, shared by every character.
    pub wind: Wind,
    /// What the last frame did.
    pub stats: AnimationStats,
}

/// Where hair meshes are simulated.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum DynamicsPath {
    /// On the GPU (`glsl/hair_dynamics.comp`): the pose never leaves the device.
    #[default]
    Gpu,
    /// On the CPU (`dynamics::HairDynamics`, all cores), the pose uploaded each frame.
    Cpu,
}

impl std::str::FromStr for DynamicsPath {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "gpu" => Ok(DynamicsPath::Gpu),
            "cpu" => Ok(DynamicsPath::Cpu),
            _ => Err(format!("'{s}': expected gpu or cpu")),
        }
    }
}

impl std::fmt::Display for DynamicsPath {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            DynamicsPath::Gpu => "gpu",
            DynamicsPath::Cpu => "cpu",
        })
    }
}

/// Hair pixels above which a character simulates every frame (halving per step down).
pub const FULL_RATE_PIXELS: f32 = 96.0;

impl Default for CrowdAnimation {
    fn default() -> Self {
        Self::new()
    }
}

impl CrowdAnimation {
    /// Nothing animated yet.
    pub fn new() -> Self {
        CrowdAnimation {
            characters: Vec::new(),
            time: 0.0,
            frame: 0,
            moving: true,
            simulating: true,
            path: DynamicsPath::default(),
            schedule: false,
            wind: Wind::default(),
            stats: AnimationStats::default(),
        }
    }

    /// Animate character `id` with `motion`; with `hair` (its mesh and colliders in the
    /// character's frame, and the character made deformable in the renderer) its hair mesh is
    /// simulated too.
    pub fn add(
        &mut self,
        id: CharacterId,
        motion: CharacterMotion,
        hair: Option<(&HairMesh, Vec<Collider>)>,
    ) {
        let roots = hair
            .as_ref()
            .map(|(mesh, _)| mesh.layers[0].clone())
            .unwrap_or_default();
        let (bounds, dynamics) = match hair {
            Some((mesh, colliders)) => {
                let (lo, hi) =
                    crate::model::hair_mesh::bounds(mesh.layers.iter().flatten().copied());
                let settings = DynamicsSettings {
                    wind: self.wind,
                    ..Default::default()
                };
                (
                    ((lo + hi) * 0.5, (hi - lo).length() * 0.5),
                    Some(HairDynamics::new(
                        mesh,
                        colliders,
                        settings,
                        motion.model(0.0),
                    )),
                )
            }
            None => ((Vec3::ZERO, 0.0), None),
        };
        self.characters.push(AnimatedCharacter {
            id,
            motion,
            dynamics,
            bounds,
            pending_dt: 0.0,
            roots,
            on_gpu: false,
            walker: None,
        });
    }

    /// Animate character `id` as a skinned person walking or standing (`walker`), its hair
    /// bound to the head joint (`hair` as in [`Self::add`], colliders in the person frame);
    /// its body's skin matrices are handed to the renderer every frame.
    pub fn add_person(
        &mut self,
        id: CharacterId,
        walker: super::walk::Walker,
        hair: Option<(&HairMesh, Vec<Collider>)>,
    ) -> crate::error::Result<()> {
        let model = walker.frame(0.0)?.hair;
        self.add(id, CharacterMotion::still(model), hair);
        if let Some(c) = self.characters.last_mut() {
            c.walker = Some(walker);
        }
        Ok(())
    }

    /// Hair roots of simulated character `id` as last handed to the renderer (its frame), or
    /// `None` if its hair is not simulated.
    pub fn roots(&self, id: CharacterId) -> Option<&[Vec3]> {
        self.characters
            .iter()
            .find(|c| c.id == id && c.dynamics.is_some())
            .map(|c| c.roots.as_slice())
    }

    /// Seconds of animation so far.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// Advance by `dt` seconds: place every character, simulate the hair of those due this
    /// frame (seen by `camera` in an image `height` pixels tall) and hand their poses to
    /// `renderer`.
    pub fn advance(
        &mut self,
        renderer: &mut Renderer,
        dt: f32,
        camera: &Camera,
        height: u32,
    ) -> GpuResult<()> {
        let dt = if dt.is_finite() { dt.max(0.0) } else { 0.0 };
        if self.moving {
            self.time += dt;
        }
        self.frame += 1;
        let start = Instant::now();
        let mut stats = AnimationStats::default();
        let focal = height as f32 / (2.0 * (camera.fov_y * 0.5).tan());
        // Place everyone; pick the characters whose hair is due this frame.
        let mut due: Vec<(&mut AnimatedCharacter, glam::Mat4)> = Vec::new();
        for c in &mut self.characters {
            let model = match &c.walker {
                Some(w) => {
                    let f = w
                        .frame(self.time)
                        .map_err(|e| crate::vk::GpuError::Unsupported(e.to_string()))?;
                    renderer.set_character_pose(c.id, f.body, &f.skin)?;
                    f.hair
                }
                None => c.motion.model(self.time),
            };
            renderer.set_model(c.id, model)?;
            if c.dynamics.is_none() {
                continue;
            }
            c.pending_dt += dt;
            if !self.simulating {
                continue;
            }
            let centre = model.transform_point3(c.bounds.0);
            let scale = model.x_axis.truncate().length();
            let pixels = 2.0 * c.bounds.1 * scale * focal / camera.eye.distance(centre).max(1e-3);
            if !self.schedule || due_on(self.frame, c.id.slot(), update_interval(pixels)) {
                due.push((c, model));
            }
        }
        let wind = self.wind;
        let settings = |d: &HairDynamics| DynamicsSettings { wind, ..d.settings };
        match self.path {
            DynamicsPath::Cpu => simulate_on_cpu(renderer, &mut due, wind, &mut stats)?,
            DynamicsPath::Gpu => {
                for (c, model) in due.iter_mut() {
                    let Some(d) = c.dynamics.as_mut() else {
                        continue;
                    };
                    if !c.on_gpu {
                        renderer.simulate_hair(c.id, d)?;
                        c.on_gpu = true;
                    }
                    renderer.step_hair(c.id, c.pending_dt, *model, &settings(d))?;
                    c.pending_dt = 0.0;
                    stats.simulated += 1;
                    stats.vertices += d.vertex_count();
                }
            }
        }
        stats.path = self.path;
        stats.simulate_ms = start.elapsed().as_secs_f64() * 1e3;
        self.stats = stats;
        Ok(())
    }
}

/// Simulate the `due` characters on all cores (they are independent) and hand their poses to
/// `renderer`; a character last simulated on the GPU continues from the GPU's state.
fn simulate_on_cpu(
    renderer: &mut Renderer,
    due: &mut [(&mut AnimatedCharacter, glam::Mat4)],
    wind: Wind,
    stats: &mut AnimationStats,
) -> GpuResult<()> {
    for (c, _) in due.iter_mut() {
        if let (true, Some(d)) = (c.on_gpu, c.dynamics.as_mut()) {
            let (state, clock) = renderer.read_hair_state(c.id)?;
            d.set_state(state, clock)
                .map_err(crate::vk::GpuError::Unsupported)?;
        }
        c.on_gpu = false;
    }
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    let chunk = due.len().div_ceil(threads).max(1);
    std::thread::scope(|scope| {
        for part in due.chunks_mut(chunk) {
            scope.spawn(move || {
                for (c, model) in part.iter_mut() {
                    if let Some(d) = c.dynamics.as_mut() {
                        d.settings.wind = wind;
                        d.step(c.pending_dt, *model);
                        c.pending_dt = 0.0;
                    }
                }
            });
        }
    });
    for (c, _) in due.iter_mut() {
        if let Some(d) = &c.dynamics {
            let pose = d.pose();
            renderer.set_hair_mesh_pose(c.id, &pose)?;
            let n = c.roots.len();
            c.roots.copy_from_slice(&pose[..n]);
            stats.simulated += 1;
            stats.vertices += d.vertex_count();
        }
    }
    Ok(())
}

/// Whether a character in crowd slot `slot` on an update `interval` is due on `frame`: the
/// slot staggers the phase, so each frame updates about `1 / interval` of the characters on
/// that interval instead of all of them on one frame in `interval` (a frame-time spike).
pub fn due_on(frame: u64, slot: u32, interval: u64) -> bool {
    (frame + slot as u64).is_multiple_of(interval.max(1))
}

/// Frames between hair updates for a character whose hair is `pixels` tall on screen.
pub fn update_interval(pixels: f32) -> u64 {
    let mut interval = 1;
    let mut threshold = FULL_RATE_PIXELS;
    while pixels < threshold && interval < 8 {
        interval *= 2;
        threshold *= 0.5;
    }
    interval
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn update_interval_halves_with_size() {
        assert_eq!(update_interval(200.0), 1);
        assert_eq!(update_interval(60.0), 2);
        assert_eq!(update_interval(30.0), 4);
        assert_eq!(update_interval(5.0), 8);
    }

    /// Every slot is due once in each `interval` frames, and each frame takes an even share
    /// of the slots on that interval (64 slots on 8: 8 a frame), not all of them at once.
    #[test]
    fn updates_are_staggered_by_slot() {
        for interval in [1u64, 2, 4, 8] {
            let due = |frame: u64, slot: u32| due_on(frame, slot, interval) as u64;
            for frame in 0..16u64 {
                let slots: u64 = (0..64).map(|s| due(frame, s)).sum();
                assert_eq!(slots, 64 / interval, "interval {interval} frame {frame}");
            }
            for slot in 0..64u32 {
                let frames: u64 = (0..16).map(|f| due(f, slot)).sum();
                assert_eq!(frames, 16 / interval, "interval {interval} slot {slot}");
            }
        }
        assert!(due_on(5, 0, 0));
    }
}
