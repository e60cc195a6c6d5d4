//! A person of the crowd: the human head ([`super::human`]) on a mannequin body (torso,
//! pelvis, arms and legs), varied per person by height and head proportions, with the skin
//! tone drawn from a realistic range. Everything here is in the person's own frame (feet at
//! the origin, +Y up, facing +Z); the head's placement in that frame is
//! [`PersonShape::head_transform`], the one transform that the drawn head, the hair's scalp,
//! the dynamics colliders and the root-gap metric all use.

use glam::{Mat4, Vec3};

use super::human::{HumanHead, direction, human_head, smooth_prop_mesh};
use crate::dynamics::Collider;
use crate::error::Result;
use crate::render::core::shared::PropVertex;
use crate::rng::Pcg32;

/// How one person differs from the canonical figure.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PersonShape {
    /// Uniform scale of the whole figure about the feet.
    pub height: f32,
    /// Scale of the head about its centre: width, height, depth.
    pub head: Vec3,
    /// Skin colour, linear RGB.
    pub skin: [f32; 3],
}

impl Default for PersonShape {
    fn default() -> Self {
        PersonShape {
            height: 1.0,
            head: Vec3::ONE,
            skin: SKIN_TONES[1],
        }
    }
}

/// Skin albedos (linear RGB) from very light to very dark; people get tones between
/// neighbours.
pub const SKIN_TONES: [[f32; 3]; 5] = [
    [0.78, 0.57, 0.46],
    [0.66, 0.44, 0.32],
    [0.50, 0.31, 0.19],
    [0.32, 0.18, 0.10],
    [0.17, 0.09, 0.05],
];

impl PersonShape {
    /// A person drawn from `seed`: height 0.92-1.08 of the canonical figure, head width,
    /// height and depth each 0.94-1.06, a skin tone anywhere in [`SKIN_TONES`].
    pub fn draw(seed: u32) -> Self {
        let mut rng = Pcg32::hashed(seed as u64 ^ 0x7065_7273_6f6e);
        let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
        let height = r(0.92, 1.08);
        let head = Vec3::new(r(0.94, 1.06), r(0.94, 1.06), r(0.94, 1.06));
        let t = r(0.0, (SKIN_TONES.len() - 1) as f32);
        let (i, f) = ((t.floor() as usize).min(SKIN_TONES.len() - 2), t.fract());
        let skin = std::array::from_fn(|c| SKIN_TONES[i][c] * (1.0 - f) + SKIN_TONES[i + 1][c] * f);
        PersonShape { height, head, skin }
    }

    /// The body's placement (canonical body to person frame): the height scale.
    pub fn body_transform(&self) -> Mat4 {
        Mat4::from_scale(Vec3::splat(self.height))
    }

    /// The head's placement (canonical head to person frame): its proportions about the
    /// cranium centre, then the height scale.
    pub fn head_transform(&self) -> Result<Mat4> {
        Ok(self.head_transform_about(human_head()?.centre))
    }

    /// [`Self::head_transform`] about cranium centre `c`.
    fn head_transform_about(&self, c: Vec3) -> Mat4 {
        self.body_transform()
            * Mat4::from_translation(c)
            * Mat4::from_scale(self.head)
            * Mat4::from_translation(-c)
    }

    /// Mean linear scale of the head (for distances measured in canonical units).
    pub fn head_scale(&self) -> f32 {
        self.height * (self.head.x + self.head.y + self.head.z) / 3.0
    }

    /// This person's head: its shape and placement.
    pub fn head(&self) -> Result<PlacedHead> {
        Ok(self.head_on(human_head()?))
    }

    /// `shape` (a head in the canonical frame) placed as this person's head.
    pub fn head_on(&self, shape: &'static HumanHead) -> PlacedHead {
        let to_person = self.head_transform_about(shape.centre);
        PlacedHead {
            shape,
            to_person,
            to_canonical: to_person.inverse(),
            scale: self.head_scale(),
        }
    }

    /// Where this person's hair grows: their head and the body below it.
    pub fn site(&self) -> Result<GrowthSite> {
        Ok(self.site_on(human_head()?))
    }

