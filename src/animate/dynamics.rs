//! Hair mesh dynamics: position-based, with small steps (Macklin et al. 2019: many substeps of
//! one constraint pass each) and follow-the-leader inextensibility (Müller et al. 2012), on the
//! hair mesh's vertex columns (paper 003 section 4 animates hair by moving the hair mesh; it
//! simulates it after Wu and Yuksel 2016).
//!
//! Per substep: velocities gain gravity and wind and lose damping; the scalp layer follows the
//! character rigidly; soft XPBD constraints act (each vertex drawn toward its authored place in
//! the head frame, stiffer near the roots, so the style holds and returns to rest; neighbouring
//! columns keep their spacing so the mesh keeps its volume; vertices two layers apart keep
//! their distance against bending); vertices are pushed out of the colliders; then every
//! column is walked from the root, putting each vertex back at its rest distance from the one
//! below (exact edge lengths), with the velocity correction of dynamic follow-the-leader.
//!
//! The authored mesh is the equilibrium under gravity: the shape constraint's target sits
//! `g / k` above the authored place, so that gravity pulls the vertex exactly onto it at rest.

use glam::{Mat4, Vec3};

use crate::model::hair_mesh::HairMesh;

/// A canonical head's push-out: `(p, margin)` -> `p` moved out of it (equal when it is the
/// same function).
#[derive(Clone, Copy, Debug)]
pub struct PushOut(pub fn(Vec3, f32) -> Vec3);

impl PartialEq for PushOut {
    fn eq(&self, other: &Self) -> bool {
        std::ptr::fn_addr_eq(self.0, other.0)
    }
}

/// Something hair cannot enter, in the character's frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Collider {
    /// An ellipsoid (heads).
    Ellipsoid {
        /// Centre.
        centre: Vec3,
        /// Radii.
        radii: Vec3,
    },
    /// A head in its canonical frame (the human head of `characters::human`, which passes
    /// its `push_out`) placed by `to_person` (canonical head to the character's frame;
    /// `to_canonical` its inverse): points are pushed out to `margin` canonical metres
    /// outside it.
    Human {
        /// `(p, margin)` -> `p` moved out of the canonical head.
        push_out: PushOut,
        /// Canonical head to the character's frame.
        to_person: Mat4,
        /// The inverse.
        to_canonical: Mat4,
        /// Distance kept outside the head, canonical metres.
        margin: f32,
    },
    /// A capsule (shoulders, necks).
    Capsule {
        /// One end of the axis.
        a: Vec3,
        /// The other end.
        b: Vec3,
        /// Radius.
        radius: f32,
    },
}

impl Collider {
    /// A canonical head (its `push_out`) placed by `to_person`, kept `margin` canonical
    /// metres away.
    pub fn human(push_out: fn(Vec3, f32) -> Vec3, to_person: Mat4, margin: f32) -> Collider {
        Collider::Human {
            push_out: PushOut(push_out),
            to_person,
            to_canonical: to_person.inverse(),
            margin,
        }
    }

    /// `p` moved out of the collider (unchanged if outside).
    pub fn push_out(&self, p: Vec3) -> Vec3 {
        match *self {
            Collider::Ellipsoid { centre, radii } => {
                let q = (p - centre) / radii;
                let l = q.length();
                if (1e-9..1.0).contains(&l) {
                    centre + q / l * radii
                } else {
                    p
                }
            }
            Collider::Human {
                push_out,
                to_person,
                to_canonical,
                margin,
            } => {
                let q = to_canonical.transform_point3(p);
                let moved = (push_out.0)(q, margin);
                if moved == q {
                    p
                } else {
                    to_person.transform_point3(moved)
                }
            }
            Collider::Capsule { a, b, radius } => {
                let ab = b - a;
                let t = ((p - a).dot(ab) / ab.length_squared().max(1e-12)).clamp(0.0, 1.0);
                let c = a + ab * t;
                let d = p - c;
                let l = d.length();
                if l >= radius || l < 1e-9 {
                    p
                } else {
                    c + d / l * radius
                }
            }
        }
    }

