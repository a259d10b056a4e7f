//! The collision dispatcher (Bullet's `btCollisionDispatcher`): for every pair of shape kinds
//! an algorithm that produces contacts for the pair's persistent manifold. The table is an
//! exhaustive `match` on shapes, symmetric through one swap adapter; a user algorithm
//! registered for a pair of kinds overrides it; an unsupported pair is reported by
//! [`Dispatcher::check_pair`] (called when an object is added), never silently skipped.

use super::contact::{ContactList, ContactPoint, FeatureId, NO_FEATURE};
use super::contact_capsule_cuboid::capsule_cuboid_manifold;
use super::contact_cuboid_cuboid::{
    cuboid_cuboid_manifold_into, cuboid_cuboid_manifold_or_separation,
};
use super::convex::{
    capsule_capsule_manifold, capsule_polyhedron_manifold, perturbed_contacts,
    plane_capsule_manifold,
};
use super::manifold::{to_vec3, to_vec3a, ContactManifold, ManifoldConfig};
use super::mesh::{mesh_convex_contacts, mesh_hull_contacts, mix_feature, ContactTriangles};
use super::polyhedron::{
    plane_polyhedron_manifold, polyhedron_manifold_guided, polyhedron_manifold_into, Polyhedron,
    SAT_MAX_EDGE_PAIRS,
};
use super::polyhedron_guided::hull_manifold_or_separation_warm;
use super::triangle_cuboid::triangle_cuboid_manifold_into;
use crate::error::{CaromError, Result};
use crate::math::{Isometry, Mat3, Real, Vec3, Vec3A};
use crate::query::contact::{contact_convex_plane, contact_plane_convex};
use crate::query::{contact_convex, Contact};
use crate::shape::{ConvexRef, Plane, Shape, ShapeKind, Triangle};
use std::cell::RefCell;
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

fn swap(g: Generated, pose_ab: &Isometry) -> Generated {
    let mut contacts = g.contacts;
    swap_from(&mut contacts, 0, pose_ab);
    Generated {
        contacts,
        full: g.full,
    }
}

/// Turns the contacts `out[start..]`, computed with the shapes swapped (in B's frame), into
/// A's frame with the query convention.
fn swap_from(out: &mut [(Contact, FeatureId)], start: usize, pose_ab: &Isometry) {
    for (c, _) in &mut out[start..] {
        *c = c.swapped().transformed(pose_ab);
    }
}

