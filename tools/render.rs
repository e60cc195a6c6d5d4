//! `render`: headless render of hair meshes to PNG, printing GPU time per pass.
//!
//! ```text
//! render --mesh hairmeshes/head_long.obj --size 1280x720 --strands-per-bundle 64 -o out.png
//! render --scene scene.toml -o out.png
//! ```

use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::rc::Rc;
use std::sync::Arc;
use std::time::Instant;

use anyhow::{Context as _, Result, bail};
use clap::Parser;
use glam::{Mat4, Vec3};
use hairmesh::budget::{self, Estimate, MemoryBudget};
use hairmesh::cli::{DeviceFlags, LodFlags, LookFlags, Parsed};
use hairmesh::fsutil::RunFiles;
use hairmesh::outln;
use hairmesh::render::FrameSettings;
use hairmesh::render::scene::{SceneDesc, load_mesh};
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, LodSettings, RenderPath, Renderer, RendererDesc,
    StrandParams, View,
};
use hairmesh::vk::Context;

/// Render hair generated on the GPU from hair-mesh textures.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Hair mesh (.obj, baked on load) or baked file (.hmb).
    #[arg(long, conflicts_with = "scene")]
    mesh: Option<PathBuf>,
    /// Style TOML (overrides the style beside the mesh / in the bake).
    #[arg(long)]
    style: Option<PathBuf>,
    /// Scene TOML with several characters (see src/render/scene.rs).
    #[arg(long)]
    scene: Option<PathBuf>,
    /// Camera as `eye_x,eye_y,eye_z:target_x,target_y,target_z` (default: frame the mesh).
    #[arg(long)]
    camera: Option<String>,
    /// Direction toward the light as `x,y,z` (default: the scene's, else 0.4,1,0.6).
    #[arg(long)]
    light: Option<String>,
    /// Vertical field of view in degrees.
    #[arg(long, default_value_t = 40.0)]
    fov: f32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "1280x720")]
    size: String,
    /// Host memory the run may use, MiB: meshes and images past it are refused before loading.
    #[arg(long, value_name = "MIB", default_value = "4096", value_parser = budget::parse_budget_flag)]
    memory_budget_mib: MemoryBudget,
    /// Strands per average bundle (1..=16384).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=16384))]
    strands_per_bundle: u32,
    /// Vertices per strand are 2^e + 1 (e in 0..=6).
    #[arg(long, default_value_t = 5, value_parser = clap::value_parser!(u32).range(0..=6))]
    verts_log2: u32,
    /// Generation path: mesh (task + mesh shaders), compute (compute + vertex pulling),
    /// static (a compute frame generates the strands, then a second frame draws them again
    /// with no generation: the raster limit), or lhs (the same strands stored with 1% guides
    /// and skinned by them, the paper's baseline); for static and lhs the report is the
    /// second frame's. Default: mesh where the device supports it.
    #[arg(long)]
    path: Option<RenderPath>,
    /// Render this many identical frames and report (and write) the last: later frames give
    /// steady-state timings (lavapipe compiles shaders during the first). With the mesh or
    /// compute path.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=100))]
    repeat: u32,
    /// Size of the compute path's vertex pool in MiB (frames that need more keep whole strands
    /// up to it and report the overflow).
    #[arg(long, default_value_t = 96, value_parser = clap::value_parser!(u64).range(1..=4096))]
    vertex_pool_mib: u64,
    /// Print the frame graph of the (last) frame: every pass in order with the resources it
    /// reads and writes and the barriers the graph derived.
    #[arg(long)]
    print_frame: bool,
    #[command(flatten)]
    lod: LodFlags,
    #[command(flatten)]
    look: LookFlags,
    #[command(flatten)]
    gpu: DeviceFlags,
    /// Output PNG.
    #[arg(short, long)]
    output: PathBuf,
}

fn parse_vec3(flag: &str, s: &str) -> Result<Vec3> {
    hairmesh::render::scene::parse_vec3(s).map_err(|e| anyhow::anyhow!("{flag}: {e}"))
}

