//! People walking in Bevy, each with a hairstyle grown on its head by `HairPlugin`: the
//! skinned, clothed `character.glb` drawn and animated by Bevy (its glTF loader, its PBR, its
//! shadows), the hair drawn by the hair renderer into the same frame on the same device.
//!
//! `--headless` renders offscreen and checks the picture: after `--frames` frames of walking,
//! time stops and three frames are captured (no hair; hair behind Bevy's depth; hair ignoring
//! it). Hair must be shown (first two differ) and hidden by Bevy's geometry (last two differ),
//! each within a factor 2 of the measured share, with no Vulkan validation message. The three
//! pictures are written to `--out`.
//!
//! ```text
//! cargo run --release -p hairmesh-bevy --example crowd -- --headless --out target/bevy
//! cargo run --release -p hairmesh-bevy --features window --example crowd
//! ```

use std::path::{Path, PathBuf};
use std::process::ExitCode;
use std::sync::{Arc, Mutex};
use std::time::Duration;

use anyhow::{Context as _, Result, bail};
use bevy::app::ScheduleRunnerPlugin;
use bevy::asset::AssetPlugin;
use bevy::camera::RenderTarget;
use bevy::prelude::*;
use bevy::render::render_resource::{TextureFormat, TextureUsages};
use bevy::render::view::screenshot::{Screenshot, ScreenshotCaptured};
use bevy::window::ExitCondition;
use bevy::world_serialization::{WorldAssetRoot, WorldInstanceReady};
use clap::Parser;
use hairmesh::characters::hairstyle::StyleFamily;
use hairmesh_bevy::{
    Hair, HairFrames, HairLibrary, HairPlugin, HairPluginDesc, HairSettings, hair_camera,
};

/// Bevy with strand hair: people walking, each with a grown hairstyle.
#[derive(Parser, Clone)]
struct Args {
    /// Render offscreen, check the picture and write it to --out (no window).
    #[arg(long)]
    headless: bool,
    /// Frames of walking before the check (headless).
    #[arg(long, default_value_t = 12)]
    frames: u32,
    /// Folder for the headless pictures.
    #[arg(long, default_value = "target/bevy")]
    out: PathBuf,
    /// People (1..=64).
    #[arg(long, default_value_t = 4)]
    people: u32,
    /// Picture size, WIDTHxHEIGHT.
    #[arg(long, default_value = "640x360")]
    size: String,
    /// Look at the first person's head from a metre away (a portrait) instead of the street.
    #[arg(long)]
    close: bool,
    /// Metres Bevy's depth is pushed back before it hides hair (default: the plugin's).
    #[arg(long)]
    depth_slack: Option<f32>,
    /// Vulkan validation off (on by default: any message fails the headless check).
    #[arg(long)]
    no_validation: bool,
}

/// The glTF character, relative to `hairmeshes/`.
const CHARACTER: &str = "people/character.glb";
/// Its animation clips in file order: `walk` is the first.
const WALK_CLIP: usize = 0;
/// The folder Bevy loads assets from.
fn hairmeshes() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../hairmeshes")
}

fn main() -> ExitCode {
    match run(Args::parse()) {
        Ok(code) => code,
        Err(e) => {
            eprintln!("bevy crowd: {e:#}");
            ExitCode::FAILURE
        }
    }
}

fn run(args: Args) -> Result<ExitCode> {
    let size = parse_size(&args.size)?;
    if !(1..=64).contains(&args.people) {
        bail!("--people {}: expected 1..=64", args.people);
    }
    let root = hairmeshes();
    let character = root.join(CHARACTER);
    let own =
        hairmesh::characters::own::OwnCharacter::load(&character, "head", Default::default())?;
    // A portrait walks on the spot.
    let speed = match args.close {
        false => own.walk_speed().unwrap_or(0.0),
        true => 0.0,
    };
    drop(own);
    let hair = HairPlugin::new(HairPluginDesc {
        validation: !args.no_validation,
        device: None,
    })?;
    let assets = AssetPlugin {
        file_path: root.display().to_string(),
        ..default()
    };
    let defaults = DefaultPlugins.set(hair.render_plugin()).set(assets);
    let mut app = App::new();
    if args.headless {
        let window = WindowPlugin {
            primary_window: None,
            exit_condition: ExitCondition::DontExit,
            ..default()
        };
        app.add_plugins(defaults.set(window))
            .add_plugins(ScheduleRunnerPlugin::run_loop(Duration::ZERO));
    } else if cfg!(feature = "window") {
        app.add_plugins(defaults);
    } else {
        bail!("no window in this build (add --features window), or pass --headless");
    }
    let shots = Shots::default();
    app.add_plugins(hair)
        .insert_resource(Demo {
            args: args.clone(),
            size,
            speed,
            character,
            target: None,
        })
        .insert_resource(shots)
        .add_systems(Startup, setup)
        .add_systems(Update, walk);
    if let Some(slack) = args.depth_slack {
        app.insert_resource(HairSettings {
            depth_slack: slack,
            ..default()
        });
    }
    if args.headless {
        // A fixed step: the same frames show the same poses on any machine.
        let step = Duration::from_secs_f64(1.0 / 30.0);
        app.insert_resource(Check::default())
            .insert_resource(bevy::time::TimeUpdateStrategy::ManualDuration(step))
            .add_systems(Update, check);
    }
    Ok(match app.run() {
        AppExit::Success => ExitCode::SUCCESS,
        AppExit::Error(_) => ExitCode::FAILURE,
    })
}

