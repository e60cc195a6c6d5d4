//! A user's own character in a crowd (`crowd --character FILE.glb`): a skinned glTF whose
//! head ([`super::any_head`]) grows each copy's hair, bound to its head joint the way the
//! people's hair is ([`super::people::head_bound`]); the copies play its walk (or first) clip,
//! walking at the clip's ground speed when it plants feet, else in place.
//!
//! The hair lives in the character's bind frame (glTF metres), so a copy's hair model is its
//! root placement times the head joint's skin matrix.

use std::path::Path;

use glam::Mat4;

use super::any_head::AnyHead;
use super::hairstyle::{Hairstyle, StyleFamily};
use crate::budget::MemoryBudget;
use crate::dynamics::Collider;
use crate::error::{HairError, Result};
use crate::model::gltf::Character;
use crate::render::prop_table::PropLod;
use crate::skin::SkinnedMesh;

/// A user's character, ready to fill a crowd.
pub struct OwnCharacter {
    /// Source, for messages.
    pub name: String,
    /// The skinned meshes, skeleton and clips.
    pub character: Character,
    /// Its head, normalized for the hairstyle generator.
    pub head: AnyHead,
    /// The joint the head (and the hair) follows.
    pub head_joint: usize,
    /// The clip the copies play: `walk` if it has one, else its first.
    clip: Option<usize>,
    /// Ground speed of that clip (metres per second) when it plants feet.
    walk_speed: Option<f32>,
}

impl OwnCharacter {
    /// Read the glTF character at `path`; `joint` names its head joint.
    pub fn load(path: &Path, joint: &str, budget: MemoryBudget) -> Result<Self> {
        let character = crate::model::gltf::load_character(path, budget)?;
        Self::new(&path.display().to_string(), character, joint)
    }

    /// `character` (from `name`) with its head at joint `joint`.
    pub fn new(name: &str, character: Character, joint: &str) -> Result<Self> {
        if character.meshes.is_empty() {
            return Err(HairError::invalid(name, "no skinned mesh"));
        }
        let head_joint = super::any_head::find_joint(name, &character, joint)?;
        let head = AnyHead::from_joint(name, &character, head_joint)?;
        let clip = character
            .clips
            .iter()
            .position(|c| c.name == "walk")
            .or((!character.clips.is_empty()).then_some(0));
        let walk_speed = clip.and_then(|k| {
            let s = &character.skeleton;
            let feet = lowest_leaves(s);
            crate::skin::ground_speed(s, &character.clips[k], &feet, 0.01 * head.scale)
        });
        Ok(OwnCharacter {
            name: name.to_string(),
            character,
            head,
            head_joint,
            clip,
            walk_speed,
        })
    }

    /// Ground speed of its clip, metres per second, if the clip walks (plants its feet).
    pub fn walk_speed(&self) -> Option<f32> {
        self.walk_speed
    }

    /// A hairstyle of `family` from `seed` on its head, in its bind frame.
    pub fn grow(&self, family: StyleFamily, seed: u32) -> Result<Hairstyle> {
        self.head.grow(family, seed)
    }

    /// Its meshes, then [`super::people::FAR_LEVELS`] far versions of each in the same order
    /// (a level that clustering empties, as an iris smaller than a cell, draws nothing):
    /// what `Renderer::set_skinned_meshes` takes.
    pub fn skinned_meshes(&self) -> Vec<SkinnedMesh> {
        let plan = self.far_plan();
        super::people::with_far_levels(self.character.meshes.clone(), |_| plan)
    }

    /// How every mesh's far versions are made: the people's first far cell in the character's
    /// units, and every level (its head is part of its body, so they coarsen together).
    fn far_plan(&self) -> super::people::FarPlan {
        super::people::FarPlan {
            cell: super::people::FAR_CELL * self.head.scale,
            levels: super::people::FAR_LEVELS,
            // Its scalp is part of the body: clustered, so it never bulges through the hair.
            method: super::people::FarMethod::Cluster,
        }
    }

    /// When each mesh switches to its far version (as the people's do:
    /// [`super::people::skinned_lods`]).
    pub fn skinned_lods(&self) -> Vec<PropLod> {
        let plan = self.far_plan();
        let n = self.character.meshes.len();
        super::people::far_level_lods(&self.character.meshes, n, |_| plan)
    }

    /// The parts a copy wears: every mesh, in its own colours.
    pub fn parts(&self) -> Vec<(usize, [f32; 4])> {
        (0..self.character.meshes.len())
            .map(|k| (k, [1.0; 4]))
            .collect()
    }

    /// Joints of its skin matrices.
    pub fn joint_count(&self) -> usize {
        self.character.skeleton.joints.len()
    }

    /// Its skin matrices at `t` seconds into its clip (the bind pose without one), and the
    /// head joint's.
    pub fn pose(&self, t: f32) -> (Vec<Mat4>, Mat4) {
        let s = &self.character.skeleton;
        let pose = match self.clip {
            Some(k) => self.character.clips[k].sample(s, t),
            None => s.rest_pose(),
        };
        let m = s.skin_matrices(&pose);
        let head = m[self.head_joint];
        (m, head)
    }

    /// Colliders for the hair dynamics in the bind frame: the neck, shoulders and chest the
    /// generator settled the hair against (the canonical person's, carried by the head's
    /// normalization), then the head itself.
    pub fn colliders(&self) -> Result<Vec<Collider>> {
        let to = self.head.to_user;
        let s = self.head.scale;
        let mut out: Vec<Collider> = self
            .head
            .site()
            .body
            .into_iter()
            .map(|c| match c {
                Collider::Capsule { a, b, radius } => Collider::Capsule {
                    a: to.transform_point3(a),
                    b: to.transform_point3(b),
                    radius: radius * s,
                },
                Collider::Ellipsoid { centre, radii } => Collider::Ellipsoid {
                    centre: to.transform_point3(centre),
                    radii: radii * s,
                },
                other => other,
            })
            .collect();
        out.push(Collider::head(&self.head.head.map, to, 0.005));
        Ok(out)
    }
}

/// The feet a walk plants: the two joints without children that stand lowest at rest.
fn lowest_leaves(s: &crate::skin::Skeleton) -> Vec<usize> {
    let globals = s.globals(&s.rest_pose());
    let mut leaves: Vec<usize> = (0..s.joints.len())
        .filter(|&j| !s.joints.iter().any(|k| k.parent == Some(j)))
        .collect();
    leaves.sort_by(|&a, &b| globals[a].w_axis.y.total_cmp(&globals[b].w_axis.y));
    leaves.truncate(2);
    leaves
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The example character walks at about the people's speed, its meshes come with far
    /// versions, and its hair colliders end with its head.
    #[test]
    fn the_example_character_walks_and_collides() {
        let own = OwnCharacter::load(
            Path::new("hairmeshes/people/character.glb"),
            "head",
            MemoryBudget::default(),
        )
        .unwrap();
        let speed = own.walk_speed().expect("its walk plants its feet");
        println!("walk speed {speed} m/s");
        assert!((0.8..1.4).contains(&speed), "{speed}");
        let meshes = own.skinned_meshes();
        let levels = super::super::people::FAR_LEVELS;
        assert_eq!(meshes.len(), (1 + levels) * own.character.meshes.len());
        assert_eq!(
            own.skinned_lods().len(),
            levels * own.character.meshes.len()
        );
        let c = own.colliders().unwrap();
        assert!(matches!(c.last(), Some(Collider::Head { .. })));
        let (m, head) = own.pose(0.3);
        assert_eq!(m.len(), own.joint_count());
        assert_eq!(head, m[own.head_joint]);
    }
}
