//! Ray and shape casts through the World against the brute force over every body with
//! `query::raycast` / `query::shape_cast`: random rays (hit rate guarded), rays grazing faces,
//! starting inside bodies, infinite length, far from the origin, masks, teleported bodies.
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::query::{raycast, shape_cast};
use carom_dynamics::collision::shape::{Capsule, Shape};
use carom_dynamics::*;
use pipeline::*;
use std::sync::Arc;

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> Real {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        ((self.0 >> 11) as f64 / (1u64 << 53) as f64) as Real
    }
    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.next()
    }
}

fn scene(offset: Vec3, rng: &mut Lcg) -> (World, Vec<BodyHandle>) {
    let mut w = world(false);
    let mut hs = vec![w
        .add_body(&BodyDesc::fixed(
            cuboid(Vec3::new(20.0, 0.5, 20.0)),
            Isometry::from_translation(offset - Vec3::Y * 0.5),
        ))
        .unwrap()];
    let capsule: Arc<Shape> = Arc::new(Capsule::new(0.2, 0.4).unwrap().into());
    for i in 0..60 {
        let shape = match i % 3 {
            0 => sphere(rng.range(0.1, 0.6)),
            1 => cuboid(Vec3::new(rng.range(0.1, 0.6), rng.range(0.1, 0.6), 0.3)),
            _ => capsule.clone(),
        };
        let p = offset
            + Vec3::new(
                rng.range(-8.0, 8.0),
                rng.range(0.5, 6.0),
                rng.range(-8.0, 8.0),
            );
        let q =
            Quat::from_rotation_y(rng.range(0.0, 6.0)) * Quat::from_rotation_x(rng.range(0.0, 3.0));
        let mut d = BodyDesc::dynamic(shape, Isometry::new(p, q), 500.0);
        d.filter.group = if i % 4 == 0 { 2 } else { 1 };
        hs.push(w.add_body(&d).unwrap());
    }
    // Remove a few so the slots have holes.
    for &h in &[hs[5], hs[17]] {
        w.remove_body(h).unwrap();
    }
    hs.retain(|&h| w.bodies().contains(h));
    (w, hs)
}

/// Closest hit over every body (ties to the lower slot), and the second-best distance.
fn brute_ray(
    w: &World,
    hs: &[BodyHandle],
    o: Vec3,
    d: Vec3,
    max: Real,
    mask: u32,
) -> (Option<(BodyHandle, Real)>, Real) {
    let mut hits: Vec<(Real, u32, BodyHandle)> = Vec::new();
    for &h in hs {
        let obj = w.object(h).unwrap().unwrap();
        let co = w.collision().get(obj).unwrap();
        if co.filter.group & mask == 0 {
            continue;
        }
        let pose = w.bodies().pose(h).unwrap();
        if let Some(hit) = raycast(&co.shape, &pose, o, d, max, true).unwrap() {
            hits.push((hit.distance, h.index, h));
        }
    }
    hits.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
    let second = hits.get(1).map_or(Real::INFINITY, |x| x.0);
    (hits.first().map(|x| (x.2, x.0)), second)
}

fn check_rays(offset: Vec3) {
    let mut rng = Lcg(7);
    let (mut w, hs) = scene(offset, &mut rng);
    // Teleport one body: queries follow the bodies' current poses.
    w.set_pose(
        hs[3],
        Isometry::from_translation(offset + Vec3::new(0.0, 3.0, 0.0)),
    )
    .unwrap();
    let mut origins = Vec::new();
    let mut dirs = Vec::new();
    for _ in 0..400 {
        origins.push(offset + Vec3::new(rng.range(-10.0, 10.0), rng.range(0.2, 8.0), -12.0));
        dirs.push(Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.4, 0.1), 1.0));
    }
    // Rays starting inside a body, and grazing the ground's top face.
    origins.push(offset + Vec3::new(0.0, 3.0, 0.0));
    dirs.push(Vec3::X);
    origins.push(offset + Vec3::new(-30.0, 0.0, 0.0));
    dirs.push(Vec3::X);
    for (max, mask) in [(30.0, u32::MAX), (Real::INFINITY, u32::MAX), (30.0, 2)] {
        let batch = w.raycast_batch(&origins, &dirs, max, mask).unwrap();
        let mut hits = 0;
        for (i, got) in batch.iter().enumerate() {
            let d = dirs[i].normalize();
            let (want, second) = brute_ray(&w, &hs, origins[i], d, max, mask);
            match (got, want) {
                (None, None) => {}
                (Some(g), Some((b, dist))) => {
                    hits += 1;
                    let tol = 1e-4 * (1.0 + offset.length());
                    assert!(
                        (g.hit.distance - dist).abs() <= tol,
                        "ray {i}: {} vs {dist}",
                        g.hit.distance
                    );
                    if second - dist > tol {
                        assert_eq!(g.body, b, "ray {i}");
                    }
                    let p = origins[i] + d * g.hit.distance;
                    assert!((g.hit.point - p).length() <= 10.0 * tol, "ray {i}: point");
                    assert!((g.hit.normal.length() - 1.0).abs() < 1e-3);
                }
                (g, w) => panic!("ray {i} (max {max}, mask {mask}): {g:?} vs brute force {w:?}"),
            }
            let single = w.raycast(origins[i], dirs[i], max, mask).unwrap();
            assert_eq!(single, *got, "single and batch differ on ray {i}");
        }
        // Both hits and misses occur (the mask keeps a quarter of the bodies).
        let rate = hits as Real / batch.len() as Real;
        assert!(
            hits >= 8 && rate < 0.9,
            "hit rate {rate} (max {max}, mask {mask})"
        );
    }
    let inside = w
        .raycast(offset + Vec3::new(0.0, 3.0, 0.0), Vec3::X, 5.0, u32::MAX)
        .unwrap()
        .unwrap();
    assert_eq!(inside.body, hs[3]);
    assert_eq!(inside.hit.distance, 0.0);
}

