//! `crowd`: hundreds of characters, each with its own generated hairstyle, on the one-frame
//! renderer. Headless mode renders an orbit around the crowd to PNGs plus a CSV of per-frame
//! statistics:
//!
//! ```text
//! crowd --headless --frames 3 --count 16 --size 640x360 --out frames/
//! ```
//!
//! Without `--headless` it opens a window (winit, swapchain) with an orbit / fly camera; keys
//! switch LoD, path, present mode and strand settings (see `window.rs` and the README).

use std::io::Write as _;
use std::path::PathBuf;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result, bail};
use clap::Parser;
use glam::Vec3;
use hairmesh::animate::{CharacterMotion, CrowdAnimation, Wind};
use hairmesh::bake::deform::DeformBasis;
use hairmesh::characters::own::OwnCharacter;
use hairmesh::characters::preset::{self, Preset, SPACING, StrandDensity};
use hairmesh::cli::{DeviceFlags, LodFlags, LookFlags};
use hairmesh::fsutil::{RunFiles, StagedFolder};
use hairmesh::render::{
    Camera, FrameOptions, LodSettings, RenderPath, Renderer, RendererDesc, StrandParams, View,
};
use hairmesh::vk::{Context, ContextDesc};
use hairmesh::{BakeOptions, outln};

mod window;

