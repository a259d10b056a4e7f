//! Joint rows in the step: prepare, refresh, warm start, solve and store, shared by both
//! solvers. Joints are graph-coloured like the contacts (module `coloring`, Box2D v3's
//! constraint graph colours joints too): the joints of one colour share no dynamic body, so
//! the soft step solves a colour in parallel blocks (module `soft_stages`) and walks the
//! joints colour by colour; sequential impulses (one thread) walk them in joint slot order.
//! Both solve the joints before the contacts of each iteration (Bullet solves non-contact
//! constraints first as well). The colouring depends only on the joint set and
//! which bodies move, so the order — and every bit of the result — is the same for any
//! thread count. The point of a ball, hinge, cone-twist or fixed joint is one world-frame
//! 3×3 block ([`PointBlock`], solved first); runs of the other equality rows (a hinge's
//! alignment, a fixed joint's rotation) are solved as coupled blocks ([`Block`]).
//!
//! The rows live in the world-owned [`JointScratch`]: [`prepare`] fills it once per step
//! in colour order (no allocation once the buffers have grown to the joint count); the soft
//! step lays the same buffers out with [`plan`] and builds each joint's rows in its first
//! joint pass, in parallel blocks, then refreshes the rows in place after each position
//! update (Box3D's split of `b3PrepareJoint` from the substep solves; module
//! `joint::build`).

use super::coloring::{colour_into, ColourScratch, Colouring};
use super::rows::{Block, Motion, PointBlock, Row, RowKind};
use super::{Softness, SolverBody};
use crate::body_set::BodySet;
use crate::joint::{layout, prepare_own, refresh_own, JointRows, JointSet, ROW_SLOTS};
use carom_collision::math::{Real, Vec3, Vec3A};
use std::ops::Range;

/// The joint rows of the current step, reused from step to step: one [`JointRows`] per
/// active joint (in colour order), their rows and blocks in two shared buffers.
#[derive(Debug, Clone, Default)]
pub(crate) struct JointScratch {
    pub joints: Vec<JointRows>,
    pub rows: Vec<Row>,
    pub blocks: Vec<Block>,
    /// Per row (parallel to `rows`): the soft step's impulse summed over the substeps so
    /// far — each substep's accumulated impulse after its last pass (the relax), i.e. the
    /// impulse the row applied in that substep. Breaking compares the step's sum, not the
    /// last substep's impulse scaled up (a load that peaks in an early substep counts).
    /// Summed only for breakable joints (zero for the others: breaking never reads them).
    pub sums: Vec<Real>,
    /// Colour ranges into `joints`; the last one is the overflow colour (possibly empty),
    /// whose joints may share bodies.
    pub colours: Vec<Range<usize>>,
    /// Indices into `joints` in joint slot order: the order in which sequential impulses
    /// visit them (see [`solve`]).
    by_slot: Vec<usize>,
    /// Slots of the active joints, in slot order, and their body pairs (colouring input).
    active: Vec<usize>,
    pairs: Vec<(usize, usize)>,
    colouring: Colouring,
    colour_scratch: ColourScratch,
}

/// Builds the rows of every active joint, with their effective masses, for a step of `h`
/// (sequential impulses: one thread, the whole step); `impulse_in` converts stored per-step
/// impulses to the solver's units: the layout of [`plan`], then every joint built in its
/// slots one after another, so the rows of a colour are contiguous and in the order the
/// passes read them. The soft step builds the joints of a plan in its first joint pass
/// instead, in the colours' parallel blocks.
pub(crate) fn prepare(
    s: &mut JointScratch,
    joints: &JointSet,
    set: &BodySet,
    bodies: &[SolverBody],
    h: Real,
    impulse_in: Real,
) {
    plan(s, joints, bodies);
    let JointScratch {
        joints: planned,
        rows,
        blocks,
        ..
    } = s;
    for jr in planned.iter_mut() {
        let Some(j) = joints.get_index(jr.joint) else {
            continue;
        };
        let (own, own_blocks) = (&mut rows[jr.rows.clone()], &mut blocks[jr.blocks.clone()]);
        let pair = (&bodies[jr.a], &bodies[jr.b]);
        prepare_own(jr, j, set, pair, h, impulse_in, own, own_blocks);
    }
}

