//! Broadphase bad input (NaN, inverted boxes, stale handles), the one-call
//! `overlapping_pairs` under proptest with degenerate boxes, and identical results on 1 and 2
//! threads.

mod broadphase_common;

#[cfg(feature = "parallel")]
use broadphase_common::{moved_box, random_box, Rng, Scene};
use carom_collision::broadphase::{overlapping_pairs, AnyBroadPhase, BroadPhase, Filter, Method};
use carom_collision::math::{Aabb, Real, Vec3};
use carom_collision::CaromError;
use proptest::prelude::*;

#[test]
fn nan_inverted_and_stale_handles_are_errors() {
    for m in Method::ALL {
        let mut bp = AnyBroadPhase::new(m);
        let good = Aabb::new(Vec3::ZERO, Vec3::ONE);
        let nan = Aabb::new(Vec3::new(0.0, Real::NAN, 0.0), Vec3::ONE);
        let inf = Aabb::new(Vec3::ZERO, Vec3::new(Real::INFINITY, 1.0, 1.0));
        let inverted = Aabb::new(Vec3::ONE, Vec3::ZERO);
        for bad in [nan, inf, inverted] {
            assert!(matches!(
                bp.create_proxy(bad, Filter::default()),
                Err(CaromError::InvalidValue { .. })
            ));
        }
        let h = bp.create_proxy(good, Filter::default()).unwrap();
        let h2 = bp.create_proxy(good, Filter::default()).unwrap();
        assert!(bp.update_proxy(h, nan, Vec3::ZERO).is_err(), "{m:?}");
        assert!(bp.update_proxy(h, inverted, Vec3::ZERO).is_err(), "{m:?}");
        assert_eq!(bp.aabb(h).unwrap(), good, "rejected update leaves the box");
        bp.update_pairs();
        assert_eq!(bp.pairs(), vec![(h, h2)]);
        bp.remove_proxy(h).unwrap();
        assert!(
            matches!(bp.remove_proxy(h), Err(CaromError::UnknownHandle(_))),
            "{m:?}"
        );
        assert!(bp.update_proxy(h, good, Vec3::ZERO).is_err());
        assert!(bp.set_resting(h, true).is_err());
        assert!(bp.set_filter(h, Filter::default()).is_err());
        let ch = bp.update_pairs().clone();
        assert_eq!(
            ch.removed,
            vec![(h, h2)],
            "{m:?}: removed pair keeps the old handle"
        );
        // The slot is reused with a new generation: the old handle stays stale.
        let h3 = bp.create_proxy(good, Filter::default()).unwrap();
        assert_eq!(h3.index, h.index);
        assert_ne!(h3.generation, h.generation);
        assert!(bp.remove_proxy(h).is_err());
        let bogus = carom_collision::broadphase::ProxyHandle {
            index: 1000,
            generation: 0,
        };
        assert!(bp.remove_proxy(bogus).is_err());
        assert!(bp.aabb(bogus).is_err());
        bp.update_pairs();
        assert_eq!(
            bp.pairs(),
            vec![(h3, h2)]
                .into_iter()
                .map(|(a, b)| (a.min(b), a.max(b)))
                .collect::<Vec<_>>()
        );
    }
}

#[test]
fn overlapping_pairs_rejects_bad_arrays() {
    let mins = [[0.0, 0.0, 0.0], [1.0, 1.0, 1.0]];
    let maxs = [[1.0, 1.0, 1.0]];
    assert!(overlapping_pairs(&mins, &maxs, Method::Tree).is_err());
    let maxs = [[1.0, 1.0, 1.0], [0.5, 2.0, 2.0]];
    let err = overlapping_pairs(&mins, &maxs, Method::Sap).unwrap_err();
    assert!(err.to_string().contains("box[1]"), "{err}");
    assert!("octree".parse::<Method>().is_err());
    assert_eq!("sort_sweep".parse::<Method>().unwrap(), Method::SortSweep);
}