    /// [`Self::site`] with `shape` as the head (the mannequin's neck, shoulders and chest
    /// below it: a head normalized into the canonical frame sits where the Sintel head does).
    pub fn site_on(&self, shape: &'static HumanHead) -> GrowthSite {
        let b = self.body_transform();
        let body = BODY
            .iter()
            .filter(|p| p.collides)
            .map(|part| Collider::Capsule {
                a: b.transform_point3(part.a),
                b: b.transform_point3(part.b),
                radius: part.ra.max(part.rb) * self.height,
            })
            .collect();
        GrowthSite {
            head: self.head_on(shape),
            body,
            height: self.height,
            proportions: self.head * self.height,
        }
    }

    /// Colliders for the hair dynamics: the neck, the shoulders and the upper torso (the
    /// body's own shapes, [`body_mesh`]), then the head itself.
    pub fn colliders(&self) -> Result<Vec<Collider>> {
        let site = self.site()?;
        let mut out = site.body;
        // The head last: where the neck capsule and the jaw disagree, the head wins.
        out.push(Collider::head(
            &site.head.shape.map,
            site.head.to_person,
            0.005,
        ));
        Ok(out)
    }
}

/// Where hair grows, in a person frame (canonical scaled by the person's size): what the
/// hairstyle generator needs of a person, whichever head they have.
pub struct GrowthSite {
    /// The head.
    pub head: PlacedHead,
    /// Colliders of the body below the head (neck, shoulders, chest), person frame.
    pub body: Vec<Collider>,
    /// Scale of the person (lengths of hair scale with it).
    pub height: f32,
    /// Scale of the head: width, height, depth (with the height scale).
    pub proportions: Vec3,
}

/// A head placed in a person's frame.
#[derive(Clone, Copy)]
pub struct PlacedHead {
    /// The canonical head.
    pub shape: &'static HumanHead,
    /// Canonical head to person frame.
    pub to_person: Mat4,
    /// Person frame to canonical head.
    pub to_canonical: Mat4,
    /// Mean scale of `to_person`.
    pub scale: f32,
}

impl PlacedHead {
    /// Scalp point at polar angle `theta` and azimuth `phi` of the canonical head.
    pub fn surface(&self, theta: f32, phi: f32) -> Vec3 {
        self.to_person
            .transform_point3(self.shape.surface(theta, phi))
    }

    /// Outward unit normal of the head surface near the point at `(theta, phi)` (finite
    /// differences of the mapped surface).
    pub fn normal(&self, theta: f32, phi: f32) -> Vec3 {
        let e = 0.02;
        let dt = self.surface(theta + e, phi) - self.surface((theta - e).max(0.0), phi);
        let dp = self.surface(theta, phi + e) - self.surface(theta, phi - e);
        let n = dp.cross(dt);
        let out = self.surface(theta, phi) - self.centre();
        if n.length_squared() < 1e-14 || theta < 0.05 {
            return out.normalize_or(Vec3::Y);
        }
        let n = n.normalize();
        if n.dot(out) < 0.0 { -n } else { n }
    }

    /// Cranium centre in the person frame.
    pub fn centre(&self) -> Vec3 {
        self.to_person.transform_point3(self.shape.centre)
    }

    /// Typical head radius ([`CANONICAL_RADIUS`] at scale 1).
    pub fn radius(&self) -> f32 {
        CANONICAL_RADIUS * self.scale
    }

    /// Signed radial distance of `p` outside the head, metres (approximate under
    /// non-uniform proportions: measured in the canonical head and scaled back).
    pub fn gap(&self, p: Vec3) -> f32 {
        self.shape.radial_gap(self.to_canonical.transform_point3(p)) * self.scale
    }

    /// [`Self::gap`] to the head without its ears ([`super::human::HumanHead::cranium_gap`]).
    pub fn cranium_gap(&self, p: Vec3) -> f32 {
        self.shape
            .cranium_gap(self.to_canonical.transform_point3(p))
            * self.scale
    }

    /// `p` moved radially to at least `margin` metres outside the head.
    pub fn push_out(&self, p: Vec3, margin: f32) -> Vec3 {
        let q = self.to_canonical.transform_point3(p);
        let moved = self.shape.push_out(q, margin / self.scale);
        if moved == q {
            p
        } else {
            self.to_person.transform_point3(moved)
        }
    }

