//! The crowd's bodies: two skinned, clothed figures (`hairmeshes/people/man.glb` and
//! `woman.glb`, MakeHuman CC0, made by `tools/people/make_people.sh`), read through the glTF
//! reader, and per person an outfit (figure, clothes and their colours) and a gait (walk or
//! idle clip, phase). The figures carry no head: each person wears the Sintel head of
//! [`super::human`], bound to the skeleton's `head` joint (the canonical head frame is the
//! figures' bind frame, their neck joint where the bust's neck meets it).

use std::sync::{Arc, OnceLock};

use glam::{Mat4, Vec3};

use crate::budget::MemoryBudget;
use crate::error::{HairError, Result};
use crate::model::gltf::{Character, parse_character};
use crate::rng::Pcg32;

/// The two figures, in [`Figure`] order.
static FIGURES: OnceLock<std::result::Result<[Arc<Character>; 2], String>> = OnceLock::new();

/// Which figure a person has.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Figure {
    /// `man.glb`.
    Man = 0,
    /// `woman.glb`.
    Woman = 1,
}

/// The clothing and skin meshes every figure has, in this order.
pub const PARTS: [&str; 6] = ["skin", "shirt", "sleeves", "trousers", "shoes", "skirt"];

/// The two figures (parsed once).
pub fn figures() -> Result<&'static [Arc<Character>; 2]> {
    FIGURES
        .get_or_init(|| {
            let read = |name: &str, bytes: &[u8]| {
                let c = parse_character(name, bytes, None, MemoryBudget::default())
                    .map_err(|e| e.to_string())?;
                for part in PARTS {
                    if !c.meshes.iter().any(|m| m.name == part) {
                        return Err(format!("{name}: no mesh '{part}'"));
                    }
                }
                Ok(Arc::new(c))
            };
            Ok([
                read(
                    "hairmeshes/people/man.glb",
                    include_bytes!("../../hairmeshes/people/man.glb"),
                )?,
                read(
                    "hairmeshes/people/woman.glb",
                    include_bytes!("../../hairmeshes/people/woman.glb"),
                )?,
            ])
        })
        .as_ref()
        .map_err(|e| HairError::invalid("hairmeshes/people", e.clone()))
}

/// Every figure's meshes, figure after figure (what `Renderer::set_skinned_meshes` takes):
/// mesh `k` of figure `f` is at `f * PARTS.len() + k`.
pub fn skinned_meshes() -> Result<Vec<crate::skin::SkinnedMesh>> {
    let mut out = Vec::new();
    for c in figures()? {
        for part in PARTS {
            let m = c.meshes.iter().find(|m| m.name == part);
            out.extend(m.cloned());
        }
    }
    Ok(out)
}

/// What one person wears, and how they move.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Outfit {
    /// Figure.
    pub figure: Figure,
    /// Shirt colour (linear RGB).
    pub shirt: [f32; 3],
    /// Trousers or skirt colour.
    pub legs: [f32; 3],
    /// Shoe colour.
    pub shoes: [f32; 3],
    /// Long sleeves (else the forearms show).
    pub long_sleeves: bool,
    /// A long skirt instead of trousers (only people who stand: a long skirt skinned to the
    /// legs tears when they walk).
    pub skirt: bool,
    /// Walks (else stands, the idle clip).
    pub walks: bool,
    /// Seconds into the clip at time 0.
    pub phase: f32,
}

/// Shirt colours (linear RGB): muted everyday fabrics.
const SHIRTS: [[f32; 3]; 10] = [
    [0.05, 0.09, 0.22],
    [0.5, 0.5, 0.48],
    [0.6, 0.58, 0.52],
    [0.22, 0.03, 0.03],
    [0.04, 0.14, 0.06],
    [0.3, 0.18, 0.07],
    [0.02, 0.02, 0.025],
    [0.35, 0.08, 0.18],
    [0.12, 0.25, 0.4],
    [0.55, 0.4, 0.12],
];
/// Trouser and skirt colours.
const LEGS: [[f32; 3]; 6] = [
    [0.03, 0.04, 0.09],
    [0.015, 0.015, 0.018],
    [0.18, 0.15, 0.1],
    [0.1, 0.1, 0.1],
    [0.05, 0.08, 0.16],
    [0.25, 0.06, 0.05],
];

