//! `bench paper`: the paper's comparison in one run on one device, every method drawn by the
//! same rasterizer (`--draw hw|soft|auto`: the static and LHS paths hand their stored strands
//! to the software rasterizer too, so the comparison is generation against skinning and stored
//! strands). (a) Per sample model at about 100K strands (`--scale full`) without LoD: hair mesh
//! on the mesh and compute paths vs linear hair skinning (1% guides) vs static strands (the
//! raster limit); (b) a crowd of 100 characters of about 100K strands each with LoD on vs off;
//! (c) one head at near / mid / far with LoD on vs off; (d) bytes on the GPU per model for each
//! method; (e) the paper's 200 furry teapots of about 50K strands each, LoD on vs off. Warm-up
//! then `runs` timed frames with timestamp queries; medians and spread; CSV plus a one-screen
//! summary. `--scale small` shrinks strand counts, crowds and image so lavapipe finishes each
//! scenario in about a minute; `--scenario models|crowd|distance|storage|teapots` runs one of
//! them (default all).

use std::sync::Arc;

use anyhow::{Result, bail};
use glam::{Mat4, Vec3};
use hairmesh::fsutil::OutputPath;
use hairmesh::outln;
use hairmesh::reference::generate::strands_per_bundle_for;
use hairmesh::render::scene::load_mesh;
use hairmesh::render::{
    Camera, FrameOptions, FrameReport, RenderPath, Renderer, RendererDesc, StrandParams,
    StrandRaster,
};
use hairmesh::vk::{Context, ContextDesc};

