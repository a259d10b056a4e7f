//! Joints against oracles: pendulum period, hinge limits under load, motor speed, slider
//! limits, spring sag, breaking, collision filtering, and a ragdoll from the scene.
mod common;
use carom_dynamics::collision::math::{consts::PI, Isometry, Quat, Real, Vec3};
use carom_dynamics::*;
use common::*;

const KINDS: [SolverKind; 2] = [SolverKind::SoftStep, SolverKind::SequentialImpulse];

fn world(kind: SolverKind, gravity: Vec3) -> DynamicsWorld {
    let mut p = WorldParams {
        gravity,
        ..Default::default()
    };
    p.solver.kind = kind;
    p.sleep.enabled = false;
    DynamicsWorld::new(p).unwrap()
}

fn anchor(w: &mut DynamicsWorld, at: Vec3) -> BodyHandle {
    w.create_body(&BodyDesc {
        body_type: BodyType::Static,
        pose: Isometry::from_translation(at),
        ..Default::default()
    })
    .unwrap()
}

fn ball(w: &mut DynamicsWorld, at: Vec3, r: Real) -> BodyHandle {
    w.create_body(&BodyDesc::dynamic(
        sphere(r),
        Isometry::from_translation(at),
        1000.0,
    ))
    .unwrap()
}

