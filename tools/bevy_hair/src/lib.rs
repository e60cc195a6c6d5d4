//! Strand hair from hair meshes in Bevy: [`HairPlugin`] makes Bevy render on a Vulkan device
//! that also has the hair renderer's features (through `hairmesh`'s wgpu bridge, one device,
//! one queue), and records the hair of every [`Hair`] entity into each 3D camera's frame after
//! Bevy's opaque pass: seen through Bevy's camera, hidden behind Bevy's depth (reversed-Z, as
//! Bevy draws it), composited over Bevy's colour before its transparent pass and tonemapping.
//!
//! ```no_run
//! use bevy::prelude::*;
//! use bevy::world_serialization::WorldAssetRoot;
//! use hairmesh::characters::hairstyle::StyleFamily;
//! use hairmesh_bevy::{Hair, HairPlugin, hair_camera};
//!
//! let hair = HairPlugin::new(Default::default()).expect("a Vulkan device for the hair");
//! App::new()
//!     .add_plugins(DefaultPlugins.set(hair.render_plugin()))
//!     .add_plugins(hair)
//!     .add_systems(Startup, |mut commands: Commands, assets: Res<AssetServer>| {
//!         commands.spawn((hair_camera(), Transform::from_xyz(0.0, 1.6, 3.0)));
//!         let person = "hairmeshes/people/character.glb";
//!         let scene = assets.load(GltfAssetLabel::Scene(0).from_asset(person));
//!         commands.spawn((WorldAssetRoot(scene), Hair::grown(person, "head", StyleFamily::Bob, 7)));
//!     })
//!     .run();
//! ```
//!
//! Cameras drawing hair need a single-sample depth the hair can read: `Msaa::Off` and
//! `Camera3d::depth_texture_usages` with `TEXTURE_BINDING` ([`hair_camera`] sets both).

mod library;
mod render_world;

use std::path::PathBuf;
use std::sync::Mutex;

use bevy::prelude::*;
use bevy::render::RenderPlugin;
use bevy::render::renderer::{
    RenderAdapter, RenderAdapterInfo, RenderDevice, RenderInstance, RenderQueue, WgpuWrapper,
};
use bevy::render::settings::RenderCreation;
use hairmesh::characters::hairstyle::StyleFamily;
pub use hairmesh::characters::preset::StrandDensity;
use hairmesh::vk::wgpu_host::wgpu;
use hairmesh::vk::{WgpuDesc, WgpuDevice};

pub use library::{HairLibrary, LoadedHair, PlacedHair};
pub use render_world::{FrameRecord, HairFrames};

/// The hair of one entity.
#[derive(Component, Clone, Debug)]
#[require(Transform)]
pub struct Hair {
    /// Where the hair comes from.
    pub source: HairSource,
    /// How densely it grows at full detail (the renderer thins it with distance): grown hair
    /// a real head's 175 strands per cm² by default, a hair mesh 64 strands per bundle (its
    /// units are its own).
    pub density: StrandDensity,
}

/// Where a [`Hair`] comes from.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum HairSource {
    /// A hair mesh (`.obj`, baked on load with the `.toml` style beside it, or a baked
    /// `.hmb`), placed by the entity's `GlobalTransform`.
    Mesh(PathBuf),
    /// A hairstyle of `family` (from `seed`) grown on the head of the skinned glTF
    /// `character` (the same file the entity's scene shows), bound to its joint named
    /// `joint`: the hair follows that joint as Bevy animates it.
    Grown {
        /// The glTF file (`.glb`/`.gltf`).
        character: PathBuf,
        /// Its head joint's node name.
        joint: String,
        /// The hairstyle family.
        family: StyleFamily,
        /// The hairstyle's seed.
        seed: u32,
    },
}

impl Hair {
    /// The hair mesh at `path`.
    pub fn mesh(path: impl Into<PathBuf>) -> Self {
        Hair {
            source: HairSource::Mesh(path.into()),
            density: StrandDensity::PerReferenceBundle(64),
        }
    }

    /// The same hair at `density`.
    pub fn with_density(self, density: StrandDensity) -> Self {
        Hair { density, ..self }
    }

    /// A hairstyle of `family` grown on the head (joint `joint`) of the glTF `character`.
    pub fn grown(
        character: impl Into<PathBuf>,
        joint: &str,
        family: StyleFamily,
        seed: u32,
    ) -> Self {
        Hair {
            source: HairSource::Grown {
                character: character.into(),
                joint: joint.to_string(),
                family,
                seed,
            },
            density: StrandDensity::default(),
        }
    }
}

