//! `bench raster`: the software rasterizer against hardware strips, from one run on one
//! device. Scenes: one head at near / mid / far (LoD on), about 100K strands of 33 vertices
//! at mid distance (LoD off), and a crowd of 100 characters with LoD. For each scene and
//! generation path: median GPU frame time of hardware strips (opaque, and with k-buffer OIT,
//! the image the software path matches), of the software rasterizer (`soft`) and of the per
//! bundle split (`auto`), both compositing like OIT; and the ratios to hardware.

use std::sync::Arc;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::outln;
use hairmesh::reference::generate::strands_per_bundle_for;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, RenderPath, Renderer, RendererDesc, StrandParams, StrandRaster,
    Transparency, View,
};
use hairmesh::vk::{Context, ContextDesc};

/// What `bench raster` measures.
pub struct RasterArgs {
    /// Image size.
    pub size: (u32, u32),
    /// Timed frames per measurement (after one warm-up).
    pub runs: usize,
    /// Characters of the crowd scene.
    pub crowd: usize,
    /// Strands of the dense scene.
    pub strands: u32,
    /// Choose the GPU by name substring.
    pub device: Option<String>,
    /// Only these scenes (names as printed); empty: all.
    pub scenes: Vec<String>,
    /// `auto`: strands drawn at most this many pixels wide go to software.
    pub auto_split: f32,
    /// Only these columns (`hw-opaque`, `hw-oit`, `soft`, `auto`); empty: all.
    pub draws: Vec<String>,
}

struct Scene {
    name: String,
    renderer: Renderer,
    camera: Camera,
    lod: bool,
}

fn desc(a: &RasterArgs) -> RendererDesc {
    RendererDesc {
        auto_split_pixels: a.auto_split,
        ..RendererDesc::default().size(a.size.0, a.size.1)
    }
}

/// Median GPU ms of a measurement, the warm-up's statistics and the median ms of each pass.
type Timing = (f64, hairmesh::render::FrameStats, String);

/// [`Timing`] of `runs` frames after one warm-up.
fn time(r: &mut Renderer, view: &View, opts: FrameOptions, runs: usize) -> Result<Timing> {
    let first = r.render_one(view, &opts)?;
    let (reports, wall) = super::timed_frames(r, view, &opts, runs)?;
    let passes: Vec<String> = super::median_passes(&first, &reports)
        .iter()
        .map(|(n, ms)| format!("{n} {ms:.2}"))
        .collect();
    let ms = super::median(reports.iter().map(|r| r.gpu_ms()).collect());
    Ok((
        ms,
        first.stats,
        format!("{} (frame wall {wall:.1} ms)", passes.join(", ")),
    ))
}

fn head_scenes(ctx: &Arc<Context>, a: &RasterArgs) -> Result<Vec<Scene>> {
    let (baked, style) = load_mesh(
        std::path::Path::new("hairmeshes/head_long.obj"),
        None,
        Default::default(),
    )?;
    let at = super::dolly(&baked);
    let head = |strands_per_bundle: u32| -> Result<Renderer> {
        let mut r = Renderer::new(ctx, &desc(a))?;
        r.add_character(
            &baked,
            &style,
            StrandParams {
                strands_per_bundle,
                verts_log2: 5,
            },
            Mat4::IDENTITY,
        )?;
        Ok(r)
    };
    let mut scenes = Vec::new();
    for (name, k) in [("head near", 0.6), ("head mid", 2.5), ("head far", 8.0)] {
        scenes.push(Scene {
            name: name.into(),
            renderer: head(64)?,
            camera: at(k),
            lod: true,
        });
    }
    let (per_bundle, strands) = strands_per_bundle_for(&baked, &style, a.strands as u64);
    scenes.push(Scene {
        name: format!("{}K strands", strands.div_ceil(1000)),
        renderer: head(per_bundle)?,
        camera: at(1.0),
        lod: false,
    });
    Ok(scenes)
}

fn crowd_scene(ctx: &Arc<Context>, a: &RasterArgs) -> Result<Scene> {
    let meshes = super::CROWD_MESHES
        .iter()
        .map(|m| load_mesh(std::path::Path::new(m), None, Default::default()))
        .collect::<Result<Vec<_>, _>>()?;
    let mut r = Renderer::new(ctx, &desc(a))?;
    let side = (a.crowd as f32).sqrt().ceil() as usize;
    let params = StrandParams {
        strands_per_bundle: 16,
        verts_log2: 4,
    };
    for i in 0..a.crowd {
        let (baked, style) = &meshes[i % meshes.len()];
        r.add_character(baked, style, params, super::crowd_model(i, side, baked))?;
    }
    Ok(Scene {
        name: format!("crowd of {}", a.crowd),
        renderer: r,
        camera: Camera::look_at(Vec3::new(0.0, 1.7, 0.6), Vec3::new(0.0, 1.5, 6.0), 50.0),
        lod: true,
    })
}

/// Run the comparison and print the table.
/// Every `--scenes` name chooses a scene (a prefix of its printed name), checked before any
/// scene is built.
fn check_scene_names(a: &RasterArgs) -> Result<()> {
    let (baked, style) = load_mesh(
        std::path::Path::new("hairmeshes/head_long.obj"),
        None,
        Default::default(),
    )?;
    let strands = strands_per_bundle_for(&baked, &style, a.strands as u64).1;
    let names = [
        "head near".to_string(),
        "head mid".into(),
        "head far".into(),
        format!("{}K strands", strands.div_ceil(1000)),
        format!("crowd of {}", a.crowd),
    ];
    if let Some(n) = a
        .scenes
        .iter()
        .find(|n| !names.iter().any(|s| s.starts_with(n.as_str())))
    {
        bail!(
            "--scenes {n}: chooses no scene; scenes: {}",
            names.join(", ")
        );
    }
    Ok(())
}

