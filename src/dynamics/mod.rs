//! Hair mesh dynamics: position-based, with small steps (Macklin et al. 2019: many substeps of
//! one constraint pass each) and follow-the-leader inextensibility (Müller et al. 2012), on the
//! hair mesh's vertex columns (paper 003 section 4 animates hair by moving the hair mesh; it
//! simulates it after Wu and Yuksel 2016).
//!
//! Per substep, in phases that each read only what the phase before wrote, so every vertex
//! (or column) of a phase can be solved at once: this is the CPU twin of
//! `glsl/hair_dynamics.comp`, which runs the same phases in the same order.
//! 1. **Predict**: velocities gain gravity and wind and lose damping; the scalp layer follows
//!    the character rigidly; each vertex is pulled toward its authored place in the head frame
//!    (a soft XPBD constraint, stiffer near the roots, so the style holds and returns to rest).
//! 2. **Spacing**: neighbouring columns keep their distance on every layer, so the mesh keeps
//!    its volume.
//! 3. **Bending**: vertices two layers apart keep their distance.
//! 4. **Follow the leader**, per column from the root: each vertex goes back to its rest
//!    distance from the one below (exact edge lengths), alternating with the colliders'
//!    push-out.
//! 5. **Velocities** from the positions, with the velocity correction of dynamic
//!    follow-the-leader.
//!
//! Spacing and bending are solved Gauss-Seidel a colour at a time: the constraints are coloured
//! so that no two of a colour share a vertex, which makes the result independent of the order
//! within a colour and lets the GPU solve a colour in parallel and still equal this code within
//! rounding. (Jacobi with averaging, the other parallel order, left head_long 2 mm from rest
//! 10 s after its motion stopped, oscillating; the coloured order settles like the sequential
//! one.)
//!
//! The authored mesh is the equilibrium under gravity: the shape constraint's target sits
//! `g / k` above the authored place, so that gravity pulls the vertex exactly onto it at rest
//! (the sag-free initialisation of Hsu et al. 2022, for this force model).

mod collider;
mod placement;

pub use collider::{Collider, RadialMap, angles};
pub use placement::{MAX_FRAME_STEP, Placement, StepClock, StepPlan, rotate, slerp};

use glam::{Mat4, Vec3};

use crate::model::hair_mesh::HairMesh;

/// Wind: a global direction with gusts, settable live.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Wind {
    /// World direction (normalised when used).
    pub direction: Vec3,
    /// Mean acceleration on the tips, m/s^2 (0: calm).
    pub strength: f32,
    /// Gust amplitude as a fraction of the strength, 0..=1.
    pub gustiness: f32,
}

impl Default for Wind {
    fn default() -> Self {
        Wind {
            direction: Vec3::X,
            strength: 0.0,
            gustiness: 0.5,
        }
    }
}

impl Wind {
    /// Acceleration at world point `p` and time `t` on a vertex at fraction `along` of its
    /// column (tips catch more wind than roots).
    pub fn acceleration(&self, p: Vec3, t: f32, along: f32) -> Vec3 {
        if self.strength <= 0.0 {
            return Vec3::ZERO;
        }
        let dir = self.direction.normalize_or(Vec3::X);
        // Gusts: two incommensurate sines travelling along the wind, plus a little
        // across-wind variation so strands do not move in lockstep.
        let s = p.dot(dir) * 2.0 - t;
        let gust = 1.0 + self.gustiness * (0.6 * (1.7 * s).sin() + 0.4 * (4.3 * s + 1.3).sin());
        let across = 0.15 * (3.1 * p.y + 2.3 * t).sin();
        (dir + Vec3::Y * across) * (self.strength * gust * (0.3 + 0.7 * along))
    }
}

/// Simulation settings.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DynamicsSettings {
    /// Substeps per frame.
    pub substeps: u32,
    /// World gravity, m/s^2.
    pub gravity: Vec3,
    /// Wind.
    pub wind: Wind,
    /// Velocity damping per second (fraction lost is `1 - exp(-damping dt)`).
    pub damping: f32,
    /// Stiffness of the pull toward the authored shape at the roots (per unit mass, 1/s^2);
    /// it falls by [`SHAPE_TIP_LOSS`] of it at the tips.
    pub shape_stiffness: f32,
    /// Compliance of the spacing between neighbouring columns.
    pub spacing_compliance: f32,
    /// Compliance of the bending distance (vertices two layers apart).
    pub bend_compliance: f32,
    /// Velocity correction of follow-the-leader (0..=1; Müller et al. use 0.9).
    pub ftl_damping: f32,
}

