//! The per-substep refresh against its oracle, a fresh preparation at the same poses: for
//! every joint type, with off-centre masses and far from the origin, the refreshed rows
//! (Jacobians, errors, effective masses, blocks) equal the rows built from scratch, and
//! the accumulated impulses are kept. Also the rows that are undefined at some poses (the
//! cone's swing and twist axes).

use super::build::{prepare_joint, refresh_joint, JointRows};
use super::{Axis, AxisMode, JointDesc, JointKind, JointSet, Motor, Spring};
use crate::body::BodyDesc;
use crate::body_set::{BodyHandle, BodySet};
use crate::integrate;
use crate::solver::rows::{Block, Row};
use crate::solver::SolverBody;
use carom_collision::math::{Isometry, Quat, Real, Vec3, Vec3A};
use carom_collision::shape::{ConvexHull, Shape};
use std::sync::Arc;

/// A box-shaped hull whose centre of mass is off the body origin.
fn off_centre_hull(offset: Vec3) -> Arc<Shape> {
    let mut points = Vec::new();
    for i in 0..8 {
        let s = |bit: usize| if i & bit != 0 { 1.0 } else { -1.0 };
        points.push(offset + Vec3::new(0.4 * s(1), 0.2 * s(2), 0.3 * s(4)));
    }
    Arc::new(ConvexHull::new(&points).unwrap().into())
}

fn kinds() -> Vec<JointKind> {
    let spring = Axis {
        mode: AxisMode::Limited {
            low: -0.2,
            high: 0.3,
        },
        motor: None,
        spring: Some(Spring {
            hertz: 4.0,
            damping_ratio: 0.7,
            rest: 0.1,
        }),
    };
    let motor = Some(Motor {
        speed: 1.0,
        max_force: 5.0,
    });
    let free = Axis {
        mode: AxisMode::Free,
        motor,
        spring: None,
    };
    vec![
        JointKind::Ball,
        JointKind::Fixed,
        JointKind::Hinge {
            limits: None,
            motor: None,
        },
        JointKind::Hinge {
            limits: Some((-0.4, 0.9)),
            motor,
        },
        JointKind::ConeTwist {
            swing1: 0.5,
            swing2: 0.3,
            twist: 0.2,
        },
        JointKind::ConeTwist {
            swing1: 0.5,
            swing2: 0.3,
            twist: 0.0,
        },
        JointKind::Slider {
            limits: Some((-0.5, 0.5)),
            motor,
        },
        JointKind::Generic6Dof {
            linear: [spring, Axis::default(), free],
            angular: [free, spring, Axis::default()],
        },
    ]
}

struct Rig {
    set: BodySet,
    joints: JointSet,
    a: BodyHandle,
    b: BodyHandle,
}

fn rig(kind: JointKind, origin: Vec3) -> Rig {
    let mut set = BodySet::new();
    let pose_a = Isometry::new(origin, Quat::from_rotation_y(0.3));
    let pose_b = Isometry::new(
        origin + Vec3::new(0.9, 0.1, -0.2),
        Quat::from_rotation_x(-0.2),
    );
    let a = set
        .insert(&BodyDesc::dynamic(
            off_centre_hull(Vec3::new(0.2, -0.1, 0.05)),
            pose_a,
            1000.0,
        ))
        .unwrap();
    let b = set
        .insert(&BodyDesc::dynamic(
            off_centre_hull(Vec3::new(-0.1, 0.15, 0.2)),
            pose_b,
            700.0,
        ))
        .unwrap();
    let frame_a = Isometry::new(Vec3::new(0.5, 0.05, 0.0), Quat::from_rotation_z(0.4));
    // Frame B at the same world pose as frame A: the joint starts satisfied.
    let frame_b = pose_b.inv_mul(&pose_a.mul(&frame_a));
    let mut joints = JointSet::default();
    joints.insert(JointDesc::new(a, b, frame_a, frame_b, kind));
    Rig { set, joints, a, b }
}

