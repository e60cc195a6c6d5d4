//! The main world's half: hair loaded (and grown, and baked) off the main thread once per
//! source, and placed every frame by its entity's transform or its head joint's.

use std::collections::HashMap;
use std::sync::Arc;

use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, block_on};
use hairmesh::HairStyle;
use hairmesh::bake::{BakeOptions, BakedHairMesh, bake};
use hairmesh::budget::MemoryBudget;
use hairmesh::characters::own::OwnCharacter;
use hairmesh::characters::preset::StrandDensity;
use hairmesh::render::StrandParams;

use crate::{Hair, HairSource, to_glam};

/// Vertices per strand at full detail, as `2^VERTS_LOG2` (the crowd's).
const VERTS_LOG2: u32 = 5;

/// Hair ready for the renderer: the baked hair mesh, its style, and for grown hair the head
/// joint's inverse bind matrix (the hair is grown in the character's bind frame).
pub struct LoadedHair {
    /// The five textures' contents.
    pub baked: BakedHairMesh,
    /// The styling parameters.
    pub style: HairStyle,
    /// Strand and vertex counts at full detail.
    pub params: StrandParams,
    /// The head joint's inverse bind matrix (grown hair); `None`: placed by the entity.
    pub inverse_bind: Option<glam::Mat4>,
}

/// Every hair source met so far: loading, ready or refused (with the one-line reason,
/// logged once).
#[derive(Resource, Default)]
pub struct HairLibrary {
    entries: HashMap<(HairSource, (bool, u32)), Entry>,
}

enum Entry {
    Loading(Task<Result<LoadedHair, String>>),
    Ready(Arc<LoadedHair>),
    Failed(String),
}

impl HairLibrary {
    /// Sources still loading.
    pub fn loading(&self) -> usize {
        let busy = |e: &&Entry| matches!(e, Entry::Loading(_));
        self.entries.values().filter(busy).count()
    }

    /// The refusals so far, one line each.
    pub fn failures(&self) -> Vec<String> {
        let text = |e: &Entry| match e {
            Entry::Failed(why) => Some(why.clone()),
            _ => None,
        };
        self.entries.values().filter_map(text).collect()
    }

    /// The hair of `hair`, starting its load the first time it is asked for.
    fn get(&mut self, hair: &Hair) -> Option<Arc<LoadedHair>> {
        let key = (hair.source.clone(), density_key(hair.density));
        let entry = self.entries.entry(key).or_insert_with(|| {
            let (source, asked) = (hair.source.clone(), hair.density);
            let pool = AsyncComputeTaskPool::get();
            Entry::Loading(pool.spawn(async move { load(&source, asked) }))
        });
        if let Entry::Loading(task) = entry
            && task.is_finished()
        {
            *entry = match block_on(task) {
                Ok(hair) => Entry::Ready(Arc::new(hair)),
                Err(why) => {
                    error!("hair: {why}");
                    Entry::Failed(why)
                }
            };
        }
        match entry {
            Entry::Ready(hair) => Some(hair.clone()),
            _ => None,
        }
    }
}

/// A [`StrandDensity`] as a key of the library (its kind and number's bits).
fn density_key(d: StrandDensity) -> (bool, u32) {
    match d {
        StrandDensity::PerCm2(v) => (true, v.to_bits()),
        StrandDensity::PerReferenceBundle(n) => (false, n),
    }
}

/// Load (grow, bake) the hair of `source` at density `asked`.
fn load(source: &HairSource, asked: StrandDensity) -> Result<LoadedHair, String> {
    let params = |strands_per_bundle| StrandParams {
        strands_per_bundle,
        verts_log2: VERTS_LOG2,
    };
    match source {
        HairSource::Mesh(path) => {
            let StrandDensity::PerReferenceBundle(n) = asked else {
                return Err(format!(
                    "{}: a hair mesh's units are its own: give its density in strands per bundle",
                    path.display()
                ));
            };
            let (baked, style) =
                hairmesh::render::scene::load_mesh(path, None, MemoryBudget::default())
                    .map_err(|e| e.to_string())?;
            Ok(LoadedHair {
                baked,
                style,
                params: params(n),
                inverse_bind: None,
            })
        }
        HairSource::Grown {
            character,
            joint,
            family,
            seed,
        } => {
            let own = OwnCharacter::load(character, joint, MemoryBudget::default())
                .map_err(|e| e.to_string())?;
            let grown = own.grow(*family, *seed).map_err(|e| e.to_string())?;
            let baked = bake(&grown.mesh, &grown.style, BakeOptions::default(), |_, _| {})
                .map_err(|e| e.to_string())?;
            let skeleton = &own.character.skeleton;
            // glTF characters are in metres.
            let n = match asked {
                StrandDensity::PerCm2(d) => grown
                    .strands_per_bundle_at(d, 1.0)
                    .map_err(|e| format!("{}: {e}", character.display()))?,
                StrandDensity::PerReferenceBundle(n) => grown.strands_per_bundle(n),
            };
            Ok(LoadedHair {
                params: params(n),
                baked,
                style: grown.style,
                inverse_bind: Some(skeleton.joints[own.head_joint].inverse_bind),
            })
        }
    }
}

