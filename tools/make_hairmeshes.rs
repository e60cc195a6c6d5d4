//! Generates the sample hair meshes in `hairmeshes/` (OBJ + style TOML), or grows the crowd's
//! hairstyle families on a head of the user's. Deterministic: running it again reproduces the
//! committed files byte for byte.
//!
//! `cargo run --release --bin make-hairmeshes -- [OUT_DIR]`
//! `cargo run --release --bin make-hairmeshes -- --head FILE.{obj,glb,gltf} --family bob -o DIR`

use std::f32::consts::PI;
use std::path::{Path, PathBuf};

use anyhow::Result;
use clap::Parser;
use glam::{Vec2, Vec3};
use hairmesh::budget::MemoryBudget;
use hairmesh::characters::any_head::AnyHead;
use hairmesh::characters::hairstyle::StyleFamily;
use hairmesh::fsutil::OutputPath;
use hairmesh::model::gltf::load_character;
use hairmesh::model::obj_io::hair_mesh_obj_bytes;
use hairmesh::{ExtrudeDesc, Face, HairMesh, extrude};

/// A scalp under construction: positions, uvs, faces.
#[derive(Default)]
struct Scalp {
    pos: Vec<Vec3>,
    uv: Vec<Vec2>,
    faces: Vec<Face>,
}

impl Scalp {
    fn vertex(&mut self, p: Vec3, uv: Vec2) -> u32 {
        self.pos.push(p);
        self.uv.push(uv);
        (self.pos.len() - 1) as u32
    }
}

/// Latitude-longitude sphere cells between polar angles `theta0..theta1` (0 = +Y pole), with a
/// triangle fan at the pole when `theta0 == 0`; `keep(i, j)` filters cells.
fn sphere_scalp(
    radius: f32,
    lon: usize,
    lat: usize,
    theta1: f32,
    keep: impl Fn(usize, usize) -> bool,
) -> Scalp {
    let mut s = Scalp::default();
    let point = |i: usize, j: usize| {
        let phi = 2.0 * PI * i as f32 / lon as f32;
        let theta = theta1 * j as f32 / lat as f32;
        Vec3::new(
            theta.sin() * phi.sin(),
            theta.cos(),
            theta.sin() * phi.cos(),
        ) * radius
    };
    // Rows j = 1..=lat (row 0 is the pole), lon + 1 columns so the uv seam splits vertices.
    let mut id = vec![vec![u32::MAX; lon + 1]; lat + 1];
    let used = |i: usize, j: usize| {
        (j > 0 && keep(i % lon, j - 1))
            || (j < lat && keep(i % lon, j))
            || (i > 0 && j > 0 && keep(i - 1, j - 1))
            || (i > 0 && j < lat && keep(i - 1, j))
    };
    for (j, row) in id.iter_mut().enumerate().skip(1) {
        for (i, slot) in row.iter_mut().enumerate() {
            if used(i, j) {
                *slot = s.vertex(
                    point(i, j),
                    Vec2::new(i as f32 / lon as f32, j as f32 / lat as f32),
                );
            }
        }
    }
    for i in 0..lon {
        if keep(i, 0) {
            let pole = s.vertex(
                Vec3::Y * radius,
                Vec2::new((i as f32 + 0.5) / lon as f32, 0.0),
            );
            s.faces.push(Face::Tri([pole, id[1][i], id[1][i + 1]]));
        }
    }
    for j in 1..lat {
        for i in 0..lon {
            if keep(i, j) {
                s.faces.push(Face::Quad([
                    id[j][i],
                    id[j + 1][i],
                    id[j + 1][i + 1],
                    id[j][i + 1],
                ]));
            }
        }
    }
    s
}

fn build(name: &str, s: &Scalp, desc: &ExtrudeDesc) -> Result<HairMesh> {
    Ok(extrude(name, &s.pos, &s.uv, &s.faces, desc)?)
}

/// (a) A sphere fully covered with short fur.
fn sphere_fur() -> Result<HairMesh> {
    let s = sphere_scalp(0.5, 16, 8, PI, |_, _| true);
    // The south pole row would collapse to a point: close it with triangles instead.
    let mut s = s;
    let south: Vec<usize> = (0..s.faces.len())
        .filter(|&f| matches!(s.faces[f], Face::Quad(q) if s.pos[q[1] as usize].y < -0.49))
        .collect();
    for f in south {
        if let Face::Quad(q) = s.faces[f] {
            s.faces[f] = Face::Tri([q[0], q[1], q[3]]);
        }
    }
    let used: Vec<bool> = (0..s.pos.len())
        .map(|v| s.faces.iter().any(|f| f.vertices().contains(&(v as u32))))
        .collect();
    let s = compact(s, &used);
    build("sphere_fur", &s, &ExtrudeDesc::new(3, 0.04))
}