/// `WIDTHxHEIGHT`, 16..=4096 each.
fn parse_size(size: &str) -> Result<(u32, u32)> {
    size.split_once('x')
        .and_then(|(a, b)| Some((a.parse::<u32>().ok()?, b.parse::<u32>().ok()?)))
        .filter(|&(a, b)| (16..=4096).contains(&a) && (16..=4096).contains(&b))
        .with_context(|| format!("--size {size}: expected WIDTHxHEIGHT, 16..=4096 each"))
}

#[derive(Resource)]
struct Demo {
    args: Args,
    size: (u32, u32),
    /// Ground speed of the walk clip (m/s).
    speed: f32,
    /// The glTF file the hair is grown from (the one Bevy shows).
    character: PathBuf,
    /// The offscreen picture (headless).
    target: Option<Handle<Image>>,
}

/// A walker: along its facing direction at the clip's ground speed, wrapping at the edges.
#[derive(Component)]
struct Walker {
    graph: Handle<AnimationGraph>,
    clip: AnimationNodeIndex,
    phase: f32,
}

/// How far the walkers go before they wrap around (metres from the centre).
const HALF_STREET: f32 = 3.0;

fn setup(
    mut commands: Commands,
    mut demo: ResMut<Demo>,
    assets: Res<AssetServer>,
    mut meshes: ResMut<Assets<Mesh>>,
    mut materials: ResMut<Assets<StandardMaterial>>,
    mut graphs: ResMut<Assets<AnimationGraph>>,
    mut images: ResMut<Assets<Image>>,
) {
    commands.spawn((
        Mesh3d(meshes.add(Plane3d::default().mesh().size(20.0, 20.0))),
        MeshMaterial3d(materials.add(Color::srgb(0.42, 0.40, 0.36))),
    ));
    commands.spawn((
        DirectionalLight {
            illuminance: 8000.0,
            shadow_maps_enabled: true,
            ..default()
        },
        Transform::from_xyz(3.0, 6.0, 4.0).looking_at(Vec3::ZERO, Vec3::Y),
    ));
    commands.insert_resource(GlobalAmbientLight {
        brightness: 400.0,
        ..default()
    });
    let eye = match demo.args.close {
        false => Transform::from_xyz(0.0, 1.7, 4.2).looking_at(Vec3::new(0.0, 1.3, 0.0), Vec3::Y),
        true => {
            let head = place(0, demo.args.people).translation + Vec3::Y * 1.55;
            Transform::from_translation(head + Vec3::new(0.3, 0.15, 1.0)).looking_at(head, Vec3::Y)
        }
    };
    // AgX, ACES and TonyMcMapface need Bevy's `tonemapping_luts`; this one does not.
    let tonemapping = bevy::core_pipeline::tonemapping::Tonemapping::AcesFitted;
    let camera = commands.spawn((hair_camera(), tonemapping, eye)).id();
    if demo.args.headless {
        let (w, h) = demo.size;
        let mut image = Image::new_target_texture(w, h, TextureFormat::Rgba8UnormSrgb, None);
        image.texture_descriptor.usage |= TextureUsages::COPY_SRC;
        let handle = images.add(image);
        commands
            .entity(camera)
            .insert(RenderTarget::Image(handle.clone().into()));
        demo.target = Some(handle);
    }
    let (graph, clip) = AnimationGraph::from_clip(
        assets.load(GltfAssetLabel::Animation(WALK_CLIP).from_asset(CHARACTER)),
    );
    let graph = graphs.add(graph);
    let scene = assets.load(GltfAssetLabel::Scene(0).from_asset(CHARACTER));
    for k in 0..demo.args.people {
        let family = StyleFamily::PEOPLE[k as usize % StyleFamily::PEOPLE.len()];
        let hair = Hair::grown(&demo.character, "head", family, 7 + k);
        commands
            .spawn((
                WorldAssetRoot(scene.clone()),
                place(k, demo.args.people),
                hair,
                Walker {
                    graph: graph.clone(),
                    clip,
                    phase: k as f32 * 0.37,
                },
            ))
            .observe(start_walking);
    }
}

