//! Convex hull construction: quickhull.
//!
//! C. B. Barber, D. P. Dobkin & H. Huhdanpaa, "The Quickhull Algorithm for Convex Hulls",
//! ACM TOMS 22(4), 1996, with the robustness measures of D. Gregorius, "Implementing
//! Quickhull" (GDC 2014), also used by Jolt's `ConvexHullBuilder`:
//!
//! - the cloud is shifted to the centre of its bounding box and scaled by a power of two
//!   (exact) to unit size, so far-from-origin, tiny and huge clouds behave alike;
//! - "thick" planes: a point counts as outside a face only if it is more than
//!   `tol = 3 ε (max|x| + max|y| + max|z|)` above it; points within `tol` of the hull are
//!   dropped;
//! - a robust initial tetrahedron (extreme points, then the furthest from their line, then the
//!   furthest from their plane), which is also where flat and degenerate inputs are detected;
//! - conflict lists (each outside point belongs to one face it is above), the horizon found by
//!   a depth-first search that yields it as an ordered loop, and a check that it is one simple
//!   loop; coplanar neighbouring faces share one plane, and an eye point that is only "outside"
//!   through a poorly conditioned plane is dropped (all in `quickhull_builder`);
//! - the triangles are then merged into convex polygons (see `quickhull_merge`).
//!
//! Quickhull never removes a vertex that later points made redundant (within the tolerance of
//! the hull of the others); such vertices show up as reflex or collinear in a merged face, and
//! the hull is built again without them (at most `MAX_ROUNDS` times).
//!
//! If a step meets an inconsistency that only rounding can cause (a horizon that is not a simple
//! loop, a zero-area face, a non-manifold result), the build restarts with a larger tolerance;
//! the number of iterations is capped by the number of points, so it always terminates.

use super::quickhull_builder::Builder;
use super::quickhull_merge::{merge_triangles, Triangle};
use crate::error::{CaromError, Result};
use crate::math::{Real, Vec3, EPSILON};

/// A hull as convex polygons over its own vertex list.
#[derive(Debug, Clone, PartialEq)]
pub struct HullPolygons {
    /// Hull vertices (a subset of the input points, unchanged).
    pub vertices: Vec<Vec3>,
    /// Faces: counter-clockwise (from outside) loops of indices into `vertices`. Each face is a
    /// convex polygon without collinear vertices; adjacent faces are not coplanar.
    pub faces: Vec<Vec<u32>>,
}

/// Multipliers of the base tolerance tried in turn when rounding makes a build inconsistent.
const TOLERANCE_SCALES: [Real; 4] = [1.0, 16.0, 256.0, 4096.0];

/// "No face".
pub(super) const NONE: u32 = u32::MAX;

/// The convex hull of `points` by quickhull (see the module documentation).
///
/// Duplicate, coplanar, nearly coplanar and interior points are handled. Fails with a
/// [`CaromError`] naming the problem when there is no 3D hull: fewer than 4 points, a NaN or
/// infinite coordinate, or all points coincident, collinear or coplanar (within the
/// tolerance).
pub fn quickhull(points: &[Vec3]) -> Result<HullPolygons> {
    if points.len() < 4 {
        return Err(CaromError::invalid(
            "points",
            points.len(),
            "need at least 4 points for a 3D convex hull",
        ));
    }
    if let Some(i) = points.iter().position(|p| !p.is_finite()) {
        return Err(CaromError::invalid(
            format!("points[{i}]"),
            points[i],
            "must be finite",
        ));
    }
    let local = normalize(points)?;
    let max_abs = local.iter().fold(Vec3::ZERO, |m, p| m.max(p.abs()));
    let base_tol = 3.0 * EPSILON * (max_abs.x + max_abs.y + max_abs.z);
    // Thinner than this in some direction counts as flat (fixed across retries).
    let flat_tol = 16.0 * base_tol;
    // Points kept so far (indices into `points`) and the last hull built.
    let mut active: Vec<u32> = (0..points.len() as u32).collect();
    let mut last = None;
    for _ in 0..MAX_ROUNDS {
        let subset: Vec<Vec3> = active.iter().map(|&i| local[i as usize]).collect();
        let (faces, redundant, vertices) = match build_with_retries(&subset, base_tol, flat_tol) {
            Ok(built) => built,
            Err(e) => return last.map(|faces| reindex(points, faces)).ok_or(e),
        };
        let faces: Vec<Vec<u32>> = faces
            .into_iter()
            .map(|f| f.into_iter().map(|i| active[i as usize]).collect())
            .collect();
        if redundant.is_empty() {
            return Ok(reindex(points, faces));
        }
        // Hull vertices that lie within the tolerance of the hull of the others (reflex or
        // collinear in a face): build again without them.
        // Points off the triangle hull are within the tolerance of it, and stay so.
        active = vertices
            .into_iter()
            .filter(|i| redundant.binary_search(i).is_err())
            .map(|i| active[i as usize])
            .collect();
        last = Some(faces);
    }
    Ok(reindex(points, last.unwrap_or_default()))
}

/// At most this many builds drop redundant vertices and start again.
const MAX_ROUNDS: usize = 8;

