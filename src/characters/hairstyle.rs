//! The hairstyle generator: a distinct hair mesh and style from a seed and a style family,
//! grown from the scalp region of a [`HeadShape`]. Deterministic: the same family, seed and
//! head give byte-identical meshes (and bakes).

use glam::{Vec2, Vec3};

use super::head::{HeadShape, ScalpRegion, scalp};
use crate::error::Result;
use crate::model::hair_mesh::{ExtrudeDesc, HairMesh, extrude};
use crate::model::style::HairStyle;
use crate::rng::Pcg32;

/// Style families.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StyleFamily {
    /// Short hair close to the head.
    ShortCrop,
    /// Chin-length hair falling straight.
    Bob,
    /// Long straight hair.
    LongStraight,
    /// Long curly hair.
    LongCurly,
    /// Hair gathered at the back of the head and falling from there.
    Ponytail,
    /// A spiky strip over the top.
    Mohawk,
    /// Voluminous, very curly hair standing away from the head.
    Afro,
    /// Short fur all over a ball.
    Fur,
    /// The hair mesh `fit` made from the Sintel Lite strands (`hairmeshes/sintel.obj`),
    /// placed on the head.
    Fitted,
}

impl StyleFamily {
    /// The families people get.
    pub const PEOPLE: [StyleFamily; 8] = [
        StyleFamily::ShortCrop,
        StyleFamily::Bob,
        StyleFamily::LongStraight,
        StyleFamily::LongCurly,
        StyleFamily::Ponytail,
        StyleFamily::Mohawk,
        StyleFamily::Afro,
        StyleFamily::Fitted,
    ];
}

/// A generated hairstyle.
pub struct Hairstyle {
    /// Family it was drawn from.
    pub family: StyleFamily,
    /// The hair mesh.
    pub mesh: HairMesh,
    /// Its style.
    pub style: HairStyle,
}

/// Hair colours (linear RGB): black, dark brown, brown, auburn, blonde, grey.
const PALETTE: [[f32; 3]; 6] = [
    [0.02, 0.018, 0.016],
    [0.07, 0.04, 0.022],
    [0.18, 0.1, 0.045],
    [0.28, 0.085, 0.035],
    [0.55, 0.4, 0.2],
    [0.42, 0.4, 0.38],
];

/// Uniform in `[lo, hi)`.
fn range(rng: &mut Pcg32, lo: f32, hi: f32) -> f32 {
    lo + (hi - lo) * rng.next_f32()
}

/// Extrusion of one family: layers, step range, gravity.
struct Growth {
    region: ScalpRegion,
    grid: usize,
    layers: usize,
    step: (f32, f32),
    gravity: f32,
}

fn growth(family: StyleFamily) -> Growth {
    let full = ScalpRegion::Full;
    let g = |region, grid, layers, step, gravity| Growth {
        region,
        grid,
        layers,
        step,
        gravity,
    };
    match family {
        StyleFamily::ShortCrop => g(full, 14, 3, (0.009, 0.014), 0.35),
        StyleFamily::Bob => g(full, 14, 6, (0.026, 0.034), 0.9),
        StyleFamily::LongStraight | StyleFamily::Fitted => g(full, 14, 10, (0.04, 0.055), 0.95),
        StyleFamily::LongCurly => g(full, 14, 9, (0.035, 0.045), 0.8),
        StyleFamily::Ponytail => g(full, 14, 10, (0.035, 0.05), 1.0),
        StyleFamily::Mohawk => g(
            ScalpRegion::Strip { half_width: 0.02 },
            16,
            4,
            (0.025, 0.04),
            0.0,
        ),
        StyleFamily::Afro => g(full, 14, 5, (0.024, 0.032), 0.0),
        StyleFamily::Fur => g(ScalpRegion::All, 12, 3, (0.012, 0.02), 0.25),
    }
}