fn naive(mins: &[[Real; 3]], maxs: &[[Real; 3]]) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    for i in 0..mins.len() {
        for j in i + 1..mins.len() {
            if (0..3).all(|k| mins[i][k] <= maxs[j][k] && mins[j][k] <= maxs[i][k]) {
                out.push((i as u32, j as u32));
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(96))]
    /// Lattice boxes: many zero extents, shared faces, duplicates, far offsets.
    #[test]
    fn every_method_matches_naive_on_degenerate_boxes(
        raw in prop::collection::vec(((0i32..6, 0i32..6, 0i32..6), (0i32..3, 0i32..3, 0i32..3)), 0..60),
        far in prop::bool::ANY,
        scale in prop::sample::select(vec![1e-3 as Real, 1.0, 1e3]),
    ) {
        let off: Real = if far { 1.0e5 } else { 0.0 };
        let mins: Vec<[Real; 3]> = raw.iter().map(|((x, y, z), _)| {
            [*x as Real * scale + off, *y as Real * scale - off, *z as Real * scale]
        }).collect();
        let maxs: Vec<[Real; 3]> = raw.iter().zip(&mins).map(|((_, (a, b, c)), m)| {
            [m[0] + *a as Real * scale, m[1] + *b as Real * scale, m[2] + *c as Real * scale]
        }).collect();
        let expect = naive(&mins, &maxs);
        for m in Method::ALL {
            prop_assert_eq!(overlapping_pairs(&mins, &maxs, m).unwrap(), expect.clone(), "{:?}", m);
        }
    }
}

/// Runs a scene of motion for every method and returns the pairs and changes of each frame.
/// Per frame: the pairs, the number added, the number removed.
#[cfg(feature = "parallel")]
type Frames = Vec<(Vec<(u32, u32)>, usize, usize)>;

#[cfg(feature = "parallel")]
fn record(method: Method, n: usize, frames: usize) -> Frames {
    let mut rng = Rng(42);
    let mut bp = AnyBroadPhase::new(method);
    let mut hs = Vec::new();
    for _ in 0..n {
        hs.push(
            bp.create_proxy(random_box(&mut rng, Scene::Uniform), Filter::default())
                .unwrap(),
        );
    }
    let mut out = Vec::new();
    for _ in 0..frames {
        for &h in &hs {
            let b = bp.aabb(h).unwrap();
            let (nb, d) = moved_box(&mut rng, &b, Scene::Uniform);
            bp.update_proxy(h, nb, d).unwrap();
        }
        let ch = bp.update_pairs().clone();
        let pairs = bp
            .pairs()
            .into_iter()
            .map(|(a, b)| (a.index, b.index))
            .collect();
        out.push((pairs, ch.added.len(), ch.removed.len()));
    }
    out
}

#[cfg(feature = "parallel")]
#[test]
fn results_identical_on_one_and_two_threads() {
    let pool = |n| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .unwrap()
    };
    for m in Method::ALL {
        let n = if m == Method::BruteForce { 300 } else { 3000 };
        let one = pool(1).install(|| record(m, n, 3));
        let two = pool(2).install(|| record(m, n, 3));
        assert!(one.iter().all(|f| !f.0.is_empty()));
        assert_eq!(one, two, "{m:?}");
    }
    // Large enough for the parallel sort's merge and several sweep chunks.
    let mut rng = Rng(8);
    let mins: Vec<[Real; 3]> = (0..70_000)
        .map(|_| rng.vec(-200.0, 200.0).to_array())
        .collect();
    let maxs: Vec<[Real; 3]> = mins
        .iter()
        .map(|m| [m[0] + 1.0, m[1] + 1.0, m[2] + 1.0])
        .collect();
    let one = pool(1).install(|| overlapping_pairs(&mins, &maxs, Method::SortSweep).unwrap());
    let two = pool(2).install(|| overlapping_pairs(&mins, &maxs, Method::SortSweep).unwrap());
    assert!(one.len() > 100);
    assert_eq!(one, two);
    let grid = overlapping_pairs(&mins, &maxs, Method::Grid).unwrap();
    assert_eq!(one, grid, "sort-sweep vs grid on 70k boxes");
}
