//! Bad input is rejected with an error naming the value; stale handles never reach another
//! body; a removed body takes its joints with it.
mod common;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::shape::MassProperties;
use carom_dynamics::*;
use common::*;

fn err_names<T: std::fmt::Debug>(r: Result<T, carom_dynamics::collision::CaromError>, name: &str) {
    let e = r.unwrap_err().to_string();
    assert!(e.contains(name), "error {e:?} should name {name}");
}

#[test]
fn bad_bodies_are_rejected() {
    let mut w = DynamicsWorld::new(WorldParams::default()).unwrap();
    let s = sphere(0.5);
    let mut d = BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0);
    d.mass = MassSpec::Mass(0.0);
    err_names(w.create_body(&d), "body.mass");
    d.mass = MassSpec::Mass(-2.0);
    err_names(w.create_body(&d), "-2");
    d.mass = MassSpec::Density(Real::NAN);
    err_names(w.create_body(&d), "density");
    d.mass = MassSpec::Properties(MassProperties::new(
        1.0,
        Vec3::ZERO,
        Vec3::new(1.0, 0.0, 1.0),
    ));
    err_names(w.create_body(&d), "inertia");
    let mut d = BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0);
    d.pose.translation.y = Real::NAN;
    err_names(w.create_body(&d), "body.pose.translation");
    let mut d = BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0);
    d.pose.rotation = Quat::from_xyzw(0.0, 0.0, 0.0, 3.0);
    err_names(w.create_body(&d), "body.pose.rotation");
    let mut d = BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0);
    d.linear_velocity.x = Real::INFINITY;
    err_names(w.create_body(&d), "body.linear_velocity");
    let mut d = BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0);
    d.restitution = 1.5;
    err_names(w.create_body(&d), "body.restitution");
    let d = BodyDesc::default(); // dynamic without a shape
    err_names(w.create_body(&d), "body.shape");
    let mut d = BodyDesc::fixed(s.clone(), Isometry::IDENTITY);
    d.angular_velocity = Vec3::X;
    assert!(w.create_body(&d).is_err());
    assert!(w.bodies().is_empty());
}

#[test]
fn bad_forces_dt_and_contacts_are_rejected() {
    let mut w = DynamicsWorld::new(WorldParams::default()).unwrap();
    let ground = add_ground(&mut w);
    let b = w
        .create_body(&BodyDesc::dynamic(sphere(0.5), Isometry::IDENTITY, 1000.0))
        .unwrap();
    err_names(
        w.bodies_mut().add_force(b, Vec3::new(Real::NAN, 0.0, 0.0)),
        "force",
    );
    err_names(
        w.bodies_mut().add_torque(b, Vec3::splat(Real::INFINITY)),
        "torque",
    );
    err_names(
        w.bodies_mut().apply_impulse(b, Vec3::NAN, Vec3::ZERO),
        "impulse",
    );
    err_names(
        w.bodies_mut().set_linear_velocity(ground, Vec3::X),
        "static",
    );
    for dt in [0.0, -1.0, Real::NAN, Real::INFINITY] {
        err_names(w.step(dt, &mut []), "dt");
    }
    let mut m = ContactManifold::new(ground, b, Vec3::new(0.0, 2.0, 0.0));
    m.push(ContactPoint::new(Vec3::ZERO, Vec3::ZERO, 0.0, 0))
        .unwrap();
    err_names(w.step(1.0 / 60.0, &mut [m.clone()]), "contacts[0].normal");
    m.normal = Vec3::Y;
    m.points_mut()[0].separation = Real::NAN;
    err_names(
        w.step(1.0 / 60.0, &mut [m.clone()]),
        "contacts[0].points[0]",
    );
    m.points_mut()[0].separation = 0.0;
    m.friction = -1.0;
    err_names(w.step(1.0 / 60.0, &mut [m.clone()]), "contacts[0].friction");
    m.friction = 0.5;
    for _ in 0..3 {
        m.push(ContactPoint::default()).unwrap();
    }
    assert!(m.push(ContactPoint::default()).is_err(), "a fifth point");
    let before = w.state_hash();
    w.bodies_mut().remove(b).unwrap();
    err_names(w.step(1.0 / 60.0, &mut [m]), "body_b");
    assert_eq!(before, w.state_hash(), "a rejected step changes nothing");
    assert!(w.bodies().pose(b).is_err(), "stale handle");
    let params = WorldParams {
        gravity: Vec3::NAN,
        ..Default::default()
    };
    err_names(DynamicsWorld::new(params), "gravity");
}