    /// A sphere fitted to the scalp (layer 0) of `mesh` by least squares, shrunk to 97% so the
    /// roots start outside it: a head collider for meshes that come without one.
    pub fn fit_scalp(mesh: &HairMesh) -> Collider {
        // |p|^2 = 2 c.p + (r^2 - |c|^2): linear in (c, d); normal equations, then elimination.
        let mut a = [[0.0f64; 5]; 4];
        for p in &mesh.layers[0] {
            let row = [2.0 * p.x as f64, 2.0 * p.y as f64, 2.0 * p.z as f64, 1.0];
            for i in 0..4 {
                for j in 0..4 {
                    a[i][j] += row[i] * row[j];
                }
                a[i][4] += row[i] * p.length_squared() as f64;
            }
        }
        for c in 0..4 {
            let pivot = (c..4)
                .max_by(|&x, &y| a[x][c].abs().total_cmp(&a[y][c].abs()))
                .unwrap_or(c);
            a.swap(c, pivot);
            if a[c][c].abs() < 1e-30 {
                // Degenerate scalp (flat): a sphere at its centre that catches nothing.
                let (lo, hi) = crate::model::hair_mesh::bounds(mesh.layers[0].iter().copied());
                return Collider::Ellipsoid {
                    centre: (lo + hi) * 0.5,
                    radii: Vec3::splat(1e-6),
                };
            }
            let pivot_row = a[c];
            for (r, row) in a.iter_mut().enumerate() {
                if r != c {
                    let f = row[c] / pivot_row[c];
                    for (x, p) in row.iter_mut().zip(pivot_row) {
                        *x -= f * p;
                    }
                }
            }
        }
        let x: Vec<f64> = (0..4).map(|i| a[i][4] / a[i][i]).collect();
        let centre = Vec3::new(x[0] as f32, x[1] as f32, x[2] as f32);
        let r = (x[3] + centre.length_squared() as f64).max(0.0).sqrt() as f32;
        Collider::Ellipsoid {
            centre,
            radii: Vec3::splat(r * 0.97),
        }
    }

    fn transformed(&self, m: &Mat4) -> Collider {
        let scale = m.x_axis.truncate().length();
        match *self {
            Collider::Ellipsoid { centre, radii } => Collider::Ellipsoid {
                centre: m.transform_point3(centre),
                // Rigid motions with uniform scale; ellipsoid axes stay world-aligned, which
                // holds for the turns about the vertical the crowd uses and is close for sway.
                radii: radii * scale,
            },
            Collider::Human {
                push_out,
                to_person,
                margin,
                ..
            } => Collider::human(push_out.0, *m * to_person, margin),
            Collider::Capsule { a, b, radius } => Collider::Capsule {
                a: m.transform_point3(a),
                b: m.transform_point3(b),
                radius: radius * scale,
            },
        }
    }
}

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
    /// it falls to 30% at the tips.
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

/// Longest step simulated at once (distant characters step several frames at a time); longer
/// gaps (a hitch) are slowed down rather than integrated with a step that could explode.
pub const MAX_FRAME_STEP: f32 = 0.125;

