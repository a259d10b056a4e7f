//! The tests' reference drivers of the wide passes (module `contact_simd`): every colour in
//! turn, optionally on rayon inside a colour, then the overflow colour on the scalar path.

use super::super::coloring::solve_coloured;
use super::super::contact::ContactConstraint;
use super::super::SolverBody;
use super::run::{Bodies, Closure};
use super::{WideBody, WideConstraint, WideScratch, LANES};

/// Runs `wide_fn` on every wide constraint, colour by colour (in parallel inside a colour of
/// at least `min_batch` constraints when `parallel`), then `scalar_fn` on the overflow
/// colour of `cons`. Same bits whatever the thread count; no allocation. The soft step runs
/// the colours through its stage list instead (module `soft_stages`, [`super::solve_range`]); this
/// driver is the tests' reference.
pub(crate) fn solve<F, S>(
    wide: &mut WideScratch,
    cons: &mut [ContactConstraint],
    bodies: &mut [SolverBody],
    parallel: bool,
    min_batch: usize,
    wide_fn: F,
    scalar_fn: S,
) where
    F: Fn(&mut WideConstraint, &mut WideBody, &mut WideBody) + Sync,
    S: Fn(&mut ContactConstraint, &mut SolverBody, &mut SolverBody) + Sync,
{
    solve_active(
        wide,
        cons,
        bodies,
        (parallel, min_batch),
        |_| true,
        wide_fn,
        scalar_fn,
    );
}

/// [`solve`] on the wide constraints for which `active` holds; the others are skipped
/// without gathering their bodies (e.g. restitution on constraints without restitution).
pub(crate) fn solve_active<A, F, S>(
    wide: &mut WideScratch,
    cons: &mut [ContactConstraint],
    bodies: &mut [SolverBody],
    (parallel, min_batch): (bool, usize),
    active: A,
    wide_fn: F,
    scalar_fn: S,
) where
    A: Fn(&WideConstraint) -> bool + Sync,
    F: Fn(&mut WideConstraint, &mut WideBody, &mut WideBody) + Sync,
    S: Fn(&mut ContactConstraint, &mut SolverBody, &mut SolverBody) + Sync,
{
    for r in &wide.ranges {
        let chunk = &mut wide.cons[r.clone()];
        let shared = Bodies {
            ptr: bodies.as_mut_ptr(),
            len: bodies.len(),
        };
        let go_parallel = parallel && chunk.len() * LANES >= min_batch.max(2);
        if go_parallel && solve_parallel(chunk, shared, &wide_fn, &active) {
            continue;
        }
        for c in chunk.iter_mut() {
            // SAFETY: `shared` is the only access to `bodies` here; one constraint at a time.
            unsafe { shared.run::<_, _, 0>(c, &Closure(&wide_fn), &active) };
        }
    }
    let overflow = wide.overflow.clone();
    solve_coloured(cons, &[overflow], bodies, false, min_batch, scalar_fn);
}

#[cfg(feature = "parallel")]
fn solve_parallel<F, A>(chunk: &mut [WideConstraint], shared: Bodies, f: &F, active: &A) -> bool
where
    F: Fn(&mut WideConstraint, &mut WideBody, &mut WideBody) + Sync,
    A: Fn(&WideConstraint) -> bool + Sync,
{
    use rayon::prelude::*;
    if rayon::current_num_threads() < 2 {
        return false;
    }
    // SAFETY: the wide constraints of one colour share no dynamic body, so the parallel
    // calls write disjoint bodies; non-dynamic bodies are only read.
    chunk
        .par_iter_mut()
        .with_min_len(16)
        .for_each(|c| unsafe { shared.run::<_, _, 0>(c, &Closure(f), active) });
    true
}

#[cfg(not(feature = "parallel"))]
fn solve_parallel<F, A>(_: &mut [WideConstraint], _: Bodies, _: &F, _: &A) -> bool {
    false
}