#[test]
fn stale_handles_and_removed_bodies_with_joints() {
    let mut w = DynamicsWorld::new(WorldParams::default()).unwrap();
    let s = sphere(0.2);
    let a = w
        .create_body(&BodyDesc::dynamic(s.clone(), Isometry::IDENTITY, 1000.0))
        .unwrap();
    let b = w
        .create_body(&BodyDesc::dynamic(
            s.clone(),
            Isometry::from_translation(Vec3::X),
            1000.0,
        ))
        .unwrap();
    let j = w
        .create_joint(&JointDesc::new(
            a,
            b,
            Isometry::IDENTITY,
            Isometry::IDENTITY,
            JointKind::Ball,
        ))
        .unwrap();
    let mut bad = JointDesc::new(
        a,
        b,
        Isometry::IDENTITY,
        Isometry::IDENTITY,
        JointKind::Hinge {
            limits: Some((1.0, -1.0)),
            motor: None,
        },
    );
    err_names(w.create_joint(&bad), "low");
    bad.kind = JointKind::Ball;
    bad.body_b = a;
    err_names(w.create_joint(&bad), "joint.body_b");
    assert_eq!(w.remove_body(b).unwrap(), vec![j]);
    assert!(w.joints().get(j).is_err());
    w.step(1.0 / 60.0, &mut []).unwrap();
    // The slot is reused with a new generation: the old handle stays dead.
    let c = w
        .create_body(&BodyDesc::dynamic(s, Isometry::IDENTITY, 1000.0))
        .unwrap();
    assert_eq!(c.index, b.index);
    assert_ne!(c.generation, b.generation);
    assert!(w.bodies().linear_velocity(b).is_err());
    assert!(w.bodies().linear_velocity(c).is_ok());
    let desc = JointDesc::new(
        a,
        b,
        Isometry::IDENTITY,
        Isometry::IDENTITY,
        JointKind::Ball,
    );
    assert!(w.create_joint(&desc).is_err(), "joint to a removed body");
}

/// Session 27's sweep: velocities, impulses and forces whose length overflows f32 are
/// refused (they made every later step fail on an infinite margin), several velocities are
/// checked before any changes, and a speed clamp that overflows keeps the direction (2e19
/// became 0, a gravity scale of 1e38 made NaN).
#[test]
fn huge_velocities_impulses_and_forces() {
    let mut w = DynamicsWorld::new(WorldParams::default()).unwrap();
    let ground = add_ground(&mut w);
    let b = w
        .create_body(&BodyDesc::dynamic(
            sphere(0.5),
            Isometry::from_translation(Vec3::Y * 5.0),
            1000.0,
        ))
        .unwrap();
    let before = w.state_hash();
    let huge = Vec3::new(Real::MAX, Real::MAX, 0.0);
    err_names(
        w.bodies_mut().set_linear_velocity(b, huge),
        "linear_velocity",
    );
    err_names(
        w.bodies_mut().set_angular_velocity(b, huge),
        "angular_velocity",
    );
    err_names(w.bodies_mut().apply_impulse(b, huge, Vec3::ZERO), "impulse");
    err_names(
        w.bodies_mut().apply_angular_impulse(b, huge),
        "angular_impulse",
    );
    err_names(w.bodies_mut().add_force(b, huge), "force");
    err_names(w.bodies_mut().add_torque(b, huge), "torque");
    // The second item is refused, so the first does not change either.
    err_names(
        w.bodies_mut()
            .set_velocities(&[(b, Vec3::X, Vec3::ZERO), (ground, Vec3::X, Vec3::ZERO)]),
        "handles[1]",
    );
    assert_eq!(before, w.state_hash(), "refused calls change nothing");
    let mut d = BodyDesc::dynamic(sphere(0.5), Isometry::IDENTITY, 1000.0);
    d.gravity_scale = 1e30;
    err_names(w.create_body(&d), "body.gravity_scale");
    // Past sqrt(MAX) (1.8e19 m/s in f32) the squared length overflows: refused; below it
    // the step clamps to the body's limit.
    let root = Real::MAX.sqrt();
    err_names(
        w.bodies_mut()
            .set_linear_velocity(b, Vec3::X * (1.5 * root)),
        "linear_velocity",
    );
    w.bodies_mut()
        .set_linear_velocity(b, Vec3::X * (0.5 * root))
        .unwrap();
    w.step(1.0 / 60.0, &mut []).unwrap();
    let v = w.bodies().linear_velocity(b).unwrap();
    assert!((v.x - 400.0).abs() < 1e-2 && v.is_finite(), "{v}");
    // Forces adding up past the limit: the sum is refused, the earlier force kept. On a
    // light body its velocity change overflows the clamp's square, which keeps the direction.
    let light = w
        .create_body(&BodyDesc::dynamic(
            sphere(0.5),
            Isometry::from_translation(Vec3::X * 5.0),
            1e-6,
        ))
        .unwrap();
    w.bodies_mut()
        .add_force(light, Vec3::NEG_X * (0.5 * root))
        .unwrap();
    err_names(w.bodies_mut().add_force(light, Vec3::NEG_X * root), "force");
    w.step(1.0 / 60.0, &mut []).unwrap();
    let v = w.bodies().linear_velocity(light).unwrap();
    assert!(
        v.is_finite() && (v.length() - 400.0).abs() < 1e-2 && v.x < -399.0,
        "{v}"
    );
}
