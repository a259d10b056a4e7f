//! Building the four-wide contact constraints and storing their impulses (module
//! `contact_simd`).
//!
//! The constraints of every colour but the overflow one are written straight into their
//! lanes as they are prepared ([`fill`]): no scalar constraint array is built for them and
//! transposed afterwards, and the wide constraints of the last step are overwritten in
//! place (every field of every lane that the solve reads, padding included), so a step
//! neither zeroes nor copies the (large) constraint arrays. Box2D v3 prepares its SIMD constraints the same way
//! (`b2PrepareContactsTask` writes `b2ContactConstraintSIMD` lanes directly).

use super::{WideConstraint, WidePoint, WideRow, WideScratch, LANES, NONE, NO_SLOT, V3, W};
use crate::contact::{ContactManifold, MAX_MANIFOLD_POINTS};
use crate::solver::contact::{ContactConstraint, PointConstraint};
use crate::solver::SolverBody;
use carom_collision::math::{Mat3, Real, Vec3};
use std::ops::Range;

/// Sets lane `l` of `w` to `x`.
#[inline(always)]
fn put(w: &mut W, l: usize, x: Real) {
    w.as_mut_array()[l] = x;
}

/// Sets lane `l` of `v` to `x`.
#[inline(always)]
fn put3(v: &mut V3, l: usize, x: Vec3) {
    put(&mut v.x, l, x.x);
    put(&mut v.y, l, x.y);
    put(&mut v.z, l, x.z);
}

/// `x` as a lane index of a [`WideConstraint`] (body slot, manifold index).
#[inline(always)]
pub(super) fn lane_index(x: usize) -> u32 {
    let i = u32::try_from(x).unwrap_or(NO_SLOT);
    assert!(
        i != NO_SLOT,
        "index {x} does not fit a wide constraint's u32 lane index"
    );
    i
}

/// Lane `l` of `v`.
#[inline(always)]
fn get3(v: &V3, l: usize) -> Vec3 {
    Vec3::new(v.x.as_array()[l], v.y.as_array()[l], v.z.as_array()[l])
}

/// The inputs of the row build of one wide constraint that the lanes do not keep: the
/// inverse world inertias of every lane's bodies, as nine lane vectors each (`m[c][r]`:
/// column `c`, row `r`), written lane by lane ([`WideConstraint::set_lane`]) straight into
/// that form and consumed by [`WideConstraint::finish`]. (The lever arms go straight into
/// the points, which keep them.)
#[derive(Default)]
pub(crate) struct RowInputs {
    inv_i_a: [[W; 3]; 3],
    inv_i_b: [[W; 3]; 3],
}

impl RowInputs {
    /// The inverse world inertias of the bodies `a[l]`, `b[l]` of every lane `l` (those of
    /// padding lanes are never read: their rows are zero).
    #[inline(always)]
    pub(super) fn set(&mut self, a: &[&SolverBody; LANES], b: &[&SolverBody; LANES]) {
        let lanes = |bs: &[&SolverBody; LANES], c: usize, r: usize| {
            W::from(std::array::from_fn::<Real, LANES, _>(|l| {
                bs[l].inv_i.col(c)[r]
            }))
        };
        for c in 0..3 {
            for r in 0..3 {
                self.inv_i_a[c][r] = lanes(a, c, r);
                self.inv_i_b[c][r] = lanes(b, c, r);
            }
        }
    }
}

/// Sets lane `l` of the lane-form matrix `w` (`w[c][r]`: column `c`, row `r`) to `m`.
#[inline(always)]
fn put_mat(w: &mut [[W; 3]; 3], l: usize, m: &Mat3) {
    for (wc, mc) in w.iter_mut().zip([m.x_axis, m.y_axis, m.z_axis]) {
        put(&mut wc[0], l, mc.x);
        put(&mut wc[1], l, mc.y);
        put(&mut wc[2], l, mc.z);
    }
}

/// `m * v` in every lane, in glam's order (`x_axis·v.x + y_axis·v.y + z_axis·v.z`, summed
/// left to right per component), so each lane equals the scalar `Mat3 * Vec3`.
#[inline(always)]
fn mat_mul(m: &[[W; 3]; 3], v: V3) -> V3 {
    let r = |i: usize| m[0][i] * v.x + m[1][i] * v.y + m[2][i] * v.z;
    V3 {
        x: r(0),
        y: r(1),
        z: r(2),
    }
}

/// Lanes of `v` where `mask` is set, `+0.0` elsewhere.
#[inline(always)]
pub(super) fn keep(mask: W, v: V3) -> V3 {
    let zero = W::splat(0.0);
    V3 {
        x: mask.select(v.x, zero),
        y: mask.select(v.y, zero),
        z: mask.select(v.z, zero),
    }
}