/// How the hair is drawn, for every camera (a resource of the main world).
#[derive(Resource, Clone, Copy, Debug)]
pub struct HairSettings {
    /// Draw the hair at all.
    pub enabled: bool,
    /// Hide the hair behind Bevy's depth (off only to see what Bevy's geometry hides).
    pub depth_test: bool,
    /// Shadows of the hair on itself (deep opacity maps; Bevy's geometry casts none on it).
    pub shadows: bool,
    /// Metres Bevy's depth is pushed back before it hides hair
    /// (`hairmesh::render::HostFrame::depth_slack`): grown hair lies a fraction of a
    /// millimetre above the smooth head it was grown on, which the head mesh's flat
    /// triangles cut through. Measured on `character.glb` at 640x360: with 0, the scalp hides
    /// most of a buzz cut seen from 2 m; with 3 mm, none of it.
    pub depth_slack: f32,
}

impl Default for HairSettings {
    fn default() -> Self {
        HairSettings {
            enabled: true,
            depth_test: true,
            shadows: true,
            depth_slack: 0.004,
        }
    }
}

/// What [`HairPlugin::new`] makes.
#[derive(Clone, Debug, Default)]
pub struct HairPluginDesc {
    /// Vulkan validation on (any message is counted: [`HairFrames::validation_errors`]).
    pub validation: bool,
    /// A device whose name contains this; `None`: the first that has what the hair needs.
    pub device: Option<String>,
}

/// The plugin: Bevy's render device with the hair's features, and the hair's systems.
pub struct HairPlugin {
    device: Mutex<Option<WgpuDevice>>,
    handles: BevyHandles,
}

/// Clones of the wgpu objects Bevy renders with.
#[derive(Clone)]
struct BevyHandles {
    device: wgpu::Device,
    queue: wgpu::Queue,
    adapter: wgpu::Adapter,
    instance: wgpu::Instance,
}

impl HairPlugin {
    /// Make the Vulkan device (through wgpu, with the hair renderer's features) that Bevy
    /// and the hair will share. Fails in one line when no device has what the hair needs.
    pub fn new(desc: HairPluginDesc) -> Result<Self, hairmesh::vk::GpuError> {
        let device = WgpuDevice::new(&WgpuDesc {
            validation: desc.validation,
            device: desc.device,
            features: None,
        })?;
        let handles = BevyHandles {
            device: device.device.clone(),
            queue: device.queue.clone(),
            adapter: device.adapter.clone(),
            instance: device.instance.clone(),
        };
        Ok(HairPlugin {
            device: Mutex::new(Some(device)),
            handles,
        })
    }

    /// Bevy's render plugin on the shared device: pass it to `DefaultPlugins.set(..)`.
    pub fn render_plugin(&self) -> RenderPlugin {
        let h = self.handles.clone();
        let info = h.adapter.get_info();
        RenderPlugin {
            render_creation: RenderCreation::manual(
                RenderDevice::from(h.device),
                RenderQueue(std::sync::Arc::new(WgpuWrapper::new(h.queue))),
                RenderAdapterInfo(WgpuWrapper::new(info)),
                RenderAdapter(std::sync::Arc::new(WgpuWrapper::new(h.adapter))),
                RenderInstance(std::sync::Arc::new(WgpuWrapper::new(h.instance))),
            ),
            ..Default::default()
        }
    }
}

impl Plugin for HairPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<HairSettings>()
            .init_resource::<HairLibrary>()
            .add_systems(
                PostUpdate,
                (library::find_head_joints, library::place_hair)
                    .chain()
                    .after(bevy::transform::TransformSystems::Propagate),
            );
        let device = self.device.lock().ok().and_then(|mut d| d.take());
        match device {
            Some(device) => render_world::build(app, device),
            None => error!("HairPlugin: its device was taken (the plugin was added twice)"),
        }
    }
}

/// A 3D camera the hair can draw into: single-sample, its depth readable by the hair.
pub fn hair_camera() -> impl Bundle {
    let usages = bevy::render::render_resource::TextureUsages::RENDER_ATTACHMENT
        | bevy::render::render_resource::TextureUsages::TEXTURE_BINDING;
    (
        Camera3d {
            depth_texture_usages: usages.into(),
            ..default()
        },
        Msaa::Off,
    )
}

/// Bevy's matrix as the renderer's (the same numbers; Bevy and the renderer use different
/// versions of glam).
pub(crate) fn to_glam(m: Mat4) -> glam::Mat4 {
    glam::Mat4::from_cols_array(&m.to_cols_array())
}
