//! `bench paper`: the paper's comparison in one run on one device. (a) Per sample model at
//! about 100K strands (`--scale full`) without LoD: hair mesh on the mesh and compute paths vs
//! linear hair skinning (1% guides) vs static strands (the raster limit); (b) a crowd with LoD
//! on vs off; (c) one head at near / mid / far with LoD on vs off; (d) bytes on the GPU per
//! model for each method. Warm-up then `runs` timed frames with timestamp queries; medians and
//! spread; CSV plus a one-screen summary. `--scale small` shrinks strand counts, crowd and image
//! so lavapipe finishes each scenario in about a minute; `--scenario models|crowd|distance|
//! storage` runs one of them (default all).

use std::sync::Arc;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::fsutil::OutputPath;
use hairmesh::outln;
use hairmesh::reference::generate::strands_per_bundle_for;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, RenderPath, Renderer, RendererDesc, StrandParams,
};
use hairmesh::vk::{Context, ContextDesc};

/// Sizes of one scale.
pub struct Scale {
    /// Target strands per model in (a).
    pub strands: u32,
    /// Characters in (b).
    pub crowd: usize,
    /// Image size.
    pub size: (u32, u32),
    /// Timed frames per measurement.
    pub runs: usize,
}

impl Scale {
    /// `small` (lavapipe) or `full` (the paper's counts).
    pub fn named(name: &str) -> Result<Self> {
        Ok(match name {
            "small" => Scale {
                strands: 10_000,
                crowd: 16,
                size: (480, 270),
                runs: 3,
            },
            "full" => Scale {
                strands: 100_000,
                crowd: 100,
                size: (1920, 1080),
                runs: 10,
            },
            _ => bail!("--scale {name}: small or full"),
        })
    }
}

const MODELS: [&str; 3] = [
    "hairmeshes/head_long.obj",
    "hairmeshes/sphere_fur.obj",
    "hairmeshes/triangle_tuft.obj",
];

/// (d) for the crowd's generated hairstyles (people preset, 8 characters): bytes of the five
/// textures against the LHS data (stored vertices 16 B, weights 24 B per strand, 1% guides) and
/// a `.hair` file (points and thickness), at about `strands` strands each, 17 points per strand.
fn storage_of_generated_styles(strands: u32, rows: &mut String) -> Result<()> {
    use hairmesh::characters::preset::{self, Preset};
    outln!(
        "\n(d) storage of the crowd's generated styles (people, 8 characters), {strands} strands each"
    )?;
    outln!("| style | bundles | textures | LHS data | .hair | LHS / textures |")?;
    outln!("|---|---|---|---|---|---|")?;
    for c in preset::build(Preset::People, 8, 1)? {
        let baked = hairmesh::bake(
            &c.hair.mesh,
            &c.hair.style,
            hairmesh::BakeOptions::default(),
            |_, _| {},
        )?;
        let (_, n) = strands_per_bundle_for(&baked, &c.hair.style, strands as u64);
        let points = n * 17;
        let guides = n.div_ceil(100);
        let lhs = points * 16 + n * 24 + guides * 17 * 16;
        let hair = 128 + points * 16;
        let tex = baked.texture_bytes() as u64;
        *rows += &format!("d,{:?},textures,,,,{n},,{tex}\n", c.hair.family);
        *rows += &format!("d,{:?},lhs,,,,{n},,{lhs}\n", c.hair.family);
        *rows += &format!("d,{:?},hair file,,,,{n},,{hair}\n", c.hair.family);
        outln!(
            "| {:?} | {} | {:.1} KiB | {:.1} MiB | {:.1} MiB | {:.0}x |",
            c.hair.family,
            baked.bundles.len(),
            tex as f64 / 1024.0,
            lhs as f64 / (1 << 20) as f64,
            hair as f64 / (1 << 20) as f64,
            lhs as f64 / tex as f64
        )?;
    }
    Ok(())
}

/// One CSV row: scenario, model, method, median / min / max GPU ms, strands, triangles,
/// bytes (empty when not measured).
fn csv_row(
    scenario: &str,
    model: &str,
    method: &str,
    t: &(f64, f64, f64, FrameReport),
    bytes: Option<u64>,
) -> String {
    let s = &t.3.stats;
    let bytes = bytes.map_or(String::new(), |b| b.to_string());
    format!(
        "{scenario},{model},{method},{:.3},{:.3},{:.3},{},{},{bytes}\n",
        t.0, t.1, t.2, s.strands_drawn, s.triangles_drawn
    )
}

