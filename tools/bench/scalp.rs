//! `bench scalp`: how much of each family's scalp shows through its hair in the crowd's
//! portrait (`crowd --count 1 --family F --view V --animate off`), at each density asked for:
//! the share of the scalp's pixels whose light through the hair is above one half
//! (`characters::scalp`). The scalp is drawn as a prop just above the head in two colours, with
//! the hair and with the hair moved out of view; the measure's frames have no shadows, so what
//! hides the scalp is the hair in front of it, not its shade.

use std::path::PathBuf;
use std::sync::Arc;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::characters::hairstyle::StyleFamily;
use hairmesh::characters::preset::{self, Body, Preset, StrandDensity};
use hairmesh::characters::scalp::{ShowThrough, scalp_triangles};
use hairmesh::outln;
use hairmesh::render::shared::{PropInstance, SKIN_NONE};
use hairmesh::render::{
    FrameOptions, FrameSettings, LodSettings, Renderer, RendererDesc, ShadowMode, View,
};
use hairmesh::vk::{Context, ContextDesc};

/// Arguments of `bench scalp`.
#[derive(clap::Args)]
pub struct ScalpArgs {
    /// Families (default: every people family).
    #[arg(long, value_delimiter = ',')]
    families: Vec<StyleFamily>,
    /// Densities, one row each: strands per cm² of scalp (`175`, the crowd's) or strands per
    /// reference bundle (`96/bundle`, the crowd's rule before 2026-12-07).
    #[arg(long, value_delimiter = ',', default_value = "175,96/bundle", value_parser = parse_density)]
    densities: Vec<StrandDensity>,
    /// Portrait views: front, side, back.
    #[arg(long, value_delimiter = ',', default_value = "front,back", value_parser = ["front", "side", "back"])]
    views: Vec<String>,
    /// Image side in pixels.
    #[arg(long, default_value_t = 640, value_parser = clap::value_parser!(u32).range(64..=4096))]
    size: u32,
    /// Seed of the people.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Choose the GPU by name substring.
    #[arg(long)]
    device: Option<String>,
    /// Write each row's frame with the hair (the scalp red) here as
    /// `scalp_<family>_<view>_<density>.png`.
    #[arg(long)]
    pictures: Option<PathBuf>,
}

/// `175` (per cm²) or `96/bundle`.
fn parse_density(s: &str) -> Result<StrandDensity, String> {
    let bad = || format!("{s}: expected strands per cm² (175) or per bundle (96/bundle)");
    match s.strip_suffix("/bundle") {
        Some(n) => match n.parse::<u32>() {
            Ok(n) if (1..=16384).contains(&n) => Ok(StrandDensity::PerReferenceBundle(n)),
            _ => Err(bad()),
        },
        None => match s.parse::<f32>() {
            Ok(d) if d > 0.0 && d <= 2000.0 => Ok(StrandDensity::PerCm2(d)),
            _ => Err(bad()),
        },
    }
}

fn density_name(d: StrandDensity) -> String {
    match d {
        StrandDensity::PerCm2(d) => format!("{d}/cm²"),
        StrandDensity::PerReferenceBundle(n) => format!("{n}/bundle"),
    }
}

/// The scalp prop's two colours (linear RGB).
const SCALP_COLOURS: [[f32; 4]; 2] = [[0.85, 0.08, 0.05, 1.0], [0.05, 0.1, 0.85, 1.0]];

/// One family's portrait: its renderer (the scalp the last prop mesh), its character and how its
/// hair is placed.
struct Portrait {
    renderer: Renderer,
    id: hairmesh::render::CharacterId,
    character: preset::CrowdCharacter,
    baked: hairmesh::BakedHairMesh,
    scalp_mesh: usize,
    hair_model: Mat4,
}

impl Portrait {
    fn new(ctx: &Arc<Context>, family: StyleFamily, args: &ScalpArgs) -> Result<Self> {
        let c = preset::build_families(Preset::People, 1, args.seed, &[family])?.remove(0);
        let Body::Person(person) = c.body else {
            bail!("{family:?}: not a person");
        };
        let baked = hairmesh::bake(&c.hair.mesh, &c.hair.style, Default::default(), |_, _| {})?;
        let scalp = scalp_triangles(&c.hair.mesh, &person.head()?, 6);
        let mut meshes = preset::prop_meshes()?;
        let scalp_mesh = meshes.len();
        meshes.push(hairmesh::characters::human::smooth_prop_mesh(&scalp));
        let desc = RendererDesc::default().size(args.size, args.size);
        let mut r = Renderer::new(ctx, &desc)?;
        r.set_prop_meshes(&meshes)?;
        let skinned = hairmesh::characters::people::skinned_meshes()?;
        r.set_skinned_meshes(&skinned)?;
        r.set_skinned_lods(&hairmesh::characters::people::skinned_lods(&skinned))?;
        let params = c.strand_params_at(StrandDensity::default(), 4)?;
        let id = r.add_character(&baked, &c.hair.style, params, c.model)?;
        preset::dress(&mut r, id, &c)?;
        let hair_model = match &c.walker {
            Some(w) => w.frame(0.0)?.hair,
            None => c.model,
        };
        Ok(Portrait {
            renderer: r,
            id,
            character: c,
            baked,
            scalp_mesh,
            hair_model,
        })
    }

