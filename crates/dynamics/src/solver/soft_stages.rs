//! The soft step's stage list and the executor of its blocks (Box2D v3's `b2SolverStage_*`
//! values and `b2ExecuteBlock`), run by module `stages`.
//!
//! First the contact constraints are built (SIMD only): each colour's wide constraints in
//! the same blocks as that colour's pass stages, so on two threads each core builds the
//! constraints it then solves (they are in its cache), and the colours of one block and
//! the overflow colour in one stage of one block each (Box2D v3 prepares its contacts in a
//! parallel stage too, `b2PrepareContactsTask`). Then,
//! per substep: integrate velocities (blocks of bodies; the first also computes the bodies'
//! per-step terms); warm start every joint colour
//! (blocks of joints; the joint overflow colour one block), then every contact colour
//! (blocks of constraints), then the contact overflow colour (one block); solve likewise;
//! integrate positions (blocks of bodies); refresh and relax every joint colour (each joint
//! refreshes its rows, then solves), relax every contact colour and the overflow colour.
//! After the last substep: restitution over the colours and the overflow colour; then the
//! store (velocities and world inertias into the body set in blocks of bodies, the wide
//! constraints' impulses into their manifolds in blocks of wide constraints, as Box2D v3's
//! `b2FinalizeBodies` and `b2StoreImpulses` stages). This is
//! exactly the order of the sequential solve, and inside a stage the blocks touch disjoint
//! bodies (a colour's constraints share no dynamic body; a body stage handles each body
//! once), so the result is the same bits whatever the thread count. Block sizes are
//! constants and never depend on the thread count. Consecutive contact colours too small to
//! split (and the overflow colour) form one serial stage ([`SoftStage::Serial`]): the same
//! order, fewer barriers.

use super::coloring;
use super::contact::{self, ContactConstraint, ContactScratch};
use super::contact_simd::{self, WideConstraint};
use super::joints::{JointPass, JointScratch, JointView};
use super::stages::{block_count, block_range, StageList};
use super::{Softness, SolverBody};
use crate::body_set::{world_inertia, BodyInfo, BodySet};
use crate::contact::ContactManifold;
use crate::integrate::{self, BodyTerms};
use crate::joint::JointSet;
use carom_collision::math::{Mat3, Quat, Real, Vec3};
use std::ops::Range;

/// Bodies per block of the body stages.
pub(crate) const BODY_BLOCK: usize = 128;
/// Wide (four-lane) constraints per block of a colour stage.
pub(crate) const WIDE_BLOCK: usize = 16;
/// Scalar constraints per block of a colour stage (SIMD off).
pub(crate) const SCALAR_BLOCK: usize = 64;
/// Wide constraints per block of the impulse store stage.
pub(crate) const STORE_BLOCK: usize = 64;
/// Joints per block of a joint colour stage.
pub(crate) const JOINT_BLOCK: usize = 32;
/// Scalar constraints a joint counts as when its colour is compared with
/// [`super::SolverParams`]'s `parallel_min_batch` (a ragdoll joint has six or seven rows,
/// refreshed and solved, several times a contact's work).
const JOINT_WEIGHT: usize = 8;

/// Blocks of a contact colour of `len` items (wide constraints with SIMD, `lanes` scalar
/// constraints each): none for an empty colour, one below `min_batch` scalar constraints,
/// else blocks of [`WIDE_BLOCK`] (SIMD) or [`SCALAR_BLOCK`] items. Depends only on the
/// counts, never on the thread count.
fn colour_blocks(len: usize, lanes: usize, min_batch: usize) -> usize {
    if len == 0 {
        0
    } else if len * lanes < min_batch {
        1
    } else {
        block_count(len, if lanes > 1 { WIDE_BLOCK } else { SCALAR_BLOCK })
    }
}

/// A contact or joint pass.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Pass {
    /// Apply the accumulated impulses.
    WarmStart,
    /// Solve with soft position feedback.
    Solve,
    /// Solve without bias (the joints' rows refreshed to the new poses first).
    Relax,
    /// Restitution (contacts only, after the last substep).
    Restitution,
}

