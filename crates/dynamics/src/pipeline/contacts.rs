//! The adapter between the narrowphase's persistent manifolds and the solver's contacts.
//!
//! `gather` turns every non-empty, non-sensor narrowphase manifold with a dynamic body into
//! a [`ContactManifold`] (normal A→B, see the module docs of [`crate::pipeline`]), carrying
//! the accumulated impulses in; `write_back` stores the solver's impulses into the same
//! narrowphase points afterwards. Pairs whose joint disables collisions never get points:
//! the world excludes them from contact generation ([`World::create_joint`]).
//!
//! The buffer is overwritten in place, field by field, from step to step (no manifold is
//! built and then moved), and entry `k` keeps the index of its narrowphase pair in
//! `sources[k]`, so the write-back jumps from pair to pair (`Iterator::nth` on the pair
//! slice is a pointer step) instead of walking and filtering every pair. While copying, the
//! gather sums every value it hands on (finite when all are, short of an overflow beyond
//! 10³⁸: the test of `DynamicsWorld`'s `plausible` up to a needless validation), so the
//! dynamics step need not check each manifold again.
//!
//! The frames need no per-manifold sign: `orthonormal_basis(n)` returns `(t₁, t₂)` with
//! `t₁ × t₂ = n`, so for the solver's normal `n = −n_B` its second tangent `n × t₁` is
//! `−t₂`, and the second friction impulse changes sign between the two (exact in floating
//! point). `frame_sign_is_minus_one` checks the identity.

use super::World;
use crate::body::{mix_friction, mix_restitution, BodyType};
use crate::body_set::{BodyHandle, BodySet};
use crate::contact::ContactManifold;
use carom_collision::math::{orthonormal_basis, Real, Vec3};
use carom_collision::narrowphase::PairContact;
use carom_collision::world::ObjectHandle;

impl World {
    /// Fills `self.contacts` from the narrowphase (see the module docs). Returns true when
    /// every manifold is certainly valid for the solver (the checks of
    /// [`crate::DynamicsWorld::step`] hold), false when one may not be (the step then
    /// validates them all and names the bad value).
    #[inline(never)] // its own entry in profiles
    pub(super) fn gather(&mut self) -> bool {
        let World {
            dynamics,
            collision,
            body_of,
            contacts,
            sources,
            ..
        } = self;
        let pairs = collision.narrowphase().pairs();
        gather_pairs(dynamics.bodies(), body_of, pairs, contacts, sources)
    }

    /// Stores the solver's impulses into the narrowphase points the contacts came from.
    #[inline(never)] // its own entry in profiles
    pub(super) fn write_back(&mut self) {
        let (contacts, sources) = (&self.contacts, &self.sources);
        let mut pairs = self.collision.narrowphase_mut().pairs_mut();
        // Index of the next pair `pairs` yields.
        let mut next = 0;
        for (m, &index) in contacts.iter().zip(sources) {
            let index = index as usize;
            let Some(pc) = pairs.nth(index - next) else {
                break;
            };
            next = index + 1;
            for (p, q) in pc.manifold.points.iter_mut().zip(m.points()) {
                p.normal_impulse = q.normal_impulse;
                p.tangent_impulse = [q.tangent_impulse[0], -q.tangent_impulse[1]];
            }
        }
    }

    /// Number of contact points handed to the solver at the last step.
    pub(super) fn contact_point_count(&self) -> usize {
        self.contacts.iter().map(|m| m.points().len()).sum()
    }
}

