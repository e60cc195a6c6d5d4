//! Where the mesh path's task shader puts each visible bundle's strands among the mesh
//! workgroups it launches (`glsl/strands.task`, read back by `glsl/strands.mesh`): the CPU
//! twin, so the packing is checked without a GPU.
//!
//! A strand workgroup of [`STRAND_GROUP_SIZE`] threads builds `max(S / 2^e, 1)` strands of
//! `2^e` segments, one per lane (paper 003 sec. 3.6.2). The hardware pass starts every
//! bundle in a fresh workgroup. The software passes pack: consecutive bundles of one
//! character and one vertex level form a run that fills the workgroups lane by lane, so a far
//! bundle with two strands of four segments shares a workgroup with three others instead of
//! leaving 22 of 32 threads idle. A run never shares a workgroup with another: the workgroup
//! binds one character and builds one vertex level.

use crate::render::core::shared::{PAYLOAD_LANE_BITS, STRAND_GROUP_SIZE};

/// One visible bundle of a task workgroup, as the placement sees it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PlacedBundle {
    /// Its character slot.
    pub character: u32,
    /// Segments of its strands (`2^e`).
    pub segments: u32,
    /// Strands drawn (eq. 8, at least 1).
    pub strands: u32,
}

/// Strands one workgroup builds at `segments` segments (`strands_per_workgroup`).
pub fn strands_per_workgroup(segments: u32) -> u32 {
    (STRAND_GROUP_SIZE / segments.max(1)).max(1)
}

/// The place of each bundle's first strand (`workgroup << PAYLOAD_LANE_BITS | lane`) and,
/// last, the workgroups in all (lane 0), as `strands.task` writes `TaskPayload::place`;
/// `pack`: the software passes' runs, else a workgroup per bundle.
pub fn place_strands(bundles: &[PlacedBundle], pack: bool) -> Vec<u32> {
    let (mut group, mut lane) = (0u32, 0u32);
    let mut run = None;
    let mut places = Vec::with_capacity(bundles.len() + 1);
    for b in bundles {
        let here = (b.character, b.segments);
        if !(pack && run == Some(here)) && lane > 0 {
            group += 1;
            lane = 0;
        }
        run = Some(here);
        places.push((group << PAYLOAD_LANE_BITS) | lane);
        let per = strands_per_workgroup(b.segments);
        lane += b.strands;
        group += lane / per;
        lane %= per;
    }
    group += (lane > 0) as u32;
    places.push(group << PAYLOAD_LANE_BITS);
    places
}

/// The bundle (index into `places`, without the total) whose strand sits in `lane` of
/// workgroup `group`: the last one placed at or before it (`lane_slot` in `strands.mesh`).
pub fn lane_slot(places: &[u32], group: u32, lane: u32) -> usize {
    let at = (group << PAYLOAD_LANE_BITS) | lane;
    let bundles = places.len().saturating_sub(1);
    (1..bundles).rev().find(|&j| places[j] <= at).unwrap_or(0)
}

/// Index in its bundle (slot `slot`) of the strand in `lane` of workgroup `group`, at `per`
/// strands a workgroup; at or past the bundle's count for an empty lane (`lane_strand`).
pub fn lane_strand(places: &[u32], (group, lane): (u32, u32), slot: usize, per: u32) -> u32 {
    let place = places[slot];
    let lane_mask = (1 << PAYLOAD_LANE_BITS) - 1;
    (group - (place >> PAYLOAD_LANE_BITS)) * per + lane - (place & lane_mask)
}