    /// One frame from `view` with the scalp in colour `colour`, the hair in place or not: its
    /// pixels and the strands it drew.
    fn frame(&mut self, view: &View, colour: usize, hair: bool) -> Result<(Vec<u8>, u32)> {
        let scalp = PropInstance {
            model: self.hair_model.to_cols_array_2d(),
            color: SCALP_COLOURS[colour],
            clip_to_prev: Mat4::IDENTITY.to_cols_array_2d(),
            skin: [SKIN_NONE, 0, 0, 0],
        };
        let mut props = preset::world_props();
        props.push((self.scalp_mesh, scalp));
        self.renderer.set_prop_instances(&props)?;
        // Out of view a kilometre below: the body and head stay, the hair does not.
        let away = Mat4::from_translation(Vec3::new(0.0, -1000.0, 0.0));
        let model = if hair {
            self.hair_model
        } else {
            away * self.hair_model
        };
        self.renderer.set_model(self.id, model)?;
        let settings = FrameSettings {
            path: self.renderer.default_path(),
            raster: Default::default(),
            transparency: Default::default(),
            msaa: 1,
            light_raster: Default::default(),
        }
        .with_fastest((None, None), &self.renderer.caps());
        let report = self.renderer.render_one(
            view,
            &FrameOptions {
                read_image: true,
                raster: settings.raster,
                light_raster: settings.light_raster,
                ..Default::default()
            },
        )?;
        Ok((report.rgba.unwrap_or_default(), report.stats.strands_drawn))
    }
}

/// Run `bench scalp`.
pub fn bench_scalp(args: ScalpArgs) -> Result<()> {
    let pictures = match &args.pictures {
        Some(dir) if !dir.is_dir() => bail!("--pictures {}: not a folder", dir.display()),
        p => p.clone(),
    };
    let families = match args.families.is_empty() {
        true => StyleFamily::PEOPLE.to_vec(),
        false => args.families.clone(),
    };
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(args.device.clone()),
    )?);
    outln!(
        "device: {} ({}); portraits {}x{}, crowd LoD, no shadows in the measure's frames",
        ctx.info.name,
        ctx.info.driver,
        args.size,
        args.size
    )?;
    outln!(
        "| family | scalp cm² | density | strands | view | drawn | scalp px | show-through | mean T |"
    )?;
    outln!("|---|---|---|---|---|---|---|---|---|")?;
    for family in families {
        let mut p = Portrait::new(&ctx, family, &args)?;
        let cm2 = p.character.hair.scalp_cm2(1.0);
        for view_name in &args.views {
            let camera = preset::portrait_camera(p.hair_model, view_name);
            let view = View {
                light_dir: hairmesh::render::camera::portrait_light(&camera),
                lod: LodSettings::crowd(),
                shadows: ShadowMode::Off,
                ..View::crowd_look(camera)
            };
            let bare = [p.frame(&view, 0, false)?.0, p.frame(&view, 1, false)?.0];
            for &density in &args.densities {
                let params = p.character.strand_params_at(density, 4)?;
                p.renderer.set_params(p.id, params)?;
                let full = hairmesh::reference::generate::strands_at_full_detail(
                    &p.baked,
                    &p.character.hair.style,
                    params.strands_per_bundle,
                );
                let ((red, drawn), (blue, _)) =
                    (p.frame(&view, 0, true)?, p.frame(&view, 1, true)?);
                let hair = [red, blue];
                let m = ShowThrough::measure([&hair[0], &hair[1]], [&bare[0], &bare[1]]);
                outln!(
                    "| {} | {cm2:.0} | {} | {full} | {view_name} | {} | {} | {:.3} | {:.3} |",
                    family.name(),
                    density_name(density),
                    drawn,
                    m.scalp_pixels,
                    m.share(),
                    m.mean_transmittance
                )?;
                if let Some(dir) = &pictures {
                    let name = density_name(density).replace(['/', '²'], "_");
                    let path = dir.join(format!("scalp_{}_{view_name}_{name}.png", family.name()));
                    let png = hairmesh::fsutil::encode_png(
                        &path.display().to_string(),
                        args.size,
                        args.size,
                        hair[0].clone(),
                    )?;
                    hairmesh::fsutil::write_atomic(&path, &png)?;
                }
            }
        }
    }
    Ok(())
}