/// One stage of the soft step.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum SoftStage {
    /// Gravity, forces, damping and the gyroscopic term, in blocks of bodies. The flag
    /// marks the step's first one, whose blocks first compute their bodies' per-step terms
    /// (`integrate::fill_terms`; only the selection of the moving bodies,
    /// `integrate::select_terms`, runs before the list), in the blocks every later body
    /// stage uses.
    IntegrateVelocities(bool),
    /// Joint colour `k` (an index into the joint colour ranges, the last one the joint
    /// overflow colour, which is one block), in blocks of joints. The flag marks the step's
    /// first joint pass, which first computes the effective masses of the joints' rows
    /// (left out of the serial `joints::prepare`, so they are computed in the colour's
    /// parallel blocks).
    Joints(Pass, u8, bool),
    /// Colour `k` (an index into the colour ranges), in blocks of constraints.
    Colour(Pass, u8),
    /// Contact colours `lo..hi` one after another in one block, index `colours.len()` being
    /// the overflow colour (whose constraints may share bodies): a run of colours that are
    /// one block each (too small to split), fused into one stage. The order is the one of
    /// separate one-block stages, so the bits are the same; the threads meet at one barrier
    /// per run instead of one per colour.
    Serial(Pass, u8, u8),
    /// Speed clamp and position update, in blocks of bodies.
    IntegratePositions,
    /// After the last pass: velocities back into the body set and the world inverse
    /// inertias refreshed from the new rotations (`integrate::store`), in blocks of bodies.
    StoreBodies,
    /// After the last pass: the wide constraints' impulses back into their manifolds
    /// (`contact_simd::store`), in blocks of [`STORE_BLOCK`] wide constraints.
    StoreImpulses,
    /// Before the first substep (SIMD): builds the wide constraints of colour `k` (an index
    /// into the colour ranges) in the blocks of that colour's pass stages
    /// ([`Shape::colour_blocks`]), so block `b` is built by the worker that starts at block
    /// `b` of the passes.
    Prepare(u8),
    /// Before the first substep (SIMD): one block per contact colour of one block, in
    /// colour order, then (if any) one block for the scalar constraints of the overflow
    /// colour.
    PrepareRest,
}

/// What the stage list of a step depends on.
pub(crate) struct Shape<'a> {
    pub substeps: u32,
    pub warm_starting: bool,
    /// Joint colour ranges, the last one the overflow colour.
    pub joint_colours: &'a [Range<usize>],
    /// Colour ranges (wide constraints with SIMD, scalar ones without), overflow excluded.
    pub colours: &'a [Range<usize>],
    /// Scalar constraints per item of `colours` (4 with SIMD, else 1).
    pub lanes: usize,
    /// Constraints of the overflow colour.
    pub overflow: usize,
    /// Moving bodies (integration terms).
    pub bodies: usize,
    /// Colours of fewer scalar constraints are one block ([`super::SolverParams`]'s
    /// `parallel_min_batch`).
    pub min_batch: usize,
    /// Wide constraints whose impulses the store stage writes back (0 without SIMD).
    pub wide: usize,
    /// Whether the list starts with the stages that build the contact constraints (SIMD:
    /// `contact::prepare` only assigned the lanes).
    pub prepare: bool,
}

