//! Spheres and capsules against a mesh's triangles in closed form, in the mesh's frame:
//! the per-triangle step of [`super::mesh::mesh_convex_contacts`] for round shapes.

use super::contact::{ContactList, FeatureId, NO_FEATURE};
use crate::math::{Isometry, Real, Vec3};
use crate::query::closest_points::closest_point_triangle;
use crate::query::contact_round::{contact_balls, contact_segment_triangle_separated};
use crate::query::Contact;
use crate::shape::ConvexRef;

/// A sphere or capsule placed in the mesh's frame once per pair, for the closed-form
/// triangle contacts of [`mesh_convex_contacts`] (the general dispatch inverted the pose per
/// triangle, twice for a capsule, and moved the corners and contacts between frames). The
/// formulas are the general path's: the triangle's closest point (`contact_sphere_triangle`);
/// Ericson's five closest-point queries (`contact_segment_triangle_separated`), the segment
/// clipped by the side planes on a face normal (`capsule_polyhedron_manifold`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct RoundInMesh {
    /// The shape's centre in the mesh frame: the origin of the tests (the corners are moved
    /// to it, so the arithmetic runs on small coordinates, as in the shape's own frame).
    pub(crate) o: Vec3,
    /// First segment end (capsule; the centre for a sphere), relative to `o`.
    pub(crate) p: Vec3,
    /// Second segment end (capsule), relative to `o`.
    pub(crate) q: Vec3,
    /// The radius.
    r: Real,
    /// A capsule (else a sphere).
    capsule: bool,
}

impl RoundInMesh {
    pub(crate) fn new(b: ConvexRef<'_>, pose_ab: &Isometry) -> Option<RoundInMesh> {
        match b {
            ConvexRef::Sphere(s) => Some(RoundInMesh {
                o: pose_ab.translation,
                p: Vec3::ZERO,
                q: Vec3::ZERO,
                r: s.radius(),
                capsule: false,
            }),
            ConvexRef::Capsule(k) => {
                let (p, q) = k.segment();
                let m = pose_ab.rotation_matrix();
                Some(RoundInMesh {
                    o: pose_ab.translation,
                    p: m * p,
                    q: m * q,
                    r: k.radius(),
                    capsule: true,
                })
            }
            _ => None,
        }
    }

    /// Appends the contacts (A the triangle) of triangle `t` with unit normal `n` within
    /// `prediction`; false (nothing appended) when the closed form is undecided (a capsule
    /// whose segment meets the triangle, or a sliver triangle): the caller then runs the
    /// general path.
    #[inline]
    pub(crate) fn triangle_contacts(
        &self,
        t: [Vec3; 3],
        n: Vec3,
        prediction: Real,
        out: &mut ContactList,
    ) -> bool {
        let o = self.o;
        // Back to the mesh frame.
        let moved = |c: Contact| Contact {
            point_a: c.point_a + o,
            point_b: c.point_b + o,
            ..c
        };
        let t = t.map(|v| v - o);
        if !self.capsule {
            let c = closest_point_triangle(Vec3::ZERO, t[0], t[1], t[2]);
            let k = contact_balls(c, 0.0, Vec3::ZERO, self.r, n);
            if k.distance <= prediction {
                out.push((moved(k), NO_FEATURE));
            }
            return true;
        }
        let Some(c0) = contact_segment_triangle_separated(self.p, self.q, self.r, t, prediction)
        else {
            return false;
        };
        let Some(c0) = c0 else {
            return true;
        };
        let c0 = moved(c0.swapped());
        // A face contact (normal within 0.81° of a face normal, as the polyhedron path):
        // the segment clipped by the triangle's side planes gives two points.
        let cos = c0.normal.dot(n);
        let fnorm = if cos > 0.9999 {
            n
        } else if -cos > 0.9999 {
            -n
        } else {
            out.push((c0, 2));
            return true;
        };
        let (p, q) = (self.p, self.q);
        let (mut t0, mut t1): (Real, Real) = (0.0, 1.0);
        for k in 0..3 {
            let (v0, v1) = (t[k], t[(k + 1) % 3]);
            // Outward in-plane normal of edge k (the corners run counter-clockwise about n).
            let side = (v1 - v0).cross(n).normalize_or_zero();
            let (dp, dq) = (side.dot(p - v0), side.dot(q - v0));
            if dp > 0.0 && dq > 0.0 {
                out.push((c0, 2));
                return true;
            }
            if (dp > 0.0) != (dq > 0.0) {
                let s = dp / (dp - dq);
                if dp > 0.0 {
                    t0 = t0.max(s);
                } else {
                    t1 = t1.min(s);
                }
            }
        }
        if t1 - t0 < 1.0e-4 {
            out.push((c0, 2));
            return true;
        }
        let off = fnorm.dot(t[0]);
        let start = out.len();
        for (k, s) in [t0, t1].into_iter().enumerate() {
            let e = p + (q - p) * s;
            let h = fnorm.dot(e) - off;
            let d = h - self.r;
            if d <= prediction {
                let c = Contact {
                    distance: d,
                    point_a: e - fnorm * h,
                    point_b: e - fnorm * self.r,
                    normal: fnorm,
                };
                out.push((moved(c), k as FeatureId));
            }
        }
        if out.len() == start {
            out.push((c0, 2));
        }
        true
    }
}