/// Drop unused vertices and renumber faces.
fn compact(s: Scalp, used: &[bool]) -> Scalp {
    let mut map = vec![u32::MAX; s.pos.len()];
    let mut out = Scalp::default();
    for (v, &u) in used.iter().enumerate() {
        if u {
            map[v] = out.vertex(s.pos[v], s.uv[v]);
        }
    }
    out.faces = s
        .faces
        .iter()
        .map(|f| match f {
            Face::Tri(t) => Face::Tri(t.map(|v| map[v as usize])),
            Face::Quad(q) => Face::Quad(q.map(|v| map[v as usize])),
        })
        .collect();
    out
}

/// (b) A head-like scalp (sphere cap without the face) with long hair falling under gravity.
fn head_long() -> Result<HairMesh> {
    let lon = 24;
    let lat = 8;
    // Cells cover the top 110 degrees; the front (face) keeps only the top 60 degrees.
    let s = sphere_scalp(0.1, lon, lat, 110f32.to_radians(), |i, j| {
        let phi = 360.0 * (i as f32 + 0.5) / lon as f32;
        let front = !(50.0..=310.0).contains(&phi);
        !(front && j >= 4)
    });
    build(
        "head_long",
        &s,
        &ExtrudeDesc::new(10, 0.035)
            .gravity(1.0, Vec3::NEG_Y)
            .avoid_sphere(Vec3::ZERO, 0.1),
    )
}

/// (c) A small curved 5x5-quad patch with 5 layers: 180 vertices, for the storage figure.
fn small_patch() -> Result<HairMesh> {
    let mut s = Scalp::default();
    let n = 5;
    for j in 0..=n {
        for i in 0..=n {
            let (x, z) = (i as f32 / n as f32 - 0.5, j as f32 / n as f32 - 0.5);
            s.vertex(
                Vec3::new(x, 0.2 * (1.0 - x * x - z * z), z) * 0.2,
                Vec2::new(i as f32, j as f32) / n as f32,
            );
        }
    }
    let id = |i: usize, j: usize| (j * (n + 1) + i) as u32;
    for j in 0..n {
        for i in 0..n {
            s.faces.push(Face::Quad([
                id(i, j),
                id(i, j + 1),
                id(i + 1, j + 1),
                id(i + 1, j),
            ]));
        }
    }
    build(
        "small_patch",
        &s,
        &ExtrudeDesc::new(5, 0.03).gravity(0.6, Vec3::new(1.0, -1.0, 0.0)),
    )
}

/// (d) A tuft on a triangulated hexagonal disc (all triangle bundles).
fn triangle_tuft() -> Result<HairMesh> {
    let mut s = Scalp::default();
    let rings = 2;
    let r = 0.05;
    let centre = s.vertex(Vec3::ZERO, Vec2::splat(0.5));
    let mut ring_ids = vec![vec![centre]];
    for k in 1..=rings {
        let mut ids = Vec::new();
        for c in 0..6 * k {
            let a = 2.0 * PI * c as f32 / (6 * k) as f32;
            let p = Vec2::new(a.cos(), a.sin()) * (r * k as f32 / rings as f32);
            let y = -2.0 * p.length_squared();
            ids.push(s.vertex(Vec3::new(p.x, y, p.y), Vec2::splat(0.5) + p / (2.0 * r)));
        }
        ring_ids.push(ids);
    }
    // Triangulate between consecutive rings (hexagonal lattice).
    for k in 1..=rings {
        let (inner, outer) = (&ring_ids[k - 1], &ring_ids[k]);
        for side in 0..6 {
            for step in 0..k {
                let o0 = outer[(side * k + step) % outer.len()];
                let o1 = outer[(side * k + step + 1) % outer.len()];
                let i0 = inner[((side * (k - 1)) + step) % inner.len()];
                s.faces.push(Face::Tri([i0, o0, o1]));
                if step + 1 < k {
                    let i1 = inner[((side * (k - 1)) + step + 1) % inner.len()];
                    s.faces.push(Face::Tri([i0, o1, i1]));
                }
            }
        }
    }
    build(
        "triangle_tuft",
        &s,
        &ExtrudeDesc::new(4, 0.04).gravity(0.3, Vec3::X),
    )
}