#[test]
fn rays_through_the_world_equal_the_brute_force() {
    check_rays(Vec3::ZERO);
}

#[test]
fn rays_far_from_the_origin_equal_the_brute_force() {
    check_rays(Vec3::new(1000.0, -500.0, 2000.0));
}

#[test]
fn shape_casts_through_the_world_equal_the_brute_force() {
    let mut rng = Lcg(11);
    let (w, hs) = scene(Vec3::ZERO, &mut rng);
    let probe = sphere(0.25);
    let boxy = cuboid(Vec3::new(0.3, 0.2, 0.1));
    let mut hits = 0;
    for k in 0..150 {
        let shape = if k % 2 == 0 { &probe } else { &boxy };
        let pose = Isometry::new(
            Vec3::new(rng.range(-9.0, 9.0), rng.range(0.5, 7.0), -11.0),
            Quat::from_rotation_z(rng.range(0.0, 3.0)),
        );
        let vel = Vec3::new(rng.range(-2.0, 2.0), rng.range(-3.0, 1.0), 20.0);
        let got = w.shape_cast(shape, &pose, vel, 1.0, u32::MAX).unwrap();
        let mut best: Option<(Real, BodyHandle)> = None;
        for &h in &hs {
            let obj = w.object(h).unwrap().unwrap();
            let other = &w.collision().get(obj).unwrap().shape;
            let pb = w.bodies().pose(h).unwrap();
            if let Some(hit) = shape_cast(shape, &pose, vel, other, &pb, Vec3::ZERO, 1.0).unwrap() {
                if best.is_none_or(|b| hit.toi < b.0) {
                    best = Some((hit.toi, h));
                }
            }
        }
        match (got, best) {
            (None, None) => {}
            (Some(g), Some((toi, _))) => {
                hits += 1;
                assert!(
                    (g.hit.toi - toi).abs() < 1e-4,
                    "cast {k}: {} vs {toi}",
                    g.hit.toi
                );
            }
            (g, b) => panic!("cast {k}: {g:?} vs brute force {b:?}"),
        }
    }
    assert!((20..140).contains(&hits), "{hits} hits of 150");
    // Starting in contact with the ground: time of impact 0.
    let on_ground = Isometry::from_translation(Vec3::new(15.0, 0.25, 15.0));
    let hit = w
        .shape_cast(&probe, &on_ground, Vec3::Y, 1.0, u32::MAX)
        .unwrap()
        .unwrap();
    assert_eq!(hit.body, hs[0]);
    assert!(hit.hit.toi <= 1e-4);
}

