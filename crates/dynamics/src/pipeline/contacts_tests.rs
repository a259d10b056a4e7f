//! `gather_pairs` against the previous gather kept as the oracle (`gather_reference`), bit
//! for bit, on generated narrowphase pairs: empty and sensor manifolds, unknown objects,
//! stale and self handles, static and kinematic pairs, one to six points (more than a solver
//! manifold holds), ties for the deepest point, NaN and infinite values in every field,
//! signed zeros, values far from the origin, and non-unit normals.

use super::contacts::{gather_pairs, gather_pairs_chunked, gather_parallel, write_back_range};
use crate::body::{mix_friction, mix_restitution, BodyDesc, BodyType};
use crate::body_set::tests::real_bits;
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use carom_collision::math::{orthonormal_basis, Isometry, Real, Vec3};
use carom_collision::narrowphase::{ContactManifold as NarrowManifold, ContactPoint, PairContact};
use carom_collision::shape::{Cuboid, Shape};
use carom_collision::world::ObjectHandle;
use std::sync::Arc;

/// The normal on B of the deepest point (the first of equally deep ones).
fn deepest_normal(points: &[ContactPoint]) -> Vec3 {
    let mut deepest = &points[0];
    for p in &points[1..] {
        if p.distance < deepest.distance {
            deepest = p;
        }
    }
    deepest.normal
}

/// The gather before this round (two scans per manifold, `Σ 0·x`), verbatim but for its
/// arguments and the awake test (session 17): the oracle. A manifold without an awake
/// dynamic body is not handed on; its pair goes to `resting` as body slots when its normal
/// would have passed.
fn gather_reference<'p>(
    set: &BodySet,
    body_of: &[Option<BodyHandle>],
    pairs: impl Iterator<Item = &'p PairContact<ObjectHandle>>,
    (contacts, sources): (&mut Vec<ContactManifold>, &mut Vec<u32>),
    resting: &mut Vec<(usize, usize)>,
) -> bool {
    resting.clear();
    let body = |o: ObjectHandle| body_of.get(o.index as usize).copied().flatten();
    let mut k = 0;
    let mut zero: Real = 0.0;
    let mut ranges_ok = true;
    for (index, pc) in pairs.enumerate() {
        let points = &pc.manifold.points;
        if points.is_empty() || pc.sensor {
            continue;
        }
        let (Some(ba), Some(bb)) = (body(pc.a), body(pc.b)) else {
            continue;
        };
        let Ok(ia) = set.slot(ba) else {
            continue;
        };
        let Ok(ib) = set.slot(bb) else {
            continue;
        };
        let (info_a, info_b) = (&set.info[ia], &set.info[ib]);
        let dynamic = |t: BodyType| t == BodyType::Dynamic;
        if !(dynamic(info_a.body_type) || dynamic(info_b.body_type)) || ba == bb {
            continue;
        }
        let n_b = deepest_normal(points);
        if !n_b.is_finite() || (n_b.length_squared() - 1.0).abs() > 1e-3 {
            continue;
        }
        if !(set.is_awake_dynamic(ia) || set.is_awake_dynamic(ib)) {
            resting.push((ia, ib));
            continue;
        }
        let (t1, _) = orthonormal_basis(n_b);
        if k == contacts.len() {
            contacts.push(ContactManifold::new(ba, bb, -n_b));
            sources.push(0);
        }
        let m = &mut contacts[k];
        m.body_a = ba;
        m.body_b = bb;
        m.normal = -n_b;
        m.tangent = t1;
        m.friction = mix_friction(info_a.friction, info_b.friction);
        m.restitution = mix_restitution(info_a.restitution, info_b.restitution);
        zero += m.friction * 0.0;
        ranges_ok &= m.friction >= 0.0 && (0.0..=1.0).contains(&m.restitution);
        let mut len = 0;
        for (q, p) in m.points.iter_mut().zip(points) {
            q.local_a = p.local_a;
            q.local_b = p.local_b;
            q.separation = p.distance;
            q.feature_id = p.feature;
            q.normal_impulse = p.normal_impulse;
            q.tangent_impulse = [p.tangent_impulse[0], -p.tangent_impulse[1]];
            zero += (p.local_a * 0.0 + p.local_b * 0.0).element_sum()
                + (p.distance + p.normal_impulse + p.tangent_impulse[0] + p.tangent_impulse[1])
                    * 0.0;
            len += 1;
        }
        m.len = len;
        sources[k] = index as u32;
        k += 1;
    }
    contacts.truncate(k);
    sources.truncate(k);
    zero == 0.0 && ranges_ok
}