/// Lays out the step's joints for the soft step, which builds them in its first joint pass
/// ([`JointView::run`] with `first`, in each colour's parallel blocks): the active joints (not
/// broken, a dynamic body) are coloured, and each gets, in colour order, the next ranges of
/// the shared row and block buffers for its rows and blocks (their counts depend on the
/// joint's description only, [`layout`]). Only this runs serially:
/// building the rows one joint after another was about 1.7 M instructions of every step of
/// "136 ragdolls" (1,360 joints), most of the step's serial preparation.
pub(crate) fn plan(s: &mut JointScratch, joints: &JointSet, bodies: &[SolverBody]) {
    colour_active(s, joints, bodies);
    s.joints.clear();
    s.colours.clear();
    let (mut rows, mut blocks) = (0, 0);
    for r in &s.colouring.ranges {
        let start = s.joints.len();
        for &k in &s.colouring.order[r.clone()] {
            let index = s.active[k];
            let Some(j) = joints.get_index(index) else {
                continue;
            };
            let (n_rows, n_blocks) = layout(&j.desc.kind);
            let (r, b) = (rows..rows + n_rows, blocks..blocks + n_blocks);
            s.joints.push(JointRows::planned(index, j, r, b));
            (rows, blocks) = (rows + n_rows, blocks + n_blocks);
        }
        s.colours.push(start..s.joints.len());
    }
    // Every slot is written by the first joint pass: the buffers only change length (no
    // pass over rows that are about to be overwritten).
    let idle = Row::new(0, [Vec3A::ZERO; 3], 0.0, RowKind::Equality, 0.0);
    s.rows.resize(rows, idle);
    s.blocks.resize(blocks, Block::new(0, 2));
    s.sums.clear();
    s.sums.resize(rows, 0.0);
}

/// The active joints (not broken, a dynamic body) and their colouring.
fn colour_active(s: &mut JointScratch, joints: &JointSet, bodies: &[SolverBody]) {
    s.active.clear();
    s.pairs.clear();
    for (handle, j) in joints.iter() {
        let (a, b) = (j.desc.body_a.index as usize, j.desc.body_b.index as usize);
        // The joints `prepare_joint` leaves out.
        if j.broken || !(bodies[a].dynamic || bodies[b].dynamic) {
            continue;
        }
        s.active.push(handle.index as usize);
        s.pairs.push((a, b));
    }
    let dynamic = |i: usize| bodies[i].dynamic;
    colour_into(
        &s.pairs,
        bodies.len(),
        dynamic,
        &mut s.colour_scratch,
        &mut s.colouring,
    );
}

impl JointScratch {
    /// Lists the prepared joints in joint slot order, the order of [`warm_start`] and
    /// [`solve`]: sequential impulses call it after [`prepare`] (the soft step, which walks
    /// the colours, does not need it).
    pub(crate) fn order_by_slot(&mut self) {
        self.by_slot.clear();
        self.by_slot.extend(0..self.joints.len());
        let joints = &self.joints;
        self.by_slot.sort_unstable_by_key(|&k| joints[k].joint);
    }
}

/// Applies the accumulated impulses of one joint (`point`: its point block, `rows`: its own
/// rows).
#[inline]
pub(crate) fn warm_start_joint(
    point: Option<&PointBlock>,
    rows: &[Row],
    a: &mut Motion,
    b: &mut Motion,
) {
    if let Some(p) = point {
        p.warm_start(a, b);
    }
    for row in rows {
        row.warm_start(a, b);
    }
}

/// Applies the accumulated impulses, in joint slot order (as [`solve`]).
pub(crate) fn warm_start(s: &mut JointScratch, bodies: &mut [SolverBody]) {
    for &k in &s.by_slot {
        let jr = &s.joints[k];
        let (mut a, mut b) = (Motion::of(&bodies[jr.a]), Motion::of(&bodies[jr.b]));
        warm_start_joint(jr.point.as_ref(), &s.rows[jr.rows.clone()], &mut a, &mut b);
        write_back(bodies, jr, a, b);
    }
}

fn write_back(bodies: &mut [SolverBody], jr: &JointRows, a: Motion, b: Motion) {
    a.store(&mut bodies[jr.a]);
    b.store(&mut bodies[jr.b]);
}