/// Person `k` of `n`: two rows walking opposite ways, spread along the street.
fn place(k: u32, n: u32) -> Transform {
    let row = k % 2;
    let along = (k as f32 + 0.5) / n as f32 * 2.0 * HALF_STREET - HALF_STREET;
    let (z, facing) = match row {
        0 => (0.4, std::f32::consts::FRAC_PI_2),
        _ => (-0.6, -std::f32::consts::FRAC_PI_2),
    };
    Transform::from_xyz(along, 0.0, z).with_rotation(Quat::from_rotation_y(facing))
}

/// Once a person's scene has spawned, play its walk on its animation player.
fn start_walking(
    ready: On<WorldInstanceReady>,
    mut commands: Commands,
    walkers: Query<&Walker>,
    children: Query<&Children>,
    mut players: Query<&mut AnimationPlayer>,
) {
    let Ok(walker) = walkers.get(ready.entity) else {
        return;
    };
    for child in children.iter_descendants(ready.entity) {
        if let Ok(mut player) = players.get_mut(child) {
            player.play(walker.clip).repeat().seek_to(walker.phase);
            commands
                .entity(child)
                .insert(AnimationGraphHandle(walker.graph.clone()));
        }
    }
}

/// Move every walker forward (glTF characters face +z) at the clip's ground speed.
fn walk(time: Res<Time>, demo: Res<Demo>, mut walkers: Query<&mut Transform, With<Walker>>) {
    for mut t in &mut walkers {
        let ahead = t.back();
        t.translation += ahead * demo.speed * time.delta_secs();
        if t.translation.x.abs() > HALF_STREET {
            t.translation.x = -t.translation.x.signum() * HALF_STREET;
        }
    }
}

/// The captured pictures (RGBA8), in capture order.
#[derive(Resource, Clone, Default)]
struct Shots(Arc<Mutex<Vec<Vec<u8>>>>);

/// The headless run's progress.
#[derive(Resource, Default)]
struct Check {
    /// Frames so far.
    frame: u32,
    /// Frames walked with every hair drawn.
    walked: u32,
    /// Captures asked for, and the frame the settings last changed.
    asked: usize,
    settled_at: u32,
}

/// What each capture draws: no hair, hair behind Bevy's depth, hair ignoring it.
const CAPTURES: [(bool, bool); 3] = [(false, true), (true, true), (true, false)];
/// Frames between a settings change and its capture (extract and pipelined rendering lag).
const SETTLE: u32 = 3;
/// Frames to wait for the hair to load before giving up.
const LOAD_FRAMES: u32 = 20_000;

#[allow(clippy::too_many_arguments)]
fn check(
    mut commands: Commands,
    mut state: ResMut<Check>,
    demo: Res<Demo>,
    shots: Res<Shots>,
    library: Res<HairLibrary>,
    frames: Res<HairFrames>,
    placed: Query<(), With<hairmesh_bevy::PlacedHair>>,
    mut settings: ResMut<HairSettings>,
    mut time: ResMut<Time<Virtual>>,
    mut exit: MessageWriter<AppExit>,
) {
    state.frame += 1;
    let failures = library.failures();
    let record = frames.record();
    if !failures.is_empty() || record.last_error.is_some() || state.frame > LOAD_FRAMES {
        let why = failures.join("; ") + record.last_error.as_deref().unwrap_or("");
        error!("the hair did not draw: {why} ({} frames)", state.frame);
        exit.write(AppExit::error());
        return;
    }
    let all_placed = placed.iter().count() == demo.args.people as usize;
    if state.walked < demo.args.frames {
        // Time stands still until every hair is drawn, then walks `--frames` steps.
        match library.loading() == 0 && all_placed && record.completed > 0 {
            true => {
                time.unpause();
                state.walked += 1;
            }
            false => time.pause(),
        }
        return;
    }
    time.pause();
    let taken = shots.0.lock().map(|s| s.len()).unwrap_or(0);
    if taken < state.asked {
        return;
    }
    if state.asked == CAPTURES.len() {
        let result = finish(&demo, &shots, &frames);
        if let Err(e) = &result {
            error!("{e:#}");
        }
        exit.write(result.map_or(AppExit::error(), |_| AppExit::Success));
        return;
    }
    let (enabled, depth_test) = CAPTURES[state.asked];
    if (settings.enabled, settings.depth_test) != (enabled, depth_test) || state.settled_at == 0 {
        settings.enabled = enabled;
        settings.depth_test = depth_test;
        state.settled_at = state.frame;
        return;
    }
    if state.frame < state.settled_at + SETTLE {
        return;
    }
    let Some(target) = demo.target.clone() else {
        return;
    };
    let store = shots.clone();
    commands
        .spawn(Screenshot::image(target))
        .observe(move |shot: On<ScreenshotCaptured>| {
            if let (Ok(mut s), Some(data)) = (store.0.lock(), shot.image.data.clone()) {
                s.push(data);
            }
        });
    state.asked += 1;
    state.settled_at = 0;
}