fn prepare(r: &Rig, bodies: &[SolverBody]) -> (JointRows, Vec<Row>, Vec<Block>) {
    let (mut rows, mut blocks) = (Vec::new(), Vec::new());
    let (_, j) = r.joints.iter().next().unwrap();
    let jr = prepare_joint(
        0,
        j,
        &r.set,
        bodies,
        1.0 / 240.0,
        0.25,
        &mut rows,
        &mut blocks,
        true,
    );
    (jr.unwrap(), rows, blocks)
}

/// A rig of `kind` at `origin` whose joint stores the slot impulses `impulse(slot)`, its
/// solver bodies, and the joint prepared by the oracle ([`prepare`]).
#[allow(clippy::type_complexity)]
fn prepared(
    kind: JointKind,
    origin: Vec3,
    impulse: impl Fn(usize) -> Real,
) -> (Rig, Vec<SolverBody>, (JointRows, Vec<Row>, Vec<Block>)) {
    let mut r = rig(kind, origin);
    {
        let (_, j) = r.joints.iter_mut().next().unwrap();
        for (s, x) in j.impulses.iter_mut().enumerate() {
            *x = impulse(s);
        }
    }
    let mut bodies = Vec::new();
    integrate::load(&r.set, &mut bodies);
    let p = prepare(&r, &bodies);
    (r, bodies, p)
}

fn moved(r: &mut Rig, turn_b: Quat) {
    let (ia, ib) = (r.a.index as usize, r.b.index as usize);
    r.set.position[ia] += Vec3::new(0.02, -0.03, 0.01);
    r.set.rotation[ia] = (Quat::from_rotation_x(0.15) * r.set.rotation[ia]).normalize();
    r.set.position[ib] += Vec3::new(-0.01, 0.04, 0.03);
    r.set.rotation[ib] = (turn_b * r.set.rotation[ib]).normalize();
}

fn assert_same_point(fresh: &JointRows, refreshed: &JointRows, what: &str) {
    match (&fresh.point, &refreshed.point) {
        (None, None) => {}
        (Some(x), Some(y)) => {
            assert_eq!([x.ra, x.rb, x.c], [y.ra, y.rb, y.c], "{what}: point");
            assert_eq!(x.axes, y.axes, "{what}: point axes");
            assert_eq!((x.ma, x.mb), (y.ma, y.mb), "{what}: point I⁻¹ [r]×");
            assert_eq!((x.inv_k, x.valid), (y.inv_k, y.valid), "{what}: point K⁻¹");
        }
        _ => panic!("{what}: a point block on one side only"),
    }
}

fn assert_same_rows(fresh: &[Row], refreshed: &[Row], what: &str) {
    assert_eq!(fresh.len(), refreshed.len(), "{what}");
    for (x, y) in fresh.iter().zip(refreshed) {
        assert_eq!(x.slot, y.slot, "{what}");
        assert_eq!(x.kind, y.kind, "{what}");
        assert_eq!((x.lo, x.hi), (y.lo, y.hi), "{what}");
        let jx = [x.lin, x.ang_a, x.ang_b, x.ia, x.ib];
        let jy = [y.lin, y.ang_a, y.ang_b, y.ia, y.ib];
        assert_eq!(jx, jy, "{what}: slot {}", x.slot);
        assert_eq!(x.c, y.c, "{what}: slot {}", x.slot);
        assert_eq!(x.inv_k, y.inv_k, "{what}: slot {}", x.slot);
    }
}