impl WidePoint {
    /// Lane `l` becomes point `p` but its rows (built by [`WideConstraint::finish`]); an
    /// absent point is [`PointConstraint::ZERO`].
    #[inline(always)]
    fn set_lane(&mut self, l: usize, p: &PointConstraint) {
        put3(&mut self.arm_a, l, p.arm_a);
        put3(&mut self.arm_b, l, p.arm_b);
        put(&mut self.separation, l, p.separation);
        put(&mut self.normal_impulse, l, p.normal_impulse);
        put(&mut self.tangent_impulse[0], l, p.tangent_impulse[0]);
        put(&mut self.tangent_impulse[1], l, p.tangent_impulse[1]);
        put(&mut self.max_normal_impulse, l, p.max_normal_impulse);
    }
}

impl WideConstraint {
    /// A constraint with four padding lanes.
    pub(super) fn empty() -> Self {
        WideConstraint {
            a: [NO_SLOT; LANES],
            b: [NO_SLOT; LANES],
            write_a: [false; LANES],
            write_b: [false; LANES],
            manifold: [NO_SLOT; LANES],
            lens: [0; LANES],
            inv_m_a: W::default(),
            inv_m_b: W::default(),
            normal: V3::default(),
            tangent: V3::default(),
            friction: W::default(),
            restitution: W::default(),
            bias_rate: W::default(),
            mass_scale: W::default(),
            impulse_scale: W::default(),
            points: [WidePoint::default(); MAX_MANIFOLD_POINTS],
            len: 0,
            relative_velocity: [W::default(); MAX_MANIFOLD_POINTS],
        }
    }

    /// Lane `l` becomes a padding lane (no points, no bodies; zero inverse inertias in
    /// `inputs`).
    pub(super) fn set_padding(&mut self, l: usize, inputs: &mut RowInputs) {
        self.set_lane(l, None, &[], inputs);
    }

    /// Lane `l` becomes constraint `c` (whose bodies are `bodies[c.a]`, `bodies[c.b]`), or a
    /// padding lane (no points, no bodies) for `None`. Every field of the lane is written
    /// but the rows and the points from `c.len` on (the points keep their lever arms); the
    /// inverse inertias the rows are built from go to `inputs` (zero for padding).
    /// [`WideConstraint::finish`] completes the group.
    fn set_lane(
        &mut self,
        l: usize,
        c: Option<&ContactConstraint>,
        bodies: &[SolverBody],
        inputs: &mut RowInputs,
    ) {
        let c = c.unwrap_or(&ContactConstraint::EMPTY);
        let pad = c.len == 0;
        let (a, b) = if pad { (NONE, NONE) } else { (c.a, c.b) };
        self.a[l] = if pad { NO_SLOT } else { lane_index(a) };
        self.b[l] = if pad { NO_SLOT } else { lane_index(b) };
        self.write_a[l] = !pad && bodies[a].dynamic;
        self.write_b[l] = !pad && bodies[b].dynamic;
        self.manifold[l] = if pad { NO_SLOT } else { lane_index(c.manifold) };
        self.lens[l] = c.len as u32;
        let body = |s: usize| (!pad).then(|| &bodies[s]);
        let (ba, bb) = (body(a), body(b));
        put(&mut self.inv_m_a, l, ba.map_or(0.0, |x| x.inv_m));
        put(&mut self.inv_m_b, l, bb.map_or(0.0, |x| x.inv_m));
        put_mat(&mut inputs.inv_i_a, l, ba.map_or(&Mat3::ZERO, |x| &x.inv_i));
        put_mat(&mut inputs.inv_i_b, l, bb.map_or(&Mat3::ZERO, |x| &x.inv_i));
        put3(&mut self.normal, l, c.normal);
        put3(&mut self.tangent, l, c.tangent[0]);
        debug_assert!(c.tangent[1] == c.normal.cross(c.tangent[0]));
        put(&mut self.friction, l, c.friction);
        put(&mut self.restitution, l, c.restitution);
        put(&mut self.bias_rate, l, c.softness.bias_rate);
        put(&mut self.mass_scale, l, c.softness.mass_scale);
        put(&mut self.impulse_scale, l, c.softness.impulse_scale);
        let points = self.points[..c.len].iter_mut().zip(&c.points);
        for ((wp, p), v0) in points.zip(&mut self.relative_velocity) {
            wp.set_lane(l, p);
            put(v0, l, p.relative_velocity);
        }
    }

