//! The collision dispatcher (Bullet's `btCollisionDispatcher`): for every pair of shape kinds
//! an algorithm that produces contacts for the pair's persistent manifold. The table is an
//! exhaustive `match` on shapes, symmetric through one swap adapter; a user algorithm
//! registered for a pair of kinds overrides it; an unsupported pair is reported by
//! [`Dispatcher::check_pair`] (called when an object is added), never silently skipped.

use super::contact::{ContactPoint, FeatureId, NO_FEATURE};
use super::convex::{
    capsule_capsule_manifold, capsule_polyhedron_manifold, perturbed_contacts,
    plane_capsule_manifold,
};
use super::manifold::{ContactManifold, ManifoldConfig};
use super::mesh::{mesh_convex_contacts, mix_feature};
use super::polyhedron::{plane_polyhedron_manifold, polyhedron_manifold, Polyhedron};
use crate::error::{CaromError, Result};
use crate::math::{Isometry, Real};
use crate::query::contact::{contact_convex_plane, contact_plane_convex};
use crate::query::{contact_convex, Contact};
use crate::shape::{ConvexRef, Plane, Shape, ShapeKind};
use std::collections::BTreeMap;
use std::sync::Arc;

/// Contacts produced for one pair in one step, in A's frame with the query convention
/// (normal from A towards B), each with a feature id.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Generated {
    /// The contacts.
    pub contacts: Vec<(Contact, FeatureId)>,
    /// True when `contacts` is a full manifold (replaces the cached one); false when the
    /// points are added one by one to the cache (the hybrid method).
    pub full: bool,
}

/// A user algorithm: `(shape_a, shape_b, pose_ab, config, manifold_is_empty) -> contacts`.
pub type UserAlgorithm =
    Arc<dyn Fn(&Shape, &Shape, &Isometry, &ManifoldConfig, bool) -> Generated + Send + Sync>;

/// The shape-pair table plus user overrides and the manifold configuration.
#[derive(Clone, Default)]
pub struct Dispatcher {
    user: BTreeMap<(ShapeKind, ShapeKind), UserAlgorithm>,
    /// Contact generation and caching parameters.
    pub config: ManifoldConfig,
}

impl std::fmt::Debug for Dispatcher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Dispatcher")
            .field("user_pairs", &self.user.keys().collect::<Vec<_>>())
            .field("config", &self.config)
            .finish()
    }
}

fn single(c: Option<Contact>) -> Vec<(Contact, FeatureId)> {
    c.map(|c| vec![(c, NO_FEATURE)]).unwrap_or_default()
}

fn swap(g: Generated, pose_ab: &Isometry) -> Generated {
    Generated {
        contacts: g
            .contacts
            .into_iter()
            .map(|(c, id)| (c.swapped().transformed(pose_ab), id))
            .collect(),
        full: g.full,
    }
}

/// The polyhedron view of boxes, hulls and triangles.
pub fn as_polyhedron(c: ConvexRef<'_>) -> Option<Polyhedron> {
    match c {
        ConvexRef::Cuboid(b) => Some(Polyhedron::from_cuboid(b)),
        ConvexRef::ConvexHull(h) => Some(Polyhedron::from_hull(h)),
        ConvexRef::Triangle(t) => Some(Polyhedron::from_triangle(t)),
        _ => None,
    }
}

/// Convex A against convex B (see the module docs of [`super::convex`] and
/// [`super::polyhedron`]).
pub fn convex_convex(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
) -> Generated {
    use ConvexRef as C;
    let pred = cfg.prediction;
    let full = |contacts| Generated {
        contacts,
        full: true,
    };
    match (a, b) {
        (C::Sphere(_), _) | (_, C::Sphere(_)) => full(single(contact_convex(a, b, pose_ab, pred))),
        (C::Capsule(x), C::Capsule(y)) => full(capsule_capsule_manifold(x, y, pose_ab, pred)),
        (C::Capsule(x), _) if as_polyhedron(b).is_some() => {
            let pb = as_polyhedron(b).expect("checked");
            full(capsule_polyhedron_manifold(x, b, &pb, pose_ab, pred))
        }
        (_, C::Capsule(_)) if as_polyhedron(a).is_some() => swap(
            convex_convex(b, a, &pose_ab.inverse(), cfg, want_full),
            pose_ab,
        ),
        _ => match (as_polyhedron(a), as_polyhedron(b)) {
            (Some(pa), Some(pb)) => full(polyhedron_manifold(&pa, &pb, pose_ab, pred)),
            _ if matches!(a, C::Triangle(_)) => {
                // Perturb the shape, not the triangle (whose origin is the mesh's).
                swap(
                    convex_convex(b, a, &pose_ab.inverse(), cfg, want_full),
                    pose_ab,
                )
            }
            _ => {
                let f = |p: &Isometry| contact_convex(a, b, p, pred);
                let Some(c0) = f(pose_ab) else {
                    return Generated::default();
                };
                let mut contacts = vec![(c0, NO_FEATURE)];
                if want_full {
                    let more = perturbed_contacts(
                        &f,
                        pose_ab,
                        &c0,
                        cfg.perturbation_angle,
                        cfg.perturbation_iterations,
                    );
                    contacts.extend(
                        more.into_iter()
                            .filter(|c| c.distance <= pred)
                            .map(|c| (c, NO_FEATURE)),
                    );
                }
                Generated {
                    contacts,
                    full: false,
                }
            }
        },
    }
}

