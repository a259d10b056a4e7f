//! Preparing one contact constraint (module `contact`): the lever arms, the warm-start
//! impulses and the friction frame of a manifold, handed to a [`ConstraintSink`] point by
//! point, so the scalar solve gets a [`ContactConstraint`] with its Jacobian rows. The SIMD
//! build repeats this arithmetic on four lanes at once (`contact_simd_prep`), and its
//! tests compare every lane with this routine's bits.

use super::{ContactConstraint, ContactRow, Softness, SolverBody};
use crate::body_set::BodySet;
use crate::contact::ContactManifold;
use carom_collision::math::{orthonormal_basis, Real, Vec3};

/// What preparing one constraint reads: the step's manifolds and bodies, the selection and
/// its colour order, the warm-start factor and the softness pair. [`Preparer::make`] is the
/// one routine behind the serial build in [`prepare`](super::prepare) and the soft step's prepare stages
/// (module `soft_stages`), so both give the same bits.
#[derive(Clone, Copy)]
pub(crate) struct Preparer<'a> {
    /// The step's manifolds.
    pub manifolds: &'a [ContactManifold],
    /// Manifold index of each selected manifold ([`ContactScratch::selected`]).
    pub selected: &'a [usize],
    /// The colour order (`Colouring::order`): position `k` holds a selection index.
    pub order: &'a [usize],
    /// The body set (poses and centres of mass).
    pub set: &'a BodySet,
    /// The solver bodies.
    pub bodies: &'a [SolverBody],
    /// Factor of the stored impulses (per-step units to the solver's; 0: no warm start).
    pub impulse_in: Real,
    /// Softness between two dynamic bodies and against a non-dynamic one.
    pub soft: (Softness, Softness),
}

impl Preparer<'_> {
    /// Prepares the constraint at position `k` of the colour order into `out` (its Jacobian
    /// rows only when `rows`), as [`prepare_one`] does.
    #[inline]
    pub(crate) fn make(&self, k: usize, out: &mut ContactConstraint, rows: bool) {
        self.make_into(k, &mut ScalarSink { out, rows });
    }

    /// Prepares the constraint at position `k` of the colour order into `sink`.
    #[inline(always)]
    pub(crate) fn make_into(&self, k: usize, sink: &mut impl ConstraintSink) {
        let m_index = self.selected[self.order[k]];
        let m = &self.manifolds[m_index];
        prepare_one(
            sink,
            m,
            m_index,
            self.set,
            self.bodies,
            self.impulse_in,
            self.soft,
        );
    }
}

/// What [`prepare_one`] computes for one point of a constraint: all a solve reads but the
/// Jacobian rows, which the receiver builds from the lever arms (scalar: [`ContactRow::new`];
/// SIMD: four constraints at once).
#[derive(Clone, Copy)]
pub(crate) struct PreparedPoint {
    /// Lever arm from A's centre of mass to the anchor.
    pub arm_a: Vec3,
    /// Lever arm from B's centre of mass to the anchor.
    pub arm_b: Vec3,
    /// Signed separation.
    pub separation: Real,
    /// Normal relative velocity at preparation (for restitution).
    pub relative_velocity: Real,
    /// Warm-start normal impulse (solver units).
    pub normal_impulse: Real,
    /// Warm-start friction impulses (solver units).
    pub tangent_impulse: [Real; 2],
}

/// What [`prepare_one`] computes for a constraint as a whole.
#[derive(Clone, Copy)]
pub(crate) struct PreparedHead {
    /// Body slot of A.
    pub a: usize,
    /// Body slot of B.
    pub b: usize,
    /// Manifold index.
    pub manifold: usize,
    /// Unit normal, A to B.
    pub normal: Vec3,
    /// The friction frame `t₀` and `t₁ = n × t₀`.
    pub tangent: [Vec3; 2],
    /// Combined friction.
    pub friction: Real,
    /// Combined restitution.
    pub restitution: Real,
    /// The softness of the pair.
    pub softness: Softness,
    /// Point count.
    pub len: usize,
}

/// The receiver of a prepared constraint ([`prepare_one`]): the points as they are
/// computed (`point`, indices `0..len` in order), then the constraint's head (`head`). A
/// receiver writes each value where its solve reads it, so the preparation writes no
/// intermediate value that would be copied again.
pub(crate) trait ConstraintSink {
    /// Point `k` with the bodies `a`, `b` and the unit normal `n` of the constraint.
    fn point(&mut self, k: usize, p: &PreparedPoint, a: &SolverBody, b: &SolverBody, n: Vec3);
    /// The constraint's head, after all its points.
    fn head(&mut self, h: &PreparedHead, a: &SolverBody, b: &SolverBody);
}

/// A [`ConstraintSink`] into a scalar [`ContactConstraint`], with its Jacobian rows only
/// when `rows`.
struct ScalarSink<'a> {
    out: &'a mut ContactConstraint,
    rows: bool,
}