/// A crowd of characters with unique generated hair.
#[derive(Parser)]
#[command(version, about)]
pub struct Args {
    /// Render without a window to PNG files.
    #[arg(long)]
    headless: bool,
    /// Window mode: close after presenting this many frames (tests, screenshots).
    #[arg(long)]
    exit_after_frames: Option<u64>,
    /// Window mode: resize the window to another size after 3 frames and simulate a zero-size
    /// (minimised) window for 3 frames after 6 (tests).
    #[arg(long)]
    test_resize: bool,
    /// Window mode: present mode fifo, mailbox or immediate (FIFO where not offered).
    #[arg(long, default_value = "fifo", value_parser = ["fifo", "mailbox", "immediate"])]
    present_mode: String,
    /// Frames to render (headless).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100_000))]
    frames: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "960x540")]
    size: String,
    /// Host memory the run may use, MiB: a crowd, image or run past it is refused first.
    #[arg(long, value_name = "MIB", default_value = "4096", value_parser = hairmesh::budget::parse_budget_flag)]
    memory_budget_mib: hairmesh::budget::MemoryBudget,
    /// Output folder for frame PNGs and stats.csv (headless).
    #[arg(long, default_value = "crowd_frames")]
    out: PathBuf,
    /// Scene preset: people, mixed (people and furry balls) or teapots (furry Utah teapots).
    #[arg(long, default_value = "people")]
    preset: Preset,
    /// Fill the crowd with copies of this glTF character (.glb or .gltf: skinned, upright,
    /// facing +Z, metres) instead of the preset, each with its own hair grown on its head
    /// (--family) and bound to its head joint (--joint); they play its `walk` clip (else its
    /// first) and walk where that clip plants its feet.
    #[arg(long)]
    character: Option<PathBuf>,
    /// The --character's head joint.
    #[arg(long, default_value = "head", requires = "character")]
    joint: String,
    /// People's hairstyle families, comma-separated (default: all twelve in turn): buzz,
    /// shortcrop, bob, longstraight, longwavy, longcurly, ponytail, bun, sidebangs, mohawk,
    /// afro, fitted.
    #[arg(long, value_delimiter = ',')]
    family: Vec<hairmesh::characters::hairstyle::StyleFamily>,
    /// Headless camera: orbit (around the crowd), eye (at eye height in front of the crowd,
    /// looking into it) or front, side, back (a portrait of the first character's head).
    #[arg(long, default_value = "orbit", value_parser = ["orbit", "eye", "front", "side", "back"])]
    view: String,
    /// Headless lighting: crowd (the sun high and to the side), portrait (a three-quarter key
    /// from the camera's left, 28 degrees up) or auto (portrait for the front, side and back
    /// views, else crowd).
    #[arg(long, default_value = "auto", value_parser = ["auto", "crowd", "portrait"])]
    light: String,
    /// Number of characters.
    #[arg(long, default_value_t = 100, value_parser = clap::value_parser!(u32).range(1..=preset::MAX_CROWD as i64))]
    count: u32,
    /// Seed of the hairstyles and placement.
    #[arg(long, default_value_t = 1)]
    seed: u32,
    /// Strands per cm² of scalp: a real head carries 150-200 (90-150K strands on a full
    /// head; the level of detail draws what the pixels need). Fur grows 96 per bundle.
    #[arg(long, default_value_t = hairmesh::characters::hairstyle::SCALP_STRANDS_PER_CM2)]
    strands_per_cm2: f32,
    /// Instead of --strands-per-cm2: strands per bundle of 24 cm² of scalp (people with
    /// coarser hair meshes get proportionally more per bundle), and per bundle of fur.
    #[arg(long, conflicts_with = "strands_per_cm2", value_parser = clap::value_parser!(u32).range(1..=16384))]
    strands_per_bundle: Option<u32>,
    /// Vertices per strand are 2^e + 1 (e in 0..=6).
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(0..=6))]
    verts_log2: u32,
    /// The volume tier (seed 002): far characters' hair ray-marched through strand density
    /// volumes, and volumetric ambient occlusion of every character's hair; off: strands
    /// only, no occlusion.
    #[arg(long, default_value = "on", value_parser = hairmesh::render::parse_switch, action = clap::ArgAction::Set)]
    volumes: bool,
    /// The volume tier's switch band FAR,NEAR: hair boxes below FAR pixels across are drawn as
    /// volumes alone, above NEAR as strands alone, blended between.
    #[arg(long, default_value = "40,64")]
    volume_band: String,
    /// Characters walk, turn and sway, and their hair meshes are simulated (people and furry
    /// balls; teapots move without hair dynamics).
    #[arg(long, default_value = "on", value_parser = hairmesh::render::parse_switch, action = clap::ArgAction::Set)]
    animate: bool,
    /// Where hair dynamics run: gpu (one compute dispatch for every character; the pose never
    /// leaves the GPU) or cpu (all cores; poses uploaded every frame).
    #[arg(long, default_value = "gpu")]
    dynamics: hairmesh::animate::DynamicsPath,
    /// Simulate characters small on screen less often (every 2nd, 4th or 8th frame below 96,
    /// 48 and 24 pixels of hair, with the time they skipped in one step); off: every character
    /// every frame (1000 people: 340 ms more a frame on lavapipe, FLIP 0.015 against on).
    #[arg(long, default_value = "on", value_parser = hairmesh::render::parse_switch, action = clap::ArgAction::Set)]
    dynamics_schedule: bool,
    /// Wind strength on the hair tips, m/s^2 (0..=100; gusty).
    #[arg(long, default_value_t = 0.0)]
    wind: f32,
    /// Wind direction x,y,z.
    #[arg(long, default_value = "1,0,0.3")]
    wind_dir: String,
    /// Headless: the camera orbits the crowd (off: it stays at frame 0's place).
    #[arg(long, default_value = "on", value_parser = hairmesh::render::parse_switch, action = clap::ArgAction::Set)]
    orbit: bool,
    #[command(flatten)]
    lod: LodFlags,
    #[command(flatten)]
    look: LookFlags,
    #[command(flatten)]
    gpu: DeviceFlags,
    /// Generation path (default: mesh where supported).
    #[arg(long, value_parser = parse_generated_path)]
    path: Option<RenderPath>,
}

pub fn parse_size(s: &str) -> Result<(u32, u32)> {
    hairmesh::render::scene::parse_size(s).map_err(anyhow::Error::msg)
}

/// The crowd: generated characters and their bakes.
pub struct Scene {
    characters: Vec<preset::CrowdCharacter>,
    /// The user's character the crowd copies (`--character`), else the people.
    own: Option<Arc<OwnCharacter>>,
    baked: Vec<hairmesh::BakedHairMesh>,
    /// Per character, its bundles' first roots in its own frame (the root-gap reference).
    expected: Vec<Vec<glam::Vec3>>,
    /// Seconds to generate and bake.
    pub generate_s: f64,
}

