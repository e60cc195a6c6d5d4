//! Structure-aware mutation fuzzing of every reader: the hair mesh OBJ reader (and the bake of
//! what it accepts), style TOML, scene TOML and the baked `.hmb` reader.
//!
//! Valid seed files (the samples in `hairmeshes/`, a scene, a bake) are mutated with a seeded
//! PCG: text readers get line edits (delete, duplicate, swap, insert statements from a
//! dictionary of hostile lines), token replacement by hostile numbers (`nan`, `inf`, `1e38`,
//! `-1`, `4294967296`, ...), truncation, byte flips and invalid UTF-8; `.hmb` files get header
//! and `MeshInfo` fields set to extreme values, bit flips, truncation and growth, with the
//! CRC recomputed half of the time so mutations reach the size checks behind it. Every input
//! must be accepted or rejected with an error: a panic is a finding. `tests/fuzz.rs` runs a
//! fixed-seed batch (with an allocation bound); `bench fuzz --iterations N` runs campaigns.

use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::Path;
use std::time::Instant;

use crate::rng::Pcg32;

/// The readers under test.
#[derive(Clone, Copy, Debug, PartialEq, Eq, clap::ValueEnum)]
pub enum Reader {
    /// `obj_io::parse_hair_mesh_obj` (+ `bake` of small accepted meshes) and `parse_scalp`.
    Obj,
    /// `HairStyle::from_toml`.
    Style,
    /// `SceneDesc::parse`.
    Scene,
    /// `baked_file::from_bytes`.
    Hmb,
    /// `HairFile::parse` (`.hair` strand files).
    Hair,
    /// `StrandModel::from_tfx` (TressFX strand files) and `fit` of small accepted models.
    Tfx,
    /// `obj_io::parse_triangles` (`fit --head`), and a small `fit` on every accepted head.
    Head,
    /// `SceneDesc::parse` of a scene naming the sample files, then `load_mesh` of every
    /// character it names (each file it names is read through the input policy).
    SceneFiles,
    /// `model::gltf::parse_character` (glTF characters) on the shipped man.
    Gltf,
    /// The same reader on a `.gltf` document whose buffer is a file beside it: the JSON
    /// mutated (the buffer's `uri` and `byteLength` included), or the `.bin` file mutated
    /// (bytes changed, cut short, grown).
    GltfExternal,
}

impl Reader {
    /// Every reader.
    pub const ALL: [Reader; 10] = [
        Reader::Obj,
        Reader::Style,
        Reader::Scene,
        Reader::Hmb,
        Reader::Hair,
        Reader::Tfx,
        Reader::Head,
        Reader::SceneFiles,
        Reader::Gltf,
        Reader::GltfExternal,
    ];
}

/// What a campaign found.
#[derive(Clone, Debug, Default)]
pub struct FuzzReport {
    /// Inputs tried.
    pub inputs: u64,
    /// Inputs the reader accepted.
    pub accepted: u64,
    /// Inputs the reader rejected with an error.
    pub rejected: u64,
    /// Panic messages with the iteration that found them.
    pub panics: Vec<(u64, String)>,
    /// Slowest single input, milliseconds.
    pub slowest_ms: f64,
}

const OBJ_SEEDS: [&str; 4] = [
    include_str!("../hairmeshes/small_patch.obj"),
    include_str!("../hairmeshes/triangle_tuft.obj"),
    include_str!("../hairmeshes/sphere_fur.obj"),
    include_str!("../hairmeshes/head_long.obj"),
];
const STYLE_SEEDS: [&str; 4] = [
    include_str!("../hairmeshes/small_patch.toml"),
    include_str!("../hairmeshes/triangle_tuft.toml"),
    include_str!("../hairmeshes/sphere_fur.toml"),
    include_str!("../hairmeshes/head_long.toml"),
];
const SCENE_SEED: &str = "size = [320, 240]\n[camera]\neye = [0.0, 0.1, 0.6]\n\
    target = [0.0, -0.05, 0.0]\nfov_y_degrees = 40.0\n[light]\ndirection = [0.3, 1.0, 0.5]\n\
    [[character]]\nmesh = \"a.obj\"\ntranslation = [0.1, 0.0, 0.0]\nrotation_y_degrees = 30.0\n\
    scale = 1.5\nstrands_per_bundle = 64\nverts_log2 = 5\n[[character]]\nmesh = \"b.hmb\"\n\
    style = \"b.toml\"\n";

