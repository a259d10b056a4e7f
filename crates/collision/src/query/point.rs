//! Point queries: project a point on a shape's boundary, signed distance, inside test.
//!
//! Exact closed forms for spheres, boxes, capsules, cylinders, planes, triangles and hulls
//! (face planes inside, GJK outside); GJK (outside) and EPA (inside) against the exact
//! support map for cones and scaled shapes. Meshes and heightfields are surfaces here (the
//! closest triangle through the midphase traversals, `inside` false); compounds take the child with the smallest signed distance.

use super::closest_points::{closest_point_segment, closest_point_triangle};
use super::epa::epa;
use super::gjk::{gjk, GjkResult};
use super::result::PointProjection;
use super::support_adapters::{Exact, PointSupport};
use crate::error::Result;
use crate::math::{check_finite_vec, Isometry, Real, Vec3};
use crate::midphase::TriangleSource;
use crate::shape::{ConvexHull, ConvexRef, Shape};

/// Projects the world point `point` on `shape` at `pose`.
pub fn project_point(shape: &Shape, pose: &Isometry, point: Vec3) -> Result<PointProjection> {
    let pose = crate::query::check_pose("pose", pose)?;
    let point = check_finite_vec("point", point)?;
    let local = project_point_local(shape, pose.inverse_transform_point(point));
    Ok(PointProjection {
        point: pose.transform_point(local.point),
        ..local
    })
}

/// True when `point` is inside `shape` at `pose` (or on its boundary).
pub fn contains_point(shape: &Shape, pose: &Isometry, point: Vec3) -> Result<bool> {
    Ok(project_point(shape, pose, point)?.inside)
}

fn proj(point: Vec3, distance: Real) -> PointProjection {
    PointProjection {
        point,
        distance,
        inside: distance <= 0.0,
    }
}

/// [`project_point`] in the shape's local frame, without validation.
pub fn project_point_local(shape: &Shape, p: Vec3) -> PointProjection {
    match shape {
        Shape::Sphere(s) => {
            let len = p.length();
            let n = if len > 0.0 { p / len } else { Vec3::Y };
            proj(n * s.radius(), len - s.radius())
        }
        Shape::Cuboid(b) => {
            let h = b.half_extents();
            let q = p.clamp(-h, h);
            if q != p {
                return proj(q, (p - q).length());
            }
            let gaps = h - p.abs();
            let mut axis = 0;
            for i in 1..3 {
                if gaps[i] < gaps[axis] {
                    axis = i;
                }
            }
            let mut q = p;
            q[axis] = if p[axis] < 0.0 { -h[axis] } else { h[axis] };
            proj(q, -gaps[axis])
        }
        Shape::Capsule(c) => {
            let (a, b) = c.segment();
            let (s, _) = closest_point_segment(p, a, b);
            let d = p - s;
            let len = d.length();
            let n = if len > 0.0 { d / len } else { Vec3::X };
            proj(s + n * c.radius(), len - c.radius())
        }
        Shape::Cylinder(c) => {
            let (r, h) = (c.radius(), c.half_height());
            let radial = Vec3::new(p.x, 0.0, p.z);
            let rho = radial.length();
            let dir = if rho > 0.0 { radial / rho } else { Vec3::X };
            if rho > r || p.y.abs() > h {
                let q = dir * rho.min(r) + Vec3::Y * p.y.clamp(-h, h);
                return proj(q, (p - q).length());
            }
            let (side, cap) = (r - rho, h - p.y.abs());
            if side < cap {
                proj(dir * r + Vec3::Y * p.y, -side)
            } else {
                proj(radial + Vec3::Y * h.copysign(p.y), -cap)
            }
        }
        Shape::Triangle(t) => {
            let q = closest_point_triangle(p, t.a, t.b, t.c);
            proj(q, (p - q).length())
        }
        Shape::Plane(pl) => {
            let d = pl.signed_distance(p);
            proj(p - pl.normal() * d, d)
        }
        Shape::ConvexHull(h) => project_hull(h, p),
        Shape::Cone(_) | Shape::Scaled(_) => {
            project_convex_gjk(shape.as_convex().expect("convex kinds"), p)
        }
        Shape::TriMesh(_) | Shape::HeightField(_) => {
            // The midphase traversal (BVH or grid); surfaces are never "inside".
            let src = TriangleSource::of(shape).expect("mesh kinds");
            let best = src
                .closest_point(p, Real::INFINITY)
                .map_or(proj(p, Real::INFINITY), |c| proj(c.point, c.distance));
            PointProjection {
                inside: false,
                ..best
            }
        }
        Shape::Compound(c) => {
            let mut best: Option<PointProjection> = None;
            for (pose, child) in c.children() {
                let local = project_point_local(child, pose.inverse_transform_point(p));
                let r = PointProjection {
                    point: pose.transform_point(local.point),
                    ..local
                };
                if best.is_none_or(|b| r.distance < b.distance) {
                    best = Some(r);
                }
            }
            best.unwrap_or(proj(p, Real::INFINITY))
        }
    }
}

/// Hull: the nearest face plane inside (exact), GJK outside.
fn project_hull(h: &ConvexHull, p: Vec3) -> PointProjection {
    let mut best = (Real::NEG_INFINITY, Vec3::ZERO);
    for f in h.faces() {
        let d = f.normal.dot(p) - f.offset;
        if d > best.0 {
            best = (d, f.normal);
        }
    }
    if best.0 <= 0.0 {
        return proj(p - best.1 * best.0, best.0);
    }
    project_convex_gjk(ConvexRef::ConvexHull(h), p)
}

/// GJK between the shape and the point outside; EPA inside.
pub fn project_convex_gjk(shape: ConvexRef<'_>, p: Vec3) -> PointProjection {
    let a = Exact(shape);
    let b = PointSupport(p);
    match gjk(&a, &b, -p, Real::INFINITY) {
        GjkResult::Separated {
            distance, point_a, ..
        } => proj(point_a, distance),
        GjkResult::BeyondMaxDistance => proj(p, Real::INFINITY),
        GjkResult::Overlapping(s) => {
            let pen = epa(&a, &b, &s);
            PointProjection {
                point: pen.point_a,
                distance: -pen.depth,
                inside: true,
            }
        }
    }
}