impl Scene {
    /// Generate and bake the characters the flags ask for.
    pub fn build(args: &Args) -> Result<Self> {
        let start = Instant::now();
        let families = if args.family.is_empty() {
            hairmesh::characters::hairstyle::StyleFamily::PEOPLE.to_vec()
        } else {
            args.family.clone()
        };
        let own = match &args.character {
            Some(path) => Some(Arc::new(OwnCharacter::load(
                path,
                &args.joint,
                args.memory_budget_mib,
            )?)),
            None => None,
        };
        let count = args.count as usize;
        let characters = match &own {
            Some(own) => preset::build_own(own, count, args.seed, &families)?,
            None => preset::build_families(args.preset, count, args.seed, &families)?,
        };
        // Every head must hold the density asked for before anything is baked.
        for c in &characters {
            c.strand_params_at(args.density(), args.verts_log2)
                .map_err(|e| density_error(args, e))?;
        }
        let mut baked = Vec::with_capacity(characters.len());
        for c in &characters {
            baked.push(hairmesh::bake(
                &c.hair.mesh,
                &c.hair.style,
                bake_options(c, args.animate),
                |_, _| {},
            )?);
        }
        let expected = characters
            .iter()
            .zip(&baked)
            .map(|(c, b)| hairmesh::characters::people::expected_roots(b, &c.hair.style))
            .collect();
        Ok(Scene {
            characters,
            own,
            baked,
            expected,
            generate_s: start.elapsed().as_secs_f64(),
        })
    }

    /// A renderer of `width x height` holding every character and prop.
    pub fn renderer(
        &self,
        ctx: &Arc<Context>,
        args: &Args,
        width: u32,
        height: u32,
    ) -> Result<Renderer> {
        let path = args.path;
        hairmesh::render::check_msaa(ctx, args.msaa())
            .map_err(|why| anyhow::anyhow!("--msaa {}: {why}", args.msaa()))?;
        let mut renderer = Renderer::new(
            ctx,
            &RendererDesc::default()
                .size(width, height)
                .path(path)
                .msaa(args.msaa())
                .max_characters(args.count),
        )?;
        let density = args.density();
        let meshes = preset::prop_meshes()?;
        renderer.set_prop_meshes(&meshes)?;
        renderer.set_prop_instances(&preset::world_props())?;
        match &self.own {
            Some(own) => {
                renderer.set_skinned_meshes(&own.skinned_meshes())?;
                renderer.set_skinned_lods(&own.skinned_lods())?;
            }
            None => {
                let skinned = hairmesh::characters::people::skinned_meshes()?;
                renderer.set_skinned_meshes(&skinned)?;
                renderer.set_skinned_lods(&hairmesh::characters::people::skinned_lods(&skinned))?;
            }
        }
        for (c, b) in self.characters.iter().zip(&self.baked) {
            let params = c
                .strand_params_at(density, args.verts_log2)
                .map_err(|e| density_error(args, e))?;
            let id = renderer.add_character(b, &c.hair.style, params, c.model)?;
            // Heads and bodies move with their characters: drawn at the same model as the hair.
            preset::dress(&mut renderer, id, c)?;
        }
        Ok(renderer)
    }

    /// The crowd's animation (nothing moves with `--animate off`): every character's motion,
    /// and for people and furry balls their hair dynamics (their textures rebuilt on the GPU).
    pub fn animation(&self, renderer: &mut Renderer, args: &Args) -> Result<CrowdAnimation> {
        let mut anim = CrowdAnimation::new();
        anim.wind = Wind {
            direction: hairmesh::render::scene::parse_vec3(&args.wind_dir)
                .map_err(|e| anyhow::anyhow!("--wind-dir: {e}"))?,
            strength: args.wind,
            gustiness: 0.6,
        };
        if !(0.0..=100.0).contains(&args.wind) {
            bail!("--wind {}: must be 0..=100", args.wind);
        }
        anim.path = args.dynamics;
        anim.schedule = args.dynamics_schedule;
        if !args.animate {
            anim.moving = false;
            anim.simulating = false;
            return Ok(anim);
        }
        let ids = renderer.crowd().ids();
        for (k, ((c, b), id)) in self.characters.iter().zip(&self.baked).zip(ids).enumerate() {
            let motion = match c.body {
                preset::Body::Person(_) => CharacterMotion::idle(c.model, args.seed ^ k as u32),
                // Fur sways gently in place.
                _ => CharacterMotion {
                    walk_radius: 0.0,
                    ..CharacterMotion::idle(c.model, args.seed ^ k as u32)
                },
            };
            let colliders = c.colliders()?;
            let hair = match colliders {
                Some(colliders) => {
                    let options = bake_options(c, true);
                    renderer.make_deformable(id, DeformBasis::new(&c.hair.mesh, b, options)?)?;
                    Some((&c.hair.mesh, colliders))
                }
                None => None,
            };
            match &c.walker {
                Some(w) => anim.add_person(id, w.clone(), hair)?,
                None => anim.add(id, motion, hair),
            }
        }
        Ok(anim)
    }