impl Shape<'_> {
    /// Blocks of colour `r`.
    fn colour_blocks(&self, r: &Range<usize>) -> usize {
        colour_blocks(r.len(), self.lanes, self.min_batch)
    }

    /// Blocks of joint colour `k`.
    fn joint_blocks(&self, k: usize, r: &Range<usize>) -> usize {
        if r.is_empty() {
            0
        } else if k + 1 == self.joint_colours.len() || r.len() * JOINT_WEIGHT < self.min_batch {
            1
        } else {
            block_count(r.len(), JOINT_BLOCK)
        }
    }

    /// The contact and joint stages of one pass; `first` marks the step's first joint pass.
    fn pass(&self, list: &mut StageList<SoftStage>, pass: Pass, first: bool) {
        if pass != Pass::Restitution {
            for (k, r) in self.joint_colours.iter().enumerate() {
                let blocks = self.joint_blocks(k, r);
                let k = u8::try_from(k).unwrap_or(u8::MAX);
                list.push(SoftStage::Joints(pass, k, first), blocks);
            }
        }
        let byte = |k: usize| u8::try_from(k).unwrap_or(u8::MAX);
        // Start of the pending run of one-block colours.
        let mut run: Option<usize> = None;
        let flush = |list: &mut StageList<SoftStage>, run: &mut Option<usize>, end: usize| {
            if let Some(start) = run.take() {
                list.push(SoftStage::Serial(pass, byte(start), byte(end)), 1);
            }
        };
        for (k, r) in self.colours.iter().enumerate() {
            match self.colour_blocks(r) {
                0 => {}
                1 => {
                    run.get_or_insert(k);
                }
                blocks => {
                    flush(list, &mut run, k);
                    list.push(SoftStage::Colour(pass, byte(k)), blocks);
                }
            }
        }
        let n = self.colours.len();
        if self.overflow > 0 {
            run.get_or_insert(n);
            flush(list, &mut run, n + 1);
        } else {
            flush(list, &mut run, n);
        }
    }
}

/// Fills `list` with the stages of one soft step.
pub(crate) fn plan(list: &mut StageList<SoftStage>, s: &Shape) {
    list.clear();
    if s.prepare {
        let mut rest = usize::from(s.overflow > 0);
        for (k, r) in s.colours.iter().enumerate() {
            match s.colour_blocks(r) {
                0 => {}
                1 => rest += 1,
                blocks => list.push(
                    SoftStage::Prepare(u8::try_from(k).unwrap_or(u8::MAX)),
                    blocks,
                ),
            }
        }
        list.push(SoftStage::PrepareRest, rest);
    }
    let body_blocks = block_count(s.bodies, BODY_BLOCK);
    for i in 0..s.substeps {
        list.push(SoftStage::IntegrateVelocities(i == 0), body_blocks);
        if s.warm_starting {
            s.pass(list, Pass::WarmStart, i == 0);
        }
        s.pass(list, Pass::Solve, i == 0 && !s.warm_starting);
        list.push(SoftStage::IntegratePositions, body_blocks);
        s.pass(list, Pass::Relax, false);
    }
    s.pass(list, Pass::Restitution, false);
    list.push(SoftStage::StoreBodies, body_blocks);
    list.push(SoftStage::StoreImpulses, block_count(s.wide, STORE_BLOCK));
}

/// Per-step constants of the passes.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Consts {
    pub h: Real,
    pub inv_h: Real,
    pub joint_soft: Softness,
    pub max_push: Real,
    pub restitution_threshold: Real,
    pub simd: bool,
    /// Factor of the stored impulses (per substep to per step: the substep count).
    pub impulse_scale: Real,
    /// Factor of the manifolds' stored impulses for the prepare stages (per step to per
    /// substep; 0 without warm starting).
    pub impulse_in: Real,
    /// Contact softness between two dynamic bodies and against a non-dynamic one.
    pub contact_soft: (Softness, Softness),
    /// [`Shape::min_batch`], for the prepare stages to find the colours of one block.
    pub min_batch: usize,
    /// Gravity, for the bodies' per-step terms.
    pub gravity: Vec3,
    /// Whether the velocity update takes the implicit gyroscopic term.
    pub gyroscopic: bool,
}