#[test]
fn refresh_equals_a_fresh_preparation_for_every_joint_type() {
    for origin in [Vec3::ZERO, Vec3::new(1e3, -2e3, 5e2)] {
        for kind in kinds() {
            let what = format!("{kind:?} at {origin}");
            let (mut r, bodies, (mut jr, mut rows, mut blocks)) =
                prepared(kind, origin, |s| 0.01 * (s as Real + 1.0));
            for row in rows.iter_mut() {
                row.impulse = (row.impulse + 0.5).clamp(row.lo, row.hi);
            }
            let kept: Vec<Real> = rows.iter().map(|row| row.impulse).collect();
            if let Some(p) = &mut jr.point {
                // The stored slot impulses 0.01, 0.04, 0.07 along frame A's axes.
                let slots = p.slot_impulses(p.impulse);
                for (got, want) in slots.into_iter().zip([0.01, 0.04, 0.07]) {
                    assert!((got - want * 0.25).abs() < 1e-6, "{what}: {slots:?}");
                }
                p.impulse += Vec3A::new(0.5, -0.25, 0.125);
            }
            let kept_point = jr.point.map(|p| p.impulse);

            moved(
                &mut r,
                Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 0.25),
            );
            let (_, j) = r.joints.iter().next().unwrap();
            refresh_joint(&mut jr, j, &r.set, &bodies, &mut rows, &mut blocks);
            let (fresh_jr, fresh, fresh_blocks) = prepare(&r, &bodies);

            assert_same_rows(&fresh, &rows, &what);
            assert_same_point(&fresh_jr, &jr, &what);
            assert_eq!(
                kept_point,
                jr.point.map(|p| p.impulse),
                "{what}: point impulse"
            );
            let kept_now: Vec<Real> = rows.iter().map(|row| row.impulse).collect();
            assert_eq!(kept, kept_now, "{what}: impulses are kept");
            assert_eq!(fresh_blocks.len(), blocks.len(), "{what}");
            for (x, y) in fresh_blocks.iter().zip(&blocks) {
                assert_eq!(
                    (x.start, x.len, x.valid),
                    (y.start, y.len, y.valid),
                    "{what}"
                );
                assert_eq!(x.inv_k, y.inv_k, "{what}");
            }
            assert!(rows
                .iter()
                .all(|row| row.c.is_finite() && row.inv_k.is_finite()));
        }
    }
}

#[test]
fn row_counts_follow_the_joint_description() {
    // Rows besides the point block (ball, fixed, hinges, cone-twist have one).
    let counts = [0, 3, 2, 5, 3, 2, 8, 10];
    let points = [true, true, true, true, true, true, false, false];
    for ((kind, n), point) in kinds().into_iter().zip(counts).zip(points) {
        let r = rig(kind, Vec3::ZERO);
        let mut bodies = Vec::new();
        integrate::load(&r.set, &mut bodies);
        let (jr, rows, blocks) = prepare(&r, &bodies);
        assert_eq!(rows.len(), n, "{kind:?}");
        assert_eq!(jr.rows, 0..n, "{kind:?}");
        assert_eq!(jr.point.is_some(), point, "{kind:?}");
        if let Some(p) = jr.point {
            assert!(p.valid && p.c.length() < 1e-4, "{kind:?}: c = {}", p.c);
        }
        // Satisfied at the start: every equality row has zero error, every block is valid.
        assert!(blocks.iter().all(|b| b.valid), "{kind:?}");
        for row in &rows {
            if row.kind == crate::solver::rows::RowKind::Equality {
                assert!(
                    row.c.abs() < 1e-4,
                    "{kind:?}: slot {} c = {}",
                    row.slot,
                    row.c
                );
            }
        }
    }
}