    /// Largest distance, in head radii, of a person's hair roots as the GPU placed them
    /// this frame (`report.roots`: the hair's model and textures) from where the skinned scalp
    /// carries them (the body's placement and head joint), over every person (0 without
    /// people). Fails when the frame did not probe roots or missed a person.
    pub fn root_gap(
        &self,
        renderer: &Renderer,
        report: &hairmesh::render::FrameReport,
    ) -> Result<f32> {
        let Some(roots) = report.roots.as_deref() else {
            bail!("the frame did not probe roots");
        };
        let mut worst = 0.0f32;
        let ids = renderer.crowd().ids();
        for ((c, id), expected) in self.characters.iter().zip(ids).zip(&self.expected) {
            let (Some(w), Some((body, skin))) = (&c.walker, renderer.character_pose(id)) else {
                continue;
            };
            let person = match c.body {
                preset::Body::Person(p) => p,
                _ => Default::default(),
            };
            let probed = hairmesh::characters::people::probed_roots(roots, id.slot());
            let (joint, head_to_hair, head_scale) = w.scalp(&person)?;
            let head_joint = skin.get(joint).copied().unwrap_or_default();
            let gap = hairmesh::characters::people::root_gap(
                &probed,
                expected,
                (body, head_joint),
                head_to_hair,
                head_scale,
            )
            .ok_or_else(|| {
                anyhow::anyhow!(
                    "the root probe found {} of {} roots of character {}",
                    probed.len(),
                    expected.len(),
                    id.slot()
                )
            })?;
            worst = worst.max(gap);
        }
        Ok(worst)
    }

    /// Number of characters.
    pub fn character_count(&self) -> usize {
        self.characters.len()
    }

    /// The strand settings of character `i` at `density` and full vertex level `verts_log2`
    /// (fur caps the vertex level).
    pub fn strand_params(
        &self,
        i: usize,
        density: StrandDensity,
        verts_log2: u32,
    ) -> Result<StrandParams> {
        let c = self.characters.get(i).context("no such character")?;
        Ok(c.strand_params_at(density, verts_log2)?)
    }

    /// Strands every character grows at full detail at `density` (the frame line's "of").
    pub fn full_strands(&self, density: StrandDensity, verts_log2: u32) -> Result<u64> {
        let mut total = 0u64;
        for (i, b) in self.baked.iter().enumerate() {
            let n = self
                .strand_params(i, density, verts_log2)?
                .strands_per_bundle;
            let style = &self.characters[i].hair.style;
            total += hairmesh::reference::generate::strands_at_full_detail(b, style, n);
        }
        Ok(total)
    }
}

/// A density a character cannot hold, named by the flag that asked for it.
fn density_error(args: &Args, e: hairmesh::HairError) -> anyhow::Error {
    match args.strands_per_bundle {
        Some(n) => anyhow::anyhow!("--strands-per-bundle {n}: {e}"),
        None => anyhow::anyhow!("--strands-per-cm2 {}: {e}", args.strands_per_cm2),
    }
}

/// Bake options of `c`: animated hair gets a decode box grown by its longest vertex column, so
/// no pose can leave it.
fn bake_options(c: &preset::CrowdCharacter, animated: bool) -> BakeOptions {
    let mesh = &c.hair.mesh;
    let n = mesh.vertices_per_layer();
    let reach = (0..n)
        .map(|i| {
            mesh.layers
                .windows(2)
                .map(|w| w[0][i].distance(w[1][i]))
                .sum::<f32>()
        })
        .fold(0.0f32, f32::max);
    BakeOptions {
        motion_margin: if animated && c.body != preset::Body::Teapot {
            reach
        } else {
            0.0
        },
        ..Default::default()
    }
}

