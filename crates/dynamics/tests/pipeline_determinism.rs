//! Determinism of the full pipeline: a pile of mixed bodies hashes to the same bits on 1 and
//! 2 threads and across runs (narrowphase in parallel over pairs, solver colours in parallel).
mod pipeline;
use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::*;
use pipeline::*;

fn pile_hash(n_steps: usize) -> u64 {
    let mut p = PipelineParams::default();
    p.dynamics.solver.parallel_min_batch = 2;
    let mut w = World::new(p).unwrap();
    ground(&mut w, 0.6);
    let mut k = 0;
    for layer in 0..6 {
        for i in 0..5 {
            for j in 0..5 {
                k += 1;
                let p = Vec3::new(
                    i as Real * 0.9 + 0.13 * layer as Real,
                    0.6 + layer as Real * 1.1,
                    j as Real * 0.9 - 0.07 * layer as Real,
                );
                let rot = Quat::from_rotation_y(0.1 * k as Real)
                    * Quat::from_rotation_x(0.05 * layer as Real);
                let shape = if k % 3 == 0 {
                    sphere(0.4)
                } else {
                    cuboid(Vec3::new(0.4, 0.3, 0.35))
                };
                w.add_body(&BodyDesc::dynamic(shape, Isometry::new(p, rot), 800.0))
                    .unwrap();
            }
        }
    }
    let mut touched = 0;
    for _ in 0..n_steps {
        touched = touched.max(w.step(1.0 / 60.0).unwrap().manifolds);
    }
    assert!(touched > 100, "the pile never formed ({touched} manifolds)");
    w.state_hash()
}

#[test]
fn pile_is_bit_identical_on_one_and_two_threads_and_across_runs() {
    let n = steps(240, 120);
    let run = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| pile_hash(n))
    };
    let one = run(1);
    let two = run(2);
    let again = run(2);
    assert_eq!(one, two, "1 vs 2 threads");
    assert_eq!(two, again, "two runs");
}

/// The 136-ragdoll benchmark scene (1360 hinge and cone-twist joints), both solvers: the
/// joint rows are prepared, refreshed and solved sequentially, the contacts in parallel.
fn ragdoll_hash(kind: SolverKind, n_steps: usize) -> u64 {
    let mut p = PipelineParams::default();
    p.dynamics.solver.parallel_min_batch = 2;
    p.dynamics.solver.kind = kind;
    let mut w = World::from_scene_with(&carom_scenes::bullet::ragdolls(), p).unwrap();
    let mut touched = 0;
    for _ in 0..n_steps {
        touched = touched.max(w.step(1.0 / 60.0).unwrap().manifolds);
    }
    assert!(
        touched > 100,
        "{kind:?}: the ragdolls never landed ({touched} manifolds)"
    );
    w.state_hash()
}

#[test]
fn ragdolls_are_bit_identical_on_one_and_two_threads() {
    let n = steps(90, 45);
    for kind in [SolverKind::SoftStep, SolverKind::SequentialImpulse] {
        let run = |threads: usize| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| ragdoll_hash(kind, n))
        };
        assert_eq!(run(1), run(2), "{kind:?}: 1 vs 2 threads");
    }
}
