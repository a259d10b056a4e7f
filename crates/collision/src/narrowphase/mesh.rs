//! Convex shapes against triangle meshes and compounds: the midphase finds the triangles
//! (or children) overlapping the convex's box, each gives contacts, merged into one
//! manifold (reduced by [`super::ContactManifold::replace_all`]).
//!
//! Internal-edge correction (Coumans, "Contact Generation", "Internal edges and contact
//! normals"; Bullet's `btInternalEdgeUtility`, Jolt's active edges, Box3D's mesh edge flags):
//! with the mesh's precomputed edge kinds and dihedral angles, a contact normal is changed
//! only when it lies outside the Voronoi region of the feature it touches: on flat and
//! concave edges (and the face interior) it becomes the face normal, on real convex edges
//! it may turn up to the dihedral angle.

use super::contact::FeatureId;
use crate::math::{Isometry, Real, Vec3};
use crate::query::closest_points::closest_point_segment;
use crate::query::Contact;
use crate::shape::{ConvexRef, EdgeKind, SupportMap, TriMesh, Triangle};

/// World (here: mesh-frame) box of convex `b` at `pose_ab`, from six support queries.
pub fn convex_aabb(b: ConvexRef<'_>, pose_ab: &Isometry) -> crate::math::Aabb {
    let mut min = Vec3::ZERO;
    let mut max = Vec3::ZERO;
    for i in 0..3 {
        let mut axis = Vec3::ZERO;
        axis[i] = 1.0;
        max[i] = b.support_world(pose_ab, axis)[i];
        min[i] = b.support_world(pose_ab, -axis)[i];
    }
    crate::math::Aabb::new(min, max)
}

/// Mixes a triangle or child index into a feature id (deterministic).
#[inline]
pub fn mix_feature(index: u32, id: FeatureId) -> FeatureId {
    index.wrapping_mul(0x9E37_79B1) ^ id
}

/// Applies internal-edge correction to contact `c` (mesh frame, normal from triangle `t`
/// towards `b`, `point_a` on the triangle). Returns true when the normal was changed.
pub fn correct_internal_edge(
    mesh: &TriMesh,
    t: usize,
    tri: &Triangle,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: &mut Contact,
) -> bool {
    let Some(face_n) = tri.normal() else {
        return false;
    };
    let n = c.normal;
    let cos_n = n.dot(face_n);
    if !(-1.0e-3..=1.0 - 1.0e-6).contains(&cos_n) {
        return false;
    }
    let v = tri.vertices();
    let scale = (v[1] - v[0])
        .length()
        .max((v[2] - v[1]).length())
        .max((v[0] - v[2]).length());
    let tol = 1.0e-3 * scale + 1.0e-5;
    let edges = &mesh.edges()[t];
    for k in 0..3 {
        let (p, q) = (v[k], v[(k + 1) % 3]);
        let (_, d) = closest_point_segment(c.point_a, p, q);
        if d > tol {
            continue;
        }
        let e = edges[k];
        let allowed = match e.kind {
            EdgeKind::Boundary => true,
            EdgeKind::Flat | EdgeKind::Concave => false,
            EdgeKind::Convex => {
                let out = (q - p).cross(face_n).normalize_or_zero();
                n.dot(out) >= -1.0e-4 && cos_n >= e.angle.cos() - 1.0e-4
            }
        };
        if allowed {
            return false;
        }
    }
    // Outside every active Voronoi region (or in the face interior): use the face normal.
    let pb = b.support_world(pose_ab, -face_n);
    let d = face_n.dot(pb - v[0]);
    c.normal = face_n;
    c.distance = d;
    c.point_b = pb;
    c.point_a = pb - face_n * d;
    true
}

/// Contacts of mesh A against convex B at `pose_ab` (mesh frame, query convention).
/// `tri_contacts` gives the contacts of one triangle against B.
pub fn mesh_convex_contacts(
    mesh: &TriMesh,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    tri_contacts: &dyn Fn(&Triangle) -> Vec<(Contact, FeatureId)>,
) -> Vec<(Contact, FeatureId)> {
    let aabb = convex_aabb(b, pose_ab).expanded(prediction.max(0.0));
    let mut out = Vec::new();
    for t in mesh.overlapping_triangles(&aabb) {
        let [p, q, r] = mesh.triangle(t as usize);
        let Ok(tri) = Triangle::new(p, q, r) else {
            continue;
        };
        if tri.normal().is_none() {
            continue;
        }
        for (mut c, id) in tri_contacts(&tri) {
            correct_internal_edge(mesh, t as usize, &tri, b, pose_ab, &mut c);
            if c.distance <= prediction && c.distance.is_finite() && c.normal.is_finite() {
                out.push((c, mix_feature(t, id)));
            }
        }
    }
    out
}
