//! People who walk: the root moves along a path at the walk clip's ground speed (so the
//! planted feet do not slide) and turns along it; people who stand keep their place while the
//! idle clip plays. The body is skinned from the clip and the hair follows the head joint
//! ([`crate::characters::people::head_bound`]).

use std::sync::Arc;

use glam::{Mat4, Quat, Vec3};

use crate::characters::own::OwnCharacter;
use crate::characters::people::{Outfit, head_bound, pose, walk_speed};
use crate::characters::person::PersonShape;
use crate::dynamics::Collider;
use crate::error::Result;

/// The smallest ring people walk: turning swings a planted foot about the body, so tighter
/// rings slide the feet (0.45 m/s on a 0.6 m ring, against 1.09 m/s walking).
pub const MIN_RING_RADIUS: f32 = 4.0;

/// Where a person's root goes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum WalkPath {
    /// Stands at a placement.
    Stand(Mat4),
    /// Walks round a circle about `centre` of `radius`, starting at `angle` (radians, from
    /// +X toward +Z), counter-clockwise seen from above when `clockwise` is false.
    Ring {
        /// Centre on the ground.
        centre: Vec3,
        /// Radius, metres.
        radius: f32,
        /// Start angle.
        angle: f32,
        /// Direction.
        clockwise: bool,
    },
}

/// A skinned mesh a walker wears and its colour: `(mesh index, linear RGBA)`.
pub type SkinPart = (usize, [f32; 4]);

/// What a walker's body is.
#[derive(Clone)]
pub enum Rig {
    /// One of the crowd's people: a figure in an outfit, wearing the Sintel head.
    Person(Outfit),
    /// A copy of the user's character ([`OwnCharacter`]), its clip `phase` seconds in.
    Own {
        /// The character.
        character: Arc<OwnCharacter>,
        /// Walks (else plays its clip standing).
        walks: bool,
        /// Seconds into the clip at time 0.
        phase: f32,
    },
}

/// A walking (or standing) person.
#[derive(Clone)]
pub struct Walker {
    /// Their body: figure and clothes, or the user's character.
    pub rig: Rig,
    /// Uniform scale of the figure (the person's height).
    pub height: f32,
    /// The head's proportions (width, height, depth) about the cranium centre.
    pub head: Vec3,
    /// The path.
    pub path: WalkPath,
}

impl Walker {
    /// The root placement at `t` seconds (on the ground, facing along the path).
    pub fn root(&self, t: f32) -> Result<Mat4> {
        Ok(match self.path {
            WalkPath::Stand(m) => m,
            WalkPath::Ring {
                centre,
                radius,
                angle,
                clockwise,
            } => {
                let speed = self.speed()?;
                let sign = if clockwise { -1.0 } else { 1.0 };
                let a = angle + sign * speed * t / radius.max(0.05);
                let at = centre + Vec3::new(a.cos(), 0.0, a.sin()) * radius;
                let tangent = Vec3::new(-a.sin(), 0.0, a.cos()) * sign;
                let yaw = tangent.x.atan2(tangent.z);
                Mat4::from_rotation_translation(Quat::from_rotation_y(yaw), at)
            }
        })
    }

    /// Ground speed while walking, metres per second (0 for a clip that plants no feet).
    pub fn speed(&self) -> Result<f32> {
        Ok(match &self.rig {
            Rig::Person(outfit) => walk_speed(outfit.figure)? * self.height,
            Rig::Own { character, .. } => character.walk_speed().unwrap_or(0.0) * self.height,
        })
    }

    /// Whether they walk (else they stand and play their clip in place).
    pub fn walks(&self) -> bool {
        match &self.rig {
            Rig::Person(outfit) => outfit.walks,
            Rig::Own { walks, .. } => *walks,
        }
    }

    /// At `t` seconds: the hair's model (the head-bound person frame), the body's model
    /// and its skin matrices ([`crate::characters::people::head_bound`]).
    pub fn frame(&self, t: f32) -> Result<PersonFrame> {
        let (skin, head) = match &self.rig {
            Rig::Person(outfit) => pose(outfit, t, self.head)?,
            Rig::Own {
                character, phase, ..
            } => character.pose(t + phase),
        };
        let (hair, body) = head_bound(self.root(t)?, self.height, head);
        Ok(PersonFrame { hair, body, skin })
    }