/// A scene naming files in `hairmeshes/` (resolved against [`SAMPLE_DIR`]).
const SCENE_FILES_SEED: &str = "[[character]]\nmesh = \"small_patch.obj\"\n\
    translation = [0.1, 0.0, 0.0]\n[[character]]\nmesh = \"triangle_tuft.obj\"\n\
    style = \"small_patch.toml\"\nscale = 2.0\n";

/// Where [`SCENE_FILES_SEED`]'s names resolve.
const SAMPLE_DIR: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/hairmeshes");

const HOSTILE_NUMBERS: [&str; 16] = [
    "0",
    "-0",
    "-1",
    "1",
    "nan",
    "inf",
    "-inf",
    "1e38",
    "3.5e38",
    "-1e38",
    "1e-45",
    "4294967295",
    "4294967296",
    "18446744073709551615",
    "0.5",
    "",
];

const HOSTILE_LINES: [&str; 24] = [
    "g layer0",
    "g layer1",
    "g layer9",
    "g layer01",
    "g",
    "g a b",
    "f 1 2 3",
    "f 1/1 2/2 3/3 4/4",
    "f 1/1 99999/2 3/3",
    "f -1/-1 -2/-2 -3/-3",
    "f 1/1 1/1 1/1",
    "v 0 0 0",
    "v nan 0 0",
    "v 1e30 1e30 1e30",
    "vt 0 0 0",
    "vt 0.5",
    "curv 0 1 1 2",
    "[[character]]",
    "[camera]",
    "size = [0, 0]",
    "seed = -1",
    "color = []",
    "strands_per_bundle = 4294967295",
    "mesh = \"/dev/zero\"",
];

fn pick<'a, T>(rng: &mut Pcg32, items: &'a [T]) -> &'a T {
    &items[rng.next_u32() as usize % items.len()]
}

fn below(rng: &mut Pcg32, n: usize) -> usize {
    if n == 0 {
        0
    } else {
        rng.next_u32() as usize % n
    }
}

/// One to four text mutations of `seed`.
fn mutate_text(rng: &mut Pcg32, seed: &str) -> Vec<u8> {
    let mut lines: Vec<String> = seed.lines().map(str::to_string).collect();
    let rounds = 1 + below(rng, 4);
    let mut bytes_mutation = None;
    for _ in 0..rounds {
        let n = lines.len();
        match below(rng, 9) {
            0 if n > 0 => {
                lines.remove(below(rng, n));
            }
            1 if n > 0 => {
                let i = below(rng, n);
                let l = lines[i].clone();
                lines.insert(below(rng, n + 1), l);
            }
            2 if n > 1 => {
                let (a, b) = (below(rng, n), below(rng, n));
                lines.swap(a, b);
            }
            3 => lines.insert(below(rng, n + 1), pick(rng, &HOSTILE_LINES).to_string()),
            4..=6 if n > 0 => {
                // Replace a token (number, key or index) with a hostile number.
                let i = below(rng, n);
                let mut toks: Vec<String> = lines[i].split(' ').map(str::to_string).collect();
                let t = below(rng, toks.len());
                let value = pick(rng, &HOSTILE_NUMBERS).to_string();
                if let Some(slash) = toks[t].find('/')
                    && rng.next_u32().is_multiple_of(2)
                {
                    toks[t].replace_range(..slash, &value);
                } else {
                    toks[t] = value;
                }
                lines[i] = toks.join(" ");
            }
            7 => bytes_mutation = Some(below(rng, 3)),
            _ => {
                let n = lines.len();
                lines.truncate(below(rng, n + 1));
            }
        }
    }
    let mut out = lines.join("\n").into_bytes();
    out.push(b'\n');
    match bytes_mutation {
        Some(0) if !out.is_empty() => {
            let i = below(rng, out.len());
            out[i] ^= 1 << below(rng, 8);
        }
        Some(1) => {
            let i = below(rng, out.len() + 1);
            out.splice(i..i, [0xff, 0x00, 0xc3]);
        }
        Some(_) => {
            let n = out.len();
            out.truncate(below(rng, n + 1));
        }
        None => {}
    }
    out
}

