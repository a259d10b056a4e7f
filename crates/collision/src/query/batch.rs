//! Batch forms of the queries over many poses, rays or points: plain slices in, one result
//! per element out, in input order. With the `parallel` feature the elements are processed
//! with rayon; every element is computed by the same serial code, so results are identical
//! to the serial loop whatever the thread count.
//!
//! Pose slices may have length N or 1 (broadcast); mismatched lengths are an error.
//! When several elements are invalid, the error of the first one (in input order) is
//! returned.

use super::contact::{contact, distance, intersects};
use super::point::project_point;
use super::ray::raycast;
use super::result::{Contact, PointProjection, RayHit, ShapeCastHit};
use super::shape_cast::shape_cast;
use crate::error::{CaromError, Result};
use crate::math::{Isometry, Real, Vec3};
use crate::shape::Shape;

/// The batch size of slices of lengths `lens` (each N or 1).
fn batch_len(names: &[(&str, usize)]) -> Result<usize> {
    let n = names.iter().map(|(_, l)| *l).max().unwrap_or(0);
    for (name, l) in names {
        if *l != n && *l != 1 {
            return Err(CaromError::invalid(
                *name,
                *l,
                format!("length must be {n} (the batch size) or 1"),
            ));
        }
    }
    Ok(n)
}

#[inline]
fn at<T: Copy>(s: &[T], i: usize) -> T {
    if s.len() == 1 {
        s[0]
    } else {
        s[i]
    }
}

/// Maps `f` over `0..n`, in parallel with the `parallel` feature, and returns the results in
/// order (or the first error in order).
fn map_indexed<T: Send>(n: usize, f: impl Fn(usize) -> Result<T> + Sync + Send) -> Result<Vec<T>> {
    #[cfg(feature = "parallel")]
    let results: Vec<Result<T>> = {
        use rayon::prelude::*;
        (0..n).into_par_iter().map(&f).collect()
    };
    #[cfg(not(feature = "parallel"))]
    let results: Vec<Result<T>> = (0..n).map(&f).collect();
    results.into_iter().collect()
}

/// [`distance`] for each pair of poses.
pub fn distance_batch(
    a: &Shape,
    poses_a: &[Isometry],
    b: &Shape,
    poses_b: &[Isometry],
) -> Result<Vec<Contact>> {
    let n = batch_len(&[("poses_a", poses_a.len()), ("poses_b", poses_b.len())])?;
    map_indexed(n, |i| distance(a, &at(poses_a, i), b, &at(poses_b, i)))
}

/// [`contact`] for each pair of poses.
pub fn contact_batch(
    a: &Shape,
    poses_a: &[Isometry],
    b: &Shape,
    poses_b: &[Isometry],
    prediction: Real,
) -> Result<Vec<Option<Contact>>> {
    let n = batch_len(&[("poses_a", poses_a.len()), ("poses_b", poses_b.len())])?;
    map_indexed(n, |i| {
        contact(a, &at(poses_a, i), b, &at(poses_b, i), prediction)
    })
}

/// [`intersects`] for each pair of poses.
pub fn intersects_batch(
    a: &Shape,
    poses_a: &[Isometry],
    b: &Shape,
    poses_b: &[Isometry],
) -> Result<Vec<bool>> {
    let n = batch_len(&[("poses_a", poses_a.len()), ("poses_b", poses_b.len())])?;
    map_indexed(n, |i| intersects(a, &at(poses_a, i), b, &at(poses_b, i)))
}

/// [`raycast`] for each ray (origins and directions of length N or 1).
pub fn raycast_batch(
    shape: &Shape,
    pose: &Isometry,
    origins: &[Vec3],
    dirs: &[Vec3],
    max_distance: Real,
    solid: bool,
) -> Result<Vec<Option<RayHit>>> {
    let n = batch_len(&[("origins", origins.len()), ("directions", dirs.len())])?;
    map_indexed(n, |i| {
        raycast(
            shape,
            pose,
            at(origins, i),
            at(dirs, i),
            max_distance,
            solid,
        )
    })
}