/// Styling parameters of a family with per-character variation.
fn style_for(family: StyleFamily, seed: u32, rng: &mut Pcg32) -> HairStyle {
    let base = PALETTE[rng.next_u32() as usize % PALETTE.len()];
    let jitter = range(rng, 0.85, 1.15);
    let mut s = HairStyle {
        seed,
        strand_width: range(rng, 0.0007, 0.0011),
        tip_width_ratio: range(rng, 0.25, 0.45),
        length_variation: range(rng, 0.08, 0.25),
        root_ramp: 0.02,
        clump_strength: range(rng, 0.05, 0.3),
        clump_power: range(rng, 1.0, 2.0),
        frizz_amplitude: range(rng, 0.0005, 0.002),
        frizz_frequency: range(rng, 6.0, 14.0),
        color: base.map(|c| (c * jitter).min(1.0)),
        ..HairStyle::default()
    };
    match family {
        StyleFamily::LongCurly => {
            s.curl_radius = range(rng, 0.006, 0.012);
            s.curl_frequency = range(rng, 5.0, 11.0);
        }
        StyleFamily::Afro => {
            s.curl_radius = range(rng, 0.008, 0.014);
            s.curl_frequency = range(rng, 12.0, 22.0);
            s.frizz_amplitude = range(rng, 0.003, 0.006);
            s.clump_strength = range(rng, 0.0, 0.1);
        }
        StyleFamily::Mohawk => {
            s.clump_strength = range(rng, 0.5, 0.8);
            s.clump_power = 1.0;
        }
        StyleFamily::Bob
        | StyleFamily::LongStraight
        | StyleFamily::Ponytail
        | StyleFamily::Fitted => {
            s.wave_amplitude = range(rng, 0.0, 0.006);
            s.wave_frequency = range(rng, 2.0, 5.0);
            s.wave_angle = range(rng, 0.0, std::f32::consts::PI);
        }
        StyleFamily::ShortCrop => s.length_variation = range(rng, 0.2, 0.4),
        StyleFamily::Fur => {
            s.strand_width = range(rng, 0.001, 0.0016);
            s.frizz_amplitude = range(rng, 0.001, 0.003);
        }
    }
    s
}

/// The Sintel hair mesh (`fit` of the Sintel Lite strands, `hairmeshes/sintel.obj`) scaled
/// and moved onto `head` (its roots' width to the head's, its crown to the head's top), with
/// the fitted style scaled alike and this character's colour.
fn fitted_sintel(seed: u32, head: &HeadShape, rng: &mut Pcg32) -> Result<Hairstyle> {
    let mesh = crate::model::obj_io::parse_hair_mesh_obj(
        "hairmeshes/sintel.obj",
        include_bytes!("../../hairmeshes/sintel.obj"),
    )?;
    let fitted = HairStyle::from_toml(
        "hairmeshes/sintel.toml",
        include_str!("../../hairmeshes/sintel.toml"),
    )?;
    let (lo, hi) = crate::model::hair_mesh::bounds(mesh.layers[0].iter().copied());
    let scale = 2.1 * head.radii.x / (hi.x - lo.x).max(1e-6);
    let crown = Vec3::new(0.5 * (lo.x + hi.x), hi.y, 0.5 * (lo.z + hi.z));
    let top = head.centre + Vec3::new(0.0, head.radii.y * 1.02, 0.0);
    // Every character's copy differs: turned a little about the vertical, the hair (not the
    // scalp) longer or shorter.
    let turn = glam::Quat::from_rotation_y(range(rng, -0.3, 0.3));
    let stretch = range(rng, 0.8, 1.2);
    let place = |p: Vec3| top + turn * ((p - crown) * scale);
    let layers = mesh
        .layers
        .iter()
        .map(|l| {
            l.iter()
                .zip(&mesh.layers[0])
                .map(|(p, root)| place(*root) + (place(*p) - place(*root)) * stretch)
                .collect()
        })
        .collect();
    let name = format!("Fitted #{seed}");
    let mesh = HairMesh::new(name, layers, None, mesh.uv.clone(), mesh.faces.clone())?;
    let own = style_for(StyleFamily::Fitted, seed, rng);
    let style = HairStyle {
        seed,
        strand_width: own.strand_width,
        root_ramp: fitted.root_ramp * scale,
        frizz_amplitude: fitted.frizz_amplitude * scale,
        frizz_frequency: fitted.frizz_frequency / scale,
        curl_radius: fitted.curl_radius * scale,
        curl_frequency: fitted.curl_frequency / scale,
        color: own.color,
        ..fitted
    };
    Ok(Hairstyle {
        family: StyleFamily::Fitted,
        mesh,
        style,
    })
}

