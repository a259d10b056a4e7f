//! The contact input of the solver: one [`ContactManifold`] per touching pair.
//!
//! This is the seam between contact generation (issue 6, `carom_collision::narrowphase`) and
//! dynamics. It holds what a persistent manifold (Bullet's `btPersistentManifold`, the
//! "Contact Generation" talk) naturally stores: the two bodies, a world normal, up to four
//! points with body-local anchors, the refreshed signed separation, a feature id, and the
//! accumulated impulses of the last step for warm starting. The solver reads the impulses in,
//! and writes the new ones back into the same struct, so the manifold keeps them for the next
//! step (matched to the new points by feature id or distance by the narrowphase).

use crate::body_set::{BodyHandle, BodySet};
use carom_collision::math::{Real, Vec3};
use carom_collision::{CaromError, Result};

/// Largest number of points per manifold (the talk's reduction to 4).
pub const MAX_MANIFOLD_POINTS: usize = 4;

/// One contact point of a manifold.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ContactPoint {
    /// The witness point on A's surface, in A's body frame (the shape frame, not the centre of
    /// mass frame).
    pub local_a: Vec3,
    /// The witness point on B's surface, in B's body frame.
    pub local_b: Vec3,
    /// Signed distance along the normal, from A's surface to B's: negative when penetrating,
    /// positive for a speculative contact (not yet touching).
    pub separation: Real,
    /// Identifies the pair of features (vertex, edge, face) that made the point, so the
    /// narrowphase can carry the impulses over from the previous step.
    pub feature_id: u32,
    /// In: accumulated normal impulse of the previous step (N·s, warm start). Out: this step's.
    pub normal_impulse: Real,
    /// In/out: accumulated friction impulses along [`ContactManifold::tangent`] and
    /// `normal × tangent`.
    pub tangent_impulse: [Real; 2],
}

impl ContactPoint {
    /// A point with zero accumulated impulses.
    pub fn new(local_a: Vec3, local_b: Vec3, separation: Real, feature_id: u32) -> Self {
        ContactPoint {
            local_a,
            local_b,
            separation,
            feature_id,
            ..Default::default()
        }
    }
}

/// All contact points between two bodies, with one shared normal.
#[derive(Debug, Clone, PartialEq)]
pub struct ContactManifold {
    /// First body.
    pub body_a: BodyHandle,
    /// Second body.
    pub body_b: BodyHandle,
    /// Unit contact normal in world space, pointing from A to B.
    pub normal: Vec3,
    /// In/out: the first friction direction (Bullet's friction anchor / direction caching).
    /// Zero on a new manifold: the solver then picks one (the sliding direction if any) and
    /// writes it here; later steps reuse its projection on the tangent plane, so warm-started
    /// friction impulses keep their meaning.
    pub tangent: Vec3,
    /// Combined friction coefficient (e.g. [`crate::mix_friction`]).
    pub friction: Real,
    /// Combined restitution (e.g. [`crate::mix_restitution`]).
    pub restitution: Real,
    pub(crate) points: [ContactPoint; MAX_MANIFOLD_POINTS],
    pub(crate) len: usize,
}

impl ContactManifold {
    /// An empty manifold between `a` and `b` with world normal `normal` (from A to B).
    pub fn new(body_a: BodyHandle, body_b: BodyHandle, normal: Vec3) -> Self {
        ContactManifold {
            body_a,
            body_b,
            normal,
            tangent: Vec3::ZERO,
            friction: 0.5,
            restitution: 0.0,
            points: [ContactPoint::default(); MAX_MANIFOLD_POINTS],
            len: 0,
        }
    }

    /// Adds a point; returns an error when the manifold is full.
    pub fn push(&mut self, p: ContactPoint) -> Result<()> {
        if self.len == MAX_MANIFOLD_POINTS {
            return Err(CaromError::invalid(
                "manifold.points",
                self.len + 1,
                "a manifold holds at most 4 points",
            ));
        }
        self.points[self.len] = p;
        self.len += 1;
        Ok(())
    }

    /// The points.
    pub fn points(&self) -> &[ContactPoint] {
        &self.points[..self.len]
    }

    /// The points, mutable (to set or read impulses).
    pub fn points_mut(&mut self) -> &mut [ContactPoint] {
        &mut self.points[..self.len]
    }

    /// Removes all points.
    pub fn clear(&mut self) {
        self.len = 0;
    }

    /// Total normal impulse of the manifold.
    pub fn total_normal_impulse(&self) -> Real {
        self.points().iter().map(|p| p.normal_impulse).sum()
    }

    /// Checks handles and values; `index` names the manifold in the error.
    pub fn validate(&self, index: usize, bodies: &BodySet) -> Result<()> {
        let name = |f: &str| format!("contacts[{index}].{f}");
        bodies.slot(self.body_a).map_err(|_| {
            CaromError::UnknownHandle(format!("{}: {:?}", name("body_a"), self.body_a))
        })?;
        bodies.slot(self.body_b).map_err(|_| {
            CaromError::UnknownHandle(format!("{}: {:?}", name("body_b"), self.body_b))
        })?;
        if self.body_a == self.body_b {
            return Err(CaromError::invalid(
                name("body_b"),
                self.body_b,
                "same body as body_a",
            ));
        }
        let n = self.normal;
        if !n.is_finite() || (n.length() - 1.0).abs() > 1e-3 {
            return Err(CaromError::invalid(
                name("normal"),
                n,
                "must be a finite unit vector",
            ));
        }
        if !self.tangent.is_finite() {
            return Err(CaromError::invalid(
                name("tangent"),
                self.tangent,
                "must be finite",
            ));
        }
        if !(self.friction.is_finite() && self.friction >= 0.0) {
            return Err(CaromError::invalid(
                name("friction"),
                self.friction,
                "must be >= 0",
            ));
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(CaromError::invalid(
                name("restitution"),
                self.restitution,
                "must be in [0, 1]",
            ));
        }
        for (k, p) in self.points().iter().enumerate() {
            let ok = p.local_a.is_finite()
                && p.local_b.is_finite()
                && p.separation.is_finite()
                && p.normal_impulse.is_finite()
                && p.tangent_impulse[0].is_finite()
                && p.tangent_impulse[1].is_finite();
            if !ok {
                return Err(CaromError::invalid(
                    name(&format!("points[{k}]")),
                    p,
                    "must be finite",
                ));
            }
        }
        Ok(())
    }
}