#[test]
fn cone_rows_are_inactive_where_their_axes_are_undefined() {
    let kind = JointKind::ConeTwist {
        swing1: 0.5,
        swing2: 0.3,
        twist: 0.2,
    };
    let mut r = rig(kind, Vec3::ZERO);
    let mut bodies = Vec::new();
    integrate::load(&r.set, &mut bodies);
    // No swing at the start: the swing row (slot 9) has no axis.
    let (mut jr, mut rows, mut blocks) = prepare(&r, &bodies);
    let swing = rows.iter().position(|row| row.slot == 9).unwrap();
    assert_eq!(rows[swing].ang_b, Vec3A::ZERO);
    assert_eq!((rows[swing].inv_k, rows[swing].impulse), (0.0, 0.0));
    // A swing about frame A's Y axis (world: rotated by A's and the frame's rotation).
    let fa = r
        .set
        .pose_of(r.a.index as usize)
        .mul(&r.joints.iter().next().unwrap().1.desc.frame_a);
    let y = fa.rotation * Vec3::Y;
    moved(&mut r, Quat::from_axis_angle(y, 0.2));
    let (_, j) = r.joints.iter().next().unwrap();
    refresh_joint(&mut jr, j, &r.set, &bodies, &mut rows, &mut blocks);
    assert!(rows[swing].ang_b.length() > 0.5 && rows[swing].inv_k > 0.0);
    // Back to no swing (B's frame turned onto A's, plus a twist about their common X):
    // the swing row is inactive again and its impulse is dropped.
    rows[swing].impulse = 1.0;
    let desc = &r.joints.iter().next().unwrap().1.desc;
    let (ia, ib) = (r.a.index as usize, r.b.index as usize);
    let twist = Quat::from_rotation_x(0.1);
    r.set.rotation[ib] =
        (r.set.rotation[ia] * desc.frame_a.rotation * twist * desc.frame_b.rotation.conjugate())
            .normalize();
    let (_, j) = r.joints.iter().next().unwrap();
    refresh_joint(&mut jr, j, &r.set, &bodies, &mut rows, &mut blocks);
    assert_eq!(rows[swing].ang_b, Vec3A::ZERO);
    assert_eq!((rows[swing].inv_k, rows[swing].impulse), (0.0, 0.0));
    let (_, fresh, _) = prepare(&r, &bodies);
    assert_same_rows(&fresh, &rows, "back to no swing");
    // The twist rows measure the twist: 0.2 - 0.1 to the upper limit.
    let upper = rows.iter().find(|row| row.slot == 13).unwrap();
    assert!((upper.c - 0.1).abs() < 1e-4, "twist row c = {}", upper.c);
}

#[test]
fn a_singular_block_falls_back_to_rows_and_stays_finite() {
    use crate::solver::joints::{solve, JointScratch};
    use crate::solver::Softness;
    use carom_collision::math::Mat3;
    // A fixed joint between two bodies whose rotation the solver cannot change (zero inverse
    // inertia): the rotation block's K is zero.
    let mut r = rig(JointKind::Fixed, Vec3::ZERO);
    let mut bodies = Vec::new();
    integrate::load(&r.set, &mut bodies);
    for b in bodies.iter_mut() {
        b.inv_i = Mat3::ZERO;
        b.v = Vec3::new(0.3, -0.2, 0.1);
        b.w = Vec3::new(1.0, 2.0, -0.5);
    }
    moved(&mut r, Quat::from_rotation_z(0.3));
    let (jr, rows, blocks) = prepare(&r, &bodies);
    assert_eq!(blocks.len(), 1);
    assert!(jr.point.unwrap().valid, "the point block has the masses");
    assert!(!blocks[0].valid, "the rotation block is singular");
    assert!(rows.iter().all(|row| row.inv_k == 0.0));
    let mut s = JointScratch::default();
    s.joints.push(jr);
    s.rows = rows;
    s.blocks = blocks;
    s.order_by_slot();
    let soft = Softness::new(60.0, 2.0, 1.0 / 240.0);
    let w0: Vec<Vec3> = bodies.iter().map(|b| b.w).collect();
    for use_bias in [true, false] {
        solve(&mut s, &mut bodies, soft, 240.0, use_bias);
    }
    for (b, w) in bodies.iter().zip(w0) {
        assert!(b.v.is_finite() && b.w.is_finite());
        assert_eq!(b.w, w, "no angular change without inverse inertia");
    }
    // The point block did act.
    let impulse = s.joints[0].point.unwrap().impulse;
    assert!(impulse.is_finite() && impulse != Vec3A::ZERO);
}