/// Generate a hairstyle of `family` for `head` from `seed`.
pub fn generate(family: StyleFamily, seed: u32, head: &HeadShape) -> Result<Hairstyle> {
    let mut rng = Pcg32::new(seed as u64 ^ (family as u64) << 40);
    if family == StyleFamily::Fitted {
        return fitted_sintel(seed, head, &mut rng);
    }
    let g = growth(family);
    let step = range(&mut rng, g.step.0, g.step.1);
    let style = style_for(family, seed, &mut rng);
    let patch = scalp(head, g.region, g.grid);
    let name = format!("{family:?} #{seed}");
    let mesh = if family == StyleFamily::Ponytail {
        ponytail(
            &name,
            head,
            &patch.positions,
            patch.uv.clone(),
            patch.faces.clone(),
            g.layers,
            step,
        )?
    } else {
        // Layers bend from the scalp normal toward down-and-back (hair falls behind the face,
        // not over it) and stay outside the head.
        let desc = ExtrudeDesc::new(g.layers, step)
            .gravity(g.gravity, Vec3::new(0.0, -1.0, -0.45).normalize())
            .avoid_sphere(head.centre, head.bounding_radius() * 1.02);
        extrude(name, &patch.positions, &patch.uv, &patch.faces, &desc)?
    };
    Ok(Hairstyle {
        family,
        mesh,
        style,
    })
}

/// Fur grown on a teapot of `height` metres from `seed` (the paper's furry-teapot scene):
/// every patch but the bottom grows short fur along its normals, bending a little downward.
pub fn teapot_fur(seed: u32, height: f32) -> Result<Hairstyle> {
    let family = StyleFamily::Fur;
    let mut rng = Pcg32::new(seed as u64 ^ (0x007e_a907_u64 << 40));
    let g = growth(family);
    let step = range(&mut rng, g.step.0, g.step.1) * 1.25;
    let gravity = range(&mut rng, 0.0, 0.5);
    let mut style = style_for(family, seed, &mut rng);
    // Teapot bundles are large: strong clumping would show the patch grid as tufts.
    style.clump_strength = range(&mut rng, 0.0, 0.08);
    let surface = super::teapot::fur_scalp(height, 5);
    let desc = ExtrudeDesc::new(g.layers, step).gravity(gravity, Vec3::NEG_Y);
    let mesh = extrude(
        format!("teapot #{seed}"),
        &surface.positions,
        &surface.uv,
        &surface.faces,
        &desc,
    )?;
    Ok(Hairstyle {
        family,
        mesh,
        style,
    })
}

/// A ponytail: layers 1-3 gather the scalp toward a tie at the back of the head, the rest
/// hang from the tie as one narrow bundle of bundles.
fn ponytail(
    name: &str,
    head: &HeadShape,
    scalp: &[Vec3],
    uv: Vec<Vec2>,
    faces: Vec<crate::model::hair_mesh::Face>,
    layers: usize,
    step: f32,
) -> Result<HairMesh> {
    let tie = head.centre + Vec3::new(0.0, 0.02, -head.radii.z * 1.08);
    let lifted: Vec<Vec3> = scalp
        .iter()
        .map(|p| *p + (*p - head.centre).normalize_or(Vec3::Y) * 0.006)
        .collect();
    let gathered: Vec<Vec3> = lifted.iter().map(|p| tie + (*p - tie) * 0.12).collect();
    let mut out = vec![scalp.to_vec(), lifted.clone()];
    for k in 2..layers {
        let layer = if k <= 3 {
            let t = (k - 1) as f32 / 3.0;
            lifted
                .iter()
                .zip(&gathered)
                .map(|(a, b)| a.lerp(*b, t * t * (3.0 - 2.0 * t)))
                .collect()
        } else {
            let drop = (k - 3) as f32 * step;
            gathered
                .iter()
                .map(|p| *p + Vec3::new(0.0, -drop, -0.25 * drop))
                .collect()
        };
        out.push(layer);
    }
    HairMesh::new(name, out, None, uv, faces)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_family_generates_a_valid_mesh() {
        let head = HeadShape::default();
        for family in StyleFamily::PEOPLE.into_iter().chain([StyleFamily::Fur]) {
            let h = generate(family, 7, &head).unwrap();
            assert!(h.mesh.faces.len() >= 10, "{family:?}");
            h.style.validate("test").unwrap();
        }
        // The fitted Sintel hair sits on the head: its roots within the head's box (grown by
        // a fifth), its crown at the head's top.
        let h = generate(StyleFamily::Fitted, 7, &head).unwrap();
        let (lo, hi) = crate::model::hair_mesh::bounds(h.mesh.layers[0].iter().copied());
        let margin = head.radii * 1.2;
        assert!(lo.cmpge(head.centre - margin).all() && hi.cmple(head.centre + margin).all());
        assert!((hi.y - (head.centre.y + head.radii.y)).abs() < 0.01, "{hi}");
        let fur = teapot_fur(3, 0.27).unwrap();
        assert!(fur.mesh.faces.len() > 500);
        fur.style.validate("test").unwrap();
    }
}