/// One pass over one joint (`point`, `rows`, `blocks`: its own): the point block first,
/// then valid blocks of equality rows together, the other rows one by one, in row order.
/// Each error is the one of the last build or refresh.
#[inline]
#[allow(clippy::too_many_arguments)]
pub(crate) fn solve_joint(
    point: Option<&mut PointBlock>,
    rows: &mut [Row],
    blocks: &[Block],
    a: &mut Motion,
    b: &mut Motion,
    soft: Softness,
    inv_h: Real,
    use_bias: bool,
) {
    if let Some(p) = point {
        p.solve(a, b, soft, use_bias);
    }
    let mut i = 0;
    for block in blocks {
        for row in &mut rows[i..block.start] {
            row.solve(a, b, soft, inv_h, use_bias);
        }
        let end = block.start + block.len;
        let run = &mut rows[block.start..end];
        if block.valid {
            block.solve(run, a, b, soft, use_bias);
        } else {
            for row in run {
                row.solve(a, b, soft, inv_h, use_bias);
            }
        }
        i = end;
    }
    for row in &mut rows[i..] {
        row.solve(a, b, soft, inv_h, use_bias);
    }
}

/// One pass over every joint ([`solve_joint`]) for sequential impulses, in joint slot order
/// (the order of creation, typically down a ragdoll's chain): one thread, no need for the
/// colour order, and with the Gauss–Seidel sweep in colour order (joints of one chain
/// visited out of order) the sequential-impulse ragdoll of `tests/joints.rs` kept a jitter
/// of 0.44 m/s, 0.99 rad/s in `f64` instead of 0.017 m/s, 0.034 rad/s.
pub(crate) fn solve(
    s: &mut JointScratch,
    bodies: &mut [SolverBody],
    soft: Softness,
    inv_h: Real,
    use_bias: bool,
) {
    for &k in &s.by_slot {
        let jr = &mut s.joints[k];
        let (mut a, mut b) = (Motion::of(&bodies[jr.a]), Motion::of(&bodies[jr.b]));
        let rows = &mut s.rows[jr.rows.clone()];
        let blocks = &s.blocks[jr.blocks.clone()];
        let point = jr.point.as_mut();
        solve_joint(point, rows, blocks, &mut a, &mut b, soft, inv_h, use_bias);
        write_back(bodies, jr, a, b);
    }
}

/// A joint pass of the soft step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum JointPass {
    /// Apply the accumulated impulses.
    WarmStart,
    /// Solve with soft position feedback.
    Solve,
    /// Refresh the rows to the current poses, then solve without bias.
    Relax,
}

/// Raw views of a [`JointScratch`] for the parallel joint stages (module `soft_stages`):
/// blocks of one colour run at the same time and each touches only its own joints' rows
/// and blocks and their dynamic bodies.
#[derive(Clone, Copy)]
pub(crate) struct JointView {
    joints: *mut JointRows,
    n_joints: usize,
    rows: *mut Row,
    n_rows: usize,
    blocks: *mut Block,
    n_blocks: usize,
    /// [`JointScratch::sums`] (as long as the rows).
    sums: *mut Real,
}

impl JointView {
    /// Views of `s`'s buffers (valid while `s` is neither moved nor resized).
    pub fn new(s: &mut JointScratch) -> JointView {
        JointView {
            joints: s.joints.as_mut_ptr(),
            n_joints: s.joints.len(),
            rows: s.rows.as_mut_ptr(),
            n_rows: s.rows.len(),
            blocks: s.blocks.as_mut_ptr(),
            n_blocks: s.blocks.len(),
            sums: {
                assert_eq!(s.sums.len(), s.rows.len());
                s.sums.as_mut_ptr()
            },
        }
    }