/// Bits of everything the solver reads from a manifold (the points up to `len`; every NaN
/// as one, see `real_bits`).
fn bits(m: &ContactManifold) -> Vec<u64> {
    let mut out = vec![
        m.body_a.index as u64,
        m.body_a.generation as u64,
        m.body_b.index as u64,
        m.body_b.generation as u64,
        m.len as u64,
    ];
    let mut reals = vec![m.friction, m.restitution];
    reals.extend(m.normal.to_array());
    reals.extend(m.tangent.to_array());
    for p in m.points() {
        reals.extend(p.local_a.to_array());
        reals.extend(p.local_b.to_array());
        reals.extend([p.separation, p.normal_impulse]);
        reals.extend(p.tangent_impulse);
        out.push(p.feature_id as u64);
    }
    out.extend(reals.iter().map(|&x| real_bits(x)));
    out
}

struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
    /// A value: mostly ordinary, sometimes a special one.
    fn real(&mut self) -> Real {
        let unit = (self.next() >> 11) as Real / (1u64 << 53) as Real * 2.0 - 1.0;
        match self.below(40) {
            0 => Real::NAN,
            1 => Real::INFINITY,
            2 => Real::NEG_INFINITY,
            3 => -0.0,
            4 => 0.0,
            5 => unit * 1.0e6,
            6 => unit * 1.0e30,
            _ => unit,
        }
    }
    fn vec(&mut self) -> Vec3 {
        Vec3::new(self.real(), self.real(), self.real())
    }
    fn normal(&mut self) -> Vec3 {
        match self.below(30) {
            0 => Vec3::new(Real::NAN, 0.0, 1.0),
            1 => Vec3::new(0.0, 2.0, 0.0),
            2 => Vec3::new(0.0, 0.0, -1.0),
            3 => Vec3::new(-0.0, 1.0, -0.0),
            _ => {
                let v = Vec3::new(self.real(), self.real(), self.real());
                if v.is_finite() && v.length() > 1e-3 {
                    v.normalize()
                } else {
                    Vec3::Y
                }
            }
        }
    }
}