/// Shares of the picture with hair shown over Bevy's colour and hidden by its depth, measured
/// at 640x360 on lavapipe with 4 people and 12 frames of walking (1,964 and 462 pixels at a
/// real head's 175 strands per cm², the same in every run: time steps are fixed; 1,539 and 547
/// at the 32 strands per bundle of before 2026-12-07); a run passes within
/// [`SHARE_TOLERANCE`] of each. Without the depth slack the scalps hide hair: 1,787 shown
/// (-9%), 737 hidden (+60%; at 32 strands a bundle 1,264, -18%, and 834, +53%).
const SHOWN_SHARE: f64 = 1964.0 / (640.0 * 360.0);
/// See [`SHOWN_SHARE`].
const HIDDEN_SHARE: f64 = 462.0 / (640.0 * 360.0);
/// Relative tolerance of the shares: pictures differ by a few pixels across drivers and CPUs;
/// losing the depth slack moves the hidden share by 60%.
const SHARE_TOLERANCE: f64 = 0.12;

/// Count shown and hidden hair pixels, write the pictures, and check both counts and the
/// validation messages.
fn finish(demo: &Demo, shots: &Shots, frames: &HairFrames) -> Result<()> {
    let shots = shots
        .0
        .lock()
        .map_err(|_| anyhow::anyhow!("captures poisoned"))?;
    let [off, with_depth, without_depth] = [&shots[0], &shots[1], &shots[2]];
    let differ = |a: &[u8], b: &[u8]| a.chunks(4).zip(b.chunks(4)).filter(|(p, q)| p != q).count();
    let shown = differ(off, with_depth);
    let hidden = differ(with_depth, without_depth);
    let (w, h) = demo.size;
    std::fs::create_dir_all(&demo.args.out)
        .with_context(|| format!("{}: cannot create", demo.args.out.display()))?;
    for (name, rgba) in [
        ("crowd.png", with_depth),
        ("no_hair.png", off),
        ("hair_without_depth.png", without_depth),
    ] {
        let path = demo.args.out.join(name);
        let png = hairmesh::fsutil::encode_png(&path.display().to_string(), w, h, rgba.clone())?;
        hairmesh::fsutil::write_atomic(&path, &png)?;
    }
    let record = frames.record();
    println!(
        "{}: {w}x{h}, {} people walking in Bevy with grown hair: {shown} hair pixels shown, {hidden} hidden by Bevy's geometry; {} hair frames, the last {} strands in {:.1} GPU ms",
        demo.args.out.join("crowd.png").display(),
        demo.args.people,
        record.completed,
        record.strands_drawn,
        record.gpu_ms,
    );
    if record.validation_errors > 0 {
        bail!("{} Vulkan validation messages", record.validation_errors);
    }
    let pixels = (w as f64) * (h as f64);
    for (what, count, measured) in [
        ("shown", shown, SHOWN_SHARE),
        ("hidden", hidden, HIDDEN_SHARE),
    ] {
        let share = count as f64 / pixels;
        let tolerance = measured * SHARE_TOLERANCE;
        if (share - measured).abs() > tolerance {
            bail!(
                "{count} hair pixels {what} ({:.3}% of the picture); expected {:.3}% +- {:.3}%",
                share * 100.0,
                measured * 100.0,
                tolerance * 100.0
            );
        }
    }
    Ok(())
}