/// One character's hair mesh in motion.
pub struct HairDynamics {
    n: usize,
    layers: usize,
    /// Authored positions, character frame, layer-major.
    rest: Vec<Vec3>,
    /// Rest distance of vertex `j` (layer >= 1) to the vertex below it.
    edge: Vec<f32>,
    /// Rest distance of vertex `j` (layer >= 2) to the vertex two layers below.
    bend: Vec<f32>,
    /// Neighbouring columns on each layer >= 1: (vertex, vertex, rest distance).
    spacing: Vec<(u32, u32, f32)>,
    colliders: Vec<Collider>,
    /// World positions and velocities.
    x: Vec<Vec3>,
    v: Vec<Vec3>,
    model: Mat4,
    time: f32,
    /// Settings (change them between steps).
    pub settings: DynamicsSettings,
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
        let mut spacing = Vec::new();
        for k in 1..layers {
            for &(a, b) in &pairs {
                let (ja, jb) = (k * n + a as usize, k * n + b as usize);
                spacing.push((ja as u32, jb as u32, rest[ja].distance(rest[jb])));
            }
        }
        let x = rest.iter().map(|p| model.transform_point3(*p)).collect();
        HairDynamics {
            n,
            layers,
            rest,
            edge,
            bend,
            spacing,
            colliders,
            x,
            v: vec![Vec3::ZERO; n * layers],
            model,
            time: 0.0,
            settings,
        }
    }

    /// Vertices simulated (all layers).
    pub fn vertex_count(&self) -> usize {
        self.x.len()
    }

    /// Advance by `dt` seconds (clamped to [`MAX_FRAME_STEP`]) while the character moves to
    /// `model`.
    pub fn step(&mut self, dt: f32, model: Mat4) {
        let dt = if dt.is_finite() {
            dt.clamp(0.0, MAX_FRAME_STEP)
        } else {
            0.0
        };
        if dt <= 0.0 {
            self.model = model;
            return;
        }
        let s = self.settings;
        let steps = s.substeps.max(1);
        let h = dt / steps as f32;
        let (s0, r0, t0) = self.model.to_scale_rotation_translation();
        let (s1, r1, t1) = model.to_scale_rotation_translation();
        for step in 1..=steps {
            let f = step as f32 / steps as f32;
            // The placement between the two frames: rotations slerped, so a sudden turn stays
            // a rigid motion through the substeps.
            let m = Mat4::from_scale_rotation_translation(
                s0.lerp(s1, f),
                r0.slerp(r1, f),
                t0.lerp(t1, f),
            );
            self.time += h;
            self.substep(h, &m);
        }
        self.model = model;
    }

    fn substep(&mut self, h: f32, m: &Mat4) {
        let s = self.settings;
        let (n, layers) = (self.n, self.layers);
        let prev = self.x.clone();
        let keep = (-s.damping * h).exp();
        let mut p = self.x.clone();
        // Scalp: rigid with the character.
        for (q, r) in p.iter_mut().zip(&self.rest).take(n) {
            *q = m.transform_point3(*r);
        }
        // Predict, and pull toward the authored shape (XPBD, per unit mass).
        for k in 1..layers {
            let along = k as f32 / (layers - 1) as f32;
            let stiffness = s.shape_stiffness * (1.0 - 0.7 * along);
            let alpha = if stiffness > 0.0 {
                1.0 / (stiffness * h * h)
            } else {
                f32::INFINITY
            };
            let sag = if stiffness > 0.0 {
                s.gravity / stiffness
            } else {
                Vec3::ZERO
            };
            for i in 0..n {
                let j = k * n + i;
                let acc = s.gravity + s.wind.acceleration(self.x[j], self.time, along);
                self.v[j] = (self.v[j] + acc * h) * keep;
                let mut q = self.x[j] + self.v[j] * h;
                let target = m.transform_point3(self.rest[j]) - sag;
                q -= (q - target) / (1.0 + alpha);
                p[j] = q;
            }
        }
        // Neighbouring columns keep their spacing; vertices two layers apart their distance.
        let spacing_alpha = s.spacing_compliance / (h * h);
        for &(a, b, d) in &self.spacing {
            let (a, b) = (a as usize, b as usize);
            distance_constraint(&mut p, (a, 1.0), (b, 1.0), d, spacing_alpha);
        }
        let bend_alpha = s.bend_compliance / (h * h);
        for k in 2..layers {
            for i in 0..n {
                let j = k * n + i;
                // The scalp (layer 0) does not move: weight 0.
                let w_below = if k == 2 { 0.0 } else { 1.0 };
                distance_constraint(
                    &mut p,
                    (j, 1.0),
                    (j - 2 * n, w_below),
                    self.bend[j],
                    bend_alpha,
                );
            }
        }
        // Colliders, placed for this substep.
        let colliders: Vec<Collider> = self.colliders.iter().map(|c| c.transformed(m)).collect();
        let collide = |mut q: Vec3| {
            for c in &colliders {
                q = c.push_out(q);
            }
            q
        };
        // Follow the leader from the root up: each vertex goes back to its rest distance from
        // the one below, alternating with the push-out so that a root jump cannot drag it into
        // a collider; edge lengths end exact. The velocity correction uses the displacement.
        let mut correction = vec![Vec3::ZERO; n * layers];
        for k in 1..layers {
            for i in 0..n {
                let (j, below) = (k * n + i, (k - 1) * n + i);
                let on_edge = |q: Vec3| {
                    let dir = (q - p[below]).try_normalize().unwrap_or(Vec3::Y);
                    p[below] + dir * self.edge[j]
                };
                let mut q = on_edge(collide(p[j]));
                // Alternate until the push-out no longer moves it (at most 16 rounds; a point
                // outside every collider costs one). Where they never agree (hair squeezed
                // between two colliders) the colliders win over the exact edge length.
                let mut settled = false;
                for _ in 0..16 {
                    let out = collide(q);
                    if out == q {
                        settled = true;
                        break;
                    }
                    q = on_edge(out);
                }
                if !settled {
                    q = collide(q);
                }
                correction[j] = q - p[j];
                p[j] = q;
            }
        }
        for k in 1..layers {
            for i in 0..n {
                let j = k * n + i;
                let mut v = (p[j] - prev[j]) / h;
                if k + 1 < layers {
                    v -= correction[j + n] * (s.ftl_damping / h);
                }
                self.v[j] = v;
            }
        }
        self.x = p;
    }

    /// The current pose in the character's frame (`layers x vertices`, layer-major), for
    /// `Renderer::set_hair_mesh_pose`.
    pub fn pose(&self) -> Vec<Vec3> {
        let inv = self.model.inverse();
        self.x.iter().map(|p| inv.transform_point3(*p)).collect()
    }

    /// World positions.
    pub fn positions(&self) -> &[Vec3] {
        &self.x
    }

    /// Largest relative deviation of a column edge from its rest length.
    pub fn max_edge_strain(&self) -> f32 {
        let n = self.n;
        (n..self.x.len())
            .map(|j| (self.x[j].distance(self.x[j - n]) / self.edge[j].max(1e-12) - 1.0).abs())
            .fold(0.0, f32::max)
    }

    /// Largest distance of a vertex from its authored place (world, at the current placement).
    pub fn max_rest_offset(&self) -> f32 {
        self.x
            .iter()
            .zip(&self.rest)
            .map(|(x, r)| x.distance(self.model.transform_point3(*r)))
            .fold(0.0, f32::max)
    }
}

/// XPBD distance constraint between points `(index, inverse mass)` with compliance
/// `alpha / h^2`.
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