const STYLES: &[(&str, &str)] = &[
    (
        "sphere_fur",
        "# Short dense fur.\nstrand_width = 0.004\ntip_width_ratio = 0.2\nlength_variation = 0.3\nroot_ramp = 0.02\nclump_strength = 0.1\nfrizz_amplitude = 0.006\nfrizz_frequency = 25.0\ncolor = [0.55, 0.45, 0.35]\n",
    ),
    (
        "head_long",
        "# Long wavy hair.\nstrand_width = 0.0008\ntip_width_ratio = 0.4\nlength_variation = 0.2\nroot_ramp = 0.04\nclump_strength = 0.35\nclump_power = 2.0\nwave_amplitude = 0.008\nwave_frequency = 6.0\nwave_phase_jitter = 0.15\nfrizz_amplitude = 0.003\nfrizz_frequency = 12.0\nfrizz_power = 2.0\ncolor = [0.30, 0.17, 0.08]\n",
    ),
    (
        "small_patch",
        "# Curly patch.\nstrand_width = 0.001\nroot_ramp = 0.02\nclump_strength = 0.2\ncurl_radius = 0.006\ncurl_frequency = 12.0\nfrizz_amplitude = 0.001\ncolor = [0.12, 0.08, 0.05]\n",
    ),
    (
        "triangle_tuft",
        "# Straight tuft on triangle bundles.\nstrand_width = 0.001\nclump_strength = 0.25\nfrizz_amplitude = 0.002\ncolor = [0.8, 0.65, 0.4]\n",
    ),
];

fn main() {
    let parsed = hairmesh::cli::parse::<Args>("make-hairmeshes");
    hairmesh::cli::clean_up_on_signals("make-hairmeshes");
    if let Err(e) = run(parsed.args) {
        hairmesh::fsutil::exit_with_error("make-hairmeshes", &e, 1);
    }
}

/// Write the sample hair meshes (OBJ) and their styles (TOML) into a folder, or, with
/// `--head`, hairstyles grown on that head.
#[derive(Parser)]
#[command(version, about)]
struct Args {
    /// Folder to write into (made if it does not exist).
    #[arg(default_value = "hairmeshes")]
    out_dir: PathBuf,
    /// Folder to write into, instead of OUT_DIR (made if it does not exist).
    #[arg(short = 'o', long = "out", conflicts_with = "out_dir")]
    out: Option<PathBuf>,
    /// A head to grow hair on: an OBJ (all of it is the head; a bust is fine) or a glTF
    /// character (the part `--joint` moves), upright (+Y) and facing +Z, in any unit.
    #[arg(long)]
    head: Option<PathBuf>,
    /// Hairstyle families to grow on `--head` (comma-separated): buzz, shortcrop, bob,
    /// longstraight, longwavy, longcurly, ponytail, bun, sidebangs, mohawk, afro, fitted.
    #[arg(long, value_delimiter = ',', requires = "head")]
    family: Vec<StyleFamily>,
    /// The glTF joint whose vertices are the head.
    #[arg(long, default_value = "head", requires = "head")]
    joint: String,
    /// Seed of the grown hairstyles.
    #[arg(long, default_value_t = 1, requires = "head")]
    seed: u32,
}

fn run(args: Args) -> Result<()> {
    let out = args.out.as_ref().unwrap_or(&args.out_dir);
    // A folder that does not exist yet is made when the files are written (and removed
    // again if writing them fails); an existing file is refused.
    if out.exists() && !out.is_dir() {
        anyhow::bail!("{}: not a folder", out.display());
    }
    match &args.head {
        Some(head) => grow_on_head(&args, head, out),
        None => samples(out),
    }
}

