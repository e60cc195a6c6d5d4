//! People who walk: the root moves along a path at the walk clip's ground speed (so the
//! planted feet do not slide) and turns along it; people who stand keep their place while the
//! idle clip plays. The body is skinned from the clip and the hair follows the head joint
//! ([`crate::characters::people::head_bound`]).

use glam::{Mat4, Quat, Vec3};

use crate::characters::people::{Outfit, head_bound, pose, walk_speed};
use crate::error::Result;

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

/// A walking (or standing) person.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Walker {
    /// Clothes, figure, clip and phase.
    pub outfit: Outfit,
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
                let speed = walk_speed(self.outfit.figure)? * self.height;
                let sign = if clockwise { -1.0 } else { 1.0 };
                let a = angle + sign * speed * t / radius.max(0.05);
                let at = centre + Vec3::new(a.cos(), 0.0, a.sin()) * radius;
                let tangent = Vec3::new(-a.sin(), 0.0, a.cos()) * sign;
                let yaw = tangent.x.atan2(tangent.z);
                Mat4::from_rotation_translation(Quat::from_rotation_y(yaw), at)
            }
        })
    }

    /// At `t` seconds: the hair's model (the head-bound person frame), the body's model
    /// and its skin matrices ([`crate::characters::people::head_bound`]).
    pub fn frame(&self, t: f32) -> Result<PersonFrame> {
        let (skin, head) = pose(&self.outfit, t, self.head)?;
        let (hair, body) = head_bound(self.root(t)?, self.height, head);
        Ok(PersonFrame { hair, body, skin })
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