/// Host memory of a run, from its flags: each character's hair mesh, textures and simulation
/// state (measured at about 175 KiB), a frame's read-back, image and PNG, and a stats row per
/// frame.
fn check_memory(args: &Args) -> Result<()> {
    let (w, h) = parse_size(&args.size)?;
    let estimate = hairmesh::budget::Estimate::new()
        .with("characters", args.count as u64, 256 << 10)
        .with("frame read-back, image and PNG", w as u64 * h as u64, 12)
        .with("stats rows", args.frames as u64, 256);
    args.memory_budget_mib.check(
        &format!("--count {} --size {}", args.count, args.size),
        "the crowd",
        &estimate,
        "lower --count or --size",
    )?;
    Ok(())
}

impl Args {
    /// The crowd's strand density: `--strands-per-bundle` where given, else
    /// `--strands-per-cm2`.
    pub fn density(&self) -> StrandDensity {
        match self.strands_per_bundle {
            Some(n) => StrandDensity::PerReferenceBundle(n),
            None => StrandDensity::PerCm2(self.strands_per_cm2),
        }
    }

    /// The LoD flags over the crowd's preset ([`LodSettings::crowd`]), checked.
    fn lod_settings(&self) -> Result<LodSettings> {
        self.lod
            .settings(LodSettings::crowd())
            .map_err(anyhow::Error::msg)
    }

    /// Samples per pixel (default 1).
    fn msaa(&self) -> u32 {
        self.look.msaa.unwrap_or(1)
    }

    /// Strand shading (default marschner, the crowd's look).
    fn shading(&self) -> hairmesh::shade::ShadingModel {
        self.look
            .shading
            .unwrap_or(hairmesh::shade::ShadingModel::Marschner)
    }

    /// Shadows (default deep opacity, the crowd's look).
    fn shadows(&self) -> hairmesh::render::ShadowMode {
        self.look
            .shadows
            .unwrap_or(hairmesh::render::ShadowMode::DeepOpacity)
    }

    /// Strand compositing (default opaque).
    fn transparency(&self) -> hairmesh::render::Transparency {
        self.look.transparency.unwrap_or_default()
    }

    /// Temporal accumulation (default off).
    fn temporal(&self) -> hairmesh::render::Temporal {
        self.look.temporal.unwrap_or_default()
    }

    /// The thick-strand appearance term (default on).
    fn lod_appearance(&self) -> bool {
        self.look.lod_appearance.unwrap_or(true)
    }

    /// Multiple scattering (default on, the crowd's look).
    fn multiple_scattering(&self) -> bool {
        self.look.multiple_scattering.unwrap_or(true)
    }

    /// The frame settings the flags ask for (the path and rasterizers the device picks are
    /// filled in once the renderer exists).
    fn frame_settings(&self) -> hairmesh::render::FrameSettings {
        hairmesh::render::FrameSettings {
            path: self.path.unwrap_or(RenderPath::Compute),
            raster: self.look.draw.unwrap_or_default(),
            transparency: self.transparency(),
            msaa: self.msaa(),
            light_raster: self.look.shadow_draw.unwrap_or_default(),
        }
    }

    /// The view's volume tier from `--volumes` and `--volume-band`.
    fn volume_tier(&self) -> Result<hairmesh::render::VolumeTier> {
        use hairmesh::render::VolumeTier;
        if !self.volumes {
            return Ok(VolumeTier::OFF);
        }
        let band = || -> Option<(f32, f32)> {
            let (far, near) = self.volume_band.split_once(',')?;
            Some((far.trim().parse().ok()?, near.trim().parse().ok()?))
        };
        let tier = VolumeTier {
            far: Some(band().ok_or_else(|| {
                anyhow::anyhow!(
                    "--volume-band {}: expected FAR,NEAR pixels",
                    self.volume_band
                )
            })?),
            ..VolumeTier::on()
        };
        tier.validate()
            .map_err(|why| anyhow::anyhow!("--volume-band {}: {why}", self.volume_band))?;
        Ok(tier)
    }
}

/// `--path`: the crowd generates its strands (mesh or compute).
fn parse_generated_path(s: &str) -> Result<RenderPath, String> {
    match s.parse()? {
        p @ (RenderPath::Mesh | RenderPath::Compute) => Ok(p),
        p => Err(format!("{p}: the crowd uses the mesh or compute path")),
    }
}