/// Raw views of everything the blocks write, shared by the threads of the region.
struct Shared<'a> {
    c: Consts,
    bodies: *mut SolverBody,
    n_bodies: usize,
    terms: *mut BodyTerms,
    n_terms: usize,
    set: *mut BodySet,
    position: *mut Vec3,
    rotation: *mut Quat,
    n_poses: usize,
    linear_velocity: *mut Vec3,
    angular_velocity: *mut Vec3,
    inv_inertia_world: *mut Mat3,
    info: *const BodyInfo,
    n_store: usize,
    manifolds: *mut ContactManifold,
    n_manifolds: usize,
    wide: *mut WideConstraint,
    n_wide: usize,
    colours: &'a [Range<usize>],
    cons: *mut ContactConstraint,
    n_cons: usize,
    overflow: Range<usize>,
    /// Colour-order position of the overflow colour's first constraint.
    overflow_order: usize,
    /// The lanes of each wide constraint (colour-order positions).
    members: &'a [[usize; contact_simd::LANES]],
    /// Manifold index of each selected manifold.
    selected: &'a [usize],
    /// The colour order (selection index at each position).
    order: &'a [usize],
    rows: JointView,
    joint_colours: &'a [Range<usize>],
    joints: &'a JointSet,
}

// SAFETY: the stage machinery runs blocks of one stage at a time, and the blocks of a stage
// write disjoint data (see the module docs and `Shared::exec`); everything else is read.
unsafe impl Sync for Shared<'_> {}

/// Runs the stages of `list` (from [`plan`]) on up to `threads` threads.
#[allow(clippy::too_many_arguments)]
pub(crate) fn run(
    list: &mut StageList<SoftStage>,
    threads: usize,
    c: Consts,
    set: &mut BodySet,
    bodies: &mut [SolverBody],
    terms: &mut [BodyTerms],
    scratch: &mut ContactScratch,
    rows: &mut JointScratch,
    joints: &JointSet,
    manifolds: &mut [ContactManifold],
) {
    let n_poses = set.position.len().min(set.rotation.len());
    let n_store = [
        set.linear_velocity.len(),
        set.angular_velocity.len(),
        set.inv_inertia_world.len(),
        set.info.len(),
    ]
    .into_iter()
    .fold(n_poses, usize::min);
    let (colours, overflow) = if c.simd {
        (&scratch.wide.ranges[..], scratch.wide.overflow.clone())
    } else {
        let r = &scratch.colouring.ranges[..];
        let (last, colours) = r.split_last().map_or((0..0, r), |(l, c)| (l.clone(), c));
        (colours, last)
    };
    let overflow_order = scratch.colouring.ranges.last().map_or(0, |r| r.start);
    let shared = Shared {
        c,
        n_bodies: bodies.len(),
        bodies: bodies.as_mut_ptr(),
        n_terms: terms.len(),
        terms: terms.as_mut_ptr(),
        position: set.position.as_mut_ptr(),
        rotation: set.rotation.as_mut_ptr(),
        n_poses,
        linear_velocity: set.linear_velocity.as_mut_ptr(),
        angular_velocity: set.angular_velocity.as_mut_ptr(),
        inv_inertia_world: set.inv_inertia_world.as_mut_ptr(),
        info: set.info.as_ptr(),
        n_store,
        n_manifolds: manifolds.len(),
        manifolds: manifolds.as_mut_ptr(),
        set,
        n_wide: scratch.wide.cons.len(),
        wide: scratch.wide.cons.as_mut_ptr(),
        colours,
        n_cons: scratch.cons.len(),
        cons: scratch.cons.as_mut_ptr(),
        overflow,
        overflow_order,
        members: &scratch.wide.members,
        selected: scratch.selected(),
        order: &scratch.colouring.order,
        rows: JointView::new(rows),
        joint_colours: &rows.colours,
        joints,
    };
    // SAFETY: see `Shared::exec`.
    list.run(threads, |kind, block, blocks| unsafe {
        shared.exec(kind, block, blocks)
    });
}

