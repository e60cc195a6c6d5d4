//! How strands are composited, chosen per frame ([`Transparency`]), and the per-pixel buffers
//! the transparent modes use ([`Transparency::buffers`], created by the frame graph).
//!
//! - **Opaque**: strands write depth, as strips at least one pixel wide (MSAA smooths
//!   their edges).
//! - **K-buffer OIT** (seed 002 sec. 4, after Bavoil et al.'s k-buffer): every strand fragment
//!   (opacity `STRAND_OPACITY` x pixel coverage, seed 002's coverage to alpha) is inserted into
//!   a per-pixel array of `K` nodes kept sorted by depth with 64-bit `atomicMin`; the node
//!   pushed past the end (always the farthest so far) is merged into a per-pixel tail (sums of
//!   premultiplied colour and optical depth, fixed point so the result does not depend on the
//!   order fragments arrive in). The resolve composites the `K` nearest in order, then the tail
//!   as one layer behind them. Memory is bounded: `K x 8 + 16` bytes per pixel.
//! - **Depth peeling** (seed 004's reference): `layers` passes, each finding the nearest
//!   fragment behind the previous layer and compositing it under the layers before; exact up
//!   to the layer count, and slow (two geometry passes per layer). Single-sample only.

use ash::vk;

use crate::render::core::graph::TransientBuffer;
use crate::render::core::shared::FrameBinding;
use crate::vk::ImageDesc;

pub use crate::render::core::shared::{MAX_OIT_BUDGET, STRAND_OPACITY};
/// Default k-buffer budget.
pub const DEFAULT_OIT_BUDGET: u32 = 8;
/// Largest number of peeled layers.
pub const MAX_PEEL_LAYERS: u32 = 256;
/// Default number of peeled layers.
pub const DEFAULT_PEEL_LAYERS: u32 = 32;

/// How the strands of a frame are composited.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Transparency {
    /// Opaque strands (depth-tested, at least one pixel wide).
    #[default]
    Opaque,
    /// Order-independent transparency with `budget` sorted nodes per pixel and a merged tail.
    KBuffer {
        /// Nodes per pixel (1..=[`MAX_OIT_BUDGET`]).
        budget: u32,
    },
    /// Depth peeling of `layers` layers (the slow reference).
    DepthPeeling {
        /// Layers peeled (1..=[`MAX_PEEL_LAYERS`]).
        layers: u32,
    },
}

impl Transparency {
    /// Mode number in `TransparencyFields::mode`.
    pub fn mode(self) -> u32 {
        match self {
            Transparency::Opaque => crate::render::core::shared::TRANSPARENCY_OPAQUE,
            Transparency::KBuffer { .. } => crate::render::core::shared::TRANSPARENCY_KBUFFER,
            Transparency::DepthPeeling { .. } => crate::render::core::shared::TRANSPARENCY_PEELING,
        }
    }

    /// `FrameBlock::transparency` for targets of `samples` samples per pixel.
    pub fn frame_fields(self, samples: u32) -> crate::render::core::shared::TransparencyFields {
        let kbuffer_nodes = match self {
            Transparency::KBuffer { budget } => budget,
            _ => 0,
        };
        crate::render::core::shared::TransparencyFields {
            mode: self.mode(),
            kbuffer_nodes,
            samples,
            _pad: 0,
        }
    }

    /// Check the budget or layer count.
    pub fn validate(self) -> Result<(), String> {
        match self {
            Transparency::Opaque => Ok(()),
            Transparency::KBuffer { budget } if (1..=MAX_OIT_BUDGET).contains(&budget) => Ok(()),
            Transparency::KBuffer { budget } => Err(format!(
                "OIT budget {budget} must be 1..={MAX_OIT_BUDGET} fragments per pixel"
            )),
            Transparency::DepthPeeling { layers } if (1..=MAX_PEEL_LAYERS).contains(&layers) => {
                Ok(())
            }
            Transparency::DepthPeeling { layers } => Err(format!(
                "depth peeling layers {layers} must be 1..={MAX_PEEL_LAYERS}"
            )),
        }
    }