/// Refuse every flag given that another flag makes unused (issue 46: a flag with no effect is
/// an error naming why, not silently ignored).
fn check_unused(p: &hairmesh::cli::Parsed<Args>) -> Result<(), String> {
    let a = &p.args;
    for id in ["frames", "out", "view", "light", "orbit"] {
        p.unused_unless(id, a.headless, "it applies to --headless runs only")?;
    }
    for id in ["exit_after_frames", "test_resize", "present_mode"] {
        p.unused_unless(
            id,
            !a.headless,
            "it applies to the window, and --headless opens none",
        )?;
    }
    p.unused_unless("volume_band", a.volumes, "--volumes is off")?;
    p.unused_unless("wind_dir", a.wind > 0.0, "--wind is 0")?;
    for id in ["wind", "dynamics", "dynamics_schedule"] {
        p.unused_unless(id, a.animate, "--animate is off")?;
    }
    p.unused_unless(
        "preset",
        a.character.is_none(),
        "--character fills the crowd",
    )?;
    p.unused_unless(
        "family",
        a.character.is_some() || a.preset != Preset::Teapots,
        "--preset teapots has no people",
    )?;
    p.unused_unless(
        "multiple_scattering",
        a.shading() == hairmesh::shade::ShadingModel::Marschner,
        "it is part of --shading marschner",
    )?;
    for id in LodFlags::TUNING_IDS.into_iter().chain(["lod_appearance"]) {
        p.unused_unless(id, a.lod.lod, "--lod is off")?;
    }
    p.unused_unless(
        "shadow_draw",
        a.shadows() != hairmesh::render::ShadowMode::Off,
        "--shadows is off",
    )?;
    Ok(())
}

/// What the checks of the flags produced.
struct Checked {
    volumes: hairmesh::render::VolumeTier,
    /// The headless run's staged output folder (`None`: a window).
    out: Option<StagedFolder>,
}

/// Every check of the flags that needs no device, before any work: unused flags, sizes, the
/// memory estimate, the volume band, wind, the settings' combination and the output folder
/// (its frame names; created when the first frame is written).
fn check_args(p: &hairmesh::cli::Parsed<Args>) -> Result<Checked> {
    check_unused(p).map_err(anyhow::Error::msg)?;
    let args = &p.args;
    check_memory(args)?;
    let volumes = args.volume_tier()?;
    let wind_dir = hairmesh::render::scene::parse_vec3(&args.wind_dir)
        .map_err(|e| anyhow::anyhow!("--wind-dir {}: {e}", args.wind_dir))?;
    if !(0.0..=100.0).contains(&args.wind) {
        bail!("--wind {}: must be 0..=100", args.wind);
    }
    if args.wind > 0.0 && !(wind_dir.is_finite() && wind_dir.length() > 0.0) {
        bail!(
            "--wind-dir {}: must be a finite, non-zero direction",
            args.wind_dir
        );
    }
    if !(args.strands_per_cm2 > 0.0 && args.strands_per_cm2 <= 2000.0) {
        bail!(
            "--strands-per-cm2 {}: must be above 0 and at most 2000",
            args.strands_per_cm2
        );
    }
    args.lod_settings()?;

    let settings = args.frame_settings();
    if let Err(why) = settings.check_combination() {
        bail!("--draw / --msaa {} / --transparency: {why}", args.msaa());
    }
    // Every output of the run is checked before the first frame, and they appear only when
    // the whole run succeeded.
    let out = if args.headless {
        let mut names: Vec<String> = (0..args.frames).map(frame_name).collect();
        names.push("stats.csv".into());
        Some(StagedFolder::check(
            &args.out,
            &names,
            &mut RunFiles::new(),
            "--out",
        )?)
    } else {
        None
    };
    Ok(Checked { volumes, out })
}

/// The flags against the device: MSAA it offers, and per-pixel storage its largest buffer
/// holds at `--size` (named as flags, never as buffers).
fn check_device_limits(ctx: &Context, args: &Args, (w, h): (u32, u32)) -> Result<()> {
    hairmesh::render::check_msaa(ctx, args.msaa())
        .map_err(|why| anyhow::anyhow!("--msaa {}: {why}", args.msaa()))?;
    hairmesh::render::passes::check_frame_storage(
        ctx.info.max_storage_buffer_range,
        (w, h),
        args.transparency(),
        args.temporal() != hairmesh::render::Temporal::Off,
        args.look.draw.is_none_or(|d| d.uses_software()),
    )
    .map_err(|why| anyhow::anyhow!("--size {w}x{h}: {why}"))
}

/// A headless frame's file name.
fn frame_name(f: u32) -> String {
    format!("frame_{f:05}.png")
}