    /// `p` moved radially to exactly `margin` metres above the head.
    pub fn project(&self, p: Vec3, margin: f32) -> Vec3 {
        let q = self.to_canonical.transform_point3(p) - self.shape.centre;
        let d = q.normalize_or(Vec3::Y);
        let r = self.shape.radius(d) + margin / self.scale;
        self.to_person.transform_point3(self.shape.centre + d * r)
    }

    /// Polar angle and azimuth of `p` about the head centre, in the canonical head.
    pub fn angles(&self, p: Vec3) -> (f32, f32) {
        let q = self.to_canonical.transform_point3(p) - self.shape.centre;
        super::human::angles(q.normalize_or(Vec3::Y))
    }
}

/// Largest distance of hair roots from the scalp of a head drawn at `head_world` (canonical
/// head to world), in head radii: `roots` in the character's frame, placed by `model` (both as
/// the renderer draws them this frame).
pub fn root_gap(head_world: Mat4, model: Mat4, roots: &[Vec3]) -> Result<f32> {
    let head = human_head()?;
    let to_canonical = head_world.inverse() * model;
    Ok(roots
        .iter()
        .map(|r| head.radial_gap(to_canonical.transform_point3(*r)).abs() / CANONICAL_RADIUS)
        .fold(0.0, f32::max))
}

/// The canonical head's typical radius, metres.
pub const CANONICAL_RADIUS: f32 = 0.11;

/// A tapered capsule of the mannequin: axis `a..b`, radii `ra` at `a` and `rb` at `b`.
struct Part {
    a: Vec3,
    b: Vec3,
    ra: f32,
    rb: f32,
    /// Hair collides with it (shoulders, upper torso, neck).
    collides: bool,
}

const fn part(a: [f32; 3], b: [f32; 3], ra: f32, rb: f32, collides: bool) -> Part {
    Part {
        a: Vec3::from_array(a),
        b: Vec3::from_array(b),
        ra,
        rb,
        collides,
    }
}

/// The mannequin below the bust (canonical frame, metres): the bust ends at the chest
/// (about 1.27 m) with its shoulders; these parts carry it to the ground.
const BODY: [Part; 14] = [
    // Neck (inside the bust's neck) and shoulders: hair colliders only where the bust has them.
    part([0.0, 1.40, -0.025], [0.0, 1.50, -0.015], 0.048, 0.048, true),
    part(
        [-0.15, 1.355, -0.03],
        [0.15, 1.355, -0.03],
        0.06,
        0.06,
        true,
    ),
    // Chest and back, waist, pelvis.
    part([0.0, 1.10, -0.005], [0.0, 1.29, -0.01], 0.125, 0.135, true),
    part([0.0, 0.90, 0.0], [0.0, 1.08, -0.005], 0.135, 0.115, false),
    // Legs: thighs, shins.
    part([-0.09, 0.86, 0.0], [-0.095, 0.48, 0.01], 0.075, 0.05, false),
    part([0.09, 0.86, 0.0], [0.095, 0.48, 0.01], 0.075, 0.05, false),
    part(
        [-0.095, 0.48, 0.01],
        [-0.095, 0.08, -0.01],
        0.05,
        0.035,
        false,
    ),
    part(
        [0.095, 0.48, 0.01],
        [0.095, 0.08, -0.01],
        0.05,
        0.035,
        false,
    ),
    // Arms: upper arms from the bust's shoulders, forearms.
    part(
        [-0.165, 1.34, -0.03],
        [-0.2, 1.07, -0.04],
        0.046,
        0.036,
        false,
    ),
    part(
        [0.165, 1.34, -0.03],
        [0.2, 1.07, -0.04],
        0.046,
        0.036,
        false,
    ),
    part(
        [-0.2, 1.07, -0.04],
        [-0.215, 0.83, 0.0],
        0.035,
        0.026,
        false,
    ),
    part([0.2, 1.07, -0.04], [0.215, 0.83, 0.0], 0.035, 0.026, false),
    // Feet.
    part(
        [-0.095, 0.035, -0.03],
        [-0.1, 0.03, 0.12],
        0.035,
        0.03,
        false,
    ),
    part([0.095, 0.035, -0.03], [0.1, 0.03, 0.12], 0.035, 0.03, false),
];