pub fn bench_raster(a: RasterArgs) -> Result<()> {
    if a.crowd == 0 || a.crowd > 1024 {
        bail!("--crowd: 1..=1024 characters");
    }
    check_scene_names(&a)?;
    const DRAWS: [&str; 4] = ["hw-opaque", "hw-oit", "soft", "auto"];
    if let Some(d) = a.draws.iter().find(|d| !DRAWS.contains(&d.as_str())) {
        bail!("--draws {d}: one of {}", DRAWS.join(", "));
    }
    let ctx = Arc::new(Context::new(
        &ContextDesc::default().device(a.device.clone()),
    )?);
    let (w, h) = a.size;
    outln!(
        "bench raster: {} ({}), {w}x{h}, median GPU ms of {} frames; soft and auto keep {} fragments per pixel and composite like oit:8; auto sends strands drawn at most {} px wide to software",
        ctx.info.name,
        ctx.info.driver,
        a.runs,
        hairmesh::render::soft::DEFAULT_SOFT_K,
        a.auto_split
    )?;
    let mut scenes = head_scenes(&ctx, &a)?;
    scenes.push(crowd_scene(&ctx, &a)?);
    scenes.retain(|s| a.scenes.is_empty() || a.scenes.iter().any(|n| s.name.starts_with(n)));
    if !scenes
        .first()
        .is_some_and(|s| s.renderer.has_software_raster())
    {
        bail!(
            "{}: no software rasterizer (needs 64-bit atomics)",
            ctx.info.name
        );
    }
    print_table_header()?;
    let mut pass_lines = Vec::new();
    let oit = Transparency::KBuffer { budget: 8 };
    let soft = StrandRaster::Software { k: 8 };
    let auto = StrandRaster::Auto { k: 8 };
    for s in &mut scenes {
        let mut paths = vec![RenderPath::Compute];
        if s.renderer.has_mesh_path() {
            paths.insert(0, RenderPath::Mesh);
        }
        let opaque_view = super::bench_view(s.camera, s.lod);
        let oit_view = View {
            transparency: oit,
            ..opaque_view
        };
        for path in paths {
            let opts = |raster| FrameOptions {
                path: Some(path),
                raster,
                ..Default::default()
            };
            let r = &mut s.renderer;
            let wants = |d: &str| a.draws.is_empty() || a.draws.iter().any(|w| w == d);
            let mut cell = |d: &str, v: &View, raster| -> Result<Option<Timing>> {
                match wants(d) {
                    true => Ok(Some(time(r, v, opts(raster), a.runs)?)),
                    false => Ok(None),
                }
            };
            let hw_opaque = cell("hw-opaque", &opaque_view, StrandRaster::Hardware)?;
            let hw_oit = cell("hw-oit", &oit_view, StrandRaster::Hardware)?;
            let sw = cell("soft", &oit_view, soft)?;
            let au = cell("auto", &oit_view, auto)?;
            let passes = |t: &Option<Timing>| t.as_ref().map_or("-".into(), |t| t.2.clone());
            pass_lines.push(format!(
                "| {} | {path:?} | {} | {} |",
                s.name,
                passes(&hw_oit),
                passes(&sw)
            ));
            print_row(&s.name, path, [&hw_opaque, &hw_oit, &sw, &au])?;
        }
    }
    print_pass_table(&pass_lines)
}

/// The second table: the median GPU ms of every pass, hardware with OIT and software.
fn print_pass_table(pass_lines: &[String]) -> Result<()> {
    outln!("\nMedian GPU ms per pass, hardware with oit and software:")?;
    outln!("| scene | path | hw oit passes | soft passes |")?;
    outln!("|---|---|---|---|")?;
    for l in pass_lines {
        outln!("{l}")?;
    }
    Ok(())
}

/// One row of the raster table: the four draws' median GPU ms, their ratios and the software
/// draw's segments.
fn print_row(name: &str, path: RenderPath, cells: [&Option<Timing>; 4]) -> Result<()> {
    let [hw_opaque, hw_oit, sw, au] = cells;
    let ms = |t: &Option<Timing>| t.as_ref().map(|t| t.0);
    let fmt = |v: Option<f64>| v.map_or("-".into(), |v| format!("{v:.2}"));
    let ratio = |x: Option<f64>, y: Option<f64>| fmt(x.zip(y).map(|(x, y)| x / y));
    let stats = cells
        .into_iter()
        .find_map(|t| t.as_ref().map(|t| t.1))
        .unwrap_or_default();
    let segments = sw.as_ref().map_or("-".into(), |t| {
        let s = &t.1;
        let dropped = s.segments_written < s.segments_demanded
            || s.tile_entries_written < s.tile_entries_demanded;
        format!(
            "{}{}",
            s.segments_written,
            if dropped { " (overflow)" } else { "" }
        )
    });
    outln!(
        "| {} | {path:?} | {} | {} | {} | {} | {} | {} | {} | {} | {segments} |",
        name,
        stats.strands_drawn,
        fmt(ms(hw_opaque)),
        fmt(ms(hw_oit)),
        fmt(ms(sw)),
        fmt(ms(au)),
        ratio(ms(sw), ms(hw_oit)),
        ratio(ms(sw), ms(hw_opaque)),
        ratio(ms(au), ms(hw_oit)),
    )?;
    Ok(())
}

/// The first table's header.
fn print_table_header() -> Result<()> {
    outln!(
        "| scene | path | strands | hw opaque | hw oit | soft | auto | soft / hw oit | soft / hw opaque | auto / hw oit | segments (soft) |"
    )?;
    outln!("|---|---|---|---|---|---|---|---|---|---|---|")?;
    Ok(())
}