/// The kinds of [`kinds`] and every other branch of the row generator: limits without a
/// motor, a motor without limits, equal limits (one equality row), locked axes, springs.
fn all_kinds() -> Vec<JointKind> {
    let motor = Some(Motor {
        speed: -0.5,
        max_force: 2.0,
    });
    let axis = |mode, motor, spring| Axis {
        mode,
        motor,
        spring,
    };
    let spring = Some(Spring {
        hertz: 2.0,
        damping_ratio: 1.0,
        rest: 0.0,
    });
    let equal = AxisMode::Limited {
        low: 0.1,
        high: 0.1,
    };
    let range = AxisMode::Limited {
        low: -0.1,
        high: 0.2,
    };
    let mut all = kinds();
    all.extend([
        JointKind::Hinge {
            limits: Some((-0.4, 0.9)),
            motor: None,
        },
        JointKind::Hinge {
            limits: None,
            motor,
        },
        JointKind::Hinge {
            limits: Some((0.3, 0.3)),
            motor,
        },
        JointKind::Slider {
            limits: None,
            motor: None,
        },
        JointKind::Slider {
            limits: Some((0.2, 0.2)),
            motor: None,
        },
        JointKind::Generic6Dof {
            linear: [
                axis(equal, None, None),
                axis(AxisMode::Free, None, spring),
                axis(range, motor, None),
            ],
            angular: [
                axis(AxisMode::Locked, motor, None),
                axis(equal, None, spring),
                axis(AxisMode::Free, None, None),
            ],
        },
        JointKind::Generic6Dof {
            linear: [Axis::default(); 3],
            angular: [axis(AxisMode::Free, None, None); 3],
        },
    ]);
    all
}

#[test]
fn a_joint_built_in_its_planned_slots_equals_a_prepared_one() {
    // The soft step lays every joint out from its description (`layout`), then each joint
    // builds its rows and blocks in the slots laid out for it (`prepare_own`, in parallel
    // blocks). Oracle: `prepare_joint` appending the rows, with masses. The slots start as
    // garbage (NaN Jacobians, a motor kind, wrong blocks): every one must be written.
    use super::build::{layout, prepare_own};
    use crate::solver::rows::RowKind;
    for origin in [Vec3::ZERO, Vec3::new(1e3, -2e3, 5e2)] {
        for kind in all_kinds() {
            let what = format!("{kind:?} at {origin}");
            let (r, bodies, (jr, rows, blocks)) =
                prepared(kind, origin, |s| 0.3 * (s as Real - 8.0));
            let (_, j) = r.joints.iter().next().unwrap();
            assert_eq!(layout(&kind), (rows.len(), blocks.len()), "{what}");

            let nan = Vec3A::splat(Real::NAN);
            let mut junk = Row::new(17, [nan; 3], Real::NAN, RowKind::Motor { speed: 9.0 }, 3.0);
            junk.impulse = Real::NAN;
            let mut own = vec![junk; rows.len()];
            let mut own_blocks = vec![Block::new(1, 3); blocks.len()];
            let mut planned = JointRows::planned(0, j, 0..rows.len(), 0..blocks.len());
            let pair = (&bodies[r.a.index as usize], &bodies[r.b.index as usize]);
            let h = 1.0 / 240.0;
            prepare_own(
                &mut planned,
                j,
                &r.set,
                pair,
                h,
                0.25,
                &mut own,
                &mut own_blocks,
            );

            assert_same_rows(&rows, &own, &what);
            assert_same_point(&jr, &planned, &what);
            assert_eq!(
                jr.point.map(|p| p.impulse),
                planned.point.map(|p| p.impulse)
            );
            let impulses = |rows: &[Row]| rows.iter().map(|x| x.impulse.to_bits()).collect();
            let want: Vec<_> = impulses(&rows);
            assert_eq!(want, impulses(&own), "{what}: warm-start impulses");
            for (x, y) in blocks.iter().zip(&own_blocks) {
                let key = |b: &Block| (b.start, b.len, b.valid);
                assert_eq!(key(x), key(y), "{what}");
                assert_eq!(x.inv_k, y.inv_k, "{what}");
            }
            assert_eq!(
                (jr.a, jr.b, jr.breakable),
                (planned.a, planned.b, planned.breakable)
            );
        }
    }
}
