//! The wide build (`contact_simd_prep`, four lanes at once) against its oracle, the
//! scalar route ([`ViaScalar`]: prepare a [`ContactConstraint`], copy it into
//! its lane): every field of every lane, bit for bit.

use super::{build_range, ViaScalar, WideConstraint, LANES, NONE};
use crate::body::{BodyDesc, BodyType};
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::{ContactManifold, ContactPoint};
use crate::integrate;
use crate::solver::contact::{self, ContactScratch, Preparer};
use crate::solver::contact_simd::{build_range_wide_on, Isa};
use crate::solver::{Softness, SolverBody};
use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Cuboid, Shape};
use std::sync::Arc;

/// A small deterministic generator (xorshift).
struct Rng(u64);

impl Rng {
    fn unit(&mut self) -> Real {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 40) as Real / (1u64 << 24) as Real
    }

    fn range(&mut self, lo: Real, hi: Real) -> Real {
        lo + (hi - lo) * self.unit()
    }

    fn vec(&mut self, s: Real) -> Vec3 {
        Vec3::new(self.range(-s, s), self.range(-s, s), self.range(-s, s))
    }
}

/// Bodies around `origin` (a static, a kinematic and `n` dynamic ones, moving and
/// spinning) and manifolds between random pairs, with the degenerate cases: all points at
/// one place (zero size), touching (separation 0), a cached tangent parallel to the normal,
/// zero and axis-aligned normals' tangents, one to four points.
fn scene(rng: &mut Rng, n: usize, origin: Vec3) -> (BodySet, Vec<ContactManifold>) {
    let mut set = BodySet::new();
    let unit: Arc<Shape> = Arc::new(Cuboid::new(Vec3::splat(0.5)).unwrap().into());
    let pose = |rng: &mut Rng| {
        let q = Quat::from_axis_angle(rng.vec(1.0).normalize(), rng.range(-3.0, 3.0));
        Isometry::new(origin + rng.vec(5.0), q)
    };
    let mut handles: Vec<BodyHandle> = Vec::new();
    handles.push(
        set.insert(&BodyDesc::fixed(unit.clone(), pose(rng)))
            .unwrap(),
    );
    let kinematic = BodyDesc {
        body_type: BodyType::Kinematic,
        linear_velocity: rng.vec(1.0),
        ..BodyDesc::dynamic(unit.clone(), pose(rng), 1.0)
    };
    handles.push(set.insert(&kinematic).unwrap());
    for _ in 0..n {
        let desc = BodyDesc {
            linear_velocity: rng.vec(2.0),
            angular_velocity: rng.vec(3.0),
            ..BodyDesc::dynamic(unit.clone(), pose(rng), rng.range(100.0, 2000.0))
        };
        handles.push(set.insert(&desc).unwrap());
    }
    let mut manifolds = Vec::new();
    for i in 0..4 * n {
        let a = handles[(rng.unit() * handles.len() as Real) as usize % handles.len()];
        let mut b = handles[2 + i % n];
        if a == b {
            b = handles[2 + (i + 1) % n];
        }
        let normal = match i % 5 {
            0 => Vec3::Y,
            1 => -Vec3::Z,
            _ => rng.vec(1.0).normalize(),
        };
        let mut m = ContactManifold::new(a, b, normal);
        m.friction = rng.range(0.0, 1.0);
        m.restitution = if i % 3 == 0 { rng.range(0.0, 1.0) } else { 0.0 };
        m.tangent = match i % 4 {
            0 => Vec3::ZERO,
            1 => normal,
            2 => rng.vec(1.0).normalize(),
            _ => Vec3::X,
        };
        let zero_size = i % 7 == 0;
        let first = rng.vec(0.5);
        for k in 0..1 + i % 4 {
            let at = if zero_size { first } else { rng.vec(0.5) };
            let separation = if i % 6 == 0 {
                0.0
            } else {
                rng.range(-0.05, 0.05)
            };
            let mut p = ContactPoint::new(at, at + rng.vec(0.01), separation, k as u32);
            p.normal_impulse = rng.range(0.0, 5.0);
            p.tangent_impulse = [rng.range(-1.0, 1.0), rng.range(-1.0, 1.0)];
            m.push(p).unwrap();
        }
        manifolds.push(m);
    }
    (set, manifolds)
}