impl Default for DynamicsSettings {
    fn default() -> Self {
        DynamicsSettings {
            substeps: 6,
            gravity: Vec3::new(0.0, -9.81, 0.0),
            wind: Wind::default(),
            damping: 2.0,
            // Softer shapes or stiffer spacing/bending let strongly blown hair lock into a
            // folded state that does not return to rest (measured on head_long).
            shape_stiffness: 400.0,
            spacing_compliance: 1e-3,
            bend_compliance: 1e-4,
            ftl_damping: 0.9,
        }
    }
}

impl DynamicsSettings {
    /// Check ranges (finite, non-negative, 1..=64 substeps).
    pub fn validate(&self) -> Result<(), String> {
        let finite = [
            self.gravity.x,
            self.gravity.y,
            self.gravity.z,
            self.wind.direction.x,
            self.wind.direction.y,
            self.wind.direction.z,
            self.wind.strength,
            self.wind.gustiness,
            self.damping,
            self.shape_stiffness,
            self.spacing_compliance,
            self.bend_compliance,
            self.ftl_damping,
        ];
        if finite.iter().any(|v| !v.is_finite()) {
            return Err("dynamics settings must be finite".into());
        }
        if !(1..=64).contains(&self.substeps) {
            return Err(format!("substeps {} must be 1..=64", self.substeps));
        }
        let non_negative = [
            ("wind strength", self.wind.strength),
            ("damping", self.damping),
            ("shape stiffness", self.shape_stiffness),
            ("spacing compliance", self.spacing_compliance),
            ("bend compliance", self.bend_compliance),
        ];
        if let Some((name, v)) = non_negative.iter().find(|(_, v)| *v < 0.0) {
            return Err(format!("{name} {v} must be >= 0"));
        }
        if !(0.0..=1.0).contains(&self.wind.gustiness) || !(0.0..=1.0).contains(&self.ftl_damping) {
            return Err("gustiness and follow-the-leader damping must be in 0..=1".into());
        }
        Ok(())
    }
}

/// A hair mesh's constraint structure at rest, shared by the CPU solver and the GPU's upload.
#[derive(Clone, Debug)]
pub struct HairTopology {
    /// Vertices per layer.
    pub n: usize,
    /// Layers (at least 2).
    pub layers: usize,
    /// Authored positions, character frame, layer-major.
    pub rest: Vec<Vec3>,
    /// Rest distance of vertex `j` (layer >= 1) to the vertex below it (0 on the scalp).
    pub edge: Vec<f32>,
    /// Rest distance of vertex `j` (layer >= 2) to the vertex two layers below (else 0).
    pub bend: Vec<f32>,
    /// Spacing constraints `(vertex, vertex, rest distance)`: every face edge on every layer
    /// >= 1, grouped by colour (no two constraints of a colour share a vertex).
    pub spacing: Vec<(u32, u32, f32)>,
    /// Colour `c` is `spacing[spacing_colours[c]..spacing_colours[c + 1]]`.
    pub spacing_colours: Vec<u32>,
}

/// The shape pull falls by this fraction of its root stiffness from the roots to the tips.
pub const SHAPE_TIP_LOSS: f32 = 0.7;

/// Rounds of push-out and edge-length projection per vertex in follow-the-leader.
pub const COLLISION_ROUNDS: u32 = 16;

/// A collider's bounding sphere, placed for a substep, is widened by this factor and
/// [`BOUND_PAD`] metres against rounding, so a point outside it is outside the collider.
pub const BOUND_SLACK: f32 = 1.001;
/// See [`BOUND_SLACK`].
pub const BOUND_PAD: f32 = 1e-4;

/// Colliders' bounding spheres placed for a substep: world centre and padded radius squared.
/// A point outside all of them skips the exact push-out, whose result would be itself.
pub fn placed_bounds(colliders: &[Collider], placement: &Placement) -> Vec<(Vec3, f32)> {
    let stretch = placement.scale.abs().max_element();
    colliders
        .iter()
        .map(|c| {
            let (centre, radius) = c.bounding_sphere();
            let r = radius * stretch * BOUND_SLACK + BOUND_PAD;
            (placement.apply(centre), r * r)
        })
        .collect()
}

/// Colours of the bending constraints: the constraint of layer `k` (to layer `k - 2`) has
/// colour `(k / 2) % 2`, so no two of a colour share a vertex.
pub const BEND_COLOURS: usize = 2;