#[test]
fn queries_reject_bad_input_and_handle_an_empty_world() {
    let w = world(false);
    assert!(w
        .raycast(Vec3::ZERO, Vec3::X, 10.0, u32::MAX)
        .unwrap()
        .is_none());
    assert!(w
        .shape_cast(&sphere(1.0), &Isometry::IDENTITY, Vec3::X, 1.0, u32::MAX)
        .unwrap()
        .is_none());
    let e = w
        .raycast(Vec3::ZERO, Vec3::ZERO, 10.0, u32::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains("direction"), "{e}");
    let e = w
        .raycast(Vec3::ZERO, Vec3::X, -1.0, u32::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains("max_distance"), "{e}");
    let e = w
        .raycast(Vec3::splat(Real::NAN), Vec3::X, 1.0, u32::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains("origin"), "{e}");
    let e = w
        .raycast_batch(
            &[Vec3::ZERO, Vec3::ZERO],
            &[Vec3::X, Vec3::ZERO],
            1.0,
            u32::MAX,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("ray 1"), "{e}");
    let e = w
        .raycast_batch(&[Vec3::ZERO; 3], &[Vec3::X; 2], 1.0, u32::MAX)
        .unwrap_err()
        .to_string();
    assert!(e.contains("directions"), "{e}");
    let e = w
        .shape_cast(
            &sphere(1.0),
            &Isometry::IDENTITY,
            Vec3::splat(Real::NAN),
            1.0,
            u32::MAX,
        )
        .unwrap_err()
        .to_string();
    assert!(e.contains("velocity"), "{e}");
}

/// `n` rays from the plane z = -12 across the scene (origins, directions).
fn rays_across(rng: &mut Lcg, n: usize) -> (Vec<Vec3>, Vec<Vec3>) {
    (0..n)
        .map(|_| {
            let o = Vec3::new(rng.range(-10.0, 10.0), rng.range(0.2, 8.0), -12.0);
            (
                o,
                Vec3::new(rng.range(-0.3, 0.3), rng.range(-0.4, 0.1), 1.0),
            )
        })
        .unzip()
}

/// The batch's answers from `w` (with its kept tree) and from a clone (which starts without
/// one), up to 40 m.
fn cached_and_fresh(
    w: &World,
    origins: &[Vec3],
    dirs: &[Vec3],
) -> (Vec<Option<BodyRayHit>>, Vec<Option<BodyRayHit>>) {
    let cast = |w: &World| w.raycast_batch(origins, dirs, 40.0, u32::MAX).unwrap();
    (cast(w), cast(&w.clone()))
}

#[test]
fn cached_query_trees_answer_like_fresh_ones() {
    // The world keeps its query tree between calls: reused when no box changed, refitted
    // when boxes moved, rebuilt when its node area has grown or when the bodies change. A
    // clone starts without a cache and builds afresh; over 24 steps of falling bodies, with
    // a body removed and one added on the way, both answer every ray and shape cast
    // identically, and the hits match the brute force.
    let mut rng = Lcg(3);
    let (mut w, mut hs) = scene(Vec3::ZERO, &mut rng);
    let (origins, dirs) = rays_across(&mut rng, 200);
    let probe = sphere(0.3);
    let mut hits = 0;
    for step in 0..24 {
        if step == 7 {
            w.remove_body(hs[10]).unwrap();
            hs.remove(10);
        }
        if step == 12 {
            let d = BodyDesc::dynamic(
                sphere(0.5),
                Isometry::from_translation(Vec3::new(0.5, 3.0, 0.5)),
                500.0,
            );
            hs.push(w.add_body(&d).unwrap());
        }
        let (cached, fresh) = cached_and_fresh(&w, &origins, &dirs);
        let again = w.raycast_batch(&origins, &dirs, 40.0, u32::MAX).unwrap();
        assert_eq!(cached, fresh, "step {step}: cached and fresh trees differ");
        assert_eq!(again, cached, "step {step}: a reused tree differs");
        for (i, got) in cached.iter().enumerate() {
            let (want, _) = brute_ray(&w, &hs, origins[i], dirs[i].normalize(), 40.0, u32::MAX);
            assert_eq!(got.map(|g| g.body).is_some(), want.is_some(), "ray {i}");
            if let (Some(g), Some((_, dist))) = (got, want) {
                hits += 1;
                assert!((g.hit.distance - dist).abs() <= 1e-4, "ray {i}");
            }
        }
        let pose = Isometry::from_translation(Vec3::new(rng.range(-6.0, 6.0), 4.0, -11.0));
        let vel = Vec3::new(0.0, -1.0, 20.0);
        let a = w.shape_cast(&probe, &pose, vel, 1.0, u32::MAX).unwrap();
        let b = w
            .clone()
            .shape_cast(&probe, &pose, vel, 1.0, u32::MAX)
            .unwrap();
        assert_eq!(a, b, "step {step}: shape cast");
        w.step(1.0 / 60.0).unwrap();
    }
    assert!(hits > 24 * 10, "{hits} hits");
}