/// [`World::gather`] over `pairs` (the narrowphase's, in pair order): fills `contacts` and
/// `sources` in place and returns whether every value handed on is certainly valid.
///
/// One pass per manifold: the points are copied while the deepest one is found (its normal
/// is the manifold's), and the values are summed rather than multiplied by zero and summed:
/// a sum of finite values is finite unless it overflows (beyond 10³⁸, no scene's values), and
/// any infinite or NaN value makes it infinite or NaN, so `sum.is_finite()` is true only when
/// all are finite. A false "not certain" costs the step a validation, never other bits.
/// The manifolds are the same bits as `gather_reference`'s (the previous routine, kept as
/// the test oracle in `contacts_tests.rs`).
pub(super) fn gather_pairs<'p>(
    set: &BodySet,
    body_of: &[Option<BodyHandle>],
    pairs: impl Iterator<Item = &'p PairContact<ObjectHandle>>,
    contacts: &mut Vec<ContactManifold>,
    sources: &mut Vec<u32>,
) -> bool {
    let body = |o: ObjectHandle| body_of.get(o.index as usize).copied().flatten();
    let mut k = 0;
    let mut sum: Real = 0.0;
    let mut ranges_ok = true;
    for (index, pc) in pairs.enumerate() {
        let points = &pc.manifold.points[..];
        let Some(first) = points.first() else {
            continue;
        };
        if pc.sensor {
            continue;
        }
        let (Some(ba), Some(bb)) = (body(pc.a), body(pc.b)) else {
            continue;
        };
        // One at a time: a tuple of the two `Result`s (with their error payloads) was
        // built on the stack for every manifold (~30 instructions of copies).
        let Ok(ia) = set.slot(ba) else {
            continue;
        };
        let Ok(ib) = set.slot(bb) else {
            continue;
        };
        let (info_a, info_b) = (&set.info[ia], &set.info[ib]);
        let dynamic = |t: BodyType| t == BodyType::Dynamic;
        if !(dynamic(info_a.body_type) || dynamic(info_b.body_type)) || ba == bb {
            continue;
        }
        if k == contacts.len() {
            contacts.push(ContactManifold::new(ba, bb, Vec3::Z));
            sources.push(0);
        }
        let m = &mut contacts[k];
        // The deepest point (the first of equally deep ones), found while copying: the
        // comparisons are those of a separate scan (`first` against itself is false).
        let mut deepest = first;
        let mut len = 0;
        // This manifold's sum, counted only if the manifold is handed on.
        let mut values: Real = 0.0;
        for (q, p) in m.points.iter_mut().zip(points) {
            if p.distance < deepest.distance {
                deepest = p;
            }
            q.local_a = p.local_a;
            q.local_b = p.local_b;
            q.separation = p.distance;
            q.feature_id = p.feature;
            q.normal_impulse = p.normal_impulse;
            q.tangent_impulse = [p.tangent_impulse[0], -p.tangent_impulse[1]];
            values += (p.local_a + p.local_b).element_sum()
                + ((p.distance + p.normal_impulse) + (p.tangent_impulse[0] + p.tangent_impulse[1]));
            len += 1;
        }
        // More points than a solver manifold holds (not from the narrowphase, which keeps
        // four): the deepest of all of them still gives the normal.
        for p in points.get(len..).unwrap_or_default() {
            if p.distance < deepest.distance {
                deepest = p;
            }
        }
        let n_b = deepest.normal;
        if !n_b.is_finite() || (n_b.length_squared() - 1.0).abs() > 1e-3 {
            // The copied points stay unused: entry `k` is refilled or truncated.
            continue;
        }
        let (t1, _) = orthonormal_basis(n_b);
        m.len = len;
        m.body_a = ba;
        m.body_b = bb;
        m.normal = -n_b;
        m.tangent = t1;
        m.friction = mix_friction(info_a.friction, info_b.friction);
        m.restitution = mix_restitution(info_a.restitution, info_b.restitution);
        sum += values + m.friction;
        ranges_ok &= m.friction >= 0.0 && (0.0..=1.0).contains(&m.restitution);
        sources[k] = index as u32;
        k += 1;
    }
    contacts.truncate(k);
    sources.truncate(k);
    sum.is_finite() && ranges_ok
}

#[cfg(test)]
mod tests {
    use carom_collision::math::{orthonormal_basis, Real, Vec3};

    /// The solver's second tangent `(−n) × t₁` is `−t₂` for the narrowphase's basis: the
    /// adapter maps the second friction impulse by a sign change. Normals on and near the
    /// poles (the basis' branch), along the axes, and spread over the sphere.
    #[test]
    fn frame_sign_is_minus_one() {
        let mut normals = vec![
            Vec3::X,
            -Vec3::X,
            Vec3::Y,
            -Vec3::Y,
            Vec3::Z,
            -Vec3::Z,
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
            Vec3::new(0.0, 1e-7, 1.0).normalize(),
            Vec3::new(0.0, 0.0, -0.0) + Vec3::new(0.0, 1.0, -1e-30).normalize(),
        ];
        for i in 0..2000 {
            let u = (i as Real + 0.5) / 2000.0;
            let z = 1.0 - 2.0 * u;
            let phi = i as Real * 2.399_963;
            let r = (1.0 - z * z).max(0.0).sqrt();
            normals.push(Vec3::new(r * phi.cos(), r * phi.sin(), z).normalize());
        }
        for n_b in normals {
            let (t1, t2) = orthonormal_basis(n_b);
            let second = (-n_b).cross(t1);
            assert!(
                t2.dot(second) < -0.99 && (second + t2).length() < 1e-4,
                "{n_b}: {t1} {t2} {second}"
            );
            // What the old adapter computed per manifold.
            assert_eq!(t2.dot(second).signum(), -1.0);
        }
    }
}