/// Host memory of a `w x h` frame: the read-back, the image and its PNG.
fn image_estimate(w: u32, h: u32) -> Estimate {
    Estimate::new().with("frame read-back, image and PNG", w as u64 * h as u64, 12)
}

/// Host memory of loading `meshes` (distinct files): a baked file is read, decoded and staged
/// for upload (three times its size); an OBJ is parsed (about four times its size) and its
/// bake is checked by `bake` itself.
fn mesh_estimate(meshes: &[&Path]) -> Estimate {
    let bytes = |p: &Path| std::fs::metadata(p).map_or(0, |m| m.len());
    meshes.iter().fold(Estimate::new(), |e, p| {
        e.with("mesh files, read and decoded", bytes(p), 4)
    })
}

fn check_memory(args: &Args, source: &Path, estimate: &Estimate) -> Result<()> {
    args.memory_budget_mib.check(
        &source.display().to_string(),
        "the run",
        estimate,
        "use fewer or smaller meshes, or a smaller --size",
    )?;
    Ok(())
}

/// The scene's image and every distinct mesh it names, before any is loaded.
fn check_scene_memory(args: &Args, path: &Path, scene: &SceneDesc, size: (u32, u32)) -> Result<()> {
    let mut meshes: Vec<&Path> = scene.characters.iter().map(|c| c.mesh.as_path()).collect();
    meshes.sort();
    meshes.dedup();
    check_memory(
        args,
        path,
        &image_estimate(size.0, size.1).and(mesh_estimate(&meshes)),
    )
}

fn parse_size(s: &str) -> Result<(u32, u32)> {
    hairmesh::render::scene::parse_size(s).map_err(anyhow::Error::msg)
}

/// Settings from the flags, checked.
fn lod_settings(args: &Args) -> Result<LodSettings> {
    args.lod
        .settings(LodSettings::default())
        .map_err(anyhow::Error::msg)
}

/// One character to render.
struct Character {
    /// Shared by every character of the scene that names the same mesh and style.
    baked: Rc<hairmesh::BakedHairMesh>,
    style: hairmesh::HairStyle,
    params: StrandParams,
    model: Mat4,
}

/// Everything loaded from the flags and the scene file, before any GPU work.
struct Inputs {
    characters: Vec<Character>,
    /// Every file read (the output may be none of them).
    files: Vec<PathBuf>,
    scene_camera: Option<Camera>,
    light: Vec3,
    size: (u32, u32),
    look: hairmesh::render::scene::LookDesc,
}

/// One character as the flags or the scene name it, not yet loaded.
struct PlannedCharacter {
    mesh: PathBuf,
    style: Option<PathBuf>,
    params: StrandParams,
    model: Mat4,
}

