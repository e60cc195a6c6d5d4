//! Animation clips: channels that drive one property of one joint by keyframes, sampled as
//! glTF 2.0 defines (Appendix C, "Interpolation"): step, linear (rotations by spherical linear
//! interpolation) and cubic spline (Hermite with in- and out-tangents scaled by the key
//! interval; rotations normalized after).

use glam::{Quat, Vec3, Vec4};

use super::{Pose, Skeleton};

/// How a channel interpolates between keys.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Interpolation {
    /// The value of the previous key.
    Step,
    /// Linear (slerp for rotations).
    Linear,
    /// Cubic Hermite spline; each key holds in-tangent, value, out-tangent.
    CubicSpline,
}

/// A channel's key values (for [`Interpolation::CubicSpline`], three per key: in-tangent,
/// value, out-tangent).
#[derive(Clone, Debug, PartialEq)]
pub enum ChannelValues {
    /// Joint translations.
    Translation(Vec<Vec3>),
    /// Joint rotations (x, y, z, w).
    Rotation(Vec<Vec4>),
    /// Joint scales.
    Scale(Vec<Vec3>),
}

/// One animated property of one joint.
#[derive(Clone, Debug, PartialEq)]
pub struct Channel {
    /// The joint (index into the skeleton).
    pub joint: usize,
    /// Key times, seconds, strictly increasing.
    pub times: Vec<f32>,
    /// Interpolation between keys.
    pub interpolation: Interpolation,
    /// Key values.
    pub values: ChannelValues,
}

/// A named clip: channels over `duration` seconds (looped by [`Clip::sample`]).
#[derive(Clone, Debug, PartialEq)]
pub struct Clip {
    /// Name.
    pub name: String,
    /// Length, seconds (the last key of any channel).
    pub duration: f32,
    /// Channels.
    pub channels: Vec<Channel>,
}

impl Channel {
    /// Values per key: 3 for cubic splines, else 1.
    pub fn stride(&self) -> usize {
        match self.interpolation {
            Interpolation::CubicSpline => 3,
            _ => 1,
        }
    }

    /// Key count the values hold.
    fn value_keys(&self) -> usize {
        let n = match &self.values {
            ChannelValues::Translation(v) | ChannelValues::Scale(v) => v.len(),
            ChannelValues::Rotation(v) => v.len(),
        };
        n / self.stride()
    }

    /// Check times (finite, strictly increasing, at least one) and that the values match
    /// them.
    pub fn validate(&self) -> Result<(), String> {
        if self.times.is_empty() {
            return Err("a channel has no keys".into());
        }
        if !self.times.iter().all(|t| t.is_finite() && *t >= 0.0) {
            return Err("key times must be finite and non-negative".into());
        }
        if self.times.windows(2).any(|w| w[1] <= w[0]) {
            return Err("key times must increase".into());
        }
        let stride_ok = match &self.values {
            ChannelValues::Translation(v) | ChannelValues::Scale(v) => {
                v.len() % self.stride() == 0 && v.iter().all(|x| x.is_finite())
            }
            ChannelValues::Rotation(v) => {
                v.len() % self.stride() == 0 && v.iter().all(|x| x.is_finite())
            }
        };
        if !stride_ok || self.value_keys() != self.times.len() {
            return Err(format!(
                "{} key times but values for {} keys (or non-finite values)",
                self.times.len(),
                self.value_keys()
            ));
        }
        Ok(())
    }

    /// The key interval holding `t` and the fraction into it: `(k, k + 1, s)`, clamped to
    /// the first and last keys.
    fn interval(&self, t: f32) -> (usize, usize, f32) {
        let n = self.times.len();
        if n == 1 || t <= self.times[0] {
            return (0, 0, 0.0);
        }
        if t >= self.times[n - 1] {
            return (n - 1, n - 1, 0.0);
        }
        let k = self.times.partition_point(|&x| x <= t) - 1;
        let (t0, t1) = (self.times[k], self.times[k + 1]);
        (k, k + 1, (t - t0) / (t1 - t0))
    }

    /// Value at time `t` as a 4-vector (translation and scale in xyz).
    pub fn sample(&self, t: f32) -> Vec4 {
        let (a, b, s) = self.interval(t);
        let value = |k: usize, part: usize| -> Vec4 {
            let i = k * self.stride() + part;
            match &self.values {
                ChannelValues::Translation(v) | ChannelValues::Scale(v) => v[i].extend(0.0),
                ChannelValues::Rotation(v) => v[i],
            }
        };
        let rotation = matches!(self.values, ChannelValues::Rotation(_));
        let out = match self.interpolation {
            Interpolation::Step => value(a, 0),
            Interpolation::Linear if rotation => {
                let q0 = Quat::from_vec4(value(a, 0)).normalize();
                let q1 = Quat::from_vec4(value(b, 0)).normalize();
                Vec4::from(q0.slerp(q1, s))
            }
            Interpolation::Linear => value(a, 0).lerp(value(b, 0), s),
            Interpolation::CubicSpline => {
                // glTF 2.0 Appendix C: p(s) = (2s^3 - 3s^2 + 1) v_k + (s^3 - 2s^2 + s) td b_k
                //   + (-2s^3 + 3s^2) v_k+1 + (s^3 - s^2) td a_k+1.
                let td = self.times[b] - self.times[a];
                let (s2, s3) = (s * s, s * s * s);
                value(a, 1) * (2.0 * s3 - 3.0 * s2 + 1.0)
                    + value(a, 2) * (td * (s3 - 2.0 * s2 + s))
                    + value(b, 1) * (-2.0 * s3 + 3.0 * s2)
                    + value(b, 0) * (td * (s3 - s2))
            }
        };
        if rotation {
            out.normalize_or(Vec4::W)
        } else {
            out
        }
    }
}