#[test]
fn pendulum_keeps_the_small_angle_period() {
    let (g, l, theta0): (Real, Real, Real) = (9.81, 1.0, 0.1);
    // The bob is a sphere of radius r pinned at distance l from its centre: a physical
    // pendulum, T = 2π √((I + m l²) / (m g l)) with I = 0.4 m r² (→ 2π √(l/g) as r → 0).
    // (A tiny bob makes its spin about the pin a very stiff mode that soft joints smear.)
    let r: Real = 0.2;
    let expected = 2.0 * PI * ((0.4 * r * r + l * l) / (g * l)).sqrt();
    for kind in KINDS {
        let mut w = world(kind, Vec3::new(0.0, -g, 0.0));
        let pivot = anchor(&mut w, Vec3::new(0.0, 2.0, 0.0));
        let bob = ball(
            &mut w,
            Vec3::new(l * theta0.sin(), 2.0 - l * theta0.cos(), 0.0),
            r,
        );
        let frame_b =
            Isometry::from_translation(Vec3::new(-l * theta0.sin(), l * theta0.cos(), 0.0));
        w.create_joint(&JointDesc::new(
            pivot,
            bob,
            Isometry::IDENTITY,
            frame_b,
            JointKind::Ball,
        ))
        .unwrap();
        let dt = 1.0 / 240.0;
        let mut crossings = Vec::new();
        let mut last_x = w.bodies().center_of_mass(bob).unwrap().x;
        for i in 0..(5.0 * expected / dt) as usize {
            w.step(dt, &mut []).unwrap();
            let x = w.bodies().center_of_mass(bob).unwrap().x;
            if last_x > 0.0 && x <= 0.0 {
                // Linear interpolation of the downward zero crossing.
                crossings.push((i as Real + last_x / (last_x - x)) * dt);
            }
            last_x = x;
        }
        assert!(crossings.len() >= 3, "{kind:?}: {crossings:?}");
        let period =
            (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as Real;
        // Finite amplitude (0.1 rad) lengthens the period by θ²/16 ≈ 0.06 %.
        assert!(
            (period - expected).abs() < 0.01 * expected,
            "{kind:?}: period {period} vs {expected}"
        );
        let len = (w.bodies().center_of_mass(bob).unwrap() - Vec3::new(0.0, 2.0, 0.0)).length();
        assert!((len - l).abs() < 0.005, "{kind:?}: rod length {len}");
    }
}

fn hinge_angle(w: &DynamicsWorld, b: BodyHandle) -> Real {
    let q = w.bodies().pose(b).unwrap().rotation;
    2.0 * q.z.atan2(q.w)
}

#[test]
fn hinge_limit_holds_under_load() {
    for kind in KINDS {
        let mut w = world(kind, Vec3::new(0.0, -9.81, 0.0));
        let pivot = anchor(&mut w, Vec3::new(0.0, 5.0, 0.0));
        // A 2 m bar, hinged at its left end about Z, starting horizontal: gravity swings it
        // down (negative angle) until the lower limit catches it.
        let bar = w
            .create_body(&BodyDesc::dynamic(
                cuboid(Vec3::new(1.0, 0.1, 0.1)),
                Isometry::from_translation(Vec3::new(1.0, 5.0, 0.0)),
                500.0,
            ))
            .unwrap();
        let (low, high) = (-0.5, 0.3);
        let kind_j = JointKind::Hinge {
            limits: Some((low, high)),
            motor: None,
        };
        let frame_b = Isometry::from_translation(Vec3::new(-1.0, 0.0, 0.0));
        w.create_joint(&JointDesc::new(
            pivot,
            bar,
            Isometry::IDENTITY,
            frame_b,
            kind_j,
        ))
        .unwrap();
        let mut min_angle: Real = 0.0;
        for _ in 0..300 {
            w.step(1.0 / 60.0, &mut []).unwrap();
            let a = hinge_angle(&w, bar);
            min_angle = min_angle.min(a);
            assert!(a <= high + 0.05, "{kind:?}: angle {a} above {high}");
        }
        assert!(
            min_angle >= low - 0.05,
            "{kind:?}: angle {min_angle} below {low}"
        );
        let a = hinge_angle(&w, bar);
        assert!(
            (a - low).abs() < 0.05,
            "{kind:?}: rests at {a}, limit {low}"
        );
        let anchor_err = w
            .bodies()
            .pose(bar)
            .unwrap()
            .transform_point(Vec3::new(-1.0, 0.0, 0.0))
            - Vec3::new(0.0, 5.0, 0.0);
        assert!(
            anchor_err.length() < 0.01,
            "{kind:?}: anchor drifted {anchor_err}"
        );
    }
}

#[test]
fn hinge_motor_reaches_its_speed_and_slider_limit_holds() {
    for kind in KINDS {
        let mut w = world(kind, Vec3::ZERO);
        let base = anchor(&mut w, Vec3::ZERO);
        let wheel = ball(&mut w, Vec3::ZERO, 0.3);
        let motor = Some(Motor {
            speed: 2.0,
            max_force: 1e4,
        });
        let j = JointKind::Hinge {
            limits: None,
            motor,
        };
        w.create_joint(&JointDesc::new(
            base,
            wheel,
            Isometry::IDENTITY,
            Isometry::IDENTITY,
            j,
        ))
        .unwrap();
        let slider_body = ball(&mut w, Vec3::new(0.0, 3.0, 0.0), 0.2);
        w.bodies_mut()
            .set_linear_velocity(slider_body, Vec3::new(1.0, 1.0, 0.5))
            .unwrap();
        let s = JointKind::Slider {
            limits: Some((0.0, 0.5)),
            motor: None,
        };
        let fa = Isometry::from_translation(Vec3::new(0.0, 3.0, 0.0));
        w.create_joint(&JointDesc::new(
            base,
            slider_body,
            fa,
            Isometry::IDENTITY,
            s,
        ))
        .unwrap();
        for _ in 0..120 {
            w.step(1.0 / 60.0, &mut []).unwrap();
            let p = w.bodies().center_of_mass(slider_body).unwrap() - Vec3::new(0.0, 3.0, 0.0);
            assert!(
                p.x <= 0.5 + 0.02 && p.y.abs() < 0.01 && p.z.abs() < 0.01,
                "{kind:?}: {p}"
            );
        }
        let spin = w.bodies().angular_velocity(wheel).unwrap();
        assert!(
            (spin - Vec3::new(0.0, 0.0, 2.0)).length() < 0.02,
            "{kind:?}: spin {spin}"
        );
        let x = w.bodies().center_of_mass(slider_body).unwrap().x;
        assert!((x - 0.5).abs() < 0.02, "{kind:?}: slider at {x}");
    }
}

#[test]
fn six_dof_spring_sags_by_g_over_omega_squared() {
    let hertz = 2.0;
    let omega = 2.0 * PI * hertz;
    for kind in KINDS {
        let mut w = world(kind, Vec3::new(0.0, -9.81, 0.0));
        let base = anchor(&mut w, Vec3::new(0.0, 5.0, 0.0));
        let body = ball(&mut w, Vec3::new(0.0, 5.0, 0.0), 0.2);
        let lock = Axis::default();
        let spring = Axis {
            mode: AxisMode::Free,
            motor: None,
            spring: Some(Spring {
                hertz,
                damping_ratio: 1.0,
                rest: 0.0,
            }),
        };
        let kind_j = JointKind::Generic6Dof {
            linear: [lock, spring, lock],
            angular: [lock; 3],
        };
        let desc = JointDesc::new(base, body, Isometry::IDENTITY, Isometry::IDENTITY, kind_j);
        w.create_joint(&desc).unwrap();
        for _ in 0..600 {
            w.step(1.0 / 60.0, &mut []).unwrap();
        }
        let sag = 5.0 - w.bodies().center_of_mass(body).unwrap().y;
        let expected = 9.81 / (omega * omega);
        assert!(
            (sag - expected).abs() < 0.05 * expected,
            "{kind:?}: sag {sag} vs {expected}"
        );
    }
}

#[test]
fn fixed_joint_holds_and_breakable_joint_breaks() {
    for kind in KINDS {
        let mut w = world(kind, Vec3::new(0.0, -9.81, 0.0));
        let base = anchor(&mut w, Vec3::new(0.0, 5.0, 0.0));
        let light = ball(&mut w, Vec3::new(1.0, 5.0, 0.0), 0.1);
        let fa = Isometry::from_translation(Vec3::new(1.0, 0.0, 0.0));
        let fixed = JointDesc::new(base, light, fa, Isometry::IDENTITY, JointKind::Fixed);
        w.create_joint(&fixed).unwrap();
        // A heavy ball on a joint that breaks above a tenth of its weight impulse per step.
        let heavy = ball(&mut w, Vec3::new(-1.0, 5.0, 0.0), 0.3);
        let weight_impulse = 9.81 / 60.0 / w.bodies().inv_mass(heavy).unwrap();
        let mut weak = JointDesc::new(
            base,
            heavy,
            Isometry::from_translation(Vec3::new(-1.0, 0.0, 0.0)),
            Isometry::IDENTITY,
            JointKind::Ball,
        );
        weak.break_impulse = 0.1 * weight_impulse;
        let weak_h = w.create_joint(&weak).unwrap();
        assert!(!w.should_collide(base, heavy));
        let mut broken = Vec::new();
        for _ in 0..120 {
            broken.extend(w.step(1.0 / 60.0, &mut []).unwrap().broken_joints);
        }
        assert_eq!(broken, vec![weak_h], "{kind:?}");
        assert!(w.joints().get(weak_h).unwrap().broken);
        assert!(
            w.should_collide(base, heavy),
            "a broken joint no longer filters"
        );
        assert!(
            w.bodies().center_of_mass(heavy).unwrap().y < 0.0,
            "the heavy ball fell"
        );
        let p = w.bodies().center_of_mass(light).unwrap();
        assert!(
            (p - Vec3::new(1.0, 5.0, 0.0)).length() < 0.01,
            "{kind:?}: fixed body at {p}"
        );
        let q = w.bodies().pose(light).unwrap().rotation;
        assert!(
            q.angle_between(Quat::IDENTITY) < 0.01,
            "{kind:?}: fixed body turned"
        );
    }
}

#[test]
fn ragdoll_from_the_scene_comes_to_rest() {
    let scene = carom_scenes::bullet::ragdolls();
    for kind in KINDS {
        let mut sim = Sim::new(kind, scene.gravity);
        // Scene body 0 is the ground (our plane); bodies 1..=11 are the first ragdoll.
        let mut handles = vec![sim.ground];
        for b in &scene.bodies[1..12] {
            let mut d = BodyDesc::dynamic(b.shape.clone(), b.pose, 1.0);
            d.mass = MassSpec::Mass(b.mass);
            d.friction = b.friction;
            d.linear_damping = b.linear_damping;
            d.angular_damping = b.angular_damping;
            d.pose.translation.y += 2.0;
            handles.push(sim.add(&d));
        }
        let joints: Vec<_> = scene.joints.iter().filter(|j| j.body_b < 12).collect();
        assert_eq!(joints.len(), 10);
        for j in joints {
            let desc = JointDesc::from_scene(j, &handles).unwrap();
            assert!(sim.world.should_collide(desc.body_a, desc.body_b));
            sim.world.create_joint(&desc).unwrap();
            assert!(!sim.world.should_collide(desc.body_a, desc.body_b));
        }
        let mut p = *sim.world.params();
        p.sleep.enabled = false;
        sim.world.set_params(p).unwrap();
        // Sleeping off: the ragdoll itself must settle. The sequential-impulse solver keeps a
        // joint/contact jitter that never dies out: its largest body speed wanders between
        // 0.03 and 0.19 m/s from step 1000 to 3000 (measured in f64; which value step 1800
        // lands on depends on round-off), hence its looser bound. The soft step is at rest
        // (below 1e-4 m/s from step 1000).
        for _ in 0..1800 {
            sim.step();
        }
        for &h in &handles[1..] {
            let b = sim.world.bodies();
            let (v, wv, p) = (
                b.linear_velocity(h).unwrap(),
                b.angular_velocity(h).unwrap(),
                sim.pos(h),
            );
            assert!(
                v.is_finite() && wv.is_finite() && p.is_finite(),
                "{kind:?}: NaN"
            );
            let v_max = match kind {
                SolverKind::SoftStep => 0.1,
                SolverKind::SequentialImpulse => 0.25,
            };
            assert!(
                v.length() < v_max && wv.length() < 0.5,
                "{kind:?}: still moving {v} {wv}"
            );
            assert!(p.y > -0.05 && p.y < 2.0, "{kind:?}: body at {p}");
        }
    }
}

/// A joint loaded in one step, just above or below its `break_impulse`: a ball moving at
/// `v` is stopped by a ball joint at its centre (no gravity), so the joint's impulse over
/// the first step is `m v`, nearly all of it in the first substep. Breaking used to look at
/// the last substep's impulse scaled to the step, which missed such a load (the soft step
/// held at a tenth of `m v`); it now compares the impulse summed over the substeps.
#[test]
fn joint_breaks_on_the_impulse_of_the_whole_step() {
    for kind in KINDS {
        for (factor, breaks) in [(0.1, true), (0.9, true), (1.1, false), (2.0, false)] {
            let mut w = world(kind, Vec3::ZERO);
            let base = anchor(&mut w, Vec3::new(0.0, 5.0, 0.0));
            let b = ball(&mut w, Vec3::new(0.0, 5.0, 0.0), 0.2);
            let v: Real = 3.0;
            w.bodies_mut()
                .set_linear_velocity(b, Vec3::new(v, 0.0, 0.0))
                .unwrap();
            let m = 1.0 / w.bodies().inv_mass(b).unwrap();
            let mut desc = JointDesc::new(
                base,
                b,
                Isometry::IDENTITY,
                Isometry::IDENTITY,
                JointKind::Ball,
            );
            desc.break_impulse = factor * m * v;
            let h = w.create_joint(&desc).unwrap();
            let mut broken = Vec::new();
            for step in 0..30 {
                let report = w.step(1.0 / 60.0, &mut []).unwrap();
                broken.extend(report.broken_joints.iter().map(|&j| (step, j)));
            }
            // It breaks at the end of the step that stopped the ball (the step's impulse
            // was applied), or never.
            let expected = if breaks { vec![(0, h)] } else { vec![] };
            assert_eq!(broken, expected, "{kind:?}, break at {factor} m v");
            let speed = w.bodies().linear_velocity(b).unwrap().length();
            assert!(speed < 0.05 * v, "{kind:?}: ball still at {speed}");
        }
    }
}

/// A weight hanging from a ball joint: holds when the break impulse is just above its
/// weight's impulse per step, breaks just below (a steady load, the same on every substep).
#[test]
fn joint_under_a_steady_load_breaks_just_above_its_threshold() {
    let g: Real = 9.81;
    for kind in KINDS {
        for (factor, breaks) in [(0.95, true), (1.05, false)] {
            let mut w = world(kind, Vec3::new(0.0, -g, 0.0));
            let base = anchor(&mut w, Vec3::new(0.0, 5.0, 0.0));
            let b = ball(&mut w, Vec3::new(0.0, 4.0, 0.0), 0.2);
            let m = 1.0 / w.bodies().inv_mass(b).unwrap();
            let fb = Isometry::from_translation(Vec3::new(0.0, 1.0, 0.0));
            let mut desc = JointDesc::new(base, b, Isometry::IDENTITY, fb, JointKind::Ball);
            desc.break_impulse = factor * m * g / 60.0;
            let h = w.create_joint(&desc).unwrap();
            let mut broken = Vec::new();
            for _ in 0..60 {
                broken.extend(w.step(1.0 / 60.0, &mut []).unwrap().broken_joints);
            }
            let expected = if breaks { vec![h] } else { vec![] };
            assert_eq!(broken, expected, "{kind:?}, break at {factor} m g dt");
        }
    }
}