impl Outfit {
    /// An outfit drawn from `seed`; walking when `walks`.
    pub fn draw(seed: u32, walks: bool) -> Self {
        let mut rng = Pcg32::hashed(seed as u64 ^ 0x6f75_7466_6974);
        let mut pick = |n: usize| (rng.next_u32() as usize) % n;
        let figure = if pick(2) == 0 {
            Figure::Man
        } else {
            Figure::Woman
        };
        let shirt = SHIRTS[pick(SHIRTS.len())];
        let legs = LEGS[pick(LEGS.len())];
        let shoes = [[0.02, 0.015, 0.01], [0.25, 0.25, 0.25], [0.12, 0.06, 0.03]][pick(3)];
        let long_sleeves = pick(2) == 0;
        let skirt = figure == Figure::Woman && !walks && pick(2) == 0;
        let phase = pick(1000) as f32 * 0.01;
        Outfit {
            figure,
            shirt,
            legs,
            shoes,
            long_sleeves,
            skirt,
            walks,
            phase,
        }
    }

    /// The skinned parts this person wears: `(mesh index in [`skinned_meshes`], colour)`,
    /// the skin in `skin`.
    pub fn parts(&self, skin: [f32; 3]) -> Vec<(usize, [f32; 4])> {
        let base = self.figure as usize * PARTS.len();
        let c = |rgb: [f32; 3]| [rgb[0], rgb[1], rgb[2], 1.0];
        let mut out = vec![
            (base, c(skin)),
            (base + 1, c(self.shirt)),
            (base + 4, c(self.shoes)),
        ];
        if self.long_sleeves {
            out.push((base + 2, c(self.shirt)));
        }
        out.push(match self.skirt {
            true => (base + 5, c(self.legs)),
            false => (base + 3, c(self.legs)),
        });
        out
    }
}

/// A person's skeleton at time `t`: the figure's clip (walk or idle) sampled at `t + phase`.
/// Returns the skin matrices (bind frame to the figure's frame, which moves in place: the
/// crowd moves the root along its path) and the head joint's.
pub fn pose(outfit: &Outfit, t: f32) -> Result<(Vec<Mat4>, Mat4)> {
    let figure = &figures()?[outfit.figure as usize];
    let clip = figure
        .clip(if outfit.walks { "walk" } else { "idle" })
        .ok_or_else(|| {
            HairError::invalid("hairmeshes/people", "a figure lacks its walk or idle clip")
        })?;
    let s = &figure.skeleton;
    let m = s.skin_matrices(&clip.sample(s, t + outfit.phase));
    let head = s
        .find("head")
        .ok_or_else(|| HairError::invalid("hairmeshes/people", "a figure has no head joint"))?;
    Ok((m.clone(), m[head]))
}

/// Ground speed of a figure's walk (metres per second at scale 1): the speed its planted feet
/// move backward, which the root must move forward at ([`crate::skin::ground_speed`]).
pub fn walk_speed(figure: Figure) -> Result<f32> {
    let c = &figures()?[figure as usize];
    let s = &c.skeleton;
    let walk = c
        .clip("walk")
        .ok_or_else(|| HairError::invalid("hairmeshes/people", "no walk clip"))?;
    let feet: Vec<usize> = ["ball_l", "ball_r"]
        .iter()
        .filter_map(|n| s.find(n))
        .collect();
    crate::skin::ground_speed(s, walk, &feet, 0.01)
        .ok_or_else(|| HairError::invalid("hairmeshes/people", "the walk does not plant its feet"))
}

/// The placement of a person bound to their head: the hair, head and eyes live in the
/// person frame (canonical scaled by `height` about the feet), which follows the head joint
/// (`head`, canonical bind to posed); returns the character model for `root` (the person's
/// placement) and the body's skin matrices relative to it: `model = root S H S^-1` and
/// `X_j = S H^-1 M_j`, so that `model X_j = root S M_j`.
pub fn head_bound(root: Mat4, height: f32, skin: &[Mat4], head: Mat4) -> (Mat4, Vec<Mat4>) {
    let s = Mat4::from_scale(Vec3::splat(height));
    let model = root * s * head * s.inverse();
    let back = s * head.inverse();
    (model, skin.iter().map(|m| back * *m).collect())
}