/// Grow `args.family` (every family if none) on `head` into `out`: `<family>.obj` and
/// `<family>.toml` each, in the head file's frame and units, all checked before any is
/// written.
fn grow_on_head(args: &Args, head: &Path, out: &Path) -> Result<()> {
    let families = match args.family.is_empty() {
        true => StyleFamily::PEOPLE.to_vec(),
        false => args.family.clone(),
    };
    // The whole list and every output are checked before the head is read.
    if families.contains(&StyleFamily::Fur) {
        anyhow::bail!("--family fur grows on balls and teapots, not on heads");
    }
    let mut run = hairmesh::fsutil::RunFiles::new();
    run.input(head);
    let mut checked = Vec::new();
    for family in &families {
        let path = out.join(format!("{}.obj", family.name()));
        let obj = run.output(&path, "--family")?;
        let style = run.output(&path.with_extension("toml"), "--family")?;
        checked.push((obj, style));
    }
    let any = read_head(head, &args.joint)?;
    let mut files: Vec<(OutputPath, Vec<u8>, String)> = Vec::new();
    for (family, (obj_out, style_out)) in families.into_iter().zip(checked) {
        let hair = any.grow(family, args.seed)?;
        let name = family.name();
        let path = out.join(format!("{name}.obj"));
        let comment = format!(
            "{} grown on {} by tools/make_hairmeshes.rs (seed {})",
            name,
            head.display(),
            args.seed
        );
        let bytes = hair_mesh_obj_bytes(&hair.mesh, &comment)?;
        // A real head's density on this head's scalp: a glTF head is in metres; an OBJ head's
        // units are its own, taken to be the size of Sintel's (an adult head).
        let metres = head_metres_per_unit(head, &any);
        let per_cm2 = hairmesh::characters::hairstyle::SCALP_STRANDS_PER_CM2;
        let n = hair.strands_per_bundle_at(per_cm2, metres)?;
        let line = format!(
            "{}: {} bundles, {} layers, {:.0} cm² of scalp: {n} strands per bundle for {per_cm2} per cm² (render --strands-per-bundle {n})",
            path.display(),
            hair.mesh.faces.len(),
            hair.mesh.layer_count(),
            hair.scalp_cm2(metres)
        );
        files.push((obj_out, bytes, line));
        let style = path.with_extension("toml");
        let text = format!("# {comment}\n{}", toml::to_string(&hair.style)?);
        let line = format!("{}: style", style.display());
        files.push((style_out, text.into_bytes(), line));
    }
    for (_, _, line) in &files {
        hairmesh::outln!("{line}")?;
    }
    let outputs: Vec<_> = files.iter().map(|(p, b, _)| (p, b.as_slice())).collect();
    hairmesh::fsutil::write_together(&outputs)?;
    Ok(())
}

/// Metres per unit of the head in `path`: glTF's are metres; an OBJ's units are taken from its
/// size against Sintel's adult head (`AnyHead::scale` user units per canonical metre).
fn head_metres_per_unit(path: &Path, any: &AnyHead) -> f32 {
    let gltf = path
        .extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("glb") || e.eq_ignore_ascii_case("gltf"));
    match gltf {
        true => 1.0,
        false => 1.0 / any.scale,
    }
}

/// The head in `path`: an OBJ whole, a glTF character's `joint` and below.
fn read_head(path: &Path, joint: &str) -> Result<AnyHead> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(str::to_ascii_lowercase);
    Ok(match ext.as_deref() {
        Some("obj") => AnyHead::from_obj(path)?,
        Some("glb" | "gltf") => {
            let c = load_character(path, MemoryBudget::default())?;
            AnyHead::from_character(&path.display().to_string(), &c, joint)?
        }
        _ => anyhow::bail!("{}: a head is an .obj, .glb or .gltf file", path.display()),
    })
}

/// The sample hair meshes and styles.
fn samples(out: &Path) -> Result<()> {
    let meshes = [
        sphere_fur()?,
        head_long()?,
        small_patch()?,
        triangle_tuft()?,
    ];
    // Every output is checked, and every file encoded, before the first is written.
    let mut files: Vec<(OutputPath, Vec<u8>, String)> = Vec::new();
    for mesh in &meshes {
        let path = out.join(format!("{}.obj", mesh.name));
        let bytes = hair_mesh_obj_bytes(mesh, "generated by tools/make_hairmeshes.rs")?;
        let line = format!(
            "{}: {} bundles, {} layers, {} vertices",
            path.display(),
            mesh.faces.len(),
            mesh.layer_count(),
            mesh.vertex_count()
        );
        files.push((OutputPath::check(&path, &[])?, bytes, line));
    }
    for (name, style) in STYLES {
        let path: &Path = &out.join(format!("{name}.toml"));
        let line = format!("{}: style", path.display());
        files.push((
            OutputPath::check(path, &[])?,
            style.as_bytes().to_vec(),
            line,
        ));
    }
    for (_, _, line) in &files {
        hairmesh::outln!("{line}")?;
    }
    let outputs: Vec<_> = files.iter().map(|(p, b, _)| (p, b.as_slice())).collect();
    hairmesh::fsutil::write_together(&outputs)?;
    Ok(())
}