/// Hair placed for this frame: what the render world extracts.
#[derive(Component, Clone)]
pub struct PlacedHair {
    /// The loaded hair.
    pub hair: Arc<LoadedHair>,
    /// Hair space to world space.
    pub model: glam::Mat4,
}

/// The head joint a grown hair follows (found once among the entity's descendants).
#[derive(Component, Clone, Copy)]
pub struct HairJoint(pub Entity);

/// Find each grown hair's head joint once its scene has spawned (loads start in
/// [`place_hair`], which asks the library for every hair each frame).
pub fn find_head_joints(
    mut commands: Commands,
    hairs: Query<(Entity, &Hair, Option<&HairJoint>)>,
    children: Query<&Children>,
    names: Query<&Name>,
) {
    for (entity, hair, joint) in &hairs {
        let HairSource::Grown { joint: name, .. } = &hair.source else {
            continue;
        };
        if joint.is_some() {
            continue;
        }
        let named = |e: &Entity| names.get(*e).is_ok_and(|n| n.as_str() == name);
        if let Some(found) = children.iter_descendants(entity).find(named) {
            commands.entity(entity).insert(HairJoint(found));
        }
    }
}

/// Place every loaded hair: by its entity's transform, or by its head joint's skinning
/// matrix (joint to world, times the joint's inverse bind matrix, as Bevy skins the head).
pub fn place_hair(
    mut commands: Commands,
    mut library: ResMut<HairLibrary>,
    hairs: Query<(Entity, &Hair, &GlobalTransform, Option<&HairJoint>)>,
    globals: Query<&GlobalTransform>,
) {
    for (entity, hair, global, joint) in &hairs {
        let placed = library.get(hair).and_then(|loaded| {
            let model = match (loaded.inverse_bind, joint) {
                (None, _) => to_glam(global.to_matrix()),
                (Some(inverse_bind), Some(joint)) => {
                    let joint = globals.get(joint.0).ok()?;
                    to_glam(joint.to_matrix()) * inverse_bind
                }
                (Some(_), None) => return None,
            };
            Some(PlacedHair {
                hair: loaded,
                model,
            })
        });
        match placed {
            Some(p) => commands.entity(entity).insert(p),
            None => commands.entity(entity).remove::<PlacedHair>(),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use hairmesh::characters::hairstyle::StyleFamily;
    use std::path::PathBuf;

    fn people(name: &str) -> PathBuf {
        PathBuf::from(env!("CARGO_MANIFEST_DIR"))
            .join("../../hairmeshes/people")
            .join(name)
    }

    /// Grown hair carries its head joint's inverse bind matrix (what places it on Bevy's
    /// skinned head) and a strand count scaled from the one asked for.
    #[test]
    fn grown_hair_is_baked_with_its_head_joints_inverse_bind() {
        let source = HairSource::Grown {
            character: people("character.glb"),
            joint: "head".into(),
            family: StyleFamily::Bob,
            seed: 7,
        };
        let hair = load(&source, StrandDensity::PerReferenceBundle(16)).unwrap();
        let own =
            OwnCharacter::load(&people("character.glb"), "head", MemoryBudget::default()).unwrap();
        let expected = own.character.skeleton.joints[own.head_joint].inverse_bind;
        assert_eq!(hair.inverse_bind, Some(expected));
        assert!(hair.params.strands_per_bundle >= 16);
        assert!(hair.baked.info.bundle_count > 0);
    }

    /// Bad sources are refused in one line naming the file, never a panic.
    #[test]
    fn bad_sources_are_refused_in_one_line() {
        let missing = HairSource::Mesh(people("absent.obj"));
        let why = load(&missing, StrandDensity::PerReferenceBundle(16))
            .err()
            .unwrap();
        assert!(why.contains("absent.obj") && !why.contains('\n'), "{why}");
        let no_joint = HairSource::Grown {
            character: people("character.glb"),
            joint: "tail".into(),
            family: StyleFamily::Bob,
            seed: 7,
        };
        let why = load(&no_joint, StrandDensity::default()).err().unwrap();
        assert!(why.contains("tail") && !why.contains('\n'), "{why}");
        // A hair mesh has no units to count cm² in.
        let mesh = HairSource::Mesh(people("../head_long.obj"));
        let why = load(&mesh, StrandDensity::default()).err().unwrap();
        assert!(
            why.contains("head_long.obj") && why.contains("strands per bundle"),
            "{why}"
        );
    }

    /// Grown hair at the default density: a real head's 175 strands per cm² of the
    /// character's scalp (524 cm² on `character.glb`: about 92K strands at full detail).
    #[test]
    fn grown_hair_is_a_real_heads_count() {
        let source = HairSource::Grown {
            character: people("character.glb"),
            joint: "head".into(),
            family: StyleFamily::Bob,
            seed: 7,
        };
        let hair = load(&source, StrandDensity::default()).unwrap();
        let strands = hairmesh::reference::generate::strands_at_full_detail(
            &hair.baked,
            &hair.style,
            hair.params.strands_per_bundle,
        );
        assert!((90_000..=150_000).contains(&strands), "{strands} strands");
    }
}