impl Shared<'_> {
    /// Runs block `block` of the `blocks` blocks of a stage of kind `kind` (each block an
    /// even share of the stage's items, [`block_range`]).
    ///
    /// # Safety
    /// Only blocks of one stage run at the same time. Body blocks touch the bodies (and their
    /// terms and poses) of their own range of terms, and every body appears in one term;
    /// contact and joint colour blocks touch their own constraints (joints: rows and blocks)
    /// and their dynamic bodies, disjoint within a colour, and only read non-dynamic bodies
    /// and the poses; serial stages are a single block. Prepare blocks write their own wide
    /// constraints (or the overflow colour's scalar constraints, one block) and only read
    /// the manifolds, the body set and the solver bodies, which no block of those stages
    /// writes; the first velocity stage's blocks write the terms of their own range.
    unsafe fn exec(&self, kind: SoftStage, block: usize, blocks: usize) {
        let c = &self.c;
        match kind {
            SoftStage::IntegrateVelocities(first) => {
                for i in block_range(self.n_terms, blocks, block) {
                    let t = &mut *self.terms.add(i);
                    let s = t.slot();
                    assert!(s < self.n_bodies && s < self.n_poses);
                    if first {
                        let (set, b) = (&*self.set, &*self.bodies.add(s));
                        integrate::fill_terms(t, set, b, c.gravity, c.h, c.gyroscopic);
                    }
                    let q = *self.rotation.add(s);
                    integrate::integrate_velocity(t, q, &mut *self.bodies.add(s), c.h);
                }
            }
            SoftStage::IntegratePositions => {
                for i in block_range(self.n_terms, blocks, block) {
                    let t = &*self.terms.add(i);
                    let s = t.slot();
                    assert!(s < self.n_bodies && s < self.n_poses);
                    let (p, q) = (&mut *self.position.add(s), &mut *self.rotation.add(s));
                    let b = &mut *self.bodies.add(s);
                    integrate::clamp_and_integrate_position(t, p, q, b, c.h);
                }
            }
            SoftStage::StoreBodies => {
                for i in block_range(self.n_terms, blocks, block) {
                    let s = (*self.terms.add(i)).slot();
                    assert!(s < self.n_bodies && s < self.n_store);
                    let b = &*self.bodies.add(s);
                    if b.dynamic {
                        *self.linear_velocity.add(s) = b.v;
                        *self.angular_velocity.add(s) = b.w;
                        let inv_local = &(*self.info.add(s)).inv_inertia_local;
                        *self.inv_inertia_world.add(s) =
                            world_inertia(*self.rotation.add(s), inv_local);
                    }
                }
            }
            SoftStage::Prepare(k) => {
                let r = &self.colours[k as usize];
                let b = block_range(r.len(), blocks, block);
                self.prepare_wide(r.start + b.start..r.start + b.end);
            }
            SoftStage::PrepareRest => {
                let small = self
                    .colours
                    .iter()
                    .filter(|r| colour_blocks(r.len(), contact_simd::LANES, c.min_batch) == 1)
                    .nth(block);
                match small {
                    Some(r) => self.prepare_wide(r.clone()),
                    None => self.prepare_overflow(),
                }
            }
            SoftStage::StoreImpulses => {
                let b = block_range(self.n_wide, blocks, block);
                let (m, n) = (self.manifolds, self.n_manifolds);
                contact_simd::store_range(self.wide, b, m, n, c.impulse_scale);
            }
            SoftStage::Joints(pass, k, first) => {
                let pass = match pass {
                    Pass::WarmStart => JointPass::WarmStart,
                    Pass::Solve => JointPass::Solve,
                    Pass::Relax => JointPass::Relax,
                    Pass::Restitution => return,
                };
                let r = &self.joint_colours[k as usize];
                let b = block_range(r.len(), blocks, block);
                let range = r.start + b.start..r.start + b.end;
                let (soft, set) = (c.joint_soft, &*self.set);
                let steps = (c.h, c.inv_h, c.impulse_in);
                let (bodies, n) = (self.bodies, self.n_bodies);
                self.rows
                    .run(range, pass, first, bodies, n, set, self.joints, soft, steps);
            }
            SoftStage::Colour(pass, k) => {
                let r = &self.colours[k as usize];
                let b = block_range(r.len(), blocks, block);
                let range = r.start + b.start..r.start + b.end;
                let items = if c.simd { self.n_wide } else { self.n_cons };
                assert!(range.end <= items);
                if c.simd {
                    self.wide_pass(pass, range);
                } else {
                    self.scalar_pass(pass, range);
                }
            }
            SoftStage::Serial(pass, lo, hi) => {
                for k in lo as usize..hi as usize {
                    if let Some(r) = self.colours.get(k) {
                        let items = if c.simd { self.n_wide } else { self.n_cons };
                        assert!(r.end <= items);
                        if c.simd {
                            self.wide_pass(pass, r.clone());
                        } else {
                            self.scalar_pass(pass, r.clone());
                        }
                    } else {
                        let range = self.overflow.clone();
                        assert!(range.end <= self.n_cons);
                        self.scalar_pass(pass, range);
                    }
                }
            }
        }
    }

    /// What the prepare stages read. Nothing writes the manifolds, the body set or the
    /// solver bodies while they run.
    unsafe fn preparer(&self) -> contact::Preparer<'_> {
        let c = &self.c;
        contact::Preparer {
            manifolds: std::slice::from_raw_parts(self.manifolds, self.n_manifolds),
            selected: self.selected,
            order: self.order,
            set: &*self.set,
            bodies: std::slice::from_raw_parts(self.bodies, self.n_bodies),
            impulse_in: c.impulse_in,
            soft: c.contact_soft,
        }
    }

    /// Builds the wide constraints `range` (a prepare block).
    unsafe fn prepare_wide(&self, range: Range<usize>) {
        assert!(range.end <= self.n_wide && range.end <= self.members.len());
        let p = self.preparer();
        let ws = std::slice::from_raw_parts_mut(self.wide.add(range.start), range.len());
        contact_simd::build_range_wide(ws, &self.members[range], &p);
    }

    /// Builds the scalar constraints of the overflow colour (one block).
    unsafe fn prepare_overflow(&self) {
        let range = self.overflow.clone();
        assert!(range.end <= self.n_cons);
        let p = self.preparer();
        for i in range {
            p.make(self.overflow_order + i, &mut *self.cons.add(i), true);
        }
    }

    /// A pass over the wide constraints `range`.
    unsafe fn wide_pass(&self, pass: Pass, range: Range<usize>) {
        let (c, b, n) = (&self.c, self.bodies, self.n_bodies);
        let (inv_h, max_push, threshold) = (c.inv_h, c.max_push, c.restitution_threshold);
        let all = |_: &WideConstraint| true;
        let cons = self.wide;
        match pass {
            Pass::WarmStart => {
                contact_simd::solve_range(cons, range, b, n, &contact_simd::WarmStart, &all)
            }
            Pass::Solve | Pass::Relax => {
                let use_bias = pass == Pass::Solve;
                let f = contact_simd::SoftSolve {
                    inv_h,
                    max_push,
                    use_bias,
                };
                contact_simd::solve_range(cons, range, b, n, &f, &all);
            }
            Pass::Restitution => {
                let f = contact_simd::Restitution { threshold };
                let active = contact_simd::has_restitution;
                contact_simd::solve_range(cons, range, b, n, &f, &active);
            }
        }
    }

    /// A pass over the scalar constraints `range`.
    unsafe fn scalar_pass(&self, pass: Pass, range: Range<usize>) {
        let (c, b, n) = (&self.c, self.bodies, self.n_bodies);
        let (inv_h, max_push, threshold) = (c.inv_h, c.max_push, c.restitution_threshold);
        let cons = self.cons;
        match pass {
            Pass::WarmStart => coloring::solve_range(cons, range, b, n, &contact::warm_start),
            Pass::Solve | Pass::Relax => {
                let bias = pass == Pass::Solve;
                let f = |k: &mut ContactConstraint, x: &mut _, y: &mut _| {
                    contact::solve_soft(k, x, y, inv_h, max_push, bias)
                };
                coloring::solve_range(cons, range, b, n, &f);
            }
            Pass::Restitution => {
                let f = |k: &mut ContactConstraint, x: &mut _, y: &mut _| {
                    contact::apply_restitution(k, x, y, threshold)
                };
                coloring::solve_range(cons, range, b, n, &f);
            }
        }
    }
}