/// One to three structure-aware mutations of a `.hmb` file.
fn mutate_hmb(rng: &mut Pcg32, seed: &[u8]) -> Vec<u8> {
    let mut out = seed.to_vec();
    const EXTREMES: [u32; 8] = [0, 1, 2, 3, 0x7fff_ffff, 0xffff_ffff, 0x10000, 2049];
    for _ in 0..1 + below(rng, 3) {
        match below(rng, 6) {
            // A u32 of the header or MeshInfo (offsets 8..24+64) set to an extreme.
            0 | 1 => {
                let at = 8 + 4 * below(rng, (24 + 64 - 8) / 4);
                if at + 4 <= out.len() {
                    let v = *pick(rng, &EXTREMES);
                    out[at..at + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
            // A float field of MeshInfo or HairStyle set to NaN/inf/huge.
            2 => {
                let at = 24 + 4 * below(rng, (64 + 96) / 4);
                let v = *pick(rng, &[f32::NAN, f32::INFINITY, -1e38, 1e38, 0.0, -1.0]);
                if at + 4 <= out.len() {
                    out[at..at + 4].copy_from_slice(&v.to_le_bytes());
                }
            }
            3 if !out.is_empty() => {
                let i = below(rng, out.len());
                out[i] ^= 1 << below(rng, 8);
            }
            4 => {
                let n = out.len();
                out.truncate(below(rng, n + 1));
            }
            _ => out.extend((0..below(rng, 64)).map(|_| rng.next_u32() as u8)),
        }
    }
    // Recompute length and CRC half of the time so the mutation reaches the checks behind them.
    if out.len() >= 24 && rng.next_u32().is_multiple_of(2) {
        let payload_len = (out.len() - 24) as u64;
        out[16..24].copy_from_slice(&payload_len.to_le_bytes());
        let crc = crc32fast::hash(&out[24..]);
        out[12..16].copy_from_slice(&crc.to_le_bytes());
    }
    out
}

/// A `.hair` seed: a few strands with every optional array, and the same without them.
fn hair_seeds() -> [Vec<u8>; 2] {
    use crate::model::hair_file::HairFile;
    let full = HairFile {
        segments: Some(vec![3, 1, 2]),
        default_segments: 2,
        points: (0..9).map(|i| [i as f32, 0.5 * i as f32, 0.1]).collect(),
        thickness: Some(vec![0.01; 9]),
        default_thickness: 0.01,
        transparency: Some(vec![0.2; 9]),
        default_transparency: 0.0,
        colors: Some(vec![[0.3, 0.2, 0.1]; 9]),
        default_color: [0.3, 0.2, 0.1],
        info: "fuzz seed".into(),
        hair_count: 3,
    };
    let plain = HairFile {
        segments: None,
        points: full.points[..6].to_vec(),
        thickness: None,
        transparency: None,
        colors: None,
        hair_count: 2,
        ..full.clone()
    };
    [full.to_bytes(), plain.to_bytes()]
}

/// Mutations of a `.hair` file: header words set to extremes, default floats to NaN/inf, bit
/// flips, truncation and extension.
/// A small TressFX file: 6 curved strands of 8 vertices.
fn tfx_seed() -> Vec<u8> {
    let mut b = Vec::new();
    b.extend_from_slice(&4.0f32.to_le_bytes());
    b.extend_from_slice(&6u32.to_le_bytes());
    b.extend_from_slice(&8u32.to_le_bytes());
    b.extend_from_slice(&160u32.to_le_bytes());
    b.resize(160, 0);
    for s in 0..6 {
        let a = s as f32 * 0.9;
        for v in 0..8 {
            let t = v as f32 * 0.1;
            for x in [a.cos() * (1.0 + t), 1.0 - t * t, a.sin() * (1.0 + t), 1.0] {
                b.extend_from_slice(&x.to_le_bytes());
            }
        }
    }
    b
}

/// Where a binary strand format keeps what mutations aim at.
struct BinaryLayout {
    /// Byte offset of the first header count and how many u32 counts follow.
    counts: (usize, usize),
    /// Byte offset of the first float to break and how many (`None`: anywhere in the file).
    floats: Option<(usize, usize)>,
    /// Count values tried.
    extremes: [u32; 8],
    /// Truncations shorter than this end the mutation.
    min_len: usize,
}

/// One to three mutations of `seed`: an extreme header count, a non-finite or huge float, a
/// flipped bit, or a truncation.
fn mutate_binary(rng: &mut Pcg32, seed: &[u8], layout: &BinaryLayout) -> Vec<u8> {
    let mut out = seed.to_vec();
    for _ in 0..1 + below(rng, 3) {
        match below(rng, 5) {
            0 | 1 => {
                let at = layout.counts.0 + 4 * below(rng, layout.counts.1);
                let v = *pick(rng, &layout.extremes);
                out[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
            2 => {
                let at = match layout.floats {
                    Some((first, n)) => first + 4 * below(rng, n),
                    None => 4 * below(rng, out.len() / 4),
                };
                let v = *pick(rng, &[f32::NAN, f32::INFINITY, -1e38, 0.0, 1e30]);
                out[at..at + 4].copy_from_slice(&v.to_le_bytes());
            }
            3 => {
                let i = below(rng, out.len());
                out[i] ^= 1 << below(rng, 8);
            }
            _ => {
                let n = out.len();
                out.truncate(below(rng, n + 1));
                if out.len() < layout.min_len {
                    return out;
                }
            }
        }
    }
    out
}

fn mutate_tfx(rng: &mut Pcg32, seed: &[u8]) -> Vec<u8> {
    let layout = BinaryLayout {
        counts: (4, 3),
        floats: None,
        extremes: [0, 1, 2, 7, 160, 0x7fff_ffff, 0xffff_ffff, 65535],
        min_len: 16,
    };
    mutate_binary(rng, seed, &layout)
}

fn mutate_hair(rng: &mut Pcg32, seed: &[u8]) -> Vec<u8> {
    let layout = BinaryLayout {
        counts: (4, 4),
        floats: Some((20, 5)),
        extremes: [0, 1, 2, 0x1f, 0x20, 0x7fff_ffff, 0xffff_ffff, 65535],
        min_len: 40,
    };
    mutate_binary(rng, seed, &layout)
}

fn hmb_seed() -> Vec<u8> {
    let mesh = crate::model::obj_io::parse_hair_mesh_obj("seed", OBJ_SEEDS[0].as_bytes())
        .expect("sample OBJ parses");
    let style = crate::HairStyle::from_toml("seed", STYLE_SEEDS[0]).expect("sample style");
    let baked =
        crate::bake(&mesh, &style, crate::BakeOptions::default(), |_, _| {}).expect("sample bakes");
    crate::bake::baked_file::to_bytes(&baked)
}

/// Accepted (`true`), rejected (`false`) or a panic message.
fn run_one(reader: Reader, input: &[u8]) -> Result<bool, String> {
    let result = catch_unwind(AssertUnwindSafe(|| match reader {
        Reader::Obj => {
            let mesh = crate::model::obj_io::parse_hair_mesh_obj("fuzz.obj", input);
            let _ = crate::model::obj_io::parse_scalp("fuzz.obj", input);
            match mesh {
                Ok(m) if m.vertex_count() <= 2000 => {
                    let baked = crate::bake(
                        &m,
                        &crate::HairStyle::default(),
                        crate::BakeOptions::default(),
                        |_, _| {},
                    );
                    baked.is_ok()
                }
                Ok(_) => true,
                Err(_) => false,
            }
        }
        Reader::Style => std::str::from_utf8(input)
            .ok()
            .is_some_and(|t| crate::HairStyle::from_toml("fuzz.toml", t).is_ok()),
        Reader::Scene => std::str::from_utf8(input).ok().is_some_and(|t| {
            crate::render::scene::SceneDesc::parse("fuzz.toml", t, Path::new(".")).is_ok()
        }),
        Reader::Hmb => crate::bake::baked_file::from_bytes("fuzz.hmb", input).is_ok(),
        Reader::Gltf => {
            let budget = crate::budget::MemoryBudget::default();
            crate::model::gltf::parse_character("fuzz.glb", input, None, budget).is_ok()
        }
        Reader::GltfExternal => external_gltf(input),
        Reader::Hair => crate::model::hair_file::HairFile::parse("fuzz.hair", input).is_ok(),
        Reader::Tfx => match crate::model::strands::StrandModel::from_tfx("fuzz.tfx", input) {
            Ok(m) if m.point_count() <= 4096 => {
                let opts = crate::fit::FitOptions {
                    bundles: 4,
                    layers: None,
                    ..Default::default()
                };
                crate::fit::fit(&m, None, &opts).is_ok()
            }
            Ok(_) => true,
            Err(_) => false,
        },
        Reader::Head => match crate::model::obj_io::parse_triangles("fuzz.obj", input) {
            Ok(head) if head.len() <= 4096 => {
                let model = crate::model::strands::StrandModel::from_tfx("seed", &tfx_seed())
                    .expect("the TressFX seed parses");
                let opts = crate::fit::FitOptions {
                    bundles: 4,
                    layers: None,
                    ..Default::default()
                };
                crate::fit::fit(&model, Some(&head), &opts).is_ok()
            }
            Ok(_) => true,
            Err(_) => false,
        },
        Reader::SceneFiles => std::str::from_utf8(input).ok().is_some_and(|t| {
            let base = Path::new(SAMPLE_DIR);
            match crate::render::scene::SceneDesc::parse("fuzz.toml", t, base) {
                Ok(scene) => scene.characters.iter().all(|c| {
                    crate::render::scene::load_mesh(&c.mesh, c.style.as_deref(), Default::default())
                        .is_ok()
                }),
                Err(_) => false,
            }
        }),
    }));
    result.map_err(|p| {
        p.downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_else(|| "panic".into())
    })
}

/// The glTF reader's seed: the shipped man.
const GLB_SEED: &[u8] = include_bytes!("../hairmeshes/people/man.glb");

/// A mutated GLB: its JSON chunk mutated as text and repacked, a few bytes changed anywhere
/// (the binary chunk's data, the headers), or the file cut short.
fn mutate_glb(rng: &mut Pcg32, seed: &[u8]) -> Vec<u8> {
    let json_len = u32::from_le_bytes([seed[12], seed[13], seed[14], seed[15]]) as usize;
    match below(rng, 3) {
        0 => {
            let json = std::str::from_utf8(&seed[20..20 + json_len]).unwrap_or("");
            // One JSON line per object, so line mutations hit fields.
            let text = json.replace(",\"", ",\n\"");
            let mut m: Vec<u8> = mutate_text(rng, &text)
                .into_iter()
                .filter(|&b| b != b'\n')
                .collect();
            m.resize(m.len().div_ceil(4) * 4, b' ');
            let rest = &seed[20 + json_len..];
            let mut out = Vec::with_capacity(seed.len());
            out.extend_from_slice(&seed[..8]);
            out.extend(((20 + m.len() + rest.len()) as u32).to_le_bytes());
            out.extend((m.len() as u32).to_le_bytes());
            out.extend_from_slice(b"JSON");
            out.extend(m);
            out.extend_from_slice(rest);
            out
        }
        1 => {
            let mut out = seed.to_vec();
            for _ in 0..1 + below(rng, 8) {
                let at = below(rng, out.len());
                out[at] = rng.next_u32() as u8;
            }
            out
        }
        _ => seed[..below(rng, seed.len())].to_vec(),
    }
}

/// The GLB seed split into a `.gltf` document whose buffer is the file `bin_name` beside it,
/// and that file's bytes.
fn external_seed(bin_name: &str) -> (String, &'static [u8]) {
    let json_len = u32::from_le_bytes([GLB_SEED[12], GLB_SEED[13], GLB_SEED[14], GLB_SEED[15]]);
    let json = std::str::from_utf8(&GLB_SEED[20..20 + json_len as usize]).unwrap_or("");
    let bin = GLB_SEED
        .get(20 + json_len as usize + 8..)
        .unwrap_or_default();
    let with_uri = json.replacen(
        "\"buffers\":[{",
        &format!("\"buffers\":[{{\"uri\":\"{bin_name}\","),
        1,
    );
    (with_uri, bin)
}

/// A mutated external-buffer glTF: tag 0 and a mutated document over the pristine `man.bin`,
/// or tag 1 and mutated bytes of `mutated.bin` under the pristine document.
fn mutate_external_gltf(rng: &mut Pcg32) -> Vec<u8> {
    if below(rng, 3) > 0 {
        let (json, _) = external_seed("man.bin");
        let text = json.replace(",\"", ",\n\"");
        let mut out = vec![0u8];
        out.extend(mutate_text(rng, &text).into_iter().filter(|&b| b != b'\n'));
        return out;
    }
    let (_, bin) = external_seed("mutated.bin");
    let mut out = vec![1u8];
    match below(rng, 3) {
        0 => {
            out.extend_from_slice(bin);
            for _ in 0..1 + below(rng, 16) {
                let at = 1 + below(rng, bin.len());
                out[at] = rng.next_u32() as u8;
            }
        }
        1 => out.extend_from_slice(&bin[..below(rng, bin.len())]),
        _ => {
            out.extend_from_slice(bin);
            out.resize(out.len() + 1 + below(rng, 4096), 0xff);
        }
    }
    out
}

/// The folder the external-buffer inputs are read from (removed after the campaign):
/// `man.bin` (pristine) written when missing; `mutated.bin` rewritten per input.
fn external_dir() -> std::path::PathBuf {
    let dir = std::env::temp_dir().join(format!("hairmesh-fuzz-{}", std::process::id()));
    if !dir.join("man.bin").is_file() {
        let _ = std::fs::create_dir_all(&dir);
        let _ = std::fs::write(dir.join("man.bin"), external_seed("man.bin").1);
    }
    dir
}

/// Parse one external-buffer input (see [`mutate_external_gltf`]).
fn external_gltf(input: &[u8]) -> bool {
    let dir = external_dir();
    let budget = crate::budget::MemoryBudget::default();
    let json = match input.split_first() {
        Some((0, doc)) => doc.to_vec(),
        Some((_, bin)) => {
            if std::fs::write(dir.join("mutated.bin"), bin).is_err() {
                return false;
            }
            external_seed("mutated.bin").0.into_bytes()
        }
        None => return false,
    };
    crate::model::gltf::parse_character("fuzz.gltf", &json, Some(&dir), budget).is_ok()
}

/// The mutated inputs of one campaign, in order.
struct Inputs {
    reader: Reader,
    rng: Pcg32,
    hmb: Option<Vec<u8>>,
    hair: [Vec<u8>; 2],
}

impl Inputs {
    fn new(reader: Reader, seed: u64) -> Self {
        Inputs {
            reader,
            rng: Pcg32::new(seed ^ (reader as u64) << 32),
            hmb: (reader == Reader::Hmb).then(hmb_seed),
            hair: hair_seeds(),
        }
    }

    fn next_input(&mut self) -> Vec<u8> {
        let rng = &mut self.rng;
        match self.reader {
            Reader::Obj | Reader::Head => {
                let seed = *pick(rng, &OBJ_SEEDS);
                mutate_text(rng, seed)
            }
            Reader::Style => {
                let seed = *pick(rng, &STYLE_SEEDS);
                mutate_text(rng, seed)
            }
            Reader::Scene => mutate_text(rng, SCENE_SEED),
            Reader::Hmb => mutate_hmb(rng, self.hmb.as_deref().unwrap_or_default()),
            Reader::Hair => {
                let seed = pick(rng, &self.hair).clone();
                mutate_hair(rng, &seed)
            }
            Reader::Tfx => mutate_tfx(rng, &tfx_seed()),
            Reader::SceneFiles => mutate_text(rng, SCENE_FILES_SEED),
            Reader::Gltf => mutate_glb(rng, GLB_SEED),
            Reader::GltfExternal => mutate_external_gltf(rng),
        }
    }
}

/// Input `index` (from 0) of the campaign of `reader` seeded with `seed`: the bytes a finding
/// names, to reproduce it alone (`bench fuzz --save-input`).
pub fn nth_input(reader: Reader, seed: u64, index: u64) -> Vec<u8> {
    let mut inputs = Inputs::new(reader, seed);
    for _ in 0..index {
        inputs.next_input();
    }
    inputs.next_input()
}

/// Run `iterations` mutated inputs through `reader`, seeded with `seed`.
pub fn campaign(reader: Reader, iterations: u64, seed: u64) -> FuzzReport {
    let mut inputs = Inputs::new(reader, seed);
    let mut report = FuzzReport::default();
    for i in 0..iterations {
        let input = inputs.next_input();
        let start = Instant::now();
        let outcome = run_one(reader, &input);
        report.slowest_ms = report.slowest_ms.max(start.elapsed().as_secs_f64() * 1e3);
        report.inputs += 1;
        match outcome {
            Ok(true) => report.accepted += 1,
            Ok(false) => report.rejected += 1,
            Err(msg) => report.panics.push((i, msg)),
        }
    }
    if reader == Reader::GltfExternal {
        let _ = std::fs::remove_dir_all(external_dir());
    }
    report
}