    /// Completes a group whose lanes are all set: zeroes the points `lens[l]..len` of every
    /// lane `l`, which the solve reads (it runs `len` points in every lane), and builds the
    /// rows of the points `..len` in all lanes at once, as `ContactRow::new` does for one
    /// (same operations in the same order, so the same bits); rows of absent points are
    /// zero. Points from `len` on are never read and keep whatever they held: with the
    /// constraints of a colour grouped by point count, most groups have lanes of equal
    /// length, and a group of one-point lanes builds one point instead of four.
    pub(super) fn finish(&mut self, inputs: &RowInputs) {
        for l in 0..LANES {
            for k in self.lens[l] as usize..self.len {
                self.points[k].set_lane(l, &PointConstraint::ZERO);
                put(&mut self.relative_velocity[k], l, 0.0);
            }
        }
        self.finish_rows(inputs);
    }

    /// The rows half of [`WideConstraint::finish`], for lanes whose points `lens[l]..len`
    /// are already zero.
    #[inline(always)]
    pub(super) fn finish_rows(&mut self, inputs: &RowInputs) {
        let (ia, ib) = (&inputs.inv_i_a, &inputs.inv_i_b);
        let inv_m = self.inv_m_a + self.inv_m_b;
        let lens = W::from(std::array::from_fn::<Real, LANES, _>(|l| {
            self.lens[l] as Real
        }));
        let (zero, one, eps) = (W::splat(0.0), W::splat(1.0), W::splat(Real::EPSILON));
        let dirs = [self.normal, self.tangent, self.tangent1()];
        for (k, p) in self.points[..self.len].iter_mut().enumerate() {
            let present = lens.simd_gt(W::splat(k as Real));
            let all_present = present.all();
            // Zero in the lanes without the point (zeroed above).
            let (ra, rb) = (p.arm_a, p.arm_b);
            let [t0, t1] = &mut p.tangent_rows;
            for (row, d) in [&mut p.normal_row, t0, t1].into_iter().zip(dirs) {
                let (ang_a, ang_b) = (ra.cross(d), rb.cross(d));
                let (inv_ang_a, inv_ang_b) = (mat_mul(ia, ang_a), mat_mul(ib, ang_b));
                let k = inv_m + ang_a.dot(inv_ang_a) + ang_b.dot(inv_ang_b);
                // `inv_or_zero`, and no mass for an absent point.
                let mass = (k.simd_gt(eps) & present).select(one / k, zero);
                *row = if all_present {
                    WideRow {
                        inv_ang_a,
                        inv_ang_b,
                        mass,
                    }
                } else {
                    // Zero rows (not `-0.0` from `0 × d`) in the absent lanes, as a scalar
                    // `ContactRow::ZERO`. The solve recomputes `r × d` from the zero arms
                    // there, which may give `-0.0`; it only meets the zero mass and the
                    // zero impulse of the lane, so the impulse change stays `+0.0` and the
                    // `+0.0` rows here leave the bodies' bits alone.
                    WideRow {
                        inv_ang_a: keep(present, inv_ang_a),
                        inv_ang_b: keep(present, inv_ang_b),
                        mass,
                    }
                };
            }
        }
    }
}

/// Builds the constraints of a step at once: [`assign`] the lanes, [`build_range`] every
/// wide constraint, then prepare the overflow colour's scalar constraints into `cons`
/// (cleared first; `out.overflow` is their range there). `make(k, out, rows)` prepares the
/// constraint at position `k` of the colour order (its Jacobian rows only when `rows`),
/// which will have `points(k)` points; `ranges` are the colour ranges of that order, the
/// last being the overflow colour. The soft step does not call this: it assigns the lanes
/// before its stage list and builds them in the list's first stages (module
/// `soft_stages`), each block on the thread that later solves it. Allocates only when a
/// buffer must grow.
#[cfg(test)]
pub(crate) fn fill(
    out: &mut WideScratch,
    cons: &mut Vec<ContactConstraint>,
    ranges: &[Range<usize>],
    bodies: &[SolverBody],
    points: impl Fn(usize) -> usize,
    make: impl Fn(usize, &mut ContactConstraint, bool),
) {
    assign(out, ranges, points);
    build_range(&mut out.cons, &out.members, bodies, &ViaScalar(&make));
    cons.clear();
    if let Some(overflow) = ranges.last() {
        cons.extend(overflow.clone().map(|k| {
            let mut c = ContactConstraint::EMPTY;
            make(k, &mut c, true);
            c
        }));
    }
    out.overflow = 0..cons.len();
}