/// Builds the wide constraints of `manifolds` by both routes into `direct` (the wide
/// build on `isa`) and `oracle` (lane by lane through scalar constraints), which keep what
/// they held before (the build overwrites in place). The lanes are the colouring's, or
/// `members` if given (any positions of the colour order, `NONE` anywhere).
fn build_both(
    set: &BodySet,
    manifolds: &[ContactManifold],
    bodies: &mut Vec<SolverBody>,
    isa: Isa,
    members: Option<&mut dyn FnMut(usize) -> Vec<[usize; LANES]>>,
    direct: &mut Vec<WideConstraint>,
    oracle: &mut Vec<WideConstraint>,
) {
    integrate::load(set, bodies);
    let mut scratch = ContactScratch::default();
    let soft = (
        Softness::new(30.0, 10.0, 1.0 / 240.0),
        Softness::new(60.0, 10.0, 1.0 / 240.0),
    );
    contact::prepare(
        manifolds,
        set,
        bodies,
        0.5,
        soft.0,
        soft.1,
        true,
        &mut scratch,
    );
    let p = Preparer {
        manifolds,
        selected: scratch.selected(),
        order: &scratch.colouring.order,
        set,
        bodies,
        impulse_in: 0.5,
        soft,
    };
    let members = match members {
        Some(f) => f(scratch.colouring.order.len()),
        None => scratch.wide.members.clone(),
    };
    assert!(!members.is_empty());
    for ws in [&mut *direct, &mut *oracle] {
        if ws.len() < members.len() {
            ws.resize_with(members.len(), WideConstraint::empty);
        }
    }
    let n = members.len();
    build_range_wide_on(isa, &mut direct[..n], &members, &p);
    let make = |k: usize, c: &mut contact::ContactConstraint, rows: bool| p.make(k, c, rows);
    build_range(&mut oracle[..n], &members, bodies, &ViaScalar(make));
}

/// Every field of every lane (stale points beyond `len` included) of `direct` equals
/// `oracle`'s.
fn same(direct: &[WideConstraint], oracle: &[WideConstraint], what: &str) {
    assert_eq!(direct.len(), oracle.len());
    for (i, (d, o)) in direct.iter().zip(oracle).enumerate() {
        // Debug prints each float's shortest round-trip form, signed zeros included.
        assert_eq!(
            format!("{d:?}"),
            format!("{o:?}"),
            "{what}: wide constraint {i}"
        );
    }
}

#[test]
fn wide_build_equals_the_scalar_route_bit_for_bit() {
    let mut rng = Rng(0x9e37_79b9_7f4a_7c15);
    let (mut bodies, mut direct, mut oracle) = (Vec::new(), Vec::new(), Vec::new());
    // Near and far from the origin; the second and third builds overwrite the first's
    // constraints in place (stale lanes and points).
    for origin in [
        Vec3::ZERO,
        Vec3::new(1e4, -2e4, 5e3),
        Vec3::new(-3.0, 0.0, 7.0),
    ] {
        let (set, manifolds) = scene(&mut rng, 24, origin);
        let isa = Isa::detect();
        build_both(
            &set,
            &manifolds,
            &mut bodies,
            isa,
            None,
            &mut direct,
            &mut oracle,
        );
        same(&direct, &oracle, "colouring's lanes");
    }
}

/// The wide build on every instruction set the CPU has, with lanes drawn at random: padding
/// lanes anywhere (the first lane, all four), lanes of one to four points side by side,
/// static and kinematic bodies (zero inverse masses), near and far from the origin.
#[test]
fn every_instruction_set_builds_the_scalar_bits() {
    for isa in Isa::available() {
        let mut rng = Rng(0x2545_f491_4f6c_dd1d);
        let (mut bodies, mut direct, mut oracle) = (Vec::new(), Vec::new(), Vec::new());
        for origin in [Vec3::ZERO, Vec3::new(-4e3, 1e3, 3e4)] {
            let (set, manifolds) = scene(&mut rng, 16, origin);
            let mut pick = Rng(rng.0 ^ 0x5555);
            let mut members = |n: usize| {
                let mut ms: Vec<[usize; LANES]> = (0..3 * n)
                    .map(|i| {
                        std::array::from_fn(|l| {
                            let k = (pick.unit() * n as Real) as usize % n;
                            // Every fifth lane and the whole fourth group are padding.
                            if i % 4 == 3 && i % 8 == 3 || (i + l) % 5 == 0 {
                                NONE
                            } else {
                                k
                            }
                        })
                    })
                    .collect();
                ms.push([NONE; LANES]);
                ms
            };
            build_both(
                &set,
                &manifolds,
                &mut bodies,
                isa,
                Some(&mut members),
                &mut direct,
                &mut oracle,
            );
            same(&direct, &oracle, &format!("{isa:?}"));
            // The lanes did mix point counts and padding.
            let mixed = direct.iter().any(|w| {
                let lens = w.lens;
                lens.contains(&0) && lens.contains(&1) && lens.contains(&4)
            });
            assert!(mixed, "no group mixes padding, one and four points");
        }
    }
}
