//! Unit tests of the narrowphase pipeline's settled state.

use super::*;
use crate::math::Vec3;
use crate::shape::Sphere;
use ContactEventKind::{End, Persist};

/// The settled state: taken after a quiet step that reported only `Persist`, kept by the
/// next quiet step (which hands back the same events), left by a change of the pairs
/// through a `&mut` call, an added pair or an active object.
#[test]
fn quiet_steps_settle_and_any_change_unsettles() {
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let at = |x: Real| Isometry::from_translation(Vec3::new(x, 0.0, 0.0));
    let poses = [at(0.0), at(0.99), at(1.98)];
    let lookup = |active: bool| {
        let ball = &ball;
        move |h: u32| {
            Some(NarrowObject {
                active,
                ..NarrowObject::new(ball, poses[h as usize])
            })
        }
    };
    let mut np = NarrowPhase::<u32>::default();
    let kinds = |np: &NarrowPhase<u32>| np.events().iter().map(|e| e.kind).collect::<Vec<_>>();
    np.step(&[(0, 1), (1, 2)], &[], lookup(true)).unwrap();
    assert!(!np.settled, "Begin events");
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert!(np.settled);
    assert_eq!(kinds(&np), [Persist, Persist]);
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert!(np.settled);
    assert_eq!(kinds(&np), [Persist, Persist]);
    np.set_excluded(1, 2, true);
    assert!(!np.settled);
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert_eq!(kinds(&np), [Persist, End]);
    assert!(!np.settled, "an End event");
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert!(np.settled);
    assert_eq!(kinds(&np), [Persist]);
    let _ = np.pair_slice_mut();
    assert!(!np.settled);
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert!(np.settled);
    np.step_with(&[(0, 2)], &[], lookup(false), false).unwrap();
    assert!(!np.settled, "a pair added");
    np.step_with(&[], &[], lookup(false), false).unwrap();
    assert!(np.settled);
    np.step(&[], &[], lookup(true)).unwrap();
    assert!(!np.settled, "an active object");
    assert_eq!(kinds(&np), [Persist]);
}

/// The settled path against the full one: random sequences of pair changes, exclusions,
/// sensors, mutable borrows, direct pair additions and removals, moves, and steps with and
/// without active objects, applied to two narrowphases, one of which is never let settle
/// (its flag is cleared before every step). After every step both report the same events
/// and hold the same pairs (objects, touching, sensor and excluded flags, points).
#[test]
fn settled_steps_report_what_full_steps_report() {
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let mut seed = 0x2545_f491_4f6c_dd1du64;
    let mut next = move |n: u64| {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        seed % n
    };
    let all: Vec<(u32, u32)> = (0..6u32)
        .flat_map(|a| (a + 1..6).map(move |b| (a, b)))
        .collect();
    let mut x: Vec<Real> = (0..6).map(|i| 0.9 * i as Real).collect();
    let mut fast = NarrowPhase::<u32>::default();
    let mut reference = NarrowPhase::<u32>::default();
    let mut settled_steps = 0;
    for step in 0..3000 {
        // At most one change before a step, often none (runs of quiet steps).
        let (mut added, mut removed) = (Vec::new(), Vec::new());
        match next(12) {
            0 => {
                let p = all[next(all.len() as u64) as usize];
                if fast.get(p.0, p.1).is_some() {
                    removed.push(p);
                } else {
                    added.push(p);
                }
            }
            1 => {
                let (a, b) = all[next(all.len() as u64) as usize];
                let on = next(2) == 0;
                fast.set_excluded(a, b, on);
                reference.set_excluded(a, b, on);
            }
            2 => {
                let (h, on) = (next(6) as u32, next(2) == 0);
                fast.set_sensor(h, on);
                reference.set_sensor(h, on);
            }
            3 => {
                let _ = fast.pair_slice_mut();
            }
            4 => {
                let (a, b) = all[next(all.len() as u64) as usize];
                if next(2) == 0 {
                    fast.add_pair(a, b);
                    reference.add_pair(a, b);
                } else {
                    fast.remove_pair(a, b);
                    reference.remove_pair(a, b);
                }
            }
            5 => x[next(6) as usize] = 0.3 * next(16) as Real,
            _ => {}
        }
        let active = next(3) == 0;
        let lookup = |h: u32| {
            Some(NarrowObject {
                active,
                ..NarrowObject::new(
                    &ball,
                    Isometry::from_translation(Vec3::new(x[h as usize], 0.0, 0.0)),
                )
            })
        };
        settled_steps +=
            usize::from(fast.settled && !active && added.is_empty() && removed.is_empty());
        reference.settled = false;
        let a = fast
            .step_with(&added, &removed, lookup, active)
            .unwrap()
            .to_vec();
        let b = reference
            .step_with(&added, &removed, lookup, active)
            .unwrap()
            .to_vec();
        assert_eq!(a, b, "step {step}");
        let state = |np: &NarrowPhase<u32>| {
            np.pairs()
                .map(|p| {
                    (
                        p.a,
                        p.b,
                        p.touching,
                        p.sensor,
                        p.excluded,
                        p.manifold.points.len(),
                    )
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(state(&fast), state(&reference), "step {step}");
    }
    assert!(
        settled_steps > 300,
        "the settled path ran {settled_steps} times"
    );
}