    /// Runs `pass` on the joints `range` (indices into the scratch's joint list), one after
    /// another: each reads its bodies' velocities, updates them through its rows and writes
    /// them back to the dynamic ones. With `first` (the step's first joint pass after a
    /// [`plan`]) each joint first builds its rows and blocks and their effective masses
    /// ([`prepare_own`], for the substep `h`, warm-start impulses scaled by `impulse_in`).
    ///
    /// # Safety
    /// The scratch behind `self` is alive and unchanged; `bodies` points to `n_bodies`
    /// solver bodies; during the call nothing else touches the rows and blocks of these
    /// joints or their dynamic bodies, nor writes their non-dynamic bodies or `set`'s poses
    /// (true for disjoint blocks of one joint colour, or for a block that runs alone).
    #[allow(clippy::too_many_arguments)]
    pub unsafe fn run(
        &self,
        range: Range<usize>,
        pass: JointPass,
        first: bool,
        bodies: *mut SolverBody,
        n_bodies: usize,
        set: &BodySet,
        joints: &JointSet,
        soft: Softness,
        (h, inv_h, impulse_in): (Real, Real, Real),
    ) {
        assert!(range.end <= self.n_joints);
        for i in range {
            let jr = &mut *self.joints.add(i);
            let (rows, blocks) = (jr.rows.clone(), jr.blocks.clone());
            assert!(rows.start <= rows.end && rows.end <= self.n_rows);
            assert!(blocks.start <= blocks.end && blocks.end <= self.n_blocks);
            assert!(jr.a < n_bodies && jr.b < n_bodies && jr.a != jr.b);
            let own = std::slice::from_raw_parts_mut(self.rows.add(rows.start), rows.len());
            let own_blocks =
                std::slice::from_raw_parts_mut(self.blocks.add(blocks.start), blocks.len());
            let (pa, pb) = (bodies.add(jr.a), bodies.add(jr.b));
            if first {
                if let Some(j) = joints.get_index(jr.joint) {
                    let pair = (&*pa, &*pb);
                    prepare_own(jr, j, set, pair, h, impulse_in, own, own_blocks);
                }
            }
            let (mut a, mut b) = (Motion::of(&*pa), Motion::of(&*pb));
            match pass {
                JointPass::WarmStart => warm_start_joint(jr.point.as_ref(), own, &mut a, &mut b),
                JointPass::Solve => {
                    let point = jr.point.as_mut();
                    solve_joint(point, own, own_blocks, &mut a, &mut b, soft, inv_h, true);
                }
                JointPass::Relax => {
                    // Rows follow the new poses (valid until the next position update).
                    if let Some(j) = joints.get_index(jr.joint) {
                        refresh_own(jr, j, set, &*pa, &*pb, own, own_blocks);
                    }
                    let point = jr.point.as_mut();
                    solve_joint(point, own, own_blocks, &mut a, &mut b, soft, inv_h, false);
                    // The relax is the substep's last joint pass: its impulses are the
                    // substep's (summed only where breaking reads them).
                    if jr.breakable {
                        let sums =
                            std::slice::from_raw_parts_mut(self.sums.add(rows.start), rows.len());
                        for (sum, row) in sums.iter_mut().zip(own.iter()) {
                            *sum += row.impulse;
                        }
                        if let Some(p) = &mut jr.point {
                            p.sum += p.impulse;
                        }
                    }
                }
            }
            // Only dynamic bodies are written (a shared static body is only read), through
            // the raw pointers without a reference to the whole body.
            for (p, m) in [(pa, a), (pb, b)] {
                if (*p).dynamic {
                    (*p).v = Vec3::from(m.v);
                    (*p).w = Vec3::from(m.w);
                }
            }
        }
    }
}

/// Stores the impulses (scaled to per-step units) for warm starting, and each joint's
/// peak row impulse of the step for breaking: with `summed` (the soft step) the sum of
/// the row's substep impulses ([`JointScratch::sums`]) of a breakable joint, else the
/// stored impulse (sequential impulses: one step, no substeps; an unbreakable joint, which
/// never breaks).
pub(crate) fn store(s: &JointScratch, joints: &mut JointSet, scale: Real, summed: bool) {
    for jr in &s.joints {
        if let Some(j) = joints.get_index_mut(jr.joint) {
            j.impulses = [0.0; ROW_SLOTS];
            let mut peak: Real = 0.0;
            if let Some(p) = &jr.point {
                // Components along frame A's axes (the three rows' slots before the
                // point became one block), at the last refresh's axes.
                let stored = p.slot_impulses(p.impulse * scale);
                let step = if summed && jr.breakable {
                    p.slot_impulses(p.sum)
                } else {
                    stored
                };
                for i in 0..3 {
                    j.impulses[3 * i] = stored[i];
                    peak = peak.max(step[i].abs());
                }
            }
            for (k, row) in s.rows[jr.rows.clone()].iter().enumerate() {
                let stored = row.impulse * scale;
                j.impulses[row.slot as usize] = stored;
                let step = if summed && jr.breakable {
                    s.sums[jr.rows.start + k]
                } else {
                    stored
                };
                peak = peak.max(step.abs());
            }
            j.step_peak = peak;
        }
    }
}
