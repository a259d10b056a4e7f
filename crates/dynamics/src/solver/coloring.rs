//! Graph colouring of constraints so a colour can be solved in parallel.
//!
//! Box2D v3 (`constraint_graph.c`): each constraint takes the lowest colour in which neither
//! of its *dynamic* bodies is used yet (static and kinematic bodies are never written, so
//! they can be shared). Constraints that find no free colour go to an overflow colour solved
//! sequentially. The assignment depends only on the constraint order, so the solve order —
//! and hence the result — is the same for any thread count.

use super::SolverBody;
use std::ops::Range;

/// Number of colours before the overflow colour.
pub(crate) const COLOURS: usize = 24;

/// A constraint between two solver bodies, solved by reading and writing only those two.
pub(crate) trait PairConstraint: Send {
    /// The two body slots.
    fn bodies(&self) -> (usize, usize);
}

/// Constraint order (a permutation) and colour ranges into it; the last range is the
/// overflow colour (possibly empty).
#[derive(Debug, Clone, Default)]
pub(crate) struct Colouring {
    pub order: Vec<usize>,
    pub ranges: Vec<Range<usize>>,
}

/// Colours `pairs` (body slots of each constraint); `dynamic[i]` tells whether body `i` is
/// written by the solver.
pub(crate) fn colour(pairs: &[(usize, usize)], dynamic: &[bool]) -> Colouring {
    let mut used = vec![0u32; dynamic.len()];
    let mut colour_of = Vec::with_capacity(pairs.len());
    let mut counts = [0usize; COLOURS + 1];
    for &(a, b) in pairs {
        let mask = (if dynamic[a] { used[a] } else { 0 }) | (if dynamic[b] { used[b] } else { 0 });
        let c = (!mask).trailing_zeros() as usize;
        let c = if c < COLOURS { c } else { COLOURS };
        if c < COLOURS {
            if dynamic[a] {
                used[a] |= 1 << c;
            }
            if dynamic[b] {
                used[b] |= 1 << c;
            }
        }
        colour_of.push(c);
        counts[c] += 1;
    }
    let mut starts = [0usize; COLOURS + 2];
    for c in 0..=COLOURS {
        starts[c + 1] = starts[c] + counts[c];
    }
    let mut next = starts;
    let mut order = vec![0; pairs.len()];
    for (k, &c) in colour_of.iter().enumerate() {
        order[next[c]] = k;
        next[c] += 1;
    }
    let ranges = (0..=COLOURS)
        .filter(|&c| counts[c] > 0 || c == COLOURS)
        .map(|c| starts[c]..starts[c + 1])
        .collect();
    Colouring { order, ranges }
}

/// Runs `f` on every constraint, colour by colour. Inside a colour, constraints run in
/// parallel when `parallel` and the colour holds at least `min_batch` constraints; each call
/// works on copies of its two bodies that are written back afterwards, so the result is the
/// same bits as the sequential loop. The overflow colour always runs sequentially.
pub(crate) fn solve_coloured<C, F>(
    cons: &mut [C],
    ranges: &[Range<usize>],
    bodies: &mut [SolverBody],
    parallel: bool,
    min_batch: usize,
    f: F,
) where
    C: PairConstraint,
    F: Fn(&mut C, &mut SolverBody, &mut SolverBody) + Sync,
{
    let last = ranges.len().saturating_sub(1);
    for (k, r) in ranges.iter().enumerate() {
        let chunk = &mut cons[r.clone()];
        let go_parallel = parallel && k != last && chunk.len() >= min_batch.max(2);
        if go_parallel && solve_parallel(chunk, bodies, &f) {
            continue;
        }
        for c in chunk.iter_mut() {
            let (ia, ib) = c.bodies();
            let (mut a, mut b) = (bodies[ia], bodies[ib]);
            f(c, &mut a, &mut b);
            write_back(bodies, ia, a, ib, b);
        }
    }
}

#[inline]
fn write_back(bodies: &mut [SolverBody], ia: usize, a: SolverBody, ib: usize, b: SolverBody) {
    if a.dynamic {
        bodies[ia] = a;
    }
    if b.dynamic {
        bodies[ib] = b;
    }
}

#[cfg(feature = "parallel")]
fn solve_parallel<C, F>(chunk: &mut [C], bodies: &mut [SolverBody], f: &F) -> bool
where
    C: PairConstraint,
    F: Fn(&mut C, &mut SolverBody, &mut SolverBody) + Sync,
{
    use rayon::prelude::*;
    let shared: &[SolverBody] = bodies;
    let results: Vec<(usize, SolverBody, usize, SolverBody)> = chunk
        .par_iter_mut()
        .map(|c| {
            let (ia, ib) = c.bodies();
            let (mut a, mut b) = (shared[ia], shared[ib]);
            f(c, &mut a, &mut b);
            (ia, a, ib, b)
        })
        .collect();
    for (ia, a, ib, b) in results {
        write_back(bodies, ia, a, ib, b);
    }
    true
}

#[cfg(not(feature = "parallel"))]
fn solve_parallel<C, F>(_: &mut [C], _: &mut [SolverBody], _: &F) -> bool {
    false
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn colours_share_no_dynamic_body() {
        // A chain 0-1-2-3-4 plus everything touching static body 5.
        let pairs = [
            (0, 1),
            (1, 2),
            (2, 3),
            (3, 4),
            (0, 5),
            (1, 5),
            (2, 5),
            (4, 0),
        ];
        let dynamic = [true, true, true, true, true, false];
        let c = colour(&pairs, &dynamic);
        let mut seen: Vec<usize> = c.order.clone();
        seen.sort_unstable();
        assert_eq!(seen, (0..pairs.len()).collect::<Vec<_>>());
        for r in &c.ranges[..c.ranges.len() - 1] {
            let mut touched = vec![false; dynamic.len()];
            for &k in &c.order[r.clone()] {
                for body in [pairs[k].0, pairs[k].1] {
                    if dynamic[body] {
                        assert!(!touched[body], "body {body} twice in one colour");
                        touched[body] = true;
                    }
                }
            }
        }
    }
}
