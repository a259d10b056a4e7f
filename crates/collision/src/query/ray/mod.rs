//! Ray casts against every shape.
//!
//! Analytic for spheres, boxes, capsules, cylinders, planes, triangles and hulls (face-plane
//! clipping, exact); cones (quadric); scaled shapes map the ray into the inner shape's frame (exact for every
//! inner kind); [`raycast_convex_gjk`] (the GJK ray cast of [`gjk_ray`]) serves any
//! support map; meshes and heightfields use the midphase traversals (BVH, grid) through
//! [`TriangleSource`] and compounds recurse.
//!
//! **Solid** casts report a ray starting inside a shape as a hit at distance 0 with
//! `inside = true` and normal `-dir`. **Hollow** casts report the exit point instead
//! (`inside = true`, outward normal). Triangles and meshes are surfaces: `inside` is always
//! false and the normal faces the ray's origin.

pub mod analytic;
pub mod gjk_ray;

use self::analytic::{
    ray_ball, ray_capsule, ray_cone, ray_cuboid, ray_cylinder, ray_hull, ray_hull_solid, ray_plane,
    ray_triangle, Interval,
};
use self::gjk_ray::{gjk_raycast, Single};
use super::result::RayHit;
use super::support_adapters::Exact;
use crate::error::{CaromError, Result};
use crate::math::{check_finite_vec, Isometry, Quat, Real, Vec3};
use crate::midphase::TriangleSource;
use crate::shape::{ConvexRef, Shape};

/// A ray: `origin + t·dir` for `t` in `[0, max_distance]`, `dir` of unit length.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Ray {
    /// Start point.
    pub origin: Vec3,
    /// Unit direction.
    pub dir: Vec3,
}

impl Ray {
    /// A ray; `dir` is normalised and must be finite and non-zero, `origin` finite.
    pub fn new(origin: Vec3, dir: Vec3) -> Result<Ray> {
        let origin = check_finite_vec("origin", origin)?;
        let d = check_finite_vec("direction", dir)?;
        let dir = d
            .try_normalize()
            .ok_or_else(|| CaromError::invalid("direction", dir, "must be non-zero"))?;
        Ok(Ray { origin, dir })
    }

    /// The point at parameter `t`.
    #[inline]
    pub fn at(&self, t: Real) -> Vec3 {
        self.origin + self.dir * t
    }
}

/// Casts a ray against `shape` at `pose` (world frame). `None` on a miss; `max_distance`
/// must be >= 0 (may be infinite). See the module docs for `solid`.
pub fn raycast(
    shape: &Shape,
    pose: &Isometry,
    origin: Vec3,
    dir: Vec3,
    max_distance: Real,
    solid: bool,
) -> Result<Option<RayHit>> {
    let pose = crate::query::check_pose("pose", pose)?;
    let ray = Ray::new(origin, dir)?;
    if max_distance.is_nan() || max_distance < 0.0 {
        return Err(CaromError::invalid(
            "max_distance",
            max_distance,
            "must be >= 0",
        ));
    }
    Ok(raycast_posed(shape, &pose, &ray, max_distance, solid))
}

/// [`raycast`] for a ray made once by [`Ray::new`] and cast against many shapes (a scene
/// query's candidates): the ray is not checked or normalised again, and `max_distance`
/// must be >= 0 (may be infinite; a NaN bound hits nothing). The pose is checked as in
/// [`raycast`]. The scene queries of the raytests batch spent a fifth of their instructions
/// re-making the same ray for every candidate.
pub fn raycast_ray(
    shape: &Shape,
    pose: &Isometry,
    ray: &Ray,
    max_distance: Real,
    solid: bool,
) -> Result<Option<RayHit>> {
    let pose = crate::query::check_pose("pose", pose)?;
    Ok(raycast_posed(shape, &pose, ray, max_distance, solid))
}

/// The cast of [`raycast`] and [`raycast_ray`] once their inputs are checked: the ray into
/// the shape's frame, [`raycast_local`], the hit back to the world.
fn raycast_posed(
    shape: &Shape,
    pose: &Isometry,
    ray: &Ray,
    max_distance: Real,
    solid: bool,
) -> Option<RayHit> {
    if pose.rotation == Quat::IDENTITY {
        // An unrotated shape (a static mesh placed by translation, as the raytests
        // landscape): the ray and the hit only move by the translation. Rotating by the
        // identity gives the same values up to the sign of zeros; on the 500-ray batch the
        // two rotations and the two back were ~120 instructions of every landscape cast.
        let local = Ray {
            origin: ray.origin - pose.translation,
            dir: ray.dir,
        };
        return raycast_local(shape, &local, max_distance, solid).map(|h| RayHit {
            point: h.point + pose.translation,
            ..h
        });
    }
    let local = Ray {
        origin: pose.inverse_transform_point(ray.origin),
        dir: pose.inverse_transform_vector(ray.dir),
    };
    raycast_local(shape, &local, max_distance, solid).map(|h| h.transformed(pose))
}

/// Reads a hit from an interval of parameters (`dir_len` converts parameters to
/// distances when the direction is not unit).
fn from_interval(
    i: Option<Interval>,
    o: Vec3,
    d: Vec3,
    max_t: Real,
    solid: bool,
) -> Option<RayHit> {
    let i = i?;
    if i.t1 < 0.0 {
        return None;
    }
    let (t, n, inside) = if i.t0 >= 0.0 {
        (i.t0, i.n0, false)
    } else if solid {
        (0.0, -d, true)
    } else {
        if !i.t1.is_finite() {
            return None;
        }
        (i.t1, i.n1, true)
    };
    (t <= max_t).then(|| RayHit {
        distance: t,
        point: o + d * t,
        normal: n.normalize_or(-d.normalize_or_zero()),
        inside,
        feature: None,
    })
}