/// Median and (min, max) of GPU ms over `runs` frames after one warm-up.
fn time(
    r: &mut Renderer,
    view: &hairmesh::render::View,
    path: RenderPath,
    runs: usize,
) -> Result<(f64, f64, f64, FrameReport)> {
    let opts = FrameOptions {
        path: Some(path),
        ..Default::default()
    };
    let mut last = r.render_one(view, &opts)?;
    let mut ms = Vec::with_capacity(runs);
    for _ in 0..runs {
        last = r.render_one(view, &opts)?;
        ms.push(last.gpu_ms());
    }
    let (lo, hi) = ms
        .iter()
        .fold((f64::MAX, 0.0f64), |a, &m| (a.0.min(m), a.1.max(m)));
    Ok((super::median(ms), lo, hi, last))
}

fn view(camera: Camera, lod_on: bool) -> hairmesh::render::View {
    super::bench_view(camera, lod_on)
}

/// Run every scenario at `scale`; write the CSV to `csv` when given.
pub fn bench_paper(
    scale_name: &str,
    scenario: &str,
    device: Option<String>,
    csv: Option<std::path::PathBuf>,
) -> Result<()> {
    let scale = Scale::named(scale_name)?;
    const SCENARIOS: [&str; 5] = ["all", "models", "crowd", "distance", "storage"];
    if !SCENARIOS.contains(&scenario) {
        bail!("--scenario {scenario}: one of {}", SCENARIOS.join(", "));
    }
    let wants = |name: &str| scenario == "all" || scenario == name;
    let csv_out = csv.map(|p| OutputPath::check(&p, &[])).transpose()?;
    let ctx = Arc::new(Context::new(&ContextDesc::default().device(device))?);
    let (w, h) = scale.size;
    // The largest vertex pool the device binds, up to 256 MiB (100K strands of 17 vertices
    // take 54 MiB).
    let pool = ctx.info.max_storage_buffer_range.min(256 << 20);
    let mut rows = String::from(
        "scenario,model,method,gpu_ms_median,gpu_ms_min,gpu_ms_max,strands,triangles,gpu_bytes\n",
    );
    outln!(
        "bench paper --scale {scale_name}: {} ({}), {w}x{h}, {} timed frames each",
        ctx.info.name,
        ctx.info.driver,
        scale.runs
    )?;
    // (a) and (d): per model, LoD off.
    if wants("models") {
        outln!(
            "\n(a) {} strands per model, LoD off; (d) GPU bytes per model",
            scale.strands
        )?;
        outln!(
            "| model | strands | mesh ms | compute ms | LHS ms | static ms | LHS / hair mesh | static / hair mesh | textures | LHS bytes | static bytes |"
        )?;
        outln!("|---|---|---|---|---|---|---|---|---|---|---|")?;
        for path in MODELS {
            let (baked, style) = load_mesh(std::path::Path::new(path), None, Default::default())?;
            let (per_bundle, strands) =
                strands_per_bundle_for(&baked, &style, scale.strands as u64);
            let params = StrandParams {
                strands_per_bundle: per_bundle,
                verts_log2: 4,
            };
            let mut r = Renderer::new(
                &ctx,
                &RendererDesc::default().size(w, h).vertex_pool_bytes(pool),
            )?;
            r.add_character(&baked, &style, params, Mat4::IDENTITY)?;
            let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
            let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
            let camera = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
            let v = view(camera, false);
            let mut cells = Vec::new();
            let mut mesh_ms = f64::NAN;
            if r.has_mesh_path() {
                let t = time(&mut r, &v, RenderPath::Mesh, scale.runs)?;
                mesh_ms = t.0;
                rows += &csv_row("a", path, "mesh", &t, Some(baked.texture_bytes() as u64));
            }
            let c = time(&mut r, &v, RenderPath::Compute, scale.runs)?;
            rows += &csv_row("a", path, "compute", &c, Some(baked.texture_bytes() as u64));
            let vertices = c.3.stats.vertex_slots_written;
            let static_bytes =
                vertices as u64 * size_of::<hairmesh::render::shared::HairVertex>() as u64;
            let s = time(&mut r, &v, RenderPath::Static, scale.runs)?;
            rows += &csv_row("a", path, "static", &s, Some(static_bytes));
            // A fresh compute frame holds the strands LHS stores.
            r.render_one(
                &v,
                &FrameOptions {
                    path: Some(RenderPath::Compute),
                    ..Default::default()
                },
            )?;
            let lhs_bytes = r.capture_lhs(vertices, 17, 0.01)?.bytes();
            let l = time(&mut r, &v, RenderPath::Lhs, scale.runs)?;
            rows += &csv_row("a", path, "lhs", &l, Some(lhs_bytes));
            let best = if mesh_ms.is_nan() {
                c.0
            } else {
                mesh_ms.min(c.0)
            };
            cells.push(format!(
            "| {} | {strands} | {mesh_ms:.0} | {:.0} | {:.0} | {:.0} | {:.2}x | {:.2}x | {:.0} KiB | {:.1} MiB | {:.1} MiB |",
            std::path::Path::new(path).file_stem().unwrap_or_default().to_string_lossy(),
            c.0,
            l.0,
            s.0,
            l.0 / best,
            s.0 / best,
            baked.texture_bytes() as f64 / 1024.0,
            lhs_bytes as f64 / (1 << 20) as f64,
            static_bytes as f64 / (1 << 20) as f64
        ));
            for c in cells {
                outln!("{c}")?;
            }
        }
    }
    // (b) crowd, LoD on vs off.
    if wants("crowd") {
        outln!(
            "\n(b) crowd of {} characters (sample meshes), LoD on vs off",
            scale.crowd
        )?;
        outln!("| path | LoD on ms | LoD off ms | speedup | triangles on / off |")?;
        outln!("|---|---|---|---|---|")?;
        let meshes: Vec<_> = super::CROWD_MESHES
            .iter()
            .map(|m| load_mesh(std::path::Path::new(m), None, Default::default()))
            .collect::<Result<_, _>>()?;
        let side = (scale.crowd as f32).sqrt().ceil() as usize;
        let mut r = Renderer::new(
            &ctx,
            &RendererDesc::default().size(w, h).vertex_pool_bytes(pool),
        )?;
        let params = StrandParams {
            strands_per_bundle: 16,
            verts_log2: 4,
        };
        for i in 0..scale.crowd {
            let (baked, style) = &meshes[i % meshes.len()];
            r.add_character(baked, style, params, super::crowd_model(i, side, baked))?;
        }
        let camera = Camera::look_at(Vec3::new(0.0, 1.7, 0.6), Vec3::new(0.0, 1.5, 6.0), 50.0);
        let mut paths = vec![RenderPath::Compute];
        if r.has_mesh_path() {
            paths.insert(0, RenderPath::Mesh);
        }
        for p in paths {
            let on = time(&mut r, &view(camera, true), p, scale.runs)?;
            let off = time(&mut r, &view(camera, false), p, scale.runs)?;
            rows += &csv_row("b", "crowd", &format!("{p:?} lod on"), &on, None);
            rows += &csv_row("b", "crowd", &format!("{p:?} lod off"), &off, None);
            outln!(
                "| {p:?} | {:.0} | {:.0} | {:.1}x | {} / {} |",
                on.0,
                off.0,
                off.0 / on.0,
                on.3.stats.triangles_drawn,
                off.3.stats.triangles_drawn
            )?;
        }
    }
    // (c) one head at near / mid / far.
    if wants("distance") {
        outln!("\n(c) head_long at near / mid / far (compute path), LoD on vs off")?;
        outln!("| distance | LoD on ms | LoD off ms | speedup |")?;
        outln!("|---|---|---|---|")?;
        let (baked, style) = load_mesh(std::path::Path::new(MODELS[0]), None, Default::default())?;
        let mut r = Renderer::new(
            &ctx,
            &RendererDesc::default().size(w, h).vertex_pool_bytes(pool),
        )?;
        r.add_character(
            &baked,
            &style,
            StrandParams {
                strands_per_bundle: 64,
                verts_log2: 5,
            },
            Mat4::IDENTITY,
        )?;
        let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
        let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
        let near = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
        for (name, k) in [("near", 1.0f32), ("mid", 4.0), ("far", 12.0)] {
            let cam = Camera::look_at(
                near.target + (near.eye - near.target) * k,
                near.target,
                40.0,
            );
            let on = time(&mut r, &view(cam, true), RenderPath::Compute, scale.runs)?;
            let off = time(&mut r, &view(cam, false), RenderPath::Compute, scale.runs)?;
            rows += &csv_row("c", "head_long", &format!("{name} lod on"), &on, None);
            rows += &csv_row("c", "head_long", &format!("{name} lod off"), &off, None);
            outln!(
                "| {name} | {:.0} | {:.0} | {:.1}x |",
                on.0,
                off.0,
                off.0 / on.0
            )?;
        }
    }
    if wants("storage") {
        storage_of_generated_styles(scale.strands, &mut rows)?;
    }
    if let Some(out) = csv_out {
        out.write(rows.as_bytes())?;
        outln!("\nwrote {}", out.path().display())?;
    }
    Ok(())
}