/// Colour of the bending constraint of layer `k >= 2`.
pub fn bend_colour(k: usize) -> usize {
    (k / 2) % BEND_COLOURS
}

/// Greedy edge colouring of `pairs` (in their order): each takes the smallest colour neither
/// end has yet. Returns each pair's colour.
fn edge_colours(pairs: &[(u32, u32)], vertices: usize) -> Vec<usize> {
    let mut used: Vec<Vec<bool>> = vec![Vec::new(); vertices];
    pairs
        .iter()
        .map(|&(a, b)| {
            let (a, b) = (a as usize, b as usize);
            let free = |u: &Vec<bool>, c: usize| !u.get(c).copied().unwrap_or(false);
            let c = (0..)
                .find(|&c| free(&used[a], c) && free(&used[b], c))
                .unwrap_or(0);
            for v in [a, b] {
                if used[v].len() <= c {
                    used[v].resize(c + 1, false);
                }
                used[v][c] = true;
            }
            c
        })
        .collect()
}

impl HairTopology {
    /// The constraints of `mesh` at rest.
    pub fn new(mesh: &HairMesh) -> Self {
        let n = mesh.vertices_per_layer();
        let layers = mesh.layer_count();
        let rest: Vec<Vec3> = mesh.layers.iter().flatten().copied().collect();
        let mut edge = vec![0.0; n * layers];
        let mut bend = vec![0.0; n * layers];
        for k in 1..layers {
            for i in 0..n {
                edge[k * n + i] = rest[k * n + i].distance(rest[(k - 1) * n + i]);
                if k >= 2 {
                    bend[k * n + i] = rest[k * n + i].distance(rest[(k - 2) * n + i]);
                }
            }
        }
        let mut pairs = std::collections::BTreeSet::new();
        for f in &mesh.faces {
            let v = f.vertices();
            for c in 0..v.len() {
                let (a, b) = (v[c], v[(c + 1) % v.len()]);
                pairs.insert((a.min(b), a.max(b)));
            }
        }
        let pairs: Vec<(u32, u32)> = pairs.into_iter().collect();
        let colours = edge_colours(&pairs, n);
        let colour_count = colours.iter().max().map_or(0, |c| c + 1);
        let mut spacing = Vec::new();
        let mut spacing_colours = vec![0];
        for colour in 0..colour_count {
            for k in 1..layers {
                for (&(a, b), _) in pairs.iter().zip(&colours).filter(|(_, c)| **c == colour) {
                    let (ja, jb) = (k * n + a as usize, k * n + b as usize);
                    spacing.push((ja as u32, jb as u32, rest[ja].distance(rest[jb])));
                }
            }
            spacing_colours.push(spacing.len() as u32);
        }
        HairTopology {
            n,
            layers,
            rest,
            edge,
            bend,
            spacing,
            spacing_colours,
        }
    }
}

/// Positions and velocities of a simulation (world frame).
#[derive(Clone, Debug, PartialEq)]
pub struct HairState {
    /// Positions.
    pub x: Vec<Vec3>,
    /// Velocities.
    pub v: Vec<Vec3>,
}

/// One character's hair mesh in motion (the CPU solver).
pub struct HairDynamics {
    topology: HairTopology,
    colliders: Vec<Collider>,
    state: HairState,
    clock: StepClock,
    /// Settings (change them between steps).
    pub settings: DynamicsSettings,
}

/// The per-substep constants of the predict phase.
struct Substep {
    placement: Placement,
    h: f32,
    time: f32,
    keep: f32,
}

impl HairDynamics {
    /// Start at rest: `mesh` placed by `model` (character to world), colliders in the
    /// character's frame.
    pub fn new(
        mesh: &HairMesh,
        colliders: Vec<Collider>,
        settings: DynamicsSettings,
        model: Mat4,
    ) -> Self {
        let topology = HairTopology::new(mesh);
        let x = topology
            .rest
            .iter()
            .map(|p| model.transform_point3(*p))
            .collect();
        let v = vec![Vec3::ZERO; topology.rest.len()];
        HairDynamics {
            topology,
            colliders,
            state: HairState { x, v },
            clock: StepClock::new(model),
            settings,
        }
    }

    /// Vertices simulated (all layers).
    pub fn vertex_count(&self) -> usize {
        self.state.x.len()
    }

    /// The constraint structure.
    pub fn topology(&self) -> &HairTopology {
        &self.topology
    }