/// [`raycast`] in the shape's local frame, without validation. `dir` must be unit.
pub fn raycast_local(shape: &Shape, ray: &Ray, max_distance: Real, solid: bool) -> Option<RayHit> {
    let (o, d) = (ray.origin, ray.dir);
    match shape {
        Shape::Sphere(s) => from_interval(
            ray_ball(o, d, Vec3::ZERO, s.radius()),
            o,
            d,
            max_distance,
            solid,
        ),
        Shape::Cuboid(b) => from_interval(ray_cuboid(o, d, b), o, d, max_distance, solid),
        Shape::Capsule(c) => from_interval(ray_capsule(o, d, c), o, d, max_distance, solid),
        Shape::Cylinder(c) => from_interval(ray_cylinder(o, d, c), o, d, max_distance, solid),
        Shape::ConvexHull(h) if solid => from_interval(
            ray_hull_solid(o, d, h, max_distance),
            o,
            d,
            max_distance,
            solid,
        ),
        Shape::ConvexHull(h) => from_interval(ray_hull(o, d, h), o, d, max_distance, solid),
        Shape::Plane(p) => from_interval(ray_plane(o, d, p), o, d, max_distance, solid),
        Shape::Triangle(t) => {
            let (t, n) = ray_triangle(o, d, t.a, t.b, t.c)?;
            ((0.0..=max_distance).contains(&t)).then(|| RayHit {
                distance: t,
                point: o + d * t,
                normal: n.normalize(),
                inside: false,
                feature: None,
            })
        }
        Shape::Cone(c) => from_interval(ray_cone(o, d, c), o, d, max_distance, solid),
        Shape::Scaled(s) => {
            // x_inner = x / scale: the parameter t is the same in both frames.
            let inv = Vec3::ONE / s.scale();
            let inner = Ray {
                origin: o * inv,
                dir: d * inv,
            };
            let h = raycast_scaled_inner(s.inner(), &inner, max_distance, solid)?;
            Some(RayHit {
                point: o + d * h.distance,
                normal: if h.inside && solid {
                    -d
                } else {
                    (h.normal * inv).normalize_or(-d)
                },
                ..h
            })
        }
        Shape::TriMesh(_) | Shape::HeightField(_) => {
            // The midphase traversal (BVH or grid); surfaces: the normal faces the origin.
            let h = TriangleSource::of(shape)?.ray_closest(o, d, max_distance)?;
            Some(RayHit {
                distance: h.t,
                point: h.point,
                normal: if h.normal.dot(d) > 0.0 {
                    -h.normal
                } else {
                    h.normal
                },
                inside: false,
                feature: Some(h.triangle),
            })
        }
        Shape::Compound(c) => {
            let mut best: Option<RayHit> = None;
            for (k, (pose, child)) in c.children().iter().enumerate() {
                let local = Ray {
                    origin: pose.inverse_transform_point(o),
                    dir: pose.inverse_transform_vector(d),
                };
                if let Some(h) = raycast_local(child, &local, max_distance, solid) {
                    if best.is_none_or(|b| h.distance < b.distance) {
                        best = Some(RayHit {
                            feature: Some(k as u32),
                            ..h.transformed(pose)
                        });
                    }
                }
            }
            best
        }
    }
}

/// Inner shapes of [`crate::shape::Scaled`] get a non-unit direction: analytic kinds take it
/// as is (their formulas accept any direction); the rest go through GJK.
fn raycast_scaled_inner(inner: &Shape, ray: &Ray, max_t: Real, solid: bool) -> Option<RayHit> {
    let (o, d) = (ray.origin, ray.dir);
    match inner {
        Shape::Sphere(s) => {
            from_interval(ray_ball(o, d, Vec3::ZERO, s.radius()), o, d, max_t, solid)
        }
        Shape::Cuboid(b) => from_interval(ray_cuboid(o, d, b), o, d, max_t, solid),
        Shape::Capsule(c) => from_interval(ray_capsule(o, d, c), o, d, max_t, solid),
        Shape::Cylinder(c) => from_interval(ray_cylinder(o, d, c), o, d, max_t, solid),
        Shape::ConvexHull(h) => from_interval(ray_hull(o, d, h), o, d, max_t, solid),
        Shape::Cone(c) => from_interval(ray_cone(o, d, c), o, d, max_t, solid),
        _ => raycast_convex_gjk(inner.as_convex()?, ray, max_t, solid),
    }
}

/// GJK ray cast against any convex shape (exact support), in its local frame. Hollow casts
/// cast back from beyond the shape to find the exit point.
pub fn raycast_convex_gjk(
    shape: ConvexRef<'_>,
    ray: &Ray,
    max_t: Real,
    solid: bool,
) -> Option<RayHit> {
    let (o, d) = (ray.origin, ray.dir);
    let c = Single(Exact(shape));
    let hit = gjk_raycast(&c, 0.0, o, d, max_t)?;
    if !hit.inside || solid {
        let t = hit.lambda;
        return Some(RayHit {
            distance: t,
            point: o + d * t,
            normal: hit.normal,
            inside: hit.inside,
            feature: None,
        });
    }
    // Hollow and inside: cast from beyond the shape back towards the origin.
    let aabb = shape.local_aabb();
    let span = (aabb.max - aabb.min).length() + (o - aabb.center()).length();
    let far = o + d * span;
    let back = gjk_raycast(&c, 0.0, far, -d, span)?;
    let t = span - back.lambda;
    (t <= max_t).then(|| RayHit {
        distance: t,
        point: o + d * t,
        normal: back.normal,
        inside: true,
        feature: None,
    })
}