/// Plane A against convex B: all vertices below the plane for polyhedra, the two ends of a
/// capsule, the deepest point of a sphere, else the support point plus perturbation of B.
pub fn plane_convex(
    plane: &Plane,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
) -> Generated {
    let pred = cfg.prediction;
    let (n, off) = (plane.normal(), plane.offset());
    if let Some(pb) = as_polyhedron(b) {
        return Generated {
            contacts: plane_polyhedron_manifold(n, off, &pb, pose_ab, pred),
            full: true,
        };
    }
    match b {
        ConvexRef::Capsule(c) => Generated {
            contacts: plane_capsule_manifold(n, off, c, pose_ab, pred),
            full: true,
        },
        ConvexRef::Sphere(_) => Generated {
            contacts: single(contact_plane_convex(plane, b, pose_ab, pred)),
            full: true,
        },
        _ => {
            // Perturb B: work in B's frame with B first, then swap back.
            let pose_ba = pose_ab.inverse();
            let f = |p: &Isometry| contact_convex_plane(b, plane, p, pred);
            let Some(c0) = f(&pose_ba) else {
                return Generated::default();
            };
            let mut cs = vec![c0];
            if want_full {
                cs.extend(
                    perturbed_contacts(
                        &f,
                        &pose_ba,
                        &c0,
                        cfg.perturbation_angle,
                        cfg.perturbation_iterations,
                    )
                    .into_iter()
                    .filter(|c| c.distance <= pred),
                );
            }
            swap(
                Generated {
                    contacts: cs.into_iter().map(|c| (c, NO_FEATURE)).collect(),
                    full: false,
                },
                pose_ab,
            )
        }
    }
}

/// True when the built-in table handles shapes `a` and `b` (recursing into compounds).
pub fn supported(a: &Shape, b: &Shape) -> bool {
    match (a, b) {
        (Shape::Compound(c), o) | (o, Shape::Compound(c)) => {
            c.children().iter().all(|(_, s)| supported(s, o))
        }
        (Shape::Plane(_), Shape::Plane(_) | Shape::TriMesh(_))
        | (Shape::TriMesh(_), Shape::Plane(_) | Shape::TriMesh(_)) => false,
        _ => true,
    }
}

/// The built-in algorithm table (exhaustive over shape pairs; reversed pairs go through
/// the swap adapter). Unsupported pairs are an error.
pub fn generate(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
) -> Result<Generated> {
    if let (Some(ca), Some(cb)) = (a.as_convex(), b.as_convex()) {
        return Ok(convex_convex(ca, cb, pose_ab, cfg, want_full));
    }
    let reversed = |g: Result<Generated>| g.map(|g| swap(g, pose_ab));
    match (a, b) {
        (Shape::Compound(c), _) => {
            let b_box = b.aabb(pose_ab).expanded(cfg.prediction.max(0.0));
            let mut contacts = Vec::new();
            for (i, (child_pose, child)) in c.children().iter().enumerate() {
                if !child.aabb(child_pose).intersects(&b_box) {
                    continue;
                }
                let pose_cb = child_pose.inv_mul(pose_ab);
                let g = generate(child, b, &pose_cb, cfg, true)?;
                contacts.extend(
                    g.contacts
                        .into_iter()
                        .map(|(k, id)| (k.transformed(child_pose), mix_feature(i as u32, id))),
                );
            }
            Ok(Generated {
                contacts,
                full: true,
            })
        }
        (_, Shape::Compound(_)) => reversed(generate(b, a, &pose_ab.inverse(), cfg, want_full)),
        (Shape::Plane(p), _) if b.is_convex() => Ok(plane_convex(
            p,
            b.as_convex().expect("checked"),
            pose_ab,
            cfg,
            want_full,
        )),
        (Shape::TriMesh(m), _) if b.is_convex() => {
            let cb = b.as_convex().expect("checked");
            // Shapes without one-shot manifolds (cylinders, cones, scaled shapes) use the
            // hybrid method: perturbation when the cache is empty, single points after.
            let incremental = as_polyhedron(cb).is_none()
                && !matches!(cb, ConvexRef::Sphere(_) | ConvexRef::Capsule(_));
            let tri_contacts = |t: &crate::shape::Triangle| {
                let full = want_full && incremental;
                convex_convex(ConvexRef::Triangle(t), cb, pose_ab, cfg, full).contacts
            };
            Ok(Generated {
                contacts: mesh_convex_contacts(m, cb, pose_ab, cfg.prediction, &tri_contacts),
                full: !incremental,
            })
        }
        (_, Shape::Plane(_) | Shape::TriMesh(_)) if a.is_convex() => {
            reversed(generate(b, a, &pose_ab.inverse(), cfg, want_full))
        }
        _ => Err(unsupported(a, b)),
    }
}