#[test]
fn queries_after_steps_and_moves_answer_like_fresh_ones() {
    // The step refreshes a query tree used since the last step, and a query then takes it
    // as it is; a teleport (through the world or its body set), an added or a removed body,
    // or a step taken without a query in between make the next query compute the tree
    // again. Over 300 random operations, every query answers as a clone of the world (which
    // starts without a cache) does, and the step reports the refresh's time only when a
    // query used the tree since the step before.
    let mut rng = Lcg(29);
    let (mut w, mut hs) = scene(Vec3::ZERO, &mut rng);
    let (origins, dirs) = rays_across(&mut rng, 60);
    let (mut queried, mut refreshed, mut idle) = (false, 0, 0);
    let mut ops = [0usize; 6];
    for round in 0..300 {
        let op = (rng.next() * 6.0) as usize;
        ops[op] += 1;
        let pick = |rng: &mut Lcg, hs: &[BodyHandle]| {
            hs[1 + (rng.next() * (hs.len() - 1) as Real) as usize]
        };
        let far = Isometry::from_translation(Vec3::new(
            rng.range(-8.0, 8.0),
            rng.range(0.5, 5.0),
            rng.range(-8.0, 8.0),
        ));
        match op {
            0 | 1 => {
                w.step(1.0 / 60.0).unwrap();
                let t = w.last_report().timings.query_tree;
                if queried {
                    refreshed += 1;
                } else {
                    idle += 1;
                    assert_eq!(t, std::time::Duration::ZERO, "round {round}");
                }
                queried = false;
            }
            2 => {
                let h = pick(&mut rng, &hs);
                w.set_pose(h, far).unwrap();
            }
            3 => {
                let h = pick(&mut rng, &hs);
                w.bodies_mut().set_pose(h, far).unwrap();
            }
            4 if hs.len() > 20 => {
                let h = pick(&mut rng, &hs);
                w.remove_body(h).unwrap();
                hs.retain(|&x| x != h);
            }
            _ => {
                hs.push(
                    w.add_body(&BodyDesc::dynamic(sphere(0.4), far, 500.0))
                        .unwrap(),
                );
            }
        }
        if rng.next() < 0.6 {
            let (cached, fresh) = cached_and_fresh(&w, &origins, &dirs);
            assert_eq!(cached, fresh, "round {round} (operation {op})");
            queried = true;
        }
    }
    assert!(
        refreshed > 40 && idle > 20,
        "{refreshed} refreshed, {idle} idle steps"
    );
    assert!(ops.iter().all(|&n| n > 20), "{ops:?}");
}

/// Session 27's sweep: after a body slot is reused, an exact tie of two identical boxes went
/// to the later collision object in shape casts, while rays took the lower body slot; and a
/// plane body made every shape cast fail (plane casts were unsupported).
#[test]
fn shape_cast_ties_go_to_the_lower_slot_and_planes_are_cast_against() {
    let mut w = world(false);
    let cube = cuboid(Vec3::ONE);
    let a = w
        .add_body(&BodyDesc::fixed(cube.clone(), Isometry::IDENTITY))
        .unwrap();
    let b = w
        .add_body(&BodyDesc::fixed(cube.clone(), Isometry::IDENTITY))
        .unwrap();
    w.remove_body(a).unwrap();
    let d = w
        .add_body(&BodyDesc::fixed(cube, Isometry::IDENTITY))
        .unwrap();
    assert!(d.index < b.index, "the freed slot is reused");
    w.step(1.0 / 60.0).unwrap();
    let ray = w
        .raycast(Vec3::new(-5.0, 0.0, 0.0), Vec3::X, 100.0, u32::MAX)
        .unwrap()
        .unwrap();
    let ball = sphere(0.5);
    let from = Isometry::from_translation(Vec3::new(-5.0, 0.0, 0.0));
    let cast = w
        .shape_cast(&ball, &from, Vec3::X * 10.0, 1.0, u32::MAX)
        .unwrap()
        .unwrap();
    assert_eq!((ray.body, cast.body), (d, d));
    // A plane below everything: the cast sideways still hits the box; one downwards the plane.
    let plane: Arc<Shape> = Arc::new(
        carom_dynamics::collision::shape::Plane::new(Vec3::Y, -3.0)
            .unwrap()
            .into(),
    );
    let p = w
        .add_body(&BodyDesc::fixed(plane, Isometry::IDENTITY))
        .unwrap();
    w.step(1.0 / 60.0).unwrap();
    let cast = w
        .shape_cast(&ball, &from, Vec3::X * 10.0, 1.0, u32::MAX)
        .unwrap()
        .unwrap();
    assert_eq!(cast.body, d);
    let down = w
        .shape_cast(&ball, &from, Vec3::NEG_Y * 10.0, 1.0, u32::MAX)
        .unwrap()
        .unwrap();
    assert_eq!(down.body, p);
    assert!((down.hit.toi - 0.25).abs() < 1e-5, "{}", down.hit.toi);
}