#[test]
fn gather_pairs_is_the_reference_bit_for_bit() {
    let cube: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    let mut set = BodySet::new();
    let mut rng = Rng(0x1234_5678_9abc_def1);
    let mut handles = Vec::new();
    for i in 0..12 {
        let pose = Isometry::IDENTITY;
        let mut desc = match i % 4 {
            0 => BodyDesc::fixed(cube.clone(), pose),
            1 => {
                let mut d = BodyDesc::fixed(cube.clone(), pose);
                d.body_type = BodyType::Kinematic;
                d
            }
            _ => BodyDesc::dynamic(cube.clone(), pose, 1000.0),
        };
        desc.friction = [0.0, 0.3, 0.5, 1.7][i % 4];
        desc.restitution = [0.0, 0.2, 1.0, 0.5][i / 3 % 4];
        handles.push(set.insert(&desc).unwrap());
    }
    // Bodies whose friction or restitution are out of range (set behind validation), and a
    // removed body (its handle stale).
    set.info[handles[2].index as usize].friction = -1.0;
    set.info[handles[3].index as usize].restitution = Real::NAN;
    set.info[handles[6].index as usize].friction = Real::INFINITY;
    set.remove(handles[10]).unwrap();
    // Sleeping dynamic bodies: their pairs with sleeping, static or kinematic bodies are not
    // handed on (only to the islands), those with an awake dynamic body are.
    for i in [5, 7, 11] {
        set.info[handles[i].index as usize].sleeping = true;
    }
    let body_of: Vec<Option<BodyHandle>> = (0..14)
        .map(|i| {
            if i == 13 {
                None
            } else {
                handles.get(i).copied()
            }
        })
        .collect();
    let (mut fast, mut fast_src) = (Vec::new(), Vec::new());
    let (mut slow, mut slow_src) = (Vec::new(), Vec::new());
    let (mut trues, mut falses, mut handed, mut parallel) = (0, 0, 0, 0);
    let (mut chunked, mut chunked_src, mut counts) = (Vec::new(), Vec::new(), Vec::new());
    let (mut fast_resting, mut slow_resting, mut resting_seen) = (Vec::new(), Vec::new(), 0);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(3)
        .build()
        .unwrap();
    for round in 0..400 {
        let mut pairs = Vec::new();
        for _ in 0..rng.below(24) {
            let object = |rng: &mut Rng| ObjectHandle {
                index: rng.below(15) as u32,
                generation: 0,
            };
            let (a, b) = (object(&mut rng), object(&mut rng));
            let n_points = match rng.below(10) {
                0 => 0,
                1 => 6,
                2 => 5,
                k => (k % 4 + 1) as usize,
            };
            let shared_normal = rng.normal();
            // Mostly sane values (so that many rounds are certainly valid), special ones in
            // some rounds.
            let wild = round % 3 == 0;
            let value = |rng: &mut Rng| {
                if wild {
                    rng.real()
                } else {
                    rng.real().clamp(-2.0, 2.0)
                }
            };
            let points = (0..n_points)
                .map(|k| {
                    let distance = if rng.below(4) == 0 {
                        -0.25
                    } else {
                        value(&mut rng)
                    };
                    ContactPoint {
                        distance: if distance.is_nan() && !wild {
                            0.0
                        } else {
                            distance
                        },
                        normal: if rng.below(3) == 0 {
                            rng.normal()
                        } else {
                            shared_normal
                        },
                        point_b: rng.vec(),
                        local_a: Vec3::new(value(&mut rng), value(&mut rng), value(&mut rng)),
                        local_b: Vec3::new(value(&mut rng), value(&mut rng), value(&mut rng)),
                        local_normal_b: rng.vec(),
                        feature: rng.next() as u32 ^ k as u32,
                        normal_impulse: value(&mut rng),
                        tangent_impulse: [value(&mut rng), value(&mut rng)],
                        lifetime: 0,
                    }
                })
                .collect();
            pairs.push(PairContact {
                a,
                b,
                manifold: NarrowManifold {
                    points,
                    ..Default::default()
                },
                touching: true,
                sensor: rng.below(12) == 0,
                excluded: false,
            });
        }
        fast_resting.clear();
        let ok_fast = gather_pairs(
            &set,
            &body_of,
            pairs.iter(),
            (&mut fast, &mut fast_src),
            Some(&mut fast_resting),
        );
        let ok_slow = gather_reference(
            &set,
            &body_of,
            pairs.iter(),
            (&mut slow, &mut slow_src),
            &mut slow_resting,
        );
        assert_eq!(fast_resting, slow_resting, "round {round}");
        resting_seen += slow_resting.len();
        // Without a list, the same manifolds.
        let (mut plain, mut plain_src) = (Vec::new(), Vec::new());
        let ok_plain = gather_pairs(
            &set,
            &body_of,
            pairs.iter(),
            (&mut plain, &mut plain_src),
            None,
        );
        assert_eq!(
            (ok_plain, &plain_src),
            (ok_fast, &fast_src),
            "round {round}"
        );
        assert_eq!(fast_src, slow_src, "round {round}");
        assert_eq!(fast.len(), slow.len(), "round {round}");
        for (k, (f, s)) in fast.iter().zip(&slow).enumerate() {
            assert_eq!(
                bits(f),
                bits(s),
                "round {round}, manifold {k}: {f:?} vs {s:?}"
            );
        }
        // The flag: the same unless a sum of finite values overflowed (the values here stay
        // below 10³⁰ times four terms, far from it).
        assert_eq!(ok_fast, ok_slow, "round {round}");
        // The chunked gather (parallel passes, or the serial pass it falls back to) hands on
        // the same manifolds, for chunks of one pair up.
        for chunk in [1, 2, 5] {
            let ok = pool.install(|| {
                let (c, s) = (&mut chunked, &mut chunked_src);
                if gather_parallel(&set, &body_of, &pairs, (c, s), None, &mut counts, chunk)
                    .is_some()
                {
                    parallel += 1;
                }
                // The edges are appended after what the vector held (also when a dropped
                // normal sends the gather to the serial pass after the parallel ones).
                let mut resting = vec![(99, 99)];
                let ok = gather_pairs_chunked(
                    &set,
                    &body_of,
                    &pairs,
                    (c, s),
                    Some(&mut resting),
                    &mut counts,
                    chunk,
                );
                assert_eq!(resting[0], (99, 99), "round {round}, chunk {chunk}");
                assert_eq!(resting[1..], slow_resting, "round {round}, chunk {chunk}");
                ok
            });
            assert_eq!(chunked_src, fast_src, "round {round}, chunk {chunk}");
            assert_eq!(chunked.len(), fast.len(), "round {round}, chunk {chunk}");
            for (f, c) in fast.iter().zip(&chunked) {
                assert_eq!(bits(f), bits(c), "round {round}, chunk {chunk}");
            }
            assert_eq!(ok, ok_fast, "round {round}, chunk {chunk}");
        }
        // The write-back in halves stores every manifold's impulses into its own pair, as
        // an indexed loop does (the second friction impulse negated).
        for (k, m) in fast.iter_mut().enumerate() {
            for (i, p) in m.points.iter_mut().enumerate() {
                p.normal_impulse = (round * 100 + k * 10 + i) as Real;
                p.tangent_impulse = [rng.real(), -0.0];
            }
        }
        let mut expected = pairs.clone();
        for (m, &src) in fast.iter().zip(&fast_src) {
            let points = &mut expected[src as usize].manifold.points;
            for (p, q) in points.iter_mut().zip(&m.points[..m.len]) {
                p.normal_impulse = q.normal_impulse;
                p.tangent_impulse = [q.tangent_impulse[0], -q.tangent_impulse[1]];
            }
        }
        for chunk in [1, 3, 64] {
            let mut written = pairs.clone();
            pool.install(|| write_back_range(&fast, &fast_src, &mut written, 0, chunk));
            for (w, e) in written.iter().zip(&expected) {
                let imp = |p: &PairContact<ObjectHandle>| {
                    p.manifold
                        .points
                        .iter()
                        .flat_map(|q| {
                            [q.normal_impulse, q.tangent_impulse[0], q.tangent_impulse[1]]
                        })
                        .map(real_bits)
                        .collect::<Vec<_>>()
                };
                assert_eq!(imp(w), imp(e), "round {round}, chunk {chunk}");
            }
        }
        if ok_fast {
            trues += 1;
        } else {
            falses += 1;
        }
        handed += fast.len();
    }
    // The generator reaches both answers and hands manifolds on; the parallel passes run
    // when the build has them (without the `parallel` feature the chunked gather is the
    // serial pass, checked above all the same).
    let parallel_ok = if cfg!(feature = "parallel") {
        parallel > 300
    } else {
        parallel == 0
    };
    assert!(
        trues > 50 && falses > 50 && handed > 600 && parallel_ok && resting_seen > 100,
        "{trues} {falses} {handed} {parallel} {resting_seen}"
    );
}