    /// The colliders, character frame.
    pub fn colliders(&self) -> &[Collider] {
        &self.colliders
    }

    /// Positions and velocities.
    pub fn state(&self) -> &HairState {
        &self.state
    }

    /// The clock (time simulated, placement at the last step).
    pub fn clock(&self) -> &StepClock {
        &self.clock
    }

    /// Continue from `state` and `clock` (another solver's, e.g. the GPU's); `state` must have
    /// this mesh's vertex count.
    pub fn set_state(&mut self, state: HairState, clock: StepClock) -> Result<(), String> {
        let n = self.vertex_count();
        if state.x.len() != n || state.v.len() != n {
            return Err(format!("state of {} vertices for {n}", state.x.len()));
        }
        self.state = state;
        self.clock = clock;
        Ok(())
    }

    /// Advance by `dt` seconds (clamped to [`MAX_FRAME_STEP`]) while the character moves to
    /// `model`.
    pub fn step(&mut self, dt: f32, model: Mat4) {
        let Some(plan) = self.clock.advance(dt, model, &self.settings) else {
            return;
        };
        let keep = (-self.settings.damping * plan.h).exp();
        for s in 1..=plan.substeps {
            let sub = Substep {
                placement: plan.placement(s),
                h: plan.h,
                time: plan.substep_time(s),
                keep,
            };
            self.substep(&sub);
        }
    }

    fn substep(&mut self, sub: &Substep) {
        let mut p = self.predict(sub);
        self.spacing(&mut p, sub.h);
        self.bending(&mut p, sub.h);
        let correction = self.follow_the_leader(&mut p, &sub.placement);
        self.velocities(p, &correction, sub.h);
    }

    /// Phase 1: the scalp placed rigidly, the other vertices moved by their velocities and
    /// pulled toward their authored places.
    fn predict(&mut self, sub: &Substep) -> Vec<Vec3> {
        let s = &self.settings;
        let t = &self.topology;
        let (n, layers) = (t.n, t.layers);
        let mut p = vec![Vec3::ZERO; n * layers];
        for (q, r) in p.iter_mut().zip(&t.rest).take(n) {
            *q = sub.placement.apply(*r);
        }
        for k in 1..layers {
            let along = k as f32 / (layers - 1) as f32;
            let stiffness = s.shape_stiffness * (1.0 - SHAPE_TIP_LOSS * along);
            for i in 0..n {
                let j = k * n + i;
                let acc = s.gravity + s.wind.acceleration(self.state.x[j], sub.time, along);
                let v = (self.state.v[j] + acc * sub.h) * sub.keep;
                let mut q = self.state.x[j] + v * sub.h;
                if stiffness > 0.0 {
                    let alpha = 1.0 / (stiffness * sub.h * sub.h);
                    let target = sub.placement.apply(t.rest[j]) - s.gravity / stiffness;
                    q -= (q - target) / (1.0 + alpha);
                }
                p[j] = q;
            }
        }
        p
    }

    /// Phase 2: neighbouring columns keep their spacing, a colour at a time.
    fn spacing(&self, p: &mut [Vec3], h: f32) {
        let t = &self.topology;
        let alpha = self.settings.spacing_compliance / (h * h);
        for c in t.spacing_colours.windows(2) {
            for &(a, b, rest) in &t.spacing[c[0] as usize..c[1] as usize] {
                distance_constraint(p, (a as usize, 1.0), (b as usize, 1.0), rest, alpha);
            }
        }
    }

    /// Phase 3: vertices two layers apart keep their distance, a colour at a time (the scalp
    /// does not move).
    fn bending(&self, p: &mut [Vec3], h: f32) {
        let t = &self.topology;
        let (n, layers) = (t.n, t.layers);
        let alpha = self.settings.bend_compliance / (h * h);
        for colour in 0..BEND_COLOURS {
            for k in (2..layers).filter(|&k| bend_colour(k) == colour) {
                let w_below = if k == 2 { 0.0 } else { 1.0 };
                for i in 0..n {
                    let j = k * n + i;
                    distance_constraint(p, (j, 1.0), (j - 2 * n, w_below), t.bend[j], alpha);
                }
            }
        }
    }