/// The run's inputs as the flags and the scene file describe them: read the scene (small),
/// check the memory of every mesh it names, and list every file the run reads; no mesh is
/// loaded yet.
fn plan_inputs(args: &Args) -> Result<(Inputs, Vec<PlannedCharacter>)> {
    let mut inputs = Inputs {
        characters: Vec::new(),
        files: Vec::new(),
        scene_camera: None,
        light: Vec3::new(0.4, 1.0, 0.6),
        size: parse_size(&args.size)?,
        look: Default::default(),
    };
    let mut planned = Vec::new();
    if let Some(scene_path) = &args.scene {
        let scene = SceneDesc::load(scene_path)?;
        inputs.files.push(scene_path.clone());
        if let Some([w, h]) = scene.size {
            inputs.size = parse_size(&format!("{w}x{h}"))?;
        }
        if let Some(c) = &scene.camera {
            inputs.scene_camera = Some(Camera::look_at(
                Vec3::from(c.eye),
                Vec3::from(c.target),
                c.fov_y_degrees,
            ));
        }
        if let Some(l) = &scene.light {
            inputs.light = Vec3::from(l.direction);
        }
        inputs.look = scene.look.clone();
        check_scene_memory(args, scene_path, &scene, inputs.size)?;
        for c in &scene.characters {
            inputs.files.extend(hairmesh::render::scene::mesh_inputs(
                &c.mesh,
                c.style.as_deref(),
            ));
            planned.push(PlannedCharacter {
                mesh: c.mesh.clone(),
                style: c.style.clone(),
                params: StrandParams {
                    strands_per_bundle: c.strands_per_bundle,
                    verts_log2: c.verts_log2,
                },
                model: c.model(),
            });
        }
    } else {
        let Some(mesh) = &args.mesh else {
            bail!("give --mesh or --scene")
        };
        inputs.files.extend(hairmesh::render::scene::mesh_inputs(
            mesh,
            args.style.as_deref(),
        ));
        let (w, h) = inputs.size;
        check_memory(
            args,
            mesh,
            &image_estimate(w, h).and(mesh_estimate(&[mesh.as_path()])),
        )?;
        planned.push(PlannedCharacter {
            mesh: mesh.clone(),
            style: args.style.clone(),
            params: StrandParams {
                strands_per_bundle: args.strands_per_bundle,
                verts_log2: args.verts_log2,
            },
            model: Mat4::IDENTITY,
        });
    }
    Ok((inputs, planned))
}

/// Load (and bake) every planned character; a mesh named by many characters is loaded once.
fn load_characters(args: &Args, planned: Vec<PlannedCharacter>) -> Result<Vec<Character>> {
    let mut loaded = HashMap::new();
    let mut characters = Vec::with_capacity(planned.len());
    for c in planned {
        let key = (c.mesh.clone(), c.style.clone());
        let (baked, style) = match loaded.get(&key) {
            Some(hit) => Clone::clone(hit),
            None => {
                let (b, s) = load_mesh(&c.mesh, c.style.as_deref(), args.memory_budget_mib)?;
                let hit = (Rc::new(b), s);
                loaded.insert(key, hit.clone());
                hit
            }
        };
        characters.push(Character {
            baked,
            style,
            params: c.params,
            model: c.model,
        });
    }
    Ok(characters)
}

/// `--camera` with `--fov`, checked before any work (`None`: not given).
fn flag_camera(args: &Args) -> Result<Option<Camera>> {
    hairmesh::render::camera::validate_camera(Vec3::ZERO, Vec3::Z, args.fov)
        .map_err(|e| anyhow::anyhow!("--fov: {e}"))?;
    let Some(c) = &args.camera else {
        return Ok(None);
    };
    let (eye, target) = c
        .split_once(':')
        .with_context(|| format!("--camera '{c}': expected eye:target"))?;
    Camera::checked(
        parse_vec3("--camera", eye)?,
        parse_vec3("--camera", target)?,
        args.fov,
    )
    .map(Some)
    .map_err(|e| anyhow::anyhow!("--camera: {e}"))
}

/// `--camera`, else the scene's camera, else a view framing every character.
fn pick_camera(args: &Args, flag: Option<Camera>, inputs: &Inputs) -> Camera {
    if let Some(c) = flag.or(inputs.scene_camera) {
        return c;
    }
    let (mut lo, mut hi) = (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN));
    for c in &inputs.characters {
        let o = Vec3::from_slice(&c.baked.info.pos_origin[..3]);
        let e = Vec3::from_slice(&c.baked.info.pos_extent[..3]);
        for corner in [o, o + e] {
            let p = c.model.transform_point3(corner);
            lo = lo.min(p);
            hi = hi.max(p);
        }
    }
    Camera::framing(lo, hi, hairmesh::render::DEFAULT_VIEW_DIR, args.fov)
}

/// The frame's look: each flag, else the scene's `[look]`, else the default.
struct Look {
    msaa: u32,
    transparency: hairmesh::render::Transparency,
    shading: hairmesh::shade::ShadingModel,
    shadows: hairmesh::render::ShadowMode,
    temporal: hairmesh::render::Temporal,
    lod_appearance: bool,
    multiple_scattering: bool,
}

