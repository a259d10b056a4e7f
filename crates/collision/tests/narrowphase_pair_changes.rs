//! The narrowphase's in-place pair bookkeeping (removals and insertions applied by runs)
//! against an ordered map: same pairs in the same order, kept pairs keep their state, pairs
//! removed and added in one step come back fresh.

use carom_collision::narrowphase::{Dispatcher, NarrowObject, NarrowPhase};
use std::collections::BTreeMap;

/// A small deterministic generator (xorshift).
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u32 {
        (self.next() % n) as u32
    }
}

fn check(np: &NarrowPhase<u32>, model: &BTreeMap<(u32, u32), bool>) {
    let got: Vec<((u32, u32), bool)> = np.pairs().map(|p| ((p.a, p.b), p.sensor)).collect();
    let want: Vec<((u32, u32), bool)> = model.iter().map(|(&k, &v)| (k, v)).collect();
    assert_eq!(got, want);
}

fn run(seed: u64, objects: u64, steps: usize, max_changes: u64) {
    let mut rng = Rng(seed);
    let mut np: NarrowPhase<u32> = NarrowPhase::new(Dispatcher::default());
    // The pair's `sensor` flag marks it (no object is known, so the update leaves it).
    let mut model: BTreeMap<(u32, u32), bool> = BTreeMap::new();
    let none = |_: u32| -> Option<NarrowObject<'static>> { None };
    for _ in 0..steps {
        let mut added = Vec::new();
        let mut removed = Vec::new();
        let existing: Vec<(u32, u32)> = model.keys().copied().collect();
        for _ in 0..rng.below(max_changes + 1) {
            match rng.below(4) {
                // Remove an existing pair (possibly twice, possibly re-added below).
                0 | 1 if !existing.is_empty() => {
                    removed.push(existing[rng.below(existing.len() as u64) as usize])
                }
                // Remove an unknown pair: nothing happens.
                0 => removed.push((rng.below(objects), objects as u32 + 1)),
                _ => {
                    let (a, b) = (rng.below(objects), rng.below(objects));
                    added.push((a, b));
                    if rng.below(8) == 0 {
                        added.push((a, b));
                        removed.push((a, b));
                    }
                }
            }
        }
        for k in &removed {
            model.remove(k);
        }
        for &k in &added {
            model.entry(k).or_insert(false);
        }
        np.step(&added, &removed, none).unwrap();
        check(&np, &model);
        // Mark some pairs so a record moved to the wrong place would show.
        for p in np.pairs_mut() {
            if rng.below(2) == 0 {
                p.sensor = !p.sensor;
                model.insert((p.a, p.b), p.sensor);
            }
        }
    }
}

#[test]
fn pair_changes_match_an_ordered_map() {
    for seed in 1..40u64 {
        run(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15), 12, 60, 10);
        run(seed.wrapping_mul(0x2545_F491_4F6C_DD1D), 60, 40, 80);
    }
}

#[test]
fn pair_changes_single_and_empty() {
    let mut np: NarrowPhase<u32> = NarrowPhase::new(Dispatcher::default());
    let none = |_: u32| -> Option<NarrowObject<'static>> { None };
    np.step(&[], &[], none).unwrap();
    assert_eq!(np.pairs().count(), 0);
    np.step(&[(1, 2)], &[(1, 2)], none).unwrap();
    assert_eq!(np.pairs().count(), 1);
    np.step(&[(0, 1), (3, 4)], &[(1, 2)], none).unwrap();
    let keys: Vec<_> = np.pairs().map(|p| (p.a, p.b)).collect();
    assert_eq!(keys, vec![(0, 1), (3, 4)]);
    np.step(&[], &[(0, 1), (3, 4)], none).unwrap();
    assert_eq!(np.pairs().count(), 0);
}