/// Lanes of workgroup `group` that hold strands, from lane 0 (bundle `slot`, strand `first`):
/// each bundle after it continues the run where the one before ended (`lanes_filled`).
pub fn lanes_filled(
    bundles: &[PlacedBundle],
    places: &[u32],
    (group, slot, first): (u32, usize, u32),
) -> u32 {
    let per = strands_per_workgroup(bundles[slot].segments);
    let mut n = per.min(bundles[slot].strands - first);
    for j in slot + 1..bundles.len() {
        if n >= per || places[j] != (group << PAYLOAD_LANE_BITS) | n {
            break;
        }
        n += (per - n).min(bundles[j].strands);
    }
    n
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A task workgroup's visible bundles: a few characters, mixed vertex levels, 1-40 strands.
    fn sample(seed: u32) -> Vec<PlacedBundle> {
        let mut x = seed.wrapping_mul(747_796_405).wrapping_add(2_891_336_453);
        let mut next = |n: u32| {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x % n
        };
        let mut character = 0;
        (0..32)
            .map(|_| {
                character += (next(6) == 0) as u32;
                PlacedBundle {
                    character,
                    segments: 1 << [1, 1, 2, 2, 3, 5, 6][next(7) as usize],
                    strands: 1 + next(5) * next(10),
                }
            })
            .collect()
    }

    /// Every strand of every bundle is built exactly once, in a lane below its workgroup's
    /// strand count, and every lane of a workgroup holds a strand of one character at one
    /// vertex level; packed, the workgroups are the runs' `ceil(strands / per)`, and without
    /// packing each bundle's own (the placement before packing).
    #[test]
    fn every_strand_has_one_lane_and_a_workgroup_holds_one_run() {
        for seed in 0..200 {
            let bundles = sample(seed);
            for pack in [false, true] {
                let places = place_strands(&bundles, pack);
                let groups = places[bundles.len()] >> PAYLOAD_LANE_BITS;
                let mut seen: Vec<Vec<u32>> = bundles
                    .iter()
                    .map(|b| vec![0; b.strands as usize])
                    .collect();
                for group in 0..groups {
                    let slot = lane_slot(&places, group, 0);
                    let per = strands_per_workgroup(bundles[slot].segments);
                    let first = lane_strand(&places, (group, 0), slot, per);
                    assert!(
                        first < bundles[slot].strands,
                        "{seed} {pack}: lane 0 of {group} empty"
                    );
                    let filled = lanes_filled(&bundles, &places, (group, slot, first));
                    assert!((1..=per).contains(&filled));
                    for lane in 0..per {
                        let k = lane_slot(&places, group, lane);
                        let i = lane_strand(&places, (group, lane), k, per);
                        let holds = i < bundles[k].strands;
                        assert_eq!(
                            holds,
                            lane < filled,
                            "{seed} {pack}: group {group} lane {lane}"
                        );
                        if holds {
                            let (a, b) = (bundles[k], bundles[slot]);
                            assert_eq!((a.character, a.segments), (b.character, b.segments));
                            seen[k][i as usize] += 1;
                        }
                    }
                }
                assert!(
                    seen.iter().flatten().all(|&n| n == 1),
                    "{seed} {pack}: {seen:?}"
                );
                let ceil =
                    |strands: u32, segments| strands.div_ceil(strands_per_workgroup(segments));
                let expected: u32 = if pack {
                    let mut runs: Vec<(u32, u32, u32)> = Vec::new();
                    for b in &bundles {
                        match runs.last_mut() {
                            Some(r) if (r.0, r.1) == (b.character, b.segments) => r.2 += b.strands,
                            _ => runs.push((b.character, b.segments, b.strands)),
                        }
                    }
                    runs.iter().map(|r| ceil(r.2, r.1)).sum()
                } else {
                    bundles.iter().map(|b| ceil(b.strands, b.segments)).sum()
                };
                assert_eq!(groups, expected, "{seed} {pack}");
            }
        }
    }

    /// Far bundles of two strands at four segments: eight a workgroup instead of one.
    #[test]
    fn far_bundles_share_workgroups() {
        let far = PlacedBundle {
            character: 3,
            segments: 4,
            strands: 2,
        };
        let bundles = vec![far; 32];
        let packed = place_strands(&bundles, true);
        let unpacked = place_strands(&bundles, false);
        assert_eq!(packed[32] >> PAYLOAD_LANE_BITS, 8);
        assert_eq!(unpacked[32] >> PAYLOAD_LANE_BITS, 32);
        // Another character, or another vertex level, starts a workgroup of its own.
        let mut mixed = bundles[..3].to_vec();
        mixed.push(PlacedBundle {
            character: 4,
            ..far
        });
        mixed.push(PlacedBundle { segments: 8, ..far });
        let places = place_strands(&mixed, true);
        assert_eq!(
            places,
            [
                0,
                2,
                4,
                1 << PAYLOAD_LANE_BITS,
                2 << PAYLOAD_LANE_BITS,
                3 << PAYLOAD_LANE_BITS
            ]
        );
    }
}
