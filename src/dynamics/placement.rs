//! Where a character is during a step: its placement (scale, rotation, translation) at the
//! step's two ends, interpolated per substep with a slerp, and the clock that turns frame
//! times into steps. The CPU solver and the GPU solver (`glsl/hair_dynamics.comp`) take the
//! same plan, so the GPU is given each end once and the substeps are interpolated the same way
//! on both.

use glam::{Mat4, Quat, Vec3};

use super::DynamicsSettings;

/// Longest step simulated at once (distant characters step several frames at a time); longer
/// gaps (a hitch) are slowed down rather than integrated with a step that could explode.
pub const MAX_FRAME_STEP: f32 = 0.125;

/// A similarity transform: `p -> translation + rotation (scale * p)`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Placement {
    /// Per-axis scale (uniform for the characters the crowd draws).
    pub scale: Vec3,
    /// Unit rotation.
    pub rotation: Quat,
    /// Translation.
    pub translation: Vec3,
}

/// `q` rotating `v`: `v + 2 q.xyz x (q.xyz x v + q.w v)` (as `glsl/hair_dynamics.comp`).
pub fn rotate(q: Quat, v: Vec3) -> Vec3 {
    let u = Vec3::new(q.x, q.y, q.z);
    v + 2.0 * u.cross(u.cross(v) + q.w * v)
}

/// Spherical interpolation from `a` to `b` by `f` along the shorter arc; nearly equal
/// rotations are lerped and normalised (the GPU solver's twin).
pub fn slerp(a: Quat, b: Quat, f: f32) -> Quat {
    let mut d = a.dot(b);
    let b = if d < 0.0 {
        d = -d;
        -b
    } else {
        b
    };
    if d > 0.9995 {
        return (a * (1.0 - f) + b * f).normalize();
    }
    let theta = d.acos();
    let s = theta.sin();
    a * (((1.0 - f) * theta).sin() / s) + b * ((f * theta).sin() / s)
}

impl Placement {
    /// The placement of a model matrix (a similarity: no shear).
    pub fn of(model: &Mat4) -> Placement {
        let (scale, rotation, translation) = model.to_scale_rotation_translation();
        Placement {
            scale,
            rotation: rotation.normalize(),
            translation,
        }
    }

    /// `p` placed.
    pub fn apply(&self, p: Vec3) -> Vec3 {
        self.translation + rotate(self.rotation, self.scale * p)
    }

    /// `p` taken back to the character's frame (the inverse of [`Self::apply`]).
    pub fn unapply(&self, p: Vec3) -> Vec3 {
        rotate(self.rotation.conjugate(), p - self.translation) / self.scale
    }

    /// The placement at fraction `f` from `self` to `to`: scales and translations lerped,
    /// rotations slerped, so a sudden turn stays a rigid motion through the substeps.
    pub fn between(&self, to: &Placement, f: f32) -> Placement {
        Placement {
            scale: self.scale.lerp(to.scale, f),
            rotation: slerp(self.rotation, to.rotation, f),
            translation: self.translation.lerp(to.translation, f),
        }
    }
}

/// One step of a character's hair: its substeps between two placements.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepPlan {
    /// Placement at the start of the step.
    pub from: Placement,
    /// Placement at its end.
    pub to: Placement,
    /// Substeps.
    pub substeps: u32,
    /// Seconds per substep.
    pub h: f32,
    /// Simulation time at the start of the step (substep `s` runs at `time + s h`).
    pub time: f32,
}

impl StepPlan {
    /// Placement of substep `s` (1-based; `substeps` is the end).
    pub fn placement(&self, s: u32) -> Placement {
        self.from.between(&self.to, s as f32 / self.substeps as f32)
    }

    /// Simulation time of substep `s`.
    pub fn substep_time(&self, s: u32) -> f32 {
        self.time + self.h * s as f32
    }
}

/// A simulation's time and the character's last placement: turns `(dt, model)` into steps.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StepClock {
    /// The character's placement at the end of the last step.
    pub model: Mat4,
    /// Simulated seconds.
    pub time: f32,
}

impl StepClock {
    /// At time 0, placed by `model`.
    pub fn new(model: Mat4) -> Self {
        StepClock { model, time: 0.0 }
    }

    /// Advance by `dt` seconds (clamped to [`MAX_FRAME_STEP`]) while the character moves to
    /// `model`: the step to simulate, or `None` when no time passes (the model is taken).
    pub fn advance(
        &mut self,
        dt: f32,
        model: Mat4,
        settings: &DynamicsSettings,
    ) -> Option<StepPlan> {
        let dt = if dt.is_finite() {
            dt.clamp(0.0, MAX_FRAME_STEP)
        } else {
            0.0
        };
        let from = self.model;
        self.model = model;
        if dt <= 0.0 {
            return None;
        }
        let substeps = settings.substeps.max(1);
        let h = dt / substeps as f32;
        let plan = StepPlan {
            from: Placement::of(&from),
            to: Placement::of(&model),
            substeps,
            h,
            time: self.time,
        };
        self.time = plan.substep_time(substeps);
        Some(plan)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn placement_matches_the_matrix_and_inverts() {
        let m = Mat4::from_translation(Vec3::new(1.0, 2.0, -3.0))
            * Mat4::from_rotation_y(0.7)
            * Mat4::from_rotation_z(0.2)
            * Mat4::from_scale(Vec3::splat(1.3));
        let pl = Placement::of(&m);
        let p = Vec3::new(0.3, -0.2, 0.9);
        assert!(pl.apply(p).distance(m.transform_point3(p)) < 1e-5);
        assert!(pl.unapply(pl.apply(p)).distance(p) < 1e-5);
    }

    #[test]
    fn slerp_ends_and_middle() {
        let a = Quat::from_rotation_y(0.1);
        let b = Quat::from_rotation_y(2.1);
        assert!(slerp(a, b, 0.0).abs_diff_eq(a, 1e-6));
        assert!(slerp(a, b, 1.0).abs_diff_eq(b, 1e-6));
        assert!(slerp(a, b, 0.5).abs_diff_eq(Quat::from_rotation_y(1.1), 1e-6));
        // The shorter arc, whichever sign the second quaternion has.
        assert!(slerp(a, -b, 0.5).abs_diff_eq(Quat::from_rotation_y(1.1), 1e-6));
    }

    #[test]
    fn clock_clamps_and_counts_substeps() {
        let s = DynamicsSettings::default();
        let mut c = StepClock::new(Mat4::IDENTITY);
        assert!(c.advance(0.0, Mat4::IDENTITY, &s).is_none());
        assert!(c.advance(f32::NAN, Mat4::IDENTITY, &s).is_none());
        let plan = c.advance(1.0, Mat4::IDENTITY, &s).unwrap();
        assert_eq!(plan.substeps, s.substeps);
        assert!((plan.h * s.substeps as f32 - MAX_FRAME_STEP).abs() < 1e-6);
        assert!((c.time - MAX_FRAME_STEP).abs() < 1e-6);
    }
}