impl Look {
    fn resolve(args: &Args, look: &hairmesh::render::scene::LookDesc) -> Self {
        Look {
            msaa: args.look.msaa.or(look.msaa).unwrap_or(1),
            transparency: args
                .look
                .transparency
                .or(look.transparency_mode())
                .unwrap_or_default(),
            shading: args
                .look
                .shading
                .or(look.shading_model())
                .unwrap_or(hairmesh::shade::ShadingModel::Marschner),
            shadows: args.look.shadows.or(look.shadow_mode()).unwrap_or_default(),
            temporal: args
                .look
                .temporal
                .or(look.temporal_mode())
                .unwrap_or_default(),
            lod_appearance: args
                .look
                .lod_appearance
                .or(look.lod_appearance)
                .unwrap_or(true),
            multiple_scattering: args
                .look
                .multiple_scattering
                .or(look.multiple_scattering)
                .unwrap_or(false),
        }
    }
}

/// Refuse every flag given that another flag (or the scene) makes unused.
fn check_unused(p: &Parsed<Args>, inputs: &Inputs, look: &Look) -> Result<(), String> {
    let a = &p.args;
    let scene = a.scene.is_some();
    p.unused_unless("style", !scene, "--scene names each character's style")?;
    p.unused_unless(
        "strands_per_bundle",
        !scene,
        "--scene gives each character's strands_per_bundle",
    )?;
    p.unused_unless(
        "fov",
        a.camera.is_some() || inputs.scene_camera.is_none(),
        "the scene's camera has its own field of view (give --camera to use --fov)",
    )?;
    for id in LodFlags::TUNING_IDS {
        p.unused_unless(id, a.lod.lod, "--lod is off")?;
    }
    p.unused_unless(
        "multiple_scattering",
        look.shading == hairmesh::shade::ShadingModel::Marschner,
        "it is part of the marschner shading",
    )?;
    p.unused_unless(
        "shadow_draw",
        look.shadows != hairmesh::render::ShadowMode::Off,
        "shadows are off",
    )?;
    Ok(())
}

fn print_report(
    ctx: &Context,
    args: &Args,
    (characters, settings): (usize, hairmesh::render::FrameSettings),
    out: &FrameReport,
    wall: f64,
) -> std::io::Result<()> {
    outln!("device: {} ({})", ctx.info.name, ctx.info.driver)?;
    outln!(
        "{:?} path, LoD {}, {} character(s), {} strands (up to {} vertices each), {} strand triangles, {}x{}",
        out.path,
        args.lod.lod,
        characters,
        out.stats.strands_drawn,
        (1u32 << args.verts_log2) + 1,
        out.stats.triangles_drawn,
        out.width,
        out.height
    )?;
    if out.stats.strands_drawn < out.stats.strands_demanded {
        outln!(
            "  vertex pool overflow: drew {} of {} strands ({} of {} vertex slots); raise --vertex-pool-mib or use LoD",
            out.stats.strands_drawn,
            out.stats.strands_demanded,
            out.stats.vertex_slots_written,
            out.stats.vertex_slots_demanded
        )?;
    }
    if let Some(q) = out.mesh_primitives {
        outln!("  mesh primitives generated (VK_EXT_mesh_shader query): {q}")?;
    }
    outln!(
        "  draw {}, shadow draw {}",
        settings.raster,
        settings.light_raster
    )?;
    if settings.raster.uses_software() {
        let s = &out.stats;
        outln!(
            "  software raster ({}): {} segments, {} tile entries",
            settings.raster,
            s.segments_written,
            s.tile_entries_written
        )?;
    }
    // Nothing a buffer could not hold goes unsaid (camera and light).
    let dropped = out.dropped();
    outln!("  LoD pressure {:.3}; {dropped}", out.lod_pressure())?;
    if dropped.any() {
        eprintln!("render: warning: {dropped} (buffers full)");
    }
    for (pass, ms) in &out.pass_ms {
        outln!("  gpu {pass:<10} {ms:9.3} ms")?;
    }
    if let Some(ms) = out.unscoped_ms() {
        outln!("  gpu (no scope) {ms:9.3} ms of the frame no pass scope covers")?;
    }
    outln!(
        "  total gpu  {:9.3} ms (first to last command); wall (incl. setup, shader compile) {:.2} s",
        out.gpu_ms(),
        wall
    )
}

