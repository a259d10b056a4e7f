//! The brute-force convex hull that served as the first implementation, kept as the oracle
//! for quickhull.

use carom_collision::math::{orthonormal_basis, Real, Vec3};
use carom_collision::shape::HullPolygons;
use carom_collision::{CaromError, Result};

/// Brute-force hull of `points`: every plane through three points that has all points on one
/// side (within `1e-5 ×` the largest coordinate), one per set of points on it, each face
/// polygon by Andrew's monotone chain.
/// O(n⁴); the test oracle for quickhull.
pub fn brute_force_hull(points: &[Vec3]) -> Result<HullPolygons> {
    if points.len() < 4 {
        return Err(CaromError::invalid(
            "points",
            points.len(),
            "need at least 4 points for a 3D convex hull",
        ));
    }
    let scale = points
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()))
        .max(1e-30);
    let eps = scale * 1e-5;
    let n = points.len();
    let mut planes: Vec<(Vec3, Real)> = Vec::new();
    // A face is identified by the set of points on its plane (not by its normal, which is
    // ill-defined for nearly coplanar points).
    let mut on_sets: Vec<Vec<usize>> = Vec::new();
    for i in 0..n {
        for j in i + 1..n {
            for k in j + 1..n {
                let (a, b, c) = (points[i], points[j], points[k]);
                let Some(nrm) = (b - a).cross(c - a).try_normalize() else {
                    continue;
                };
                let d = nrm.dot(a);
                let mut above = false;
                let mut below = false;
                for p in points {
                    let s = nrm.dot(*p) - d;
                    above |= s > eps;
                    below |= s < -eps;
                }
                let plane = match (above, below) {
                    (false, true) => (nrm, d),
                    (true, false) => (-nrm, -d),
                    _ => continue,
                };
                let on: Vec<usize> = (0..n)
                    .filter(|&l| (plane.0.dot(points[l]) - plane.1).abs() <= eps)
                    .collect();
                if !on_sets.contains(&on) {
                    on_sets.push(on);
                    planes.push(plane);
                }
            }
        }
    }
    if planes.len() < 4 {
        return Err(CaromError::degenerate(
            "convex hull",
            "the points are coplanar or collinear: no 3D hull exists",
        ));
    }
    let mut vertices: Vec<Vec3> = Vec::new();
    let mut faces = Vec::new();
    for (nrm, d) in &planes {
        let on: Vec<Vec3> = points
            .iter()
            .copied()
            .filter(|p| (nrm.dot(*p) - d).abs() <= eps)
            .collect();
        let (t1, t2) = orthonormal_basis(*nrm);
        let mut pts2: Vec<(Real, Real, Vec3)> =
            on.iter().map(|p| (p.dot(t1), p.dot(t2), *p)).collect();
        pts2.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.total_cmp(&b.1)));
        pts2.dedup_by(|a, b| (a.2 - b.2).length() <= eps);
        // Andrew's monotone chain (counter-clockwise in the (t1, t2) basis, i.e. about nrm).
        let cross = |o: &(Real, Real, Vec3), a: &(Real, Real, Vec3), b: &(Real, Real, Vec3)| {
            (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
        };
        let mut lower: Vec<(Real, Real, Vec3)> = Vec::new();
        for p in &pts2 {
            while lower.len() >= 2
                && cross(&lower[lower.len() - 2], &lower[lower.len() - 1], p) <= eps * scale
            {
                lower.pop();
            }
            lower.push(*p);
        }
        let mut upper: Vec<(Real, Real, Vec3)> = Vec::new();
        for p in pts2.iter().rev() {
            while upper.len() >= 2
                && cross(&upper[upper.len() - 2], &upper[upper.len() - 1], p) <= eps * scale
            {
                upper.pop();
            }
            upper.push(*p);
        }
        lower.pop();
        upper.pop();
        lower.extend(upper);
        if lower.len() < 3 {
            continue;
        }
        let mut face = Vec::new();
        for (_, _, p) in lower {
            let idx = match vertices.iter().position(|v| (*v - p).length() <= eps) {
                Some(i) => i,
                None => {
                    vertices.push(p);
                    vertices.len() - 1
                }
            };
            face.push(idx as u32);
        }
        faces.push(face);
    }
    Ok(HullPolygons { vertices, faces })
}
