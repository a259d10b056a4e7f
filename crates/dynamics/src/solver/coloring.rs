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

/// Reusable buffers of [`colour_into`]: kept by the world between steps (cleared, not
/// freed), so colouring allocates nothing once they have grown to the scene.
#[derive(Debug, Clone, Default)]
pub(crate) struct ColourScratch {
    /// Colour bit set of each body.
    used: Vec<u32>,
    /// Colour of each constraint.
    colour_of: Vec<usize>,
}

/// Colours `pairs` (body slots of each constraint, below `body_count`); `dynamic(i)` tells
/// whether body `i` is written by the solver.
#[cfg(test)]
pub(crate) fn colour(
    pairs: &[(usize, usize)],
    body_count: usize,
    dynamic: impl Fn(usize) -> bool,
) -> Colouring {
    let mut out = Colouring::default();
    colour_into(
        pairs,
        body_count,
        dynamic,
        &mut ColourScratch::default(),
        &mut out,
    );
    out
}

/// [`colour`] into reused buffers: `out` is overwritten, `scratch` holds the working arrays.
/// Allocates only when a buffer must grow.
pub(crate) fn colour_into(
    pairs: &[(usize, usize)],
    body_count: usize,
    dynamic: impl Fn(usize) -> bool,
    scratch: &mut ColourScratch,
    out: &mut Colouring,
) {
    let used = &mut scratch.used;
    used.clear();
    used.resize(body_count, 0);
    let colour_of = &mut scratch.colour_of;
    colour_of.clear();
    let mut counts = [0usize; COLOURS + 1];
    for &(a, b) in pairs {
        let (da, db) = (dynamic(a), dynamic(b));
        let mask = (if da { used[a] } else { 0 }) | (if db { used[b] } else { 0 });
        let c = (!mask).trailing_zeros() as usize;
        let c = if c < COLOURS { c } else { COLOURS };
        if c < COLOURS {
            if da {
                used[a] |= 1 << c;
            }
            if db {
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
    out.order.clear();
    out.order.resize(pairs.len(), 0);
    for (k, &c) in colour_of.iter().enumerate() {
        out.order[next[c]] = k;
        next[c] += 1;
    }
    out.ranges.clear();
    out.ranges.extend(
        (0..=COLOURS)
            .filter(|&c| counts[c] > 0 || c == COLOURS)
            .map(|c| starts[c]..starts[c + 1]),
    );
}

/// Runs `f` on every constraint, colour by colour. Inside a colour, constraints run in
/// parallel when `parallel`, the colour holds at least `min_batch` constraints and rayon has
/// more than one thread. Every call works in place on its two bodies: a colour's constraints
/// share no dynamic body, so they write disjoint bodies, and a static or kinematic body
/// (shared, never written) is handed over as a copy. The result is the same bits as the
/// sequential loop, whatever the thread count. The overflow colour always runs
/// sequentially. No allocation.
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
        let shared = SharedBodies::new(bodies);
        for c in chunk.iter_mut() {
            // SAFETY: `shared` is the only access to `bodies` in this loop and the
            // constraints run one at a time.
            unsafe { shared.with_pair(c, &f) };
        }
    }
}

/// Runs `f` on the constraints `range` of `cons`, one after another, each in place on its
/// dynamic bodies as in [`solve_coloured`]: one block of a colour (or the whole overflow
/// colour) in the stage-parallel soft step (module `stages`).
///
/// # Safety
/// `cons` points to at least `range.end` constraints and `bodies` to `len` solver bodies;
/// during the call no other live reference touches those constraints or their dynamic bodies
/// (true for disjoint blocks of one colour, or for a block that runs alone).
pub(crate) unsafe fn solve_range<C, F>(
    cons: *mut C,
    range: Range<usize>,
    bodies: *mut SolverBody,
    len: usize,
    f: &F,
) where
    C: PairConstraint,
    F: Fn(&mut C, &mut SolverBody, &mut SolverBody),
{
    let shared = SharedBodies { ptr: bodies, len };
    for i in range {
        shared.with_pair(&mut *cons.add(i), f);
    }
}

/// Raw access to the solver bodies for the constraints of one colour.
#[derive(Clone, Copy)]
struct SharedBodies {
    ptr: *mut SolverBody,
    len: usize,
}

// SAFETY: used only to solve the constraints of one colour, which write disjoint dynamic
// bodies (the colouring guarantees it) and never write non-dynamic ones.
unsafe impl Send for SharedBodies {}
unsafe impl Sync for SharedBodies {}

impl SharedBodies {
    fn new(bodies: &mut [SolverBody]) -> Self {
        SharedBodies {
            ptr: bodies.as_mut_ptr(),
            len: bodies.len(),
        }
    }

    /// Runs `f` on constraint `c` with mutable access to its dynamic bodies in place and
    /// copies of its non-dynamic ones.
    ///
    /// # Safety
    /// No other live reference may touch the dynamic bodies of `c` during the call: the
    /// caller runs only constraints of one colour concurrently.
    #[inline(always)]
    unsafe fn with_pair<C, F>(self, c: &mut C, f: &F)
    where
        C: PairConstraint,
        F: Fn(&mut C, &mut SolverBody, &mut SolverBody),
    {
        let (ia, ib) = c.bodies();
        assert!(ia < self.len && ib < self.len);
        debug_assert_ne!(ia, ib);
        let (pa, pb) = (self.ptr.add(ia), self.ptr.add(ib));
        let (mut ca, mut cb);
        let a: &mut SolverBody = if (*pa).dynamic {
            &mut *pa
        } else {
            ca = *pa;
            &mut ca
        };
        let b: &mut SolverBody = if (*pb).dynamic {
            &mut *pb
        } else {
            cb = *pb;
            &mut cb
        };
        f(c, a, b);
    }
}

#[cfg(feature = "parallel")]
fn solve_parallel<C, F>(chunk: &mut [C], bodies: &mut [SolverBody], f: &F) -> bool
where
    C: PairConstraint,
    F: Fn(&mut C, &mut SolverBody, &mut SolverBody) + Sync,
{
    use rayon::prelude::*;
    if rayon::current_num_threads() < 2 {
        return false;
    }
    let shared = SharedBodies::new(bodies);
    // SAFETY: the constraints of one colour share no dynamic body (see `colour`), so the
    // parallel calls write disjoint bodies; non-dynamic bodies are only read (copied).
    chunk
        .par_iter_mut()
        .with_min_len(64)
        .for_each(|c| unsafe { shared.with_pair(c, f) });
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
        let c = colour(&pairs, dynamic.len(), |i| dynamic[i]);
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
