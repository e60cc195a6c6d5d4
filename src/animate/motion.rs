//! Whole-character motion: each character walks a small loop around its place, turns to look
//! around and sways, from its own seed; `jerk` adds sudden head turns (for stress tests).

use glam::{Mat4, Vec3};

use crate::rng::Pcg32;

/// How one character moves over time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CharacterMotion {
    /// Placement at rest (character to world).
    pub base: Mat4,
    /// Radius of the walking loop, metres (0: stands).
    pub walk_radius: f32,
    /// Walking loops per second.
    pub walk_rate: f32,
    /// Amplitude of looking around, radians.
    pub turn: f32,
    /// Looking-around cycles per second.
    pub turn_rate: f32,
    /// Sway amplitude, radians (tilt about the feet).
    pub sway: f32,
    /// Phase offset, seconds.
    pub phase: f32,
    /// Sudden turns: amplitude in radians of a square wave of period 1.5 s (0: none).
    pub jerk: f32,
}

impl CharacterMotion {
    /// Standing still at `base`.
    pub fn still(base: Mat4) -> Self {
        CharacterMotion {
            base,
            walk_radius: 0.0,
            walk_rate: 0.0,
            turn: 0.0,
            turn_rate: 0.0,
            sway: 0.0,
            phase: 0.0,
            jerk: 0.0,
        }
    }

    /// A lively but unhurried motion drawn from `seed`.
    pub fn idle(base: Mat4, seed: u32) -> Self {
        let mut rng = Pcg32::new(seed as u64 ^ 0x6d6f_7469_6f6e);
        let mut r = |lo: f32, hi: f32| lo + (hi - lo) * rng.next_f32();
        CharacterMotion {
            base,
            walk_radius: r(0.0, 0.12),
            walk_rate: r(0.05, 0.15),
            turn: r(0.3, 0.8),
            turn_rate: r(0.1, 0.3),
            sway: r(0.02, 0.06),
            phase: r(0.0, 20.0),
            jerk: 0.0,
        }
    }

    /// Placement at time `t` seconds.
    pub fn model(&self, t: f32) -> Mat4 {
        let t = t + self.phase;
        let tau = std::f32::consts::TAU;
        let a = tau * self.walk_rate * t;
        let walk = Vec3::new(a.cos() - 1.0, 0.0, a.sin()) * self.walk_radius;
        let jerk = if self.jerk != 0.0 {
            self.jerk * (tau * t / 1.5).sin().signum()
        } else {
            0.0
        };
        let yaw = self.turn * (tau * self.turn_rate * t).sin() + jerk;
        let roll = self.sway * (tau * 0.37 * t).sin();
        let pitch = self.sway * 0.5 * (tau * 0.23 * t + 1.0).sin();
        self.base
            * Mat4::from_translation(walk)
            * Mat4::from_rotation_y(yaw)
            * Mat4::from_rotation_z(roll)
            * Mat4::from_rotation_x(pitch)
    }
}