/// The columns of `stats.csv`, one row per headless frame.
const STATS_HEADER: &str = "frame,gpu_ms,unscoped_ms,unscoped_commands,record_ms,wall_ms,simulate_ms,simulated,root_gap,strands_drawn,strands_demanded,triangles,vertex_slots_written,vertex_slots_demanded,lod_pressure,dropped_strands,dropped_segments,dropped_tile_entries,passes\n";

/// The interactive window. It makes its own device once it exists; the flags are checked
/// against the device before the crowd is built all the same.
fn run_window(args: Args, size: (u32, u32)) -> Result<()> {
    let probe = Context::new(&ContextDesc::default().device(args.gpu.device.clone()))?;
    check_device_limits(&probe, &args, size)?;
    drop(probe);
    let scene = Scene::build(&args)?;
    window::run(args, scene)
}

/// The headless run's first line: the device, the crowd, the time it took to make it.
fn print_run_line(ctx: &Context, scene: &Scene, args: &Args, renderer: &Renderer) -> Result<()> {
    outln!(
        "device: {} ({}); {} characters ({}), generated and baked in {:.2} s, textures {:.1} MiB",
        ctx.info.name,
        ctx.info.driver,
        scene.characters.len(),
        match &scene.own {
            Some(own) => own.name.clone(),
            None => format!("{:?}", args.preset),
        },
        scene.generate_s,
        renderer.crowd().texture_bytes() as f64 / (1 << 20) as f64
    )?;
    Ok(())
}

/// Headless frames into `--out` (with `stats.csv`), or the window when there is no `--out`.
fn run(parsed: hairmesh::cli::Parsed<Args>) -> Result<()> {
    let Checked { volumes, out } = check_args(&parsed)?;
    let args = parsed.args;
    let (width, height) = parse_size(&args.size)?;
    let Some(mut out) = out else {
        return run_window(args, (width, height));
    };
    // The device's limits are checked before the crowd is built.
    let ctx = Arc::new(Context::new(&args.gpu.context_desc())?);
    check_device_limits(&ctx, &args, (width, height))?;
    let scene = Scene::build(&args)?;
    let settings = args.frame_settings();
    let characters = &scene.characters;
    let mut renderer = scene.renderer(&ctx, &args, width, height)?;
    let settings = hairmesh::render::FrameSettings {
        path: renderer.default_path(),
        ..settings
    }
    .with_fastest((args.look.draw, args.look.shadow_draw), &renderer.caps());
    let mut animation = scene.animation(&mut renderer, &args)?;
    let csv_path = args.out.join("stats.csv");
    let mut csv = String::from(STATS_HEADER);
    print_run_line(&ctx, &scene, &args, &renderer)?;
    let lod = args.lod_settings()?;
    let full = scene.full_strands(args.density(), args.verts_log2)?;
    for f in 0..args.frames {
        let camera = frame_camera(&args, f, &animation, characters)?;
        // Headless frames are 1/30 s apart in animation time.
        animation.advance(&mut renderer, 1.0 / 30.0, &camera, height)?;
        let view = frame_view(&args, camera, lod, volumes);
        let t = Instant::now();
        let report = renderer.render_one(
            &view,
            &FrameOptions {
                read_image: true,
                raster: settings.raster,
                light_raster: settings.light_raster,
                probe_roots: true,
                ..Default::default()
            },
        )?;
        let wall_ms = t.elapsed().as_secs_f64() * 1e3;
        let root_gap = scene.root_gap(&renderer, &report)?;
        if ctx.validation_errors() > 0 {
            bail!(
                "{} Vulkan validation error(s) in frame {f}; no image written",
                ctx.validation_errors()
            );
        }
        report_frame(
            &mut csv,
            f,
            &report,
            (wall_ms, root_gap),
            &animation.stats,
            full,
        )?;
        let rgba = report.rgba.context("no image read back")?;
        let path = args.out.join(frame_name(f));
        let png = hairmesh::fsutil::encode_png(&path.display().to_string(), width, height, rgba)?;
        out.write(&frame_name(f), &png)?;
    }
    out.write("stats.csv", csv.as_bytes())?;
    // The last line before the files appear: a stdout that fails here leaves nothing behind.
    outln!("wrote {} frames and {}", args.frames, csv_path.display())?;
    out.publish()?;
    Ok(())
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("crowd");
    hairmesh::cli::clean_up_on_signals("crowd");
    if let Err(e) = run(parsed) {
        let _ = std::io::stdout().flush();
        hairmesh::fsutil::exit_with_error("crowd", &e, 1);
    }
}