/// [`project_point`] for each point.
pub fn project_point_batch(
    shape: &Shape,
    pose: &Isometry,
    points: &[Vec3],
) -> Result<Vec<PointProjection>> {
    map_indexed(points.len(), |i| project_point(shape, pose, points[i]))
}

/// [`shape_cast`] for each pair of poses and velocities.
#[allow(clippy::too_many_arguments)]
pub fn shape_cast_batch(
    a: &Shape,
    poses_a: &[Isometry],
    vels_a: &[Vec3],
    b: &Shape,
    poses_b: &[Isometry],
    vels_b: &[Vec3],
    max_toi: Real,
) -> Result<Vec<Option<ShapeCastHit>>> {
    let n = batch_len(&[
        ("poses_a", poses_a.len()),
        ("vels_a", vels_a.len()),
        ("poses_b", poses_b.len()),
        ("vels_b", vels_b.len()),
    ])?;
    map_indexed(n, |i| {
        shape_cast(
            a,
            &at(poses_a, i),
            at(vels_a, i),
            b,
            &at(poses_b, i),
            at(vels_b, i),
            max_toi,
        )
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::math::Quat;
    use crate::shape::{Cuboid, Sphere};

    fn poses(n: usize) -> Vec<Isometry> {
        (0..n)
            .map(|i| {
                let t = i as Real * 0.37;
                Isometry::new(
                    Vec3::new(t.sin() * 1.2, t.cos() * 0.8, (t * 1.3).sin() * 0.8),
                    Quat::from_rotation_y(t),
                )
            })
            .collect()
    }

    #[test]
    fn batches_equal_the_serial_loop() {
        let a = Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.3, 0.4)).unwrap());
        let b = Shape::Sphere(Sphere::new(0.4).unwrap());
        let pa = poses(200);
        let pb = [Isometry::IDENTITY];
        let batch = distance_batch(&a, &pa, &b, &pb).unwrap();
        for (i, c) in batch.iter().enumerate() {
            assert_eq!(*c, distance(&a, &pa[i], &b, &pb[0]).unwrap());
        }
        let hits = contact_batch(&a, &pa, &b, &pb, 0.0).unwrap();
        let inter = intersects_batch(&a, &pa, &b, &pb).unwrap();
        assert!(hits.iter().any(|h| h.is_some()) && hits.iter().any(|h| h.is_none()));
        for i in 0..pa.len() {
            assert_eq!(hits[i].is_some(), inter[i]);
        }
        let origins: Vec<Vec3> = pa.iter().map(|p| p.translation * 3.0).collect();
        let rays = raycast_batch(&a, &pb[0], &origins, &[-Vec3::X], 10.0, true).unwrap();
        for (i, r) in rays.iter().enumerate() {
            assert_eq!(
                *r,
                raycast(&a, &pb[0], origins[i], -Vec3::X, 10.0, true).unwrap()
            );
        }
        let proj = project_point_batch(&a, &pb[0], &origins).unwrap();
        assert_eq!(proj.len(), origins.len());
        let casts = shape_cast_batch(&a, &pa, &[Vec3::X], &b, &pb, &[Vec3::ZERO], 1.0).unwrap();
        assert_eq!(casts.len(), pa.len());
    }

    #[test]
    fn mismatched_lengths_and_bad_elements_are_errors() {
        let b = Shape::Sphere(Sphere::new(0.4).unwrap());
        assert!(distance_batch(&b, &poses(3), &b, &poses(2)).is_err());
        let mut p = poses(5);
        p[3].translation.x = Real::NAN;
        let e = distance_batch(&b, &p, &b, &[Isometry::IDENTITY]).unwrap_err();
        assert!(e.to_string().contains("pose_a"));
    }
}