    /// The skinned parts they wear (`(mesh, colour)`, the skin tinted `skin`) and the number
    /// of skin matrices their frames carry.
    pub fn parts(&self, skin: [f32; 3]) -> Result<(Vec<SkinPart>, usize)> {
        Ok(match &self.rig {
            Rig::Person(outfit) => (
                outfit.parts(skin),
                crate::characters::people::head_shape_joint()? + 1,
            ),
            Rig::Own { character, .. } => (character.parts(), character.joint_count()),
        })
    }

    /// Colliders for their hair dynamics, in the hair's frame; `person`: the shape of one of
    /// the people (ignored for the user's character).
    pub fn colliders(&self, person: &PersonShape) -> Result<Vec<Collider>> {
        match &self.rig {
            Rig::Person(outfit) => crate::characters::people::colliders(outfit.figure, person),
            Rig::Own { character, .. } => character.colliders(),
        }
    }

    /// How the scalp follows the skin: the index of the skin matrix that carries it, the
    /// head's placement in the hair's frame (canonical head to hair frame), and its mean
    /// scale (the root-gap unit is the canonical head radius times it).
    pub fn scalp(&self, person: &PersonShape) -> Result<(usize, Mat4, f32)> {
        Ok(match &self.rig {
            Rig::Person(_) => (
                crate::characters::people::head_shape_joint()?,
                person.head_transform()?,
                person.head_scale(),
            ),
            Rig::Own { character, .. } => {
                (character.head_joint, Mat4::IDENTITY, character.head.scale)
            }
        })
    }
}

/// A walker at one instant.
#[derive(Clone, Debug, PartialEq)]
pub struct PersonFrame {
    /// The hair's model (person frame to world).
    pub hair: Mat4,
    /// The body's model (figure frame to world).
    pub body: Mat4,
    /// The body's skin matrices, the head shape joint's last.
    pub skin: Vec<Mat4>,
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::characters::people::{Figure, Outfit, figures};

    /// World speed of the planted foot (the lower ball of the feet, while within 1 cm of the
    /// ground) of a man walking round a ring of `radius`, median over two cycles at 120 Hz.
    fn planted_speed(radius: f32) -> f32 {
        let outfit = Outfit {
            figure: Figure::Man,
            walks: true,
            phase: 0.0,
            ..Outfit::draw(1, true)
        };
        let w = Walker {
            rig: Rig::Person(outfit),
            height: 1.0,
            head: Vec3::ONE,
            path: WalkPath::Ring {
                centre: Vec3::ZERO,
                radius,
                angle: 0.0,
                clockwise: false,
            },
        };
        let c = &figures().unwrap()[0];
        let s = &c.skeleton;
        let feet = [s.find("ball_l").unwrap(), s.find("ball_r").unwrap()];
        let walk = c.clip("walk").unwrap();
        let dt = 1.0 / 120.0;
        let at = |t: f32, j: usize| {
            let globals = s.globals(&walk.sample(s, t));
            (w.root(t).unwrap() * globals[j]).w_axis.truncate()
        };
        let mut speeds = Vec::new();
        for k in 0..264 {
            let t = k as f32 * dt;
            let j = *feet
                .iter()
                .min_by(|a, b| at(t, **a).y.total_cmp(&at(t, **b).y))
                .unwrap();
            let (p0, p1) = (at(t, j), at(t + dt, j));
            if p0.y < 0.03 && p1.y < 0.03 {
                speeds.push(Vec3::new(p1.x - p0.x, 0.0, p1.z - p0.z).length() / dt);
            }
        }
        speeds.sort_by(f32::total_cmp);
        speeds[speeds.len() / 2]
    }

    /// Feet stay planted: on a straight-ish path (radius 20 m) the planted foot moves at 0.015
    /// m/s against a walking speed of 1.09 m/s (bound 0.05); on the crowd's tightest ring
    /// ([`MIN_RING_RADIUS`]) the turn swings the planted foot about the body a little more
    /// (bound: a tenth of the walking speed).
    #[test]
    fn planted_feet_do_not_slide() {
        let straight = planted_speed(20.0);
        let tight = planted_speed(MIN_RING_RADIUS);
        println!(
            "planted foot: {straight:.3} m/s on a 20 m ring, {tight:.3} m/s on {MIN_RING_RADIUS} m"
        );
        assert!(straight < 0.05, "{straight} m/s");
        assert!(tight < 0.109, "{tight} m/s");
    }
}
