//! Skeletal characters: a joint hierarchy with inverse bind matrices, animation clips
//! (translation, rotation and scale channels with step, linear and cubic-spline samplers, as
//! glTF 2.0 defines them) and skinned meshes. Everything here is the CPU side and the twin of
//! the GPU skinning pass (`glsl/skin.comp`): [`skin_vertices`] is linear blend skinning,
//! `v' = sum_i w_i M_i v` with `M_i = G_i B_i^-1` (the joint's global transform times its
//! inverse bind matrix; Magnenat-Thalmann et al. 1988, glTF 2.0 section 3.7.3).

pub mod clip;
pub mod far;

use glam::{Mat4, Quat, Vec3, Vec4};

pub use clip::{Channel, ChannelValues, Clip, Interpolation};

/// A joint's local transform: translation, rotation, scale (applied scale, then rotation,
/// then translation).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Trs {
    /// Translation.
    pub t: Vec3,
    /// Rotation (unit quaternion).
    pub r: Quat,
    /// Scale.
    pub s: Vec3,
}

impl Default for Trs {
    fn default() -> Self {
        Trs {
            t: Vec3::ZERO,
            r: Quat::IDENTITY,
            s: Vec3::ONE,
        }
    }
}

impl Trs {
    /// The matrix `T R S`.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.s, self.r, self.t)
    }
}

/// One joint of a skeleton.
#[derive(Clone, Debug, PartialEq)]
pub struct Joint {
    /// Name (the glTF node's, or `joint N`).
    pub name: String,
    /// Parent joint; `None` for a root (placed by [`Skeleton::root`]).
    pub parent: Option<usize>,
    /// Local transform at rest.
    pub rest: Trs,
    /// Inverse bind matrix: the skinned meshes' frame to the joint's at bind time.
    pub inverse_bind: Mat4,
}

/// A joint hierarchy, parents before children.
#[derive(Clone, Debug, PartialEq)]
pub struct Skeleton {
    /// The joints, every parent before its children.
    pub joints: Vec<Joint>,
    /// Transform above the root joints (their glTF ancestors that are not joints), applied
    /// before the character's own placement.
    pub root: Mat4,
}

/// A pose: one local transform per joint.
pub type Pose = Vec<Trs>;

impl Skeleton {
    /// The rest pose.
    pub fn rest_pose(&self) -> Pose {
        self.joints.iter().map(|j| j.rest).collect()
    }

    /// Index of the joint called `name`.
    pub fn find(&self, name: &str) -> Option<usize> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// Global transforms (skeleton root frame) of `pose`.
    pub fn globals(&self, pose: &[Trs]) -> Vec<Mat4> {
        let mut out: Vec<Mat4> = Vec::with_capacity(self.joints.len());
        for (j, local) in self.joints.iter().zip(pose) {
            let parent = j.parent.map_or(self.root, |p| out[p]);
            out.push(parent * local.matrix());
        }
        out
    }

    /// Skin matrices `G_j B_j^-1` of `pose`: bind-pose mesh frame to posed (eq. of the
    /// module doc).
    pub fn skin_matrices(&self, pose: &[Trs]) -> Vec<Mat4> {
        self.globals(pose)
            .iter()
            .zip(&self.joints)
            .map(|(g, j)| *g * j.inverse_bind)
            .collect()
    }

    /// Check the hierarchy: parents before children, transforms finite.
    pub fn validate(&self) -> Result<(), String> {
        for (k, j) in self.joints.iter().enumerate() {
            if j.parent.is_some_and(|p| p >= k) {
                return Err(format!("joint {k} '{}' comes before its parent", j.name));
            }
            let finite = j.rest.t.is_finite()
                && j.rest.r.is_finite()
                && j.rest.s.is_finite()
                && j.inverse_bind.is_finite();
            if !finite {
                return Err(format!("joint {k} '{}' has a non-finite transform", j.name));
            }
        }
        if !self.root.is_finite() {
            return Err("the skeleton's root transform is not finite".into());
        }
        Ok(())
    }
}

/// One vertex of a skinned mesh at bind time.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SkinVertex {
    /// Position, mesh frame.
    pub position: Vec3,
    /// Unit normal.
    pub normal: Vec3,
    /// Linear RGB colour (base colour factor times texture at the vertex).
    pub color: Vec3,
    /// GGX roughness of the surface at the vertex (0.05..=1; glTF's roughness factor, the
    /// eyes' wet 0.2, [`crate::shade::PROP_ROUGHNESS`] for skin and cloth).
    pub roughness: f32,
    /// Up to four joints (indices into the skeleton).
    pub joints: [u16; 4],
    /// Their weights (sum 1).
    pub weights: [f32; 4],
}

/// A skinned triangle mesh: vertices and a triangle list of indices into them.
#[derive(Clone, Debug, PartialEq)]
pub struct SkinnedMesh {
    /// Name (the glTF mesh's, or its material's).
    pub name: String,
    /// Vertices at bind time.
    pub vertices: Vec<SkinVertex>,
    /// Triangle list.
    pub indices: Vec<u32>,
}