impl Clip {
    /// The pose at `t` seconds (looped over the duration): the rest pose with every channel
    /// applied.
    pub fn sample(&self, skeleton: &Skeleton, t: f32) -> Pose {
        let t = if self.duration > 0.0 && t.is_finite() {
            t.rem_euclid(self.duration)
        } else {
            0.0
        };
        let mut pose = skeleton.rest_pose();
        for c in &self.channels {
            let Some(local) = pose.get_mut(c.joint) else {
                continue;
            };
            let v = c.sample(t);
            match c.values {
                ChannelValues::Translation(_) => local.t = v.truncate(),
                ChannelValues::Rotation(_) => local.r = Quat::from_vec4(v),
                ChannelValues::Scale(_) => local.s = v.truncate(),
            }
        }
        pose
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn channel(interpolation: Interpolation, values: Vec<Vec3>) -> Channel {
        Channel {
            joint: 0,
            times: vec![0.0, 1.0, 3.0],
            interpolation,
            values: ChannelValues::Translation(values),
        }
    }

    /// Step holds the previous key, linear interpolates, both clamp outside the keys.
    #[test]
    fn step_and_linear() {
        let keys = vec![Vec3::ZERO, Vec3::X, Vec3::new(3.0, 0.0, 0.0)];
        let step = channel(Interpolation::Step, keys.clone());
        assert_eq!(step.sample(0.5).x, 0.0);
        assert_eq!(step.sample(1.5).x, 1.0);
        let linear = channel(Interpolation::Linear, keys);
        assert!((linear.sample(0.5).x - 0.5).abs() < 1e-6);
        assert!((linear.sample(2.0).x - 2.0).abs() < 1e-6);
        assert_eq!(linear.sample(-1.0).x, 0.0);
        assert_eq!(linear.sample(9.0).x, 3.0);
    }

    /// A cubic spline passes through its keys, and with tangents of a straight line at
    /// constant speed it is that line.
    #[test]
    fn cubic_spline_follows_its_tangents() {
        // Keys of x = t (tangent 1 per second) at t = 0, 1, 3.
        let mut v = Vec::new();
        for x in [0.0, 1.0, 3.0] {
            v.extend([Vec3::X, Vec3::new(x, 0.0, 0.0), Vec3::X]);
        }
        let c = channel(Interpolation::CubicSpline, v);
        assert!(c.validate().is_ok());
        for t in [0.0, 0.25, 1.0, 1.7, 2.9] {
            assert!((c.sample(t).x - t).abs() < 1e-5, "t {t}: {}", c.sample(t).x);
        }
        // Zero tangents: ease in and out, halfway at the middle of the interval.
        let mut flat = Vec::new();
        for x in [0.0, 1.0, 3.0] {
            flat.extend([Vec3::ZERO, Vec3::new(x, 0.0, 0.0), Vec3::ZERO]);
        }
        let c = channel(Interpolation::CubicSpline, flat);
        assert!((c.sample(2.0).x - 2.0).abs() < 1e-5);
        assert!(c.sample(1.25).x < 1.25);
    }

    /// Rotations slerp at constant angular speed.
    #[test]
    fn rotations_slerp() {
        let q = |a: f32| Vec4::from(Quat::from_rotation_y(a));
        let c = Channel {
            joint: 0,
            times: vec![0.0, 1.0],
            interpolation: Interpolation::Linear,
            values: ChannelValues::Rotation(vec![q(0.0), q(2.0)]),
        };
        let mid = Quat::from_vec4(c.sample(0.25));
        assert!(mid.angle_between(Quat::from_rotation_y(0.5)) < 1e-4);
    }

    /// Bad channels are refused.
    #[test]
    fn bad_channels() {
        let mut c = channel(Interpolation::Linear, vec![Vec3::ZERO; 3]);
        assert!(c.validate().is_ok());
        c.times = vec![0.0, 2.0, 1.0];
        assert!(c.validate().is_err());
        c.times = vec![0.0, 1.0];
        assert!(c.validate().is_err());
        let cubic = channel(Interpolation::CubicSpline, vec![Vec3::ZERO; 3]);
        assert!(cubic.validate().is_err());
    }
}