/// Assigns the constraints of every colour but the last (`ranges`, colour ranges of the
/// colour order; the last is the overflow colour, kept scalar) to the lanes of wide
/// constraints, four at a time: `out.members[w][l]` is the colour-order index of lane `l`
/// of wide constraint `w` (`NONE` for padding) and `out.ranges` the wide range of each
/// colour. `out.cons` is resized to the wide constraints needed (reusing last step's; their
/// lanes are overwritten by [`build_range`]). `points(k)` is the point count of constraint
/// `k`. Allocates only when a buffer must grow.
///
/// Inside a colour the constraints are grouped by point count (four-point ones first, in
/// colour order within a count): a wide constraint solves as many points as its fullest
/// lane, so mixing a one-point lane with a four-point lane wastes three points of work. The
/// constraints of a colour share no dynamic body, so their order inside the colour does not
/// change any result (and depends only on the colour order, not on the thread count).
pub(crate) fn assign(
    out: &mut WideScratch,
    ranges: &[Range<usize>],
    points: impl Fn(usize) -> usize,
) {
    out.ranges.clear();
    out.members.clear();
    let colours = ranges.split_last().map_or(&[][..], |(_, c)| c);
    // Slot of a constraint with `count` points among the colour's: the four-point ones
    // first, so `MAX_MANIFOLD_POINTS - count` (a point count clamped to 1..=4).
    let slot = |k: usize| MAX_MANIFOLD_POINTS - points(k).clamp(1, MAX_MANIFOLD_POINTS);
    for r in colours {
        // A counting sort by point count, stable in colour order: count, then place each
        // constraint at its slot's next position (lane `pos % LANES` of wide constraint
        // `pos / LANES`); the last wide constraint's unused lanes stay padding.
        let mut next = [0usize; MAX_MANIFOLD_POINTS];
        for k in r.clone() {
            next[slot(k)] += 1;
        }
        let mut at = 0;
        for n in &mut next {
            (*n, at) = (at, at + *n);
        }
        let start = out.members.len();
        out.members
            .resize(start + r.len().div_ceil(LANES), [NONE; LANES]);
        let members = &mut out.members[start..];
        for k in r.clone() {
            let pos = &mut next[slot(k)];
            members[*pos / LANES][*pos % LANES] = k;
            *pos += 1;
        }
        out.ranges.push(start..out.members.len());
    }
    let used = out.members.len();
    if out.cons.len() < used {
        out.cons.resize_with(used, WideConstraint::empty);
    }
    out.cons.truncate(used);
}

/// Where [`build_range`] gets the constraint of each lane from.
#[cfg(test)]
pub(crate) trait LaneSource {
    /// Writes the constraint at position `k` of the colour order into lane `l` of `w`, as
    /// [`WideConstraint::set_lane`] writes a prepared one (the inverse inertias into
    /// `inputs`), and returns its point count.
    fn lane(
        &self,
        k: usize,
        w: &mut WideConstraint,
        l: usize,
        bodies: &[SolverBody],
        inputs: &mut RowInputs,
    ) -> usize;
}

/// A [`LaneSource`] that prepares each constraint into a scalar [`ContactConstraint`] with
/// `make(k, c, false)` and copies it into its lane ([`WideConstraint::set_lane`]): the
/// tests' route, and the oracle of the wide build (`contact_simd_prep`).
#[cfg(test)]
pub(crate) struct ViaScalar<F>(pub F);

#[cfg(test)]
impl<F: Fn(usize, &mut ContactConstraint, bool)> LaneSource for ViaScalar<F> {
    fn lane(
        &self,
        k: usize,
        w: &mut WideConstraint,
        l: usize,
        bodies: &[SolverBody],
        inputs: &mut RowInputs,
    ) -> usize {
        let mut c = ContactConstraint::EMPTY;
        (self.0)(k, &mut c, false);
        w.set_lane(l, Some(&c), bodies, inputs);
        c.len
    }
}

/// Builds the wide constraints `ws` whose lanes hold the constraints `ms` (their
/// [`WideScratch::members`]) lane by lane: each lane's constraint is prepared by `src`
/// ([`ViaScalar`]), then [`WideConstraint::finish`] builds the rows of the four lanes at
/// once. The tests' route and the oracle of the soft step's wide build
/// (`contact_simd_prep::build_range_wide`, which prepares the four lanes at once).
#[cfg(test)]
pub(crate) fn build_range(
    ws: &mut [WideConstraint],
    ms: &[[usize; LANES]],
    bodies: &[SolverBody],
    src: &impl LaneSource,
) {
    let mut inputs = RowInputs::default();
    for (w, m) in ws.iter_mut().zip(ms) {
        w.len = 0;
        for (lane, &k) in m.iter().enumerate() {
            if k == NONE {
                w.set_lane(lane, None, bodies, &mut inputs);
            } else {
                let len = src.lane(k, w, lane, bodies, &mut inputs);
                w.len = w.len.max(len);
            }
        }
        w.finish(&inputs);
    }
}