/// Everything checked before the first mesh is loaded: the flags, the scene, the output, the
/// device's MSAA and storage limits. Returns the device and the checked output.
fn check_before_work(
    parsed: &Parsed<Args>,
    inputs: &Inputs,
    look: &Look,
) -> Result<(Arc<Context>, hairmesh::fsutil::OutputPath, FrameSettings)> {
    let args = &parsed.args;
    check_unused(parsed, inputs, look).map_err(anyhow::Error::msg)?;
    let settings = FrameSettings {
        path: args.path.unwrap_or(RenderPath::Compute),
        raster: args.look.draw.unwrap_or_default(),
        transparency: look.transparency,
        msaa: look.msaa,
        light_raster: args.look.shadow_draw.unwrap_or_default(),
    };
    if let Err(why) = settings.check_combination() {
        bail!(
            "--draw / --shadow-draw / --msaa {} / --transparency / --path: {why}",
            look.msaa
        );
    }
    if let Some(l) = &args.light {
        let d = parse_vec3("--light", l)?;
        hairmesh::render::camera::validate_light(d).map_err(|e| anyhow::anyhow!("--light: {e}"))?;
    }
    let output = RunFiles::new()
        .inputs(inputs.files.iter().map(PathBuf::as_path))
        .output(&args.output, "-o")?;
    let ctx = Arc::new(Context::new(&args.gpu.context_desc())?);
    let msaa = look.msaa;
    hairmesh::render::check_msaa(&ctx, msaa).map_err(|why| {
        let flag = if args.look.msaa.is_some() {
            "--msaa"
        } else {
            "the scene's [look] msaa"
        };
        anyhow::anyhow!("{flag} {msaa}: {why}")
    })?;
    let range = ctx.info.max_storage_buffer_range;
    if args.vertex_pool_mib << 20 > range {
        bail!(
            "--vertex-pool-mib {}: more than the {} MiB this device's largest storage buffer holds",
            args.vertex_pool_mib,
            range >> 20
        );
    }
    let (w, h) = inputs.size;
    hairmesh::render::passes::check_frame_storage(
        ctx.info.max_storage_buffer_range,
        inputs.size,
        look.transparency,
        look.temporal != hairmesh::render::Temporal::Off,
        settings.raster.uses_software() || args.look.draw.is_none(),
    )
    .map_err(|why| anyhow::anyhow!("--size {w}x{h}: {why}"))?;
    Ok((ctx, output, settings))
}

fn run(parsed: Parsed<Args>) -> Result<()> {
    let args = &parsed.args;
    let lod = lod_settings(args)?;
    // Static and LHS frames draw what a compute frame generated first (asked for below).
    let path = args.path.map(|p| match p {
        RenderPath::Mesh => RenderPath::Mesh,
        _ => RenderPath::Compute,
    });
    let (mut inputs, planned) = plan_inputs(args)?;
    let look = Look::resolve(args, &inputs.look);
    let flag_camera = flag_camera(args)?;
    let (ctx, output, settings) = check_before_work(&parsed, &inputs, &look)?;
    let start = Instant::now();
    inputs.characters = load_characters(args, planned)?;
    let camera = pick_camera(args, flag_camera, &inputs);
    let (width, height) = inputs.size;
    let mut renderer = Renderer::new(
        &ctx,
        &RendererDesc::default()
            .size(width, height)
            .path(path)
            .vertex_pool_bytes(args.vertex_pool_mib << 20)
            .msaa(look.msaa)
            .max_characters(inputs.characters.len().max(1) as u32),
    )?;
    for c in &inputs.characters {
        renderer.add_character(&c.baked, &c.style, c.params, c.model)?;
    }
    let settings = settings.with_fastest((args.look.draw, args.look.shadow_draw), &renderer.caps());
    let view = View {
        light_dir: match &args.light {
            Some(l) => parse_vec3("--light", l)?,
            None => inputs.light,
        },
        lod,
        shading: look.shading,
        shadows: look.shadows,
        transparency: look.transparency,
        temporal: look.temporal,
        lod_appearance: look.lod_appearance,
        multiple_scattering: look.multiple_scattering,
        ..View::new(camera)
    };
    render_and_write(
        &parsed,
        &ctx,
        (&mut renderer, &inputs, settings),
        &view,
        (output, start),
    )
}