    /// Bytes of the per-pixel buffers for `pixels` pixels: (nodes, tail, peel depth, peel
    /// accumulation).
    pub fn buffer_bytes(self, pixels: u64) -> [u64; 4] {
        match self {
            Transparency::Opaque => [0; 4],
            Transparency::KBuffer { budget } => [pixels * budget as u64 * 8, pixels * 16, 0, 0],
            Transparency::DepthPeeling { .. } => [0, 0, pixels * 8, pixels * 16],
        }
    }
}

impl std::fmt::Display for Transparency {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Transparency::Opaque => write!(f, "opaque"),
            Transparency::KBuffer { budget } => write!(f, "oit:{budget}"),
            Transparency::DepthPeeling { layers } => write!(f, "peel:{layers}"),
        }
    }
}

impl std::str::FromStr for Transparency {
    type Err = String;
    /// `opaque`, `oit` or `oit:K` (K nodes per pixel), `peel` or `peel:N` (N layers).
    fn from_str(s: &str) -> Result<Self, String> {
        let (name, count) = crate::render::core::mode_name::name_and_count("transparency", s)?;
        let t = match name {
            "opaque" if count.is_none() => Transparency::Opaque,
            "oit" => Transparency::KBuffer {
                budget: count.unwrap_or(DEFAULT_OIT_BUDGET),
            },
            "peel" => Transparency::DepthPeeling {
                layers: count.unwrap_or(DEFAULT_PEEL_LAYERS),
            },
            _ => {
                return Err(format!(
                    "unknown transparency '{s}' (opaque, oit, oit:K, peel, peel:N)"
                ));
            }
        };
        t.validate()?;
        Ok(t)
    }
}

impl Transparency {
    /// The per-pixel buffers of this mode for `pixels` pixels, as the frame graph creates
    /// them (sized 0 where the mode does not use them): k-buffer nodes and tail sums, depth
    /// peeling's previous layer and opaque depth, and its accumulated colour.
    pub fn buffers(self, pixels: u64) -> [TransientBuffer; 4] {
        let [nodes, tail, depth, accum] = self.buffer_bytes(pixels);
        [
            TransientBuffer::storage("oit nodes", nodes, FrameBinding::OitNodes as u32).for_user(
                "per-pixel fragment lists",
                "lower --size, or K of --transparency oit:K",
            ),
            TransientBuffer::storage("oit tail", tail, FrameBinding::OitTail as u32).for_user(
                "per-pixel fragment lists",
                "lower --size, or K of --transparency oit:K",
            ),
            TransientBuffer::storage("peel depth", depth, FrameBinding::PeelDepth as u32)
                .for_user("depth peeling layers", "lower --size"),
            TransientBuffer::storage("peel accumulation", accum, FrameBinding::PeelAccum as u32)
                .for_user("depth peeling layers", "lower --size"),
        ]
    }
}

/// The depth attachment of depth peeling's layers (single sample, target size).
pub fn peel_image(width: u32, height: u32) -> ImageDesc {
    ImageDesc::new_2d(
        "peel depth",
        crate::render::core::targets::DEPTH_FORMAT,
        width,
        height,
    )
    .usage(vk::ImageUsageFlags::DEPTH_STENCIL_ATTACHMENT | vk::ImageUsageFlags::TRANSFER_SRC)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_and_rejects() {
        assert_eq!("opaque".parse(), Ok(Transparency::Opaque));
        assert_eq!(
            "oit".parse(),
            Ok(Transparency::KBuffer {
                budget: DEFAULT_OIT_BUDGET
            })
        );
        assert_eq!("oit:2".parse(), Ok(Transparency::KBuffer { budget: 2 }));
        assert_eq!(
            "peel:12".parse(),
            Ok(Transparency::DepthPeeling { layers: 12 })
        );
        for bad in [
            "oit:0", "oit:17", "peel:0", "peel:x", "opaque:3", "blend", "",
        ] {
            assert!(bad.parse::<Transparency>().is_err(), "{bad}");
        }
        for t in ["opaque", "oit:3", "peel:7"] {
            assert_eq!(t.parse::<Transparency>().unwrap().to_string(), t);
        }
        assert_eq!(
            Transparency::KBuffer { budget: 4 }.buffer_bytes(10),
            [320, 160, 0, 0]
        );
    }
}
