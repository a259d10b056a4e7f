//! The adapter between the narrowphase's persistent manifolds and the solver's contacts.
//!
//! `gather` turns every non-empty, non-sensor narrowphase manifold with a dynamic body into
//! a [`ContactManifold`] (normal A→B, see the module docs of [`crate::pipeline`]) in a
//! reused buffer, carrying the accumulated impulses in; `write_back` stores the solver's
//! impulses into the same narrowphase points afterwards. Pairs whose joint disables
//! collisions never get points: the world excludes them from contact generation
//! ([`World::create_joint`]).
//! Both walk the narrowphase's manifolds in pair order, so entry `k` of the buffer maps back
//! by its rank `sources[k].0` without any lookup table; `sources[k].1` keeps the sign that
//! maps the second tangent impulse, so the frame is computed once per manifold.

use super::World;
use crate::body::{mix_friction, mix_restitution, BodyType};
use crate::contact::{ContactManifold, ContactPoint};
use carom_collision::math::{orthonormal_basis, Real, Vec3};
use carom_collision::narrowphase::ContactManifold as NarrowManifold;

/// The normal on B (from B towards A) of the deepest point, and the sign that maps the
/// narrowphase's second tangent impulse to the solver's.
fn frame(m: &NarrowManifold) -> (Vec3, Vec3, Real) {
    let mut deepest = &m.points[0];
    for p in &m.points[1..] {
        if p.distance < deepest.distance {
            deepest = p;
        }
    }
    let n_b = deepest.normal;
    let (t1, t2) = orthonormal_basis(n_b);
    // Solver: n = -n_B, tangents (t1, n × t1).
    let sign = t2.dot((-n_b).cross(t1)).signum();
    (n_b, t1, sign)
}

impl World {
    /// Fills `self.contacts` from the narrowphase (see the module docs).
    pub(super) fn gather(&mut self) {
        self.contacts.clear();
        self.sources.clear();
        let set = self.dynamics.bodies();
        for (rank, pc) in self.collision.narrowphase().manifolds().enumerate() {
            if pc.sensor {
                continue;
            }
            let body = |o: carom_collision::world::ObjectHandle| {
                self.body_of.get(o.index as usize).copied().flatten()
            };
            let (Some(ba), Some(bb)) = (body(pc.a), body(pc.b)) else {
                continue;
            };
            let (Ok(ia), Ok(ib)) = (set.slot(ba), set.slot(bb)) else {
                continue;
            };
            let (info_a, info_b) = (&set.info[ia], &set.info[ib]);
            let dynamic = |t: BodyType| t == BodyType::Dynamic;
            if !(dynamic(info_a.body_type) || dynamic(info_b.body_type)) {
                continue;
            }
            let (n_b, t1, sign) = frame(&pc.manifold);
            if !n_b.is_finite() || (n_b.length_squared() - 1.0).abs() > 1e-3 {
                continue;
            }
            let mut m = ContactManifold::new(ba, bb, -n_b);
            m.tangent = t1;
            m.friction = mix_friction(info_a.friction, info_b.friction);
            m.restitution = mix_restitution(info_a.restitution, info_b.restitution);
            for p in pc.manifold.points.iter().take(crate::MAX_MANIFOLD_POINTS) {
                let mut q = ContactPoint::new(p.local_a, p.local_b, p.distance, p.feature);
                q.normal_impulse = p.normal_impulse;
                q.tangent_impulse = [p.tangent_impulse[0], p.tangent_impulse[1] * sign];
                // Cannot fail: at most MAX_MANIFOLD_POINTS points are taken.
                let _ = m.push(q);
            }
            self.contacts.push(m);
            self.sources.push((rank as u32, sign));
        }
    }

    /// Stores the solver's impulses into the narrowphase points the contacts came from.
    pub(super) fn write_back(&mut self) {
        let (contacts, sources) = (&self.contacts, &self.sources);
        let mut k = 0;
        for (rank, pc) in self.collision.narrowphase_mut().manifolds_mut().enumerate() {
            if k == sources.len() {
                break;
            }
            let (source, sign) = sources[k];
            if source as usize != rank {
                continue;
            }
            for (p, q) in pc.manifold.points.iter_mut().zip(contacts[k].points()) {
                p.normal_impulse = q.normal_impulse;
                p.tangent_impulse = [q.tangent_impulse[0], q.tangent_impulse[1] * sign];
            }
            k += 1;
        }
    }

    /// Number of contact points handed to the solver at the last step.
    pub(super) fn contact_point_count(&self) -> usize {
        self.contacts.iter().map(|m| m.points().len()).sum()
    }
}