    /// `p` pushed out of every collider at `placement` (bit-for-bit unchanged if outside
    /// them all).
    fn collide(&self, p: Vec3, placement: &Placement, bounds: &[(Vec3, f32)]) -> Vec3 {
        if bounds.iter().all(|&(c, r2)| (p - c).length_squared() > r2) {
            return p;
        }
        let local = placement.unapply(p);
        let moved = self.colliders.iter().fold(local, |q, c| c.push_out(q));
        if moved == local {
            p
        } else {
            placement.apply(moved)
        }
    }

    /// Phase 4: every column from the root, each vertex back at its rest distance from the one
    /// below, alternating with the push-out so that a root jump cannot drag it into a
    /// collider; edge lengths end exact. Returns each vertex's displacement.
    fn follow_the_leader(&self, p: &mut [Vec3], placement: &Placement) -> Vec<Vec3> {
        let t = &self.topology;
        let (n, layers) = (t.n, t.layers);
        let mut correction = vec![Vec3::ZERO; n * layers];
        let bounds = placed_bounds(&self.colliders, placement);
        for i in 0..n {
            for k in 1..layers {
                let (j, below) = (k * n + i, (k - 1) * n + i);
                let base = p[below];
                let on_edge = |q: Vec3| {
                    let dir = (q - base).try_normalize().unwrap_or(Vec3::Y);
                    base + dir * t.edge[j]
                };
                let mut q = on_edge(self.collide(p[j], placement, &bounds));
                // Alternate until the push-out no longer moves it (at most COLLISION_ROUNDS; a
                // point outside every collider costs one). Where they never agree (hair
                // squeezed between two colliders) the colliders win over the exact edge length.
                let mut settled = false;
                for _ in 0..COLLISION_ROUNDS {
                    let out = self.collide(q, placement, &bounds);
                    if out == q {
                        settled = true;
                        break;
                    }
                    q = on_edge(out);
                }
                if !settled {
                    q = self.collide(q, placement, &bounds);
                }
                correction[j] = q - p[j];
                p[j] = q;
            }
        }
        correction
    }

    /// Phase 5: velocities from the positions, less the follow-the-leader correction of the
    /// vertex above (Müller et al. 2012, eq. 9).
    fn velocities(&mut self, p: Vec<Vec3>, correction: &[Vec3], h: f32) {
        let t = &self.topology;
        let (n, layers) = (t.n, t.layers);
        let ftl = self.settings.ftl_damping;
        for k in 1..layers {
            for i in 0..n {
                let j = k * n + i;
                let mut v = (p[j] - self.state.x[j]) / h;
                if k + 1 < layers {
                    v -= correction[j + n] * (ftl / h);
                }
                self.state.v[j] = v;
            }
        }
        self.state.x = p;
    }

    /// The current pose in the character's frame (`layers x vertices`, layer-major), for
    /// `Renderer::set_hair_mesh_pose`.
    pub fn pose(&self) -> Vec<Vec3> {
        let placement = Placement::of(&self.clock.model);
        self.state.x.iter().map(|p| placement.unapply(*p)).collect()
    }

    /// World positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.state.x
    }

    /// Largest relative deviation of a column edge from its rest length.
    pub fn max_edge_strain(&self) -> f32 {
        max_edge_strain(&self.topology, &self.state.x)
    }

    /// Largest distance of a vertex from its authored place (world, at the current placement).
    pub fn max_rest_offset(&self) -> f32 {
        let m = self.clock.model;
        self.state
            .x
            .iter()
            .zip(&self.topology.rest)
            .map(|(x, r)| x.distance(m.transform_point3(*r)))
            .fold(0.0, f32::max)
    }
}

/// Largest relative deviation of a column edge of `x` from its rest length in `topology`.
pub fn max_edge_strain(topology: &HairTopology, x: &[Vec3]) -> f32 {
    let n = topology.n;
    (n..x.len())
        .map(|j| (x[j].distance(x[j - n]) / topology.edge[j].max(1e-12) - 1.0).abs())
        .fold(0.0, f32::max)
}

/// XPBD distance constraint between points `(index, inverse mass)` with compliance
/// `alpha / h^2` (Macklin et al. 2016, eq. 18 for one constraint from rest).
fn distance_constraint(p: &mut [Vec3], a: (usize, f32), b: (usize, f32), rest: f32, alpha: f32) {
    let d = p[a.0] - p[b.0];
    let l = d.length();
    if l < 1e-9 || a.1 + b.1 <= 0.0 {
        return;
    }
    let lambda = -(l - rest) / (a.1 + b.1 + alpha);
    let corr = d / l * lambda;
    p[a.0] += corr * a.1;
    p[b.0] -= corr * b.1;
}