impl ConstraintSink for ScalarSink<'_> {
    #[inline(always)]
    fn point(&mut self, k: usize, p: &PreparedPoint, a: &SolverBody, b: &SolverBody, n: Vec3) {
        let pt = &mut self.out.points[k];
        if self.rows {
            pt.normal_row = ContactRow::new(a, b, p.arm_a, p.arm_b, n);
        }
        pt.arm_a = p.arm_a;
        pt.arm_b = p.arm_b;
        pt.separation = p.separation;
        pt.relative_velocity = p.relative_velocity;
        pt.normal_impulse = p.normal_impulse;
        pt.tangent_impulse = p.tangent_impulse;
        pt.push_impulse = 0.0;
        pt.max_normal_impulse = 0.0;
    }

    #[inline(always)]
    fn head(&mut self, h: &PreparedHead, a: &SolverBody, b: &SolverBody) {
        let out = &mut *self.out;
        if self.rows {
            let [t1, t2] = h.tangent;
            for pt in &mut out.points[..h.len] {
                let (ra, rb) = (pt.arm_a, pt.arm_b);
                pt.tangent_rows = [
                    ContactRow::new(a, b, ra, rb, t1),
                    ContactRow::new(a, b, ra, rb, t2),
                ];
            }
        }
        out.a = h.a;
        out.b = h.b;
        out.manifold = h.manifold;
        out.normal = h.normal;
        out.tangent = h.tangent;
        out.friction = h.friction;
        out.restitution = h.restitution;
        out.softness = h.softness;
        out.len = h.len;
    }
}

/// Prepares the constraint of manifold `m` (index `m_index`), which touches an awake
/// dynamic body, into `sink`: its points `..len` in order, then its head. Into a scalar
/// constraint ([`Preparer::make`]) every field and the points `..len` are written; the
/// points from `len` on are left as they were (nothing reads them), so a reused constraint
/// is neither zeroed nor copied. `(soft, static_soft)` are the softness between two dynamic
/// bodies and against a non-dynamic one. Without `rows` the Jacobian rows are left stale:
/// the SIMD build computes them four constraints at a time from the lever arms
/// (`contact_simd::WideConstraint::finish`), with the same arithmetic as [`ContactRow::new`].
#[inline(always)]
fn prepare_one(
    sink: &mut impl ConstraintSink,
    m: &ContactManifold,
    m_index: usize,
    set: &BodySet,
    bodies: &[SolverBody],
    impulse_in: Real,
    (soft, static_soft): (Softness, Softness),
) {
    let (a, b) = (m.body_a.index as usize, m.body_b.index as usize);
    let (ba, bb) = (&bodies[a], &bodies[b]);
    let (pose_a, pose_b) = (set.pose_of(a), set.pose_of(b));
    let (com_a, com_b) = (set.position[a], set.position[b]);
    let n = m.normal.normalize();
    let points = m.points();
    let len = points.len();
    let mut centre_velocity = Vec3::ZERO;
    for (k, p) in points.iter().enumerate() {
        let c = 0.5 * (pose_a.transform_point(p.local_a) + pose_b.transform_point(p.local_b));
        let (ra, rb) = (c - com_a, c - com_b);
        let dv = bb.point_velocity(rb) - ba.point_velocity(ra);
        centre_velocity += dv;
        let prepared = PreparedPoint {
            arm_a: ra,
            arm_b: rb,
            separation: p.separation,
            relative_velocity: dv.dot(n),
            normal_impulse: p.normal_impulse * impulse_in,
            tangent_impulse: [
                p.tangent_impulse[0] * impulse_in,
                p.tangent_impulse[1] * impulse_in,
            ],
        };
        sink.point(k, &prepared, ba, bb, n);
    }
    let t1 = friction_direction(m.tangent, n, centre_velocity / len as Real);
    let t2 = n.cross(t1);
    let head = PreparedHead {
        a,
        b,
        manifold: m_index,
        normal: n,
        tangent: [t1, t2],
        friction: m.friction,
        restitution: m.restitution,
        softness: if ba.dynamic && bb.dynamic {
            soft
        } else {
            static_soft
        },
        len,
    };
    sink.head(&head, ba, bb);
}

/// The first friction direction: the cached one if still roughly in the tangent plane
/// (direction caching keeps warm-started friction meaningful), else the sliding direction,
/// else a fixed basis vector of the normal.
fn friction_direction(cached: Vec3, n: Vec3, relative_velocity: Vec3) -> Vec3 {
    let c = cached - n * n.dot(cached);
    if c.length_squared() > 0.25 {
        return c.normalize();
    }
    let vt = relative_velocity - n * n.dot(relative_velocity);
    if vt.length_squared() > 1e-6 {
        return vt.normalize();
    }
    orthonormal_basis(n).0
}