/// Builds the hull of `pts`, retrying with larger tolerances when rounding makes a build
/// inconsistent. Returns what `build` does.
fn build_with_retries(pts: &[Vec3], base_tol: Real, flat_tol: Real) -> Result<Built> {
    for scale in TOLERANCE_SCALES {
        match build(pts, base_tol * scale, flat_tol) {
            Ok(built) => return Ok(built),
            Err(Failure::Degenerate(e)) => return Err(e),
            Err(Failure::Numerical) => continue,
        }
    }
    Err(CaromError::degenerate(
        "convex hull",
        "quickhull could not build a consistent hull even at its largest tolerance \
         (numerically degenerate input)",
    ))
}

/// Why one build attempt stopped.
pub(super) enum Failure {
    /// The input has no 3D hull: report to the user.
    Degenerate(CaromError),
    /// Rounding made the construction inconsistent: retry with a larger tolerance.
    Numerical,
}

/// The points shifted to the centre of their bounding box and scaled by a power of two (an
/// exact operation) so the largest coordinate magnitude lies in `(0.5, 1]`.
fn normalize(points: &[Vec3]) -> Result<Vec<Vec3>> {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(Real::MAX), Vec3::splat(Real::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    // Halve first so the sum cannot overflow.
    let centre = lo * 0.5 + hi * 0.5;
    let shifted: Vec<Vec3> = points.iter().map(|p| *p - centre).collect();
    let extent = shifted
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
    if extent < Real::MIN_POSITIVE || !extent.is_finite() {
        return Err(CaromError::degenerate(
            "convex hull",
            "all points coincide (fewer than 4 distinct points)",
        ));
    }
    let scale = (2.0 as Real).powi(-(extent.log2().ceil() as i32));
    if !scale.is_finite() {
        return Err(CaromError::degenerate(
            "convex hull",
            format!("the point cloud's extent {extent:?} is too small or too large to represent"),
        ));
    }
    Ok(shifted.into_iter().map(|p| p * scale).collect())
}

/// Maps polygons over input point indices to polygons over their own vertex list, in order of
/// first appearance (deterministic).
fn reindex(points: &[Vec3], faces: Vec<Vec<u32>>) -> HullPolygons {
    let mut map = vec![NONE; points.len()];
    let mut vertices = Vec::new();
    let faces = faces
        .into_iter()
        .map(|face| {
            face.into_iter()
                .map(|i| {
                    if map[i as usize] == NONE {
                        map[i as usize] = vertices.len() as u32;
                        vertices.push(points[i as usize]);
                    }
                    map[i as usize]
                })
                .collect()
        })
        .collect();
    HullPolygons { vertices, faces }
}

/// A hull as polygons over point indices, the redundant vertices found while merging, and
/// the vertices of the triangle hull (sorted).
type Built = (Vec<Vec<u32>>, Vec<u32>, Vec<u32>);

/// One build attempt at tolerance `tol`: polygons over point indices, and the hull vertices
/// found redundant (see `merge_triangles`). Inputs thinner than `flat_tol` are rejected as
/// coincident, collinear or coplanar.
fn build(pts: &[Vec3], tol: Real, flat_tol: Real) -> std::result::Result<Built, Failure> {
    let mut hull = Builder::new(pts, tol, flat_tol)?;
    // Every iteration removes its eye point for good, so `pts.len()` bounds the iterations.
    let mut pending: Vec<u32> = (0..hull.faces.len() as u32).collect();
    let mut iterations = 0;
    while let Some(f) = pending.pop() {
        let face = &hull.faces[f as usize];
        if !face.alive || face.conflict.is_empty() {
            continue;
        }
        iterations += 1;
        if iterations > pts.len() {
            return Err(Failure::Numerical);
        }
        let (eye, dist) = face
            .conflict
            .iter()
            .map(|&i| (i, hull.distance(f, pts[i as usize])))
            .fold(
                (NONE, Real::MIN),
                |best, c| if c.1 > best.1 { c } else { best },
            );
        if dist <= tol {
            // The face's shared plane was refined since: its points are on the hull now.
            hull.faces[f as usize].conflict.clear();
            continue;
        }
        hull.add_point(f, eye, &mut pending)?;
        // Unless the eye was dropped, `f` is gone; otherwise look at it again.
        if hull.faces[f as usize].alive {
            pending.push(f);
        }
    }
    let alive: Vec<u32> = (0..hull.faces.len() as u32)
        .filter(|&f| hull.faces[f as usize].alive)
        .collect();
    let mut compact = vec![NONE; hull.faces.len()];
    for (k, &f) in alive.iter().enumerate() {
        compact[f as usize] = k as u32;
    }
    let triangles: Vec<Triangle> = alive
        .iter()
        .map(|&f| {
            let face = &hull.faces[f as usize];
            let plane = hull.planes[face.plane as usize];
            Triangle {
                v: face.v,
                adj: face.adj.map(|a| compact[a as usize]),
                normal: plane.normal,
                offset: plane.offset,
            }
        })
        .collect();
    if triangles.iter().any(|t| t.adj.contains(&NONE)) {
        return Err(Failure::Numerical);
    }
    let (polygons, redundant) =
        merge_triangles(pts, &triangles, 2.0 * tol).ok_or(Failure::Numerical)?;
    let mut vertices: Vec<u32> = triangles.iter().flat_map(|t| t.v).collect();
    vertices.sort_unstable();
    vertices.dedup();
    Ok((polygons, redundant, vertices))
}