/// The camera of headless frame `f`: the orbit, the eye view down the crowd, or a portrait
/// of the first character where it will be drawn this frame.
fn frame_camera(
    args: &Args,
    f: u32,
    animation: &CrowdAnimation,
    characters: &[preset::CrowdCharacter],
) -> Result<Camera> {
    Ok(match args.view.as_str() {
        "orbit" => hairmesh::characters::preset::orbit_camera(
            args.preset,
            args.count,
            if args.orbit { f } else { 0 },
        ),
        "eye" => {
            let side = (args.count as f32).sqrt().ceil();
            let depth = (side - 1.0) * SPACING;
            Camera::look_at(
                Vec3::new(0.4, 1.65, -1.6),
                Vec3::new(0.0, 1.45, depth * 0.5),
                50.0,
            )
        }
        // Where the first character will be drawn this frame: a person's head-bound frame
        // at the time the animation is about to reach, else its placement.
        view => {
            let dt = if animation.moving { 1.0 / 30.0 } else { 0.0 };
            let model = match &characters[0].walker {
                Some(w) => w.frame(animation.time() + dt)?.hair,
                None => characters[0].model,
            };
            preset::portrait_camera(model, view)
        }
    })
}

/// What headless frames show: `camera`, the crowd's or a portrait's light, and the look flags.
fn frame_view(
    args: &Args,
    camera: Camera,
    lod: LodSettings,
    volumes: hairmesh::render::VolumeTier,
) -> View {
    let portrait = match args.light.as_str() {
        "auto" => matches!(args.view.as_str(), "front" | "side" | "back"),
        other => other == "portrait",
    };
    View {
        light_dir: if portrait {
            hairmesh::render::camera::portrait_light(&camera)
        } else {
            hairmesh::render::camera::CROWD_LIGHT_DIR
        },
        lod,
        shading: args.shading(),
        shadows: args.shadows(),
        transparency: args.transparency(),
        temporal: args.temporal(),
        lod_appearance: args.lod_appearance(),
        multiple_scattering: args.multiple_scattering(),
        volumes,
        ..View::new(camera)
    }
}

/// One frame's row of `stats.csv` and its line on stdout; a warning on stderr when the
/// frame's buffers were full.
fn report_frame(
    csv: &mut String,
    f: u32,
    report: &hairmesh::render::FrameReport,
    (wall_ms, root_gap): (f64, f32),
    sim: &hairmesh::animate::AnimationStats,
    full: u64,
) -> Result<()> {
    let s = report.stats;
    let (dropped, pressure) = (report.dropped(), report.lod_pressure());
    if dropped.any() {
        eprintln!("crowd: warning: frame {f}: {dropped} (buffers full)");
    }
    csv.push_str(&format!(
        "{f},{:.3},{:.3},{},{:.3},{wall_ms:.1},{:.3},{},{root_gap:.6},{},{},{},{},{},{pressure:.4},{},{},{},{}\n",
        report.gpu_ms(),
        report.unscoped_ms().unwrap_or(f64::NAN),
        report.unscoped_commands,
        report.record_ms,
        sim.simulate_ms,
        sim.simulated,
        s.strands_drawn,
        s.strands_demanded,
        s.triangles_drawn,
        s.vertex_slots_written,
        s.vertex_slots_demanded,
        dropped.strands,
        dropped.segments,
        dropped.tile_entries,
        report.scope_summary(" ")
    ));
    outln!(
        "frame {f}: {:?} path, {} of {full} strands, {} triangles, LoD pressure {pressure:.3}, {dropped}, volumes {} alone + {} blended, GPU {:.1} ms ({}), record {:.3} ms, hair simulation ({}) {:.1} ms CPU ({} characters), root gap {root_gap:.5} head radii",
        report.path,
        s.strands_drawn,
        s.triangles_drawn,
        report.volume_characters.0,
        report.volume_characters.1,
        report.gpu_ms(),
        report.scope_summary(", "),
        report.record_ms,
        sim.path,
        sim.simulate_ms,
        sim.simulated
    )?;
    Ok(())
}