/// Sizes of one scale.
pub struct Scale {
    /// Target strands per model in (a).
    pub strands: u32,
    /// Characters in (b).
    pub crowd: usize,
    /// Target strands per character in (b).
    pub crowd_strands: u32,
    /// Teapots in (e) and target strands per teapot.
    pub teapots: (usize, u32),
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
                crowd_strands: 2_000,
                teapots: (16, 2_000),
                size: (480, 270),
                runs: 3,
            },
            "full" => Scale {
                strands: 100_000,
                crowd: 100,
                crowd_strands: 100_000,
                teapots: (200, 50_000),
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

/// A preset character's hair mesh baked with the default options.
fn bake_character(
    c: &hairmesh::characters::preset::CrowdCharacter,
) -> Result<hairmesh::BakedHairMesh> {
    let options = hairmesh::BakeOptions::default();
    Ok(hairmesh::bake(
        &c.hair.mesh,
        &c.hair.style,
        options,
        |_, _| {},
    )?)
}

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
        let baked = bake_character(&c)?;
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

/// Median and (min, max) of GPU ms over `runs` frames drawn with `raster` after one warm-up.
fn time(
    r: &mut Renderer,
    view: &hairmesh::render::View,
    (path, raster): (RenderPath, StrandRaster),
    runs: usize,
) -> Result<(f64, f64, f64, FrameReport)> {
    let opts = FrameOptions {
        path: Some(path),
        raster,
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

/// What every scenario of one run shares.
struct PaperRun {
    ctx: Arc<Context>,
    scale: Scale,
    /// Vertex pool bytes of every renderer.
    pool: u64,
    /// How every method's strands are rasterized.
    draw: StrandRaster,
    /// CSV rows so far.
    rows: String,
}

impl PaperRun {
    /// An empty renderer at the run's size and pool.
    fn renderer(&self) -> Result<Renderer> {
        let (w, h) = self.scale.size;
        let desc = RendererDesc::default()
            .size(w, h)
            .vertex_pool_bytes(self.pool);
        Ok(Renderer::new(&self.ctx, &desc)?)
    }

    /// [`time`] on `path` with the run's rasterizer.
    fn time(
        &self,
        r: &mut Renderer,
        v: &hairmesh::render::View,
        path: RenderPath,
    ) -> Result<(f64, f64, f64, FrameReport)> {
        time(r, v, (path, self.draw), self.scale.runs)
    }

    /// A compute-path frame with hardware strips: the strands the static and LHS paths then
    /// draw (software-drawn bundles leave no strands in the pool). Returns its vertex slots.
    fn store_strands(&self, r: &mut Renderer, v: &hairmesh::render::View) -> Result<u32> {
        let opts = FrameOptions {
            path: Some(RenderPath::Compute),
            ..Default::default()
        };
        Ok(r.render_one(v, &opts)?.stats.vertex_slots_written)
    }

    /// (a) and (d) for one sample model: every method, LoD off; returns the table row and
    /// (ours / LHS, ours / static).
    fn model(&mut self, path: &str) -> Result<(String, f64, f64)> {
        let (baked, style) = load_mesh(std::path::Path::new(path), None, Default::default())?;
        let (per_bundle, strands) =
            strands_per_bundle_for(&baked, &style, self.scale.strands as u64);
        let params = StrandParams {
            strands_per_bundle: per_bundle,
            verts_log2: 4,
        };
        let mut r = self.renderer()?;
        r.add_character(&baked, &style, params, Mat4::IDENTITY)?;
        let o = Vec3::from_slice(&baked.info.pos_origin[..3]);
        let e = Vec3::from_slice(&baked.info.pos_extent[..3]);
        let camera = Camera::framing(o, o + e, hairmesh::render::DEFAULT_VIEW_DIR, 40.0);
        let v = view(camera, false);
        let tex = Some(baked.texture_bytes() as u64);
        let mut mesh_ms = f64::NAN;
        if r.has_mesh_path() {
            let t = self.time(&mut r, &v, RenderPath::Mesh)?;
            mesh_ms = t.0;
            self.rows += &csv_row("a", path, "mesh", &t, tex);
        }
        let c = self.time(&mut r, &v, RenderPath::Compute)?;
        self.rows += &csv_row("a", path, "compute", &c, tex);
        let vertices = self.store_strands(&mut r, &v)?;
        let static_bytes =
            vertices as u64 * size_of::<hairmesh::render::shared::HairVertex>() as u64;
        let s = self.time(&mut r, &v, RenderPath::Static)?;
        self.rows += &csv_row("a", path, "static", &s, Some(static_bytes));
        // A fresh compute frame holds the strands LHS stores.
        self.store_strands(&mut r, &v)?;
        let lhs_bytes = r.capture_lhs(vertices, 17, 0.01)?.bytes();
        let l = self.time(&mut r, &v, RenderPath::Lhs)?;
        self.rows += &csv_row("a", path, "lhs", &l, Some(lhs_bytes));
        let ours = if mesh_ms.is_nan() {
            c.0
        } else {
            mesh_ms.min(c.0)
        };
        let row = format!(
            "| {} | {strands} | {mesh_ms:.1} | {:.1} | {:.1} | {:.1} | {:.2} | {:.2} | {:.0} KiB | {:.1} MiB | {:.1} MiB |",
            std::path::Path::new(path)
                .file_stem()
                .unwrap_or_default()
                .to_string_lossy(),
            c.0,
            l.0,
            s.0,
            ours / l.0,
            ours / s.0,
            baked.texture_bytes() as f64 / 1024.0,
            lhs_bytes as f64 / (1 << 20) as f64,
            static_bytes as f64 / (1 << 20) as f64
        );
        Ok((row, ours / l.0, ours / s.0))
    }

    /// (a) and (d) for the three sample models.
    fn models(&mut self) -> Result<()> {
        outln!(
            "\n(a) {} strands per model, LoD off, draw {}; (d) GPU bytes per model",
            self.scale.strands,
            self.draw
        )?;
        outln!(
            "| model | strands | mesh ms | compute ms | LHS ms | static ms | ours / LHS | ours / static | textures | LHS bytes | static bytes |"
        )?;
        outln!("|---|---|---|---|---|---|---|---|---|---|---|")?;
        let mut ratios = Vec::new();
        for path in MODELS {
            let (row, lhs, stat) = self.model(path)?;
            outln!("{row}")?;
            ratios.push((lhs, stat));
        }
        let range = |f: fn(&(f64, f64)) -> f64| {
            let v: Vec<f64> = ratios.iter().map(f).collect();
            (
                v.iter().copied().fold(f64::MAX, f64::min),
                v.iter().copied().fold(0.0, f64::max),
            )
        };
        let (l, s) = (range(|r| r.0), range(|r| r.1));
        let faster = |(lo, hi): (f64, f64), other: &str| match hi <= 1.0 {
            true => format!(
                "hair meshes {:.1}-{:.1}x faster than {other}",
                1.0 / hi,
                1.0 / lo
            ),
            false if lo >= 1.0 => format!("{other} {lo:.1}-{hi:.1}x faster than hair meshes"),
            false => format!(
                "hair meshes {:.1}x faster to {hi:.1}x slower than {other}",
                1.0 / lo
            ),
        };
        outln!(
            "ours / LHS {:.2}-{:.2} ({}), ours / static {:.2}-{:.2} ({}), draw {}",
            l.0,
            l.1,
            faster(l, "LHS"),
            s.0,
            s.1,
            faster(s, "static strands"),
            self.draw
        )?;
        Ok(())
    }

    /// LoD on against off for `r`'s characters seen by `camera`, on every generation path:
    /// one table row and CSV rows each, scenario `scenario`, model `name`.
    fn lod_rows(
        &mut self,
        r: &mut Renderer,
        camera: Camera,
        (scenario, name): (&str, &str),
    ) -> Result<()> {
        outln!(
            "| path | LoD on ms | LoD off ms | speedup | strands on / off | triangles + segments on / off |"
        )?;
        outln!("|---|---|---|---|---|---|")?;
        let mut paths = vec![RenderPath::Compute];
        if r.has_mesh_path() {
            paths.insert(0, RenderPath::Mesh);
        }
        for p in paths {
            let on = self.time(r, &view(camera, true), p)?;
            let off = self.time(r, &view(camera, false), p)?;
            self.rows += &csv_row(scenario, name, &format!("{p:?} lod on"), &on, None);
            self.rows += &csv_row(scenario, name, &format!("{p:?} lod off"), &off, None);
            let dropped = |f: &FrameReport| f.dropped().any();
            // Software frames draw segments, hardware ones triangles (auto: both).
            let prims = |f: &FrameReport| f.stats.triangles_drawn + f.stats.segments_written;
            outln!(
                "| {p:?} | {:.1} | {:.1} | {:.1}x | {} / {} | {} / {}{} |",
                on.0,
                off.0,
                off.0 / on.0,
                on.3.stats.strands_drawn,
                off.3.stats.strands_drawn,
                prims(&on.3),
                prims(&off.3),
                if dropped(&on.3) || dropped(&off.3) {
                    " (budget overflow)"
                } else {
                    ""
                }
            )?;
        }
        Ok(())
    }

    /// (b) the crowd of sample meshes at about `crowd_strands` strands per character.
    fn crowd(&mut self) -> Result<()> {
        let (count, strands) = (self.scale.crowd, self.scale.crowd_strands);
        outln!(
            "\n(b) crowd of {count} characters (sample meshes) of about {strands} strands each, LoD on vs off, draw {}",
            self.draw
        )?;
        let meshes: Vec<_> = super::CROWD_MESHES
            .iter()
            .map(|m| load_mesh(std::path::Path::new(m), None, Default::default()))
            .collect::<Result<_, _>>()?;
        let side = (count as f32).sqrt().ceil() as usize;
        let mut r = self.renderer()?;
        for i in 0..count {
            let (baked, style) = &meshes[i % meshes.len()];
            let (per_bundle, _) = strands_per_bundle_for(baked, style, strands as u64);
            let params = StrandParams {
                strands_per_bundle: per_bundle,
                verts_log2: 4,
            };
            r.add_character(baked, style, params, super::crowd_model(i, side, baked))?;
        }
        let camera = Camera::look_at(Vec3::new(0.0, 1.7, 0.6), Vec3::new(0.0, 1.5, 6.0), 50.0);
        self.lod_rows(&mut r, camera, ("b", "crowd"))
    }

    /// (c) one head at near / mid / far (compute path).
    fn distance(&mut self) -> Result<()> {
        outln!(
            "\n(c) head_long at near / mid / far (compute path), LoD on vs off, draw {}",
            self.draw
        )?;
        outln!("| distance | LoD on ms | LoD off ms | speedup |")?;
        outln!("|---|---|---|---|")?;
        let (baked, style) = load_mesh(std::path::Path::new(MODELS[0]), None, Default::default())?;
        let mut r = self.renderer()?;
        let params = StrandParams {
            strands_per_bundle: 64,
            verts_log2: 5,
        };
        r.add_character(&baked, &style, params, Mat4::IDENTITY)?;
        let at = super::dolly(&baked);
        for (name, k) in [("near", 1.0f32), ("mid", 4.0), ("far", 12.0)] {
            let on = self.time(&mut r, &view(at(k), true), RenderPath::Compute)?;
            let off = self.time(&mut r, &view(at(k), false), RenderPath::Compute)?;
            self.rows += &csv_row("c", "head_long", &format!("{name} lod on"), &on, None);
            self.rows += &csv_row("c", "head_long", &format!("{name} lod off"), &off, None);
            outln!(
                "| {name} | {:.1} | {:.1} | {:.1}x |",
                on.0,
                off.0,
                off.0 / on.0
            )?;
        }
        Ok(())
    }

    /// (e) the paper's furry teapots (the `teapots` crowd preset), each baked once.
    fn teapots(&mut self) -> Result<()> {
        use hairmesh::characters::preset::{self, Preset};
        let (count, strands) = self.scale.teapots;
        outln!(
            "\n(e) {count} furry teapots of about {strands} strands each, LoD on vs off, draw {}",
            self.draw
        )?;
        let mut r = self.renderer()?;
        for c in preset::build(Preset::Teapots, count, 1)? {
            let baked = bake_character(&c)?;
            let (per_bundle, _) = strands_per_bundle_for(&baked, &c.hair.style, strands as u64);
            let params = c.strand_params(StrandParams {
                strands_per_bundle: per_bundle,
                verts_log2: 4,
            });
            r.add_character(&baked, &c.hair.style, params, c.model)?;
        }
        let camera = preset::orbit_camera(Preset::Teapots, count as u32, 0);
        self.lod_rows(&mut r, camera, ("e", "teapots"))
    }
}

/// Run the scenarios (`scenario`: one, or all) at `scale_name`, every method drawn with `draw`;
/// write the CSV to `csv` when given.
pub fn bench_paper(
    scale_name: &str,
    scenario: &str,
    device: Option<String>,
    csv: Option<std::path::PathBuf>,
    draw: StrandRaster,
) -> Result<()> {
    let scale = Scale::named(scale_name)?;
    const SCENARIOS: [&str; 6] = ["all", "models", "crowd", "distance", "storage", "teapots"];
    if !SCENARIOS.contains(&scenario) {
        bail!("--scenario {scenario}: one of {}", SCENARIOS.join(", "));
    }
    let wants = |name: &str| scenario == "all" || scenario == name;
    let csv_out = csv.map(|p| OutputPath::check(&p, &[])).transpose()?;
    let ctx = Arc::new(Context::new(&ContextDesc::default().device(device))?);
    // The largest vertex pool the device binds, up to 256 MiB (100K strands of 17 vertices
    // take 54 MiB).
    let pool = ctx.info.max_storage_buffer_range.min(256 << 20);
    let (w, h) = scale.size;
    outln!(
        "bench paper --scale {scale_name} --draw {draw}: {} ({}), {w}x{h}, {} timed frames each",
        ctx.info.name,
        ctx.info.driver,
        scale.runs
    )?;
    let mut run = PaperRun {
        ctx,
        scale,
        pool,
        draw,
        rows: String::from(
            "scenario,model,method,gpu_ms_median,gpu_ms_min,gpu_ms_max,strands,triangles,gpu_bytes\n",
        ),
    };
    if draw.uses_software() && !run.renderer()?.has_software_raster() {
        bail!(
            "--draw {draw}: {} has no software rasterizer (needs 64-bit atomics)",
            run.ctx.info.name
        );
    }
    if wants("models") {
        run.models()?;
    }
    if wants("crowd") {
        run.crowd()?;
    }
    if wants("distance") {
        run.distance()?;
    }
    if wants("teapots") {
        run.teapots()?;
    }
    if wants("storage") {
        storage_of_generated_styles(run.scale.strands, &mut run.rows)?;
    }
    if let Some(out) = csv_out {
        out.write(run.rows.as_bytes())?;
        outln!("\nwrote {}", out.path().display())?;
    }
    Ok(())
}