/// A posed vertex: what the skinning pass writes.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PosedVertex {
    /// Position.
    pub position: Vec3,
    /// Unit normal.
    pub normal: Vec3,
}

/// Linear blend skinning of one vertex by `matrices` (module doc; the normal by the blended
/// matrix's upper 3x3, renormalized: exact for rotations and uniform scale). The GPU twin is
/// `glsl/skin.comp`.
pub fn skin_vertex(v: &SkinVertex, matrices: &[Mat4]) -> PosedVertex {
    let mut m = Mat4::ZERO;
    for (j, w) in v.joints.iter().zip(v.weights) {
        if w != 0.0 {
            let joint = matrices.get(*j as usize).copied().unwrap_or(Mat4::IDENTITY);
            m += joint * w;
        }
    }
    let position = (m * v.position.extend(1.0)).truncate();
    let n = (m * Vec4::new(v.normal.x, v.normal.y, v.normal.z, 0.0)).truncate();
    PosedVertex {
        position,
        normal: n.normalize_or(v.normal),
    }
}

/// Every vertex of `mesh` skinned by `matrices`.
pub fn skin_vertices(mesh: &SkinnedMesh, matrices: &[Mat4]) -> Vec<PosedVertex> {
    mesh.vertices
        .iter()
        .map(|v| skin_vertex(v, matrices))
        .collect()
}

/// The speed (units per second) at which a looping walk clip's planted feet move backward in
/// the character's frame: the root must move forward at it for the feet not to slide. Per
/// foot joint, the frames where it is within `contact` of its lowest height over the clip are
/// its stance; the speed is the median of its horizontal speed over those frames (sampled at
/// 60 Hz). `None` when no foot joint is named or the clip does not move them.
pub fn ground_speed(skeleton: &Skeleton, clip: &Clip, feet: &[usize], contact: f32) -> Option<f32> {
    let steps = ((clip.duration * 60.0).ceil() as usize).max(2);
    let dt = clip.duration / steps as f32;
    let mut speeds = Vec::new();
    for &foot in feet {
        let path: Vec<Vec3> = (0..=steps)
            .map(|k| {
                let pose = clip.sample(skeleton, k as f32 * dt);
                skeleton.globals(&pose)[foot].w_axis.truncate()
            })
            .collect();
        let low = path.iter().map(|p| p.y).fold(f32::INFINITY, f32::min);
        for w in path.windows(2) {
            if w[0].y - low < contact && w[1].y - low < contact {
                let d = w[1] - w[0];
                speeds.push(Vec3::new(d.x, 0.0, d.z).length() / dt);
            }
        }
    }
    if speeds.is_empty() {
        return None;
    }
    speeds.sort_by(f32::total_cmp);
    let median = speeds[speeds.len() / 2];
    (median > 0.0).then_some(median)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn two_bones() -> Skeleton {
        // A root at the origin and a child 1 up; bound where they stand.
        Skeleton {
            joints: vec![
                Joint {
                    name: "root".into(),
                    parent: None,
                    rest: Trs::default(),
                    inverse_bind: Mat4::IDENTITY,
                },
                Joint {
                    name: "tip".into(),
                    parent: Some(0),
                    rest: Trs {
                        t: Vec3::Y,
                        ..Default::default()
                    },
                    inverse_bind: Mat4::from_translation(-Vec3::Y),
                },
            ],
            root: Mat4::IDENTITY,
        }
    }

    /// At rest every skin matrix is the identity; a vertex weighted half to each bone moves
    /// by half of the tip's rotation.
    #[test]
    fn linear_blend_skinning_blends_the_joints() {
        let s = two_bones();
        for m in s.skin_matrices(&s.rest_pose()) {
            assert!(m.abs_diff_eq(Mat4::IDENTITY, 1e-6));
        }
        let mut pose = s.rest_pose();
        pose[1].r = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let m = s.skin_matrices(&pose);
        let v = SkinVertex {
            position: Vec3::new(0.0, 2.0, 0.0),
            normal: Vec3::X,
            color: Vec3::ONE,
            roughness: crate::shade::PROP_ROUGHNESS,
            joints: [0, 1, 0, 0],
            weights: [0.5, 0.5, 0.0, 0.0],
        };
        // Fully on the tip: (0, 2) turns about (0, 1) to (-1, 1).
        let full = skin_vertex(
            &SkinVertex {
                weights: [0.0, 1.0, 0.0, 0.0],
                ..v
            },
            &m,
        );
        assert!(
            full.position.abs_diff_eq(Vec3::new(-1.0, 1.0, 0.0), 1e-5),
            "{full:?}"
        );
        assert!(full.normal.abs_diff_eq(Vec3::Y, 1e-5));
        // Half and half: the average of (0, 2) and (-1, 1).
        let half = skin_vertex(&v, &m);
        assert!(
            half.position.abs_diff_eq(Vec3::new(-0.5, 1.5, 0.0), 1e-5),
            "{half:?}"
        );
    }

    /// A child listed before its parent is refused.
    #[test]
    fn parents_come_first() {
        let mut s = two_bones();
        assert!(s.validate().is_ok());
        s.joints[0].parent = Some(1);
        assert!(s.validate().is_err());
    }
}
