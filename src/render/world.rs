//! What the renderer draws: the characters, the props, the skinned bodies and clothes, and the
//! density volumes asked of the characters' hair. The frames ([`super::frame::Frames`]) read
//! it; the [`super::Renderer`] changes it.

use super::crowd::Crowd;
use super::features::volume::DensityVolumes;
use super::prop_table::Props;
use super::skinned_props::SkinnedProps;

/// Everything a frame draws.
pub(in crate::render) struct World {
    /// The characters: textures, records, bundles, poses and hair dynamics.
    pub(in crate::render) crowd: Crowd,
    /// World props and the props characters carry.
    pub(in crate::render) props: Props,
    /// Skinned bodies and clothes.
    pub(in crate::render) skinned: SkinnedProps,
    /// Requested strand density volumes.
    pub(in crate::render) volumes: DensityVolumes,
}