/// Render the frame (repeated, then the static or LHS second frame where asked), print the
/// report and write the image.
fn render_and_write(
    parsed: &Parsed<Args>,
    ctx: &Context,
    (renderer, inputs, settings): (&mut Renderer, &Inputs, FrameSettings),
    view: &View,
    (output, start): (hairmesh::fsutil::OutputPath, Instant),
) -> Result<()> {
    let args = &parsed.args;
    let (width, height) = inputs.size;
    let second = args
        .path
        .filter(|p| matches!(p, RenderPath::Static | RenderPath::Lhs));
    // The generating frame of a static or LHS run draws hardware strips: software-drawn
    // bundles leave no strands in the pool for the second frame to draw again.
    let opts = FrameOptions {
        read_image: true,
        raster: match second {
            Some(_) => hairmesh::render::StrandRaster::Hardware,
            None => settings.raster,
        },
        light_raster: settings.light_raster,
        describe_frame: args.print_frame,
        ..Default::default()
    };
    let mut out = renderer.render_one(view, &opts)?;
    // Later frames report steady-state timings (the first includes shader JIT on lavapipe).
    for _ in 1..args.repeat {
        out = renderer.render_one(view, &opts)?;
    }
    if let Some(second) = second {
        outln!(
            "generated (compute path): GPU {:.3} ms; then {second:?}:",
            out.gpu_ms()
        )?;
        if second == RenderPath::Lhs {
            let verts = (1usize << args.verts_log2) + 1;
            let m = renderer.capture_lhs(out.stats.vertex_slots_written, verts, 0.01)?;
            outln!(
                "LHS: {} strands, {} guides, {:.2} MiB stored",
                m.weights.len(),
                m.guides.len(),
                m.bytes() as f64 / (1 << 20) as f64
            )?;
        }
        out = renderer.render_one(
            view,
            &FrameOptions {
                path: Some(second),
                read_image: true,
                raster: settings.raster,
                light_raster: settings.light_raster,
                describe_frame: args.print_frame,
                ..Default::default()
            },
        )?;
    }
    let wall = start.elapsed().as_secs_f64();
    if let Some(graph) = &out.frame_graph {
        outln!("frame graph:\n{graph}")?;
    }
    // Nothing is written unless the frame succeeded and validation reported nothing.
    if ctx.validation_errors() > 0 {
        bail!(
            "{} Vulkan validation error(s); no image written",
            ctx.validation_errors()
        );
    }
    let rgba = out.rgba.clone().context("no image read back")?;
    let png =
        hairmesh::fsutil::encode_png(&args.output.display().to_string(), width, height, rgba)?;
    print_report(ctx, args, (inputs.characters.len(), settings), &out, wall)?;
    // The last line comes before the file: a stdout that fails leaves no output behind.
    outln!("writing {}", args.output.display())?;
    output.write(&png)?;
    Ok(())
}

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("render");
    hairmesh::cli::clean_up_on_signals("render");
    if let Err(e) = run(parsed) {
        hairmesh::fsutil::exit_with_error("render", &e, 1);
    }
}