fn unsupported(a: &Shape, b: &Shape) -> CaromError {
    CaromError::Unsupported(format!(
        "no contact algorithm for a {} against a {}",
        a.kind_name(),
        b.kind_name()
    ))
}

impl Dispatcher {
    /// A dispatcher with the built-in table and `config`.
    pub fn new(config: ManifoldConfig) -> Self {
        Dispatcher {
            user: BTreeMap::new(),
            config,
        }
    }

    /// Registers `alg` for shapes of kinds `(a, b)`; it overrides the built-in table for
    /// that pair (and, through the swap adapter, for `(b, a)`).
    pub fn register(&mut self, a: ShapeKind, b: ShapeKind, alg: UserAlgorithm) {
        self.user.insert((a, b), alg);
    }

    /// Ok when the pair has an algorithm (user or built-in), else an `Unsupported` error
    /// naming both shapes.
    pub fn check_pair(&self, a: &Shape, b: &Shape) -> Result<()> {
        let (ka, kb) = (a.kind(), b.kind());
        if self.user.contains_key(&(ka, kb)) || self.user.contains_key(&(kb, ka)) || supported(a, b)
        {
            Ok(())
        } else {
            Err(unsupported(a, b))
        }
    }

    /// Contacts for `a` and `b` (B at `pose_ab` in A's frame).
    pub fn generate(
        &self,
        a: &Shape,
        b: &Shape,
        pose_ab: &Isometry,
        want_full: bool,
    ) -> Result<Generated> {
        self.generate_with(a, b, pose_ab, &self.config, want_full)
    }

    /// [`Dispatcher::generate`] with another configuration (e.g. a per-pair prediction).
    pub fn generate_with(
        &self,
        a: &Shape,
        b: &Shape,
        pose_ab: &Isometry,
        cfg: &ManifoldConfig,
        want_full: bool,
    ) -> Result<Generated> {
        let (ka, kb) = (a.kind(), b.kind());
        if let Some(f) = self.user.get(&(ka, kb)) {
            return Ok(f(a, b, pose_ab, cfg, want_full));
        }
        if let Some(f) = self.user.get(&(kb, ka)) {
            let pose_ba = pose_ab.inverse();
            return Ok(swap(f(b, a, &pose_ba, cfg, want_full), pose_ab));
        }
        generate(a, b, pose_ab, cfg, want_full)
    }

    /// One step of the persistent manifold: refresh from the poses, generate, then replace
    /// (full manifolds) or add point by point (the hybrid method).
    pub fn update_manifold(
        &self,
        a: &Shape,
        pose_a: &Isometry,
        b: &Shape,
        pose_b: &Isometry,
        manifold: &mut ContactManifold,
    ) -> Result<()> {
        let p = self.config.prediction;
        self.update_manifold_with_prediction(a, pose_a, b, pose_b, manifold, p)
    }

    /// [`Dispatcher::update_manifold`] with a per-pair speculative margin: points are
    /// generated while the shapes are at most `prediction` apart (never less than the
    /// configured prediction), and cached points survive up to that distance. A dynamics
    /// pipeline passes the relative motion of the pair over the step, so that the solver sees
    /// speculative contacts before fast bodies meet (Catto, "Continuous Collision", GDC 2013;
    /// Rapier's soft CCD prediction distance).
    pub fn update_manifold_with_prediction(
        &self,
        a: &Shape,
        pose_a: &Isometry,
        b: &Shape,
        pose_b: &Isometry,
        manifold: &mut ContactManifold,
        prediction: Real,
    ) -> Result<()> {
        let base = &self.config;
        let prediction = prediction.max(base.prediction);
        let local = ManifoldConfig {
            prediction,
            breaking_threshold: base.breaking_threshold.max(prediction),
            ..*base
        };
        let cfg = &local;
        manifold.refresh(pose_a, pose_b, cfg.breaking_threshold);
        let pose_ab = pose_a.inv_mul(pose_b);
        let g = self.generate_with(a, b, &pose_ab, cfg, manifold.is_empty())?;
        let pts: Vec<ContactPoint> = g
            .contacts
            .iter()
            .map(|(c, id)| ContactPoint::from_local_contact(c, pose_a, pose_b, *id))
            .collect();
        if g.full {
            manifold.replace_all(pts, cfg.merge_distance);
        } else {
            for p in pts {
                manifold.add_point(p, cfg.merge_distance);
            }
        }
        Ok(())
    }
}