/// The polyhedron view of boxes, hulls and triangles.
pub fn as_polyhedron(c: ConvexRef<'_>) -> Option<Polyhedron<'_>> {
    match c {
        ConvexRef::Cuboid(b) => Some(Polyhedron::from_cuboid(b)),
        ConvexRef::ConvexHull(h) => Some(Polyhedron::from_hull(h)),
        ConvexRef::Triangle(t) => Some(Polyhedron::from_triangle(t)),
        _ => None,
    }
}

/// Whether [`as_polyhedron`] gives a view of `c`, without building it (the dispatch guards
/// of [`convex_convex_into`] run once per mesh triangle, where building the triangle's view
/// three times to test and use it was measurable).
#[inline]
fn is_polyhedral(c: ConvexRef<'_>) -> bool {
    matches!(
        c,
        ConvexRef::Cuboid(_) | ConvexRef::ConvexHull(_) | ConvexRef::Triangle(_)
    )
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
    let mut contacts = Vec::new();
    let full = convex_convex_into(a, b, pose_ab, cfg, want_full, &mut contacts);
    Generated { contacts, full }
}

/// [`convex_convex`] appending to `out`; returns whether the contacts form a full manifold.
/// Polyhedron pairs (box, hull, triangle) and spheres allocate nothing beyond `out`.
pub fn convex_convex_into(
    a: ConvexRef<'_>,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
    out: &mut ContactList,
) -> bool {
    use ConvexRef as C;
    let pred = cfg.prediction;
    let swapped = |out: &mut ContactList| {
        let start = out.len();
        let full = convex_convex_into(b, a, &pose_ab.inverse(), cfg, want_full, out);
        swap_from(out, start, pose_ab);
        full
    };
    match (a, b) {
        (C::Sphere(_), _) | (_, C::Sphere(_)) => {
            out.extend(contact_convex(a, b, pose_ab, pred).map(|c| (c, NO_FEATURE)));
            true
        }
        (C::Capsule(x), C::Capsule(y)) => {
            out.extend(capsule_capsule_manifold(x, y, pose_ab, pred));
            true
        }
        (C::Capsule(x), C::Cuboid(y)) => {
            out.extend(capsule_cuboid_manifold(x, y, pose_ab, pred));
            true
        }
        (C::Capsule(x), _) if is_polyhedral(b) => {
            let pb = as_polyhedron(b).expect("checked");
            out.extend(capsule_polyhedron_manifold(x, b, &pb, pose_ab, pred));
            true
        }
        (_, C::Capsule(_)) if is_polyhedral(a) => swapped(out),
        (C::Triangle(t), C::Cuboid(c)) => {
            triangle_cuboid_manifold_into(t, c, pose_ab, pred, out);
            true
        }
        (C::Cuboid(_), C::Triangle(_)) => swapped(out),
        (C::Cuboid(x), C::Cuboid(y)) => {
            cuboid_cuboid_manifold_into(x, y, pose_ab, pred, out);
            true
        }
        _ => match (as_polyhedron(a), as_polyhedron(b)) {
            (Some(pa), Some(pb)) => {
                if pa.flat || pb.flat || pa.edges().len() * pb.edges().len() <= SAT_MAX_EDGE_PAIRS {
                    polyhedron_manifold_into(&pa, &pb, pose_ab, pred, out);
                } else {
                    polyhedron_manifold_guided(&pa, &pb, a, b, pose_ab, pred, out);
                }
                true
            }
            // Perturb the shape, not the triangle (whose origin is the mesh's).
            _ if matches!(a, C::Triangle(_)) => swapped(out),
            _ => {
                let f = |p: &Isometry| contact_convex(a, b, p, pred);
                let Some(c0) = f(pose_ab) else {
                    return false;
                };
                out.push((c0, NO_FEATURE));
                if want_full {
                    let more = perturbed_contacts(
                        &f,
                        pose_ab,
                        &c0,
                        cfg.perturbation_angle,
                        cfg.perturbation_iterations,
                    );
                    out.extend(
                        more.into_iter()
                            .filter(|c| c.distance <= pred)
                            .map(|c| (c, NO_FEATURE)),
                    );
                }
                false
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
            contacts: contact_plane_convex(plane, b, pose_ab, pred)
                .map(|c| (c, NO_FEATURE))
                .into_iter()
                .collect(),
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
/// Triangle meshes, heightfields and planes need a convex partner (or a compound of
/// convex shapes).
pub fn supported(a: &Shape, b: &Shape) -> bool {
    let surface = |s: &Shape| {
        matches!(
            s,
            Shape::Plane(_) | Shape::TriMesh(_) | Shape::HeightField(_)
        )
    };
    match (a, b) {
        (Shape::Compound(c), o) | (o, Shape::Compound(c)) => {
            c.children().iter().all(|(_, s)| supported(s, o))
        }
        _ => !(surface(a) && surface(b)),
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
    let mut contacts = Vec::new();
    let full = generate_into(a, b, pose_ab, cfg, want_full, &mut contacts)?;
    Ok(Generated { contacts, full })
}

/// Contacts of triangles (mesh or heightfield) A against convex B, appended to `out`.
fn triangles_convex_into<M: ContactTriangles>(
    m: &M,
    cb: ConvexRef<'_>,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
    out: &mut ContactList,
) -> bool {
    // Shapes without one-shot manifolds (cylinders, cones, scaled shapes) use the hybrid
    // method: perturbation when the cache is empty, single points after.
    let incremental =
        !is_polyhedral(cb) && !matches!(cb, ConvexRef::Sphere(_) | ConvexRef::Capsule(_));
    let full = want_full && incremental;
    if let ConvexRef::ConvexHull(h) = cb {
        mesh_hull_contacts(m, h, pose_ab, cfg.prediction, out);
        return true;
    }
    let mut tri_contacts = |t: &Triangle, out: &mut ContactList| {
        convex_convex_into(ConvexRef::Triangle(t), cb, pose_ab, cfg, full, out);
    };
    mesh_convex_contacts(m, cb, pose_ab, cfg.prediction, &mut tri_contacts, out);
    !incremental
}

/// [`generate`] appending to `out`; returns whether the contacts form a full manifold.
pub fn generate_into(
    a: &Shape,
    b: &Shape,
    pose_ab: &Isometry,
    cfg: &ManifoldConfig,
    want_full: bool,
    out: &mut ContactList,
) -> Result<bool> {
    if let (Some(ca), Some(cb)) = (a.as_convex(), b.as_convex()) {
        return Ok(convex_convex_into(ca, cb, pose_ab, cfg, want_full, out));
    }
    let reversed = |out: &mut ContactList| -> Result<bool> {
        let start = out.len();
        let full = generate_into(b, a, &pose_ab.inverse(), cfg, want_full, out)?;
        swap_from(out, start, pose_ab);
        Ok(full)
    };
    match (a, b) {
        (Shape::Compound(c), _) => {
            let b_box = b.aabb(pose_ab).expanded(cfg.prediction.max(0.0));
            for (i, (child_pose, child)) in c.children().iter().enumerate() {
                if !child.aabb(child_pose).intersects(&b_box) {
                    continue;
                }
                let pose_cb = child_pose.inv_mul(pose_ab);
                let start = out.len();
                generate_into(child, b, &pose_cb, cfg, true, out)?;
                for (k, id) in &mut out[start..] {
                    *k = k.transformed(child_pose);
                    *id = mix_feature(i as u32, *id);
                }
            }
            Ok(true)
        }
        (_, Shape::Compound(_)) => reversed(out),
        (Shape::Plane(p), _) if b.is_convex() => {
            let g = plane_convex(p, b.as_convex().expect("checked"), pose_ab, cfg, want_full);
            out.extend(g.contacts);
            Ok(g.full)
        }
        (Shape::TriMesh(m), _) if b.is_convex() => {
            let cb = b.as_convex().expect("checked");
            Ok(triangles_convex_into(m, cb, pose_ab, cfg, want_full, out))
        }
        (Shape::HeightField(h), _) if b.is_convex() => {
            let cb = b.as_convex().expect("checked");
            Ok(triangles_convex_into(h, cb, pose_ab, cfg, want_full, out))
        }
        (_, Shape::Plane(_) | Shape::TriMesh(_) | Shape::HeightField(_)) if a.is_convex() => {
            reversed(out)
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
        let mut contacts = Vec::new();
        let full = self.generate_into_with(a, b, pose_ab, cfg, want_full, &mut contacts)?;
        Ok(Generated { contacts, full })
    }

    /// [`Dispatcher::generate`] appending to `out` (reusing its capacity); returns whether
    /// the contacts form a full manifold.
    pub fn generate_into(
        &self,
        a: &Shape,
        b: &Shape,
        pose_ab: &Isometry,
        want_full: bool,
        out: &mut ContactList,
    ) -> Result<bool> {
        self.generate_into_with(a, b, pose_ab, &self.config, want_full, out)
    }

    /// [`Dispatcher::generate_into`] with another configuration.
    pub fn generate_into_with(
        &self,
        a: &Shape,
        b: &Shape,
        pose_ab: &Isometry,
        cfg: &ManifoldConfig,
        want_full: bool,
        out: &mut ContactList,
    ) -> Result<bool> {
        let (ka, kb) = (a.kind(), b.kind());
        if let Some(f) = self.user.get(&(ka, kb)) {
            let g = f(a, b, pose_ab, cfg, want_full);
            out.extend(g.contacts);
            return Ok(g.full);
        }
        if let Some(f) = self.user.get(&(kb, ka)) {
            let g = swap(f(b, a, &pose_ab.inverse(), cfg, want_full), pose_ab);
            out.extend(g.contacts);
            return Ok(g.full);
        }
        generate_into(a, b, pose_ab, cfg, want_full, out)
    }

    /// One step of the persistent manifold: refresh from the poses, generate, then replace
    /// (full manifolds) or add point by point (the hybrid method). Works in per-thread
    /// scratch buffers: no heap allocation in the steady state for polyhedra and spheres.
    /// While the relative pose stays within the coherence tolerances of the last full
    /// generation ([`ContactManifold::is_coherent`]), the refreshed points are kept as they are.
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
        thread_local! {
            static SCRATCH: RefCell<(ContactList, Vec<ContactPoint>)> =
                const { RefCell::new((Vec::new(), Vec::new())) };
        }
        let base = &self.config;
        let prediction = prediction.max(base.prediction);
        let local = ManifoldConfig {
            prediction,
            breaking_threshold: base.breaking_threshold.max(prediction),
            ..*base
        };
        let cfg = &local;
        let before = manifold.len();
        // The bodies' rotation matrices, built once per pair when there are points to
        // refresh or generated points to convert (apart pairs skipped by their certificate
        // need none).
        let mut mats = None;
        if before > 0 {
            let (ra, rb) = (pose_a.rotation_matrix(), pose_b.rotation_matrix());
            manifold.refresh_with(
                &ra,
                pose_a.translation,
                &rb,
                pose_b.translation,
                cfg.breaking_threshold,
            );
            mats = Some((ra, rb));
        }
        let pose_ab = pose_a.inv_mul(pose_b);
        if before == 0 {
            // An apart pair whose separating axis still proves the gap: nothing to generate.
            if manifold
                .apart
                .is_some_and(|s| s.holds(&pose_ab, cfg.prediction))
            {
                return Ok(());
            }
        } else if manifold.len() == before && manifold.is_coherent(&pose_ab) {
            return Ok(());
        }
        SCRATCH.with(|cell| {
            // A re-entrant call (a user algorithm updating another manifold) gets fresh buffers.
            let mut fresh = Default::default();
            let mut guard = cell.try_borrow_mut();
            let (contacts, pts) = match guard.as_deref_mut() {
                Ok(s) => s,
                Err(_) => &mut fresh,
            };
            contacts.clear();
            pts.clear();
            // A hull pair's last normal (world, from B towards A) or separating axis seeds
            // GJK: the certificate is taken before it is cleared, the hint formed only on the
            // hull path (a quaternion rotation per box pair before).
            let apart = manifold.apart.take();
            let full = match (a, b) {
                // Box–box directly (the built-in table's choice), keeping the separating axis
                // of an apart pair as the manifold's certificate.
                (Shape::Cuboid(x), Shape::Cuboid(y)) if self.user.is_empty() => {
                    manifold.apart = cuboid_cuboid_manifold_or_separation(
                        x,
                        y,
                        &pose_ab,
                        cfg.prediction,
                        contacts,
                    );
                    true
                }
                // Hull–hull and hull–box directly too, keeping GJK's separating axis.
                (Shape::ConvexHull(_), Shape::ConvexHull(_) | Shape::Cuboid(_))
                | (Shape::Cuboid(_), Shape::ConvexHull(_))
                    if self.user.is_empty() =>
                {
                    let hint = match (manifold.points.first(), &apart) {
                        (Some(p), _) => Some(-pose_a.inverse_transform_vector(p.normal)),
                        (None, Some(s)) => Some(s.axis),
                        (None, None) => None,
                    };
                    manifold.apart = hull_manifold_or_separation_warm(
                        a,
                        b,
                        &pose_ab,
                        cfg.prediction,
                        hint,
                        Some(&mut manifold.warm),
                        contacts,
                    );
                    true
                }
                _ => self.generate_into_with(a, b, &pose_ab, cfg, manifold.is_empty(), contacts)?,
            };
            if !contacts.is_empty() {
                let (ra, rb) =
                    mats.unwrap_or_else(|| (pose_a.rotation_matrix(), pose_b.rotation_matrix()));
                let rb_t = rb.transpose();
                let (ta, tb) = (pose_a.translation, pose_b.translation);
                convert_points(contacts, (&ra, ta), (&rb_t, tb), pts);
            }
            manifold.generated_at = full.then_some(pose_ab);
            if full {
                manifold.replace_with(pts, cfg.merge_distance);
            } else {
                for p in pts.drain(..) {
                    manifold.add_point(p, cfg.merge_distance);
                }
            }
            Ok(())
        })
    }
}

/// Appends to `out` the contacts `contacts` (in A's frame) as [`ContactPoint`]s:
/// [`ContactPoint::from_local_contact_mat`] for each, with the same bits, but (1) the
/// matrix–vector products on SIMD columns (`Vec3A`), summed in `Mat3 * Vec3`'s order
/// (column by column, nothing fused), as the manifold's refresh does, and (2) the world
/// normal and its image in B's frame formed once per run of contacts with the same normal
/// (bit for bit): a clipped face gives every point the reference face's normal, so two of
/// the four products per point were repeated work. In f64 `Vec3A` is `Vec3` and this is the
/// scalar code.
fn convert_points(
    contacts: &[(Contact, FeatureId)],
    (ra, ta): (&Mat3, Vec3),
    (rb_t, tb): (&Mat3, Vec3),
    out: &mut Vec<ContactPoint>,
) {
    let cols = |m: &Mat3| [m.x_axis, m.y_axis, m.z_axis].map(to_vec3a);
    let (ca, cb) = (cols(ra), cols(rb_t));
    let mul = |m: &[Vec3A; 3], v: Vec3A| m[0] * v.x + m[1] * v.y + m[2] * v.z;
    let (ta, tb) = (to_vec3a(ta), to_vec3a(tb));
    let bits = |v: Vec3| v.to_array().map(Real::to_bits);
    // The last contact normal's bits, its world normal and that normal in B's frame.
    let mut last: Option<(_, Vec3A, Vec3A)> = None;
    // `extend` over the mapped slice reserves once (a `push` per point checked the capacity).
    out.extend(contacts.iter().map(|(c, id)| {
        let point_b = mul(&ca, to_vec3a(c.point_b)) + ta;
        let key = bits(c.normal);
        let (normal, local_normal_b) = match last {
            Some((k, n, ln)) if k == key => (n, ln),
            _ => {
                let n = -mul(&ca, to_vec3a(c.normal));
                let ln = mul(&cb, n);
                last = Some((key, n, ln));
                (n, ln)
            }
        };
        ContactPoint {
            distance: c.distance,
            normal: to_vec3(normal),
            point_b: to_vec3(point_b),
            local_a: c.point_a,
            local_b: to_vec3(mul(&cb, point_b - tb)),
            local_normal_b: to_vec3(local_normal_b),
            feature: *id,
            normal_impulse: 0.0,
            tangent_impulse: [0.0; 2],
            lifetime: 0,
        }
    }));
}

#[cfg(test)]
#[path = "dispatcher_tests.rs"]
mod tests;