/// Groups already prepared scalar constraints (`cons`, in colour order with colour `ranges`,
/// the last being the overflow colour) into `out`, as [`fill`] does while preparing; the
/// overflow colour stays in `cons` (`out.overflow` is its range). For the tests, which
/// compare the wide routines with the scalar ones on the same constraints.
#[cfg(test)]
pub(crate) fn build(
    cons: &[ContactConstraint],
    ranges: &[Range<usize>],
    bodies: &[SolverBody],
    out: &mut WideScratch,
) {
    let mut scratch = Vec::new();
    let points = |k: usize| cons[k].len;
    let Some((overflow, colours)) = ranges.split_last() else {
        let make = |k: usize, c: &mut ContactConstraint, _: bool| *c = cons[k].clone();
        fill(out, &mut scratch, ranges, bodies, points, make);
        return;
    };
    // The overflow colour is left out of the lanes and kept in `cons` by range.
    let mut rs: Vec<Range<usize>> = colours.to_vec();
    rs.push(overflow.start..overflow.start);
    let make = |k: usize, c: &mut ContactConstraint, _: bool| *c = cons[k].clone();
    fill(out, &mut scratch, &rs, bodies, points, make);
    out.overflow = overflow.clone();
}

/// Writes the accumulated impulses (scaled to per-step units) and the friction direction of
/// every lane into its manifold, as `contact::store` does for scalar constraints.
#[cfg(test)]
pub(crate) fn store(wide: &WideScratch, manifolds: &mut [ContactManifold], scale: Real) {
    let range = 0..wide.cons.len();
    // SAFETY: both pointers come from live slices of the given lengths, borrowed here.
    unsafe {
        store_range(
            wide.cons.as_ptr(),
            range,
            manifolds.as_mut_ptr(),
            manifolds.len(),
            scale,
        );
    }
}

/// [`store`] of the wide constraints `range` of `cons` into the manifolds behind
/// `manifolds` (`len` of them): one block of the soft step's parallel store stage (module
/// `soft_stages`). Each manifold is in one lane of one wide constraint, so blocks of
/// disjoint ranges write disjoint manifolds.
///
/// # Safety
/// `cons` points to at least `range.end` constraints and `manifolds` to `len` manifolds;
/// during the call nothing else touches those constraints or the manifolds of their lanes.
pub(crate) unsafe fn store_range(
    cons: *const WideConstraint,
    range: Range<usize>,
    manifolds: *mut ContactManifold,
    len: usize,
    scale: Real,
) {
    for i in range {
        let w = &*cons.add(i);
        for l in 0..LANES {
            let m_index = w.manifold[l];
            if m_index == NO_SLOT {
                continue;
            }
            let m_index = m_index as usize;
            assert!(m_index < len);
            let m = &mut *manifolds.add(m_index);
            m.tangent = get3(&w.tangent, l);
            for (out, wp) in m
                .points_mut()
                .iter_mut()
                .zip(&w.points[..w.lens[l] as usize])
            {
                out.normal_impulse = wp.normal_impulse.as_array()[l] * scale;
                out.tangent_impulse = [
                    wp.tangent_impulse[0].as_array()[l] * scale,
                    wp.tangent_impulse[1].as_array()[l] * scale,
                ];
            }
        }
    }
}

/// Copies the impulses of every lane back into the scalar constraint it was built from
/// (`cons[manifold]` in the tests, where constraint `k` is manifold `k`).
#[cfg(test)]
pub(crate) fn write_back(wide: &WideScratch, cons: &mut [ContactConstraint]) {
    for w in &wide.cons {
        for l in 0..LANES {
            let Some(c) = cons
                .iter_mut()
                .find(|c| w.manifold[l] != NO_SLOT && c.manifold == w.manifold[l] as usize)
            else {
                continue;
            };
            for (k, p) in c.points[..c.len].iter_mut().enumerate() {
                let wp = &w.points[k];
                p.normal_impulse = wp.normal_impulse.as_array()[l];
                p.tangent_impulse = [
                    wp.tangent_impulse[0].as_array()[l],
                    wp.tangent_impulse[1].as_array()[l],
                ];
                p.max_normal_impulse = wp.max_normal_impulse.as_array()[l];
            }
        }
    }
}

#[cfg(test)]
#[path = "contact_simd_build_tests.rs"]
mod tests;
