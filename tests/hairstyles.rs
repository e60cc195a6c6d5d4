//! The hairstyle generator: deterministic (same seed, byte-identical bakes) and every character
//! of a crowd gets its own hair (pairwise different textures and styles).

use hairmesh::bake::baked_file;
use hairmesh::characters::preset::{Preset, build};
use hairmesh::{BakeOptions, bake};

fn bakes(count: usize, seed: u32) -> Vec<Vec<u8>> {
    preset_bakes(Preset::Mixed, count, seed)
}

fn preset_bakes(preset: Preset, count: usize, seed: u32) -> Vec<Vec<u8>> {
    build(preset, count, seed)
        .unwrap()
        .iter()
        .map(|c| {
            let b = bake(
                &c.hair.mesh,
                &c.hair.style,
                BakeOptions::default(),
                |_, _| {},
            )
            .unwrap();
            baked_file::to_bytes(&b)
        })
        .collect()
}

#[test]
fn same_seed_gives_byte_identical_bakes() {
    let a = bakes(16, 42);
    let b = bakes(16, 42);
    assert_eq!(a, b);
    let c = bakes(16, 43);
    assert_ne!(a, c, "another seed gives other hair");
    assert_eq!(
        preset_bakes(Preset::Teapots, 3, 42),
        preset_bakes(Preset::Teapots, 3, 42)
    );
}

#[test]
fn every_character_has_its_own_hair() {
    let mut all = bakes(16, 7);
    all.extend(preset_bakes(Preset::Teapots, 6, 7));
    for i in 0..all.len() {
        for j in i + 1..all.len() {
            let (a, b) = (&all[i], &all[j]);
            // Different sizes, or at least 5% of the bytes differ.
            let differing = if a.len() == b.len() {
                a.iter().zip(b).filter(|(x, y)| x != y).count()
            } else {
                a.len().max(b.len())
            };
            assert!(
                differing * 20 > a.len().min(b.len()),
                "characters {i} and {j} share most of their hair ({differing} differing bytes)"
            );
        }
    }
}