/// Hands: ellipsoids at the wrists.
const HANDS: [(Vec3, Vec3); 2] = [
    (
        Vec3::new(-0.22, 0.76, 0.005),
        Vec3::new(0.024, 0.065, 0.042),
    ),
    (Vec3::new(0.22, 0.76, 0.005), Vec3::new(0.024, 0.065, 0.042)),
];

/// Triangles of a tapered capsule (a cone frustum capped by two spheres).
fn capsule(out: &mut Vec<[Vec3; 3]>, p: &Part, rings: usize, segments: usize) {
    let axis = (p.b - p.a).normalize_or(Vec3::Y);
    let side = axis.any_orthonormal_vector();
    let up = axis.cross(side);
    let ring = |centre: Vec3, r: f32, k: usize| {
        let phi = std::f32::consts::TAU * k as f32 / segments as f32;
        centre + (side * phi.cos() + up * phi.sin()) * r
    };
    for k in 0..segments {
        let (a0, a1) = (ring(p.a, p.ra, k), ring(p.a, p.ra, k + 1));
        let (b0, b1) = (ring(p.b, p.rb, k), ring(p.b, p.rb, k + 1));
        out.push([a0, b0, b1]);
        out.push([a0, b1, a1]);
    }
    ellipsoid(out, p.a, Vec3::splat(p.ra), rings, segments);
    ellipsoid(out, p.b, Vec3::splat(p.rb), rings, segments);
}

/// Triangles of an axis-aligned ellipsoid, counter-clockwise seen from outside.
pub fn ellipsoid(
    out: &mut Vec<[Vec3; 3]>,
    centre: Vec3,
    radii: Vec3,
    rings: usize,
    segments: usize,
) {
    let point = |ring: usize, seg: usize| {
        let theta = std::f32::consts::PI * ring as f32 / rings as f32;
        let phi = std::f32::consts::TAU * seg as f32 / segments as f32;
        centre + direction(theta, phi) * radii
    };
    for ring in 0..rings {
        for seg in 0..segments {
            let (a, b) = (point(ring, seg), point(ring + 1, seg));
            let (c, d) = (point(ring + 1, seg + 1), point(ring, seg + 1));
            out.push([a, c, b]);
            out.push([a, d, c]);
        }
    }
}

/// The mannequin body below the bust (canonical frame).
pub fn body_mesh() -> Vec<PropVertex> {
    let mut tris = Vec::new();
    for p in &BODY {
        capsule(&mut tris, p, 8, 18);
    }
    for (c, r) in HANDS {
        ellipsoid(&mut tris, c, r, 8, 14);
    }
    smooth_prop_mesh(&tris)
}

/// The head and shoulders (the bust, canonical frame).
pub fn head_mesh() -> Result<Vec<PropVertex>> {
    Ok(human_head()?.prop_mesh())
}

/// Height (canonical frame, metres) below which the bust is cut off when it sits on a skinned
/// body: the neck, above the shoulders, inside the body's collar.
pub const NECK_CUT: f32 = 1.43;

/// The bust above [`NECK_CUT`] (triangles wholly above it), the head the crowd's skinned
/// people wear.
pub fn neck_up_mesh() -> Result<Vec<PropVertex>> {
    let full = head_mesh()?;
    Ok(full
        .chunks_exact(3)
        .filter(|t| t.iter().all(|v| v.position[1] >= NECK_CUT))
        .flatten()
        .copied()
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn people_differ_and_their_heads_follow_them() {
        let a = PersonShape::draw(1);
        let b = PersonShape::draw(2);
        assert_ne!(a, b);
        for p in [a, b] {
            assert!((0.92..=1.08).contains(&p.height));
            let head = p.head().unwrap();
            let top = head.surface(0.0, 0.0);
            assert!((top.y - 1.70 * p.height).abs() < 0.03, "{top}");
            assert!(head.gap(top).abs() < 1e-4);
            let n = head.normal(0.8, 1.0);
            assert!(n.dot(head.surface(0.8, 1.0) - head.centre()) > 0.0);
        }
        assert!(!body_mesh().is_empty());
    }
}
