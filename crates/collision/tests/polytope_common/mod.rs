//! The polytope oracle of the polyhedral-manifold tests: the exact intersection polytope,
//! computed by brute force.
//!
//! The oracle knows nothing of GJK, EPA, Gauss maps or clipping: for two posed polytopes
//! (hulls, boxes, triangles) it
//!
//! - enumerates every triple of the two shapes' face planes, solves for the corner and keeps
//!   the corners inside all half-spaces: the vertices of the intersection polytope `I = A ∩ B`;
//! - computes the minimum SAT penetration over *every* candidate axis (all face normals of
//!   both shapes and all edge–edge cross products, both signs, no pruning): the depth
//!   `max_A(u·x) - min_B(u·x)` minimised over the axes is the minimum translational distance
//!   of two convex polytopes.
//!
//! Proptest then draws random hull–hull, box–box and triangle–polytope configurations,
//! including touching contacts, coplanar faces, parallel edges and poses far from the
//! origin, and checks each manifold: its deepest point equals the minimum SAT penetration,
//! every point lies on the contact region (each witness point on its own shape's surface and
//! inside the other shape up to its depth), and face-on
//! contacts cover the contact region (area of the manifold against the area of `I`'s
//! projection). The oracle runs in f64 in both builds.

#![allow(dead_code)]

#[path = "../common/mod.rs"]
pub mod common;

use carom_collision::math::{Isometry, Quat, Real, Vec3};
use carom_collision::narrowphase::polyhedron::{polyhedron_manifold, Polyhedron};
use carom_collision::narrowphase::{ContactManifold, Dispatcher, ManifoldConfig};
use carom_collision::query::{self, Contact};
use carom_collision::shape::{ConvexHull, Cuboid, Shape, SupportMap};
use glam::DVec3;
use proptest::prelude::*;
use proptest::test_runner::RngSeed;

#[allow(clippy::unnecessary_cast)] // a no-op in the f64 build
pub fn d3(v: Vec3) -> DVec3 {
    DVec3::new(v.x as f64, v.y as f64, v.z as f64)
}

#[allow(clippy::unnecessary_cast)]
pub fn r(x: Real) -> f64 {
    x as f64
}

#[allow(clippy::unnecessary_cast)] // a no-op in the f64 build
pub fn v3(x: DVec3) -> Vec3 {
    Vec3::new(x.x as Real, x.y as Real, x.z as Real)
}

/// A posed convex polytope in world space (f64): vertices, outward planes `n·x <= d`, edges.
/// A flat polytope (a triangle) lists its front and back planes first.
pub struct Poly {
    pub verts: Vec<DVec3>,
    pub planes: Vec<(DVec3, f64)>,
    pub edges: Vec<(DVec3, DVec3)>,
    pub flat: bool,
}

impl Poly {
    pub fn new(local: &Shape, pose: &Isometry) -> Poly {
        let p = |v: Vec3| d3(pose.transform_point(v));
        let n = |v: Vec3| d3(pose.transform_vector(v)).normalize();
        match local {
            Shape::Cuboid(b) => {
                let h = b.half_extents();
                let corner = |i: usize| {
                    Vec3::new(
                        if i & 1 != 0 { h.x } else { -h.x },
                        if i & 2 != 0 { h.y } else { -h.y },
                        if i & 4 != 0 { h.z } else { -h.z },
                    )
                };
                let verts: Vec<DVec3> = (0..8).map(|i| p(corner(i))).collect();
                let mut planes = Vec::new();
                for k in 0..3 {
                    for s in [1.0, -1.0] {
                        let mut axis = Vec3::ZERO;
                        axis[k] = s;
                        let nn = n(axis);
                        let on = p(axis * h[k]);
                        planes.push((nn, nn.dot(on)));
                    }
                }
                let mut edges = Vec::new();
                for i in 0..8usize {
                    for k in 0..3 {
                        let j = i | (1 << k);
                        if j != i {
                            edges.push((verts[i], verts[j]));
                        }
                    }
                }
                Poly {
                    verts,
                    planes,
                    edges,
                    flat: false,
                }
            }
            Shape::ConvexHull(hull) => {
                let verts: Vec<DVec3> = hull.vertices().iter().map(|v| p(*v)).collect();
                let planes = hull
                    .faces()
                    .iter()
                    .map(|f| {
                        let nn = n(f.normal);
                        (nn, nn.dot(p(f.normal * f.offset)))
                    })
                    .collect();
                let edges = hull
                    .edges()
                    .iter()
                    .map(|e| (verts[e[0] as usize], verts[e[1] as usize]))
                    .collect();
                Poly {
                    verts,
                    planes,
                    edges,
                    flat: false,
                }
            }
            Shape::Triangle(t) => {
                let verts: Vec<DVec3> = t.vertices().iter().map(|v| p(*v)).collect();
                let nn = (verts[1] - verts[0]).cross(verts[2] - verts[0]).normalize();
                let mut planes = vec![(nn, nn.dot(verts[0])), (-nn, -nn.dot(verts[0]))];
                let mut edges = Vec::new();
                for k in 0..3 {
                    let (a, b) = (verts[k], verts[(k + 1) % 3]);
                    let side = (b - a).cross(nn).normalize();
                    planes.push((side, side.dot(a)));
                    edges.push((a, b));
                }
                Poly {
                    verts,
                    planes,
                    edges,
                    flat: true,
                }
            }
            _ => unreachable!("polytopes only"),
        }
    }

    /// Largest plane violation of `x` (<= 0 inside). For a flat polytope the front and back
    /// planes are relaxed by `thickness`.
    pub fn outside(&self, x: DVec3, thickness: f64) -> f64 {
        self.planes
            .iter()
            .enumerate()
            .map(|(i, (n, d))| {
                let s = n.dot(x) - d;
                if self.flat && i < 2 {
                    s - thickness
                } else {
                    s
                }
            })
            .fold(f64::NEG_INFINITY, f64::max)
    }

    pub fn max_dot(&self, u: DVec3) -> f64 {
        self.verts
            .iter()
            .map(|v| v.dot(u))
            .fold(f64::NEG_INFINITY, f64::max)
    }
}

/// The vertices of `A ∩ B` by brute force: every triple of planes, kept when inside all
/// half-spaces (within `tol`).
pub fn intersection_vertices(a: &Poly, b: &Poly, tol: f64) -> Vec<DVec3> {
    let planes: Vec<(DVec3, f64)> = a.planes.iter().chain(&b.planes).copied().collect();
    let mut out = Vec::new();
    for i in 0..planes.len() {
        for j in i + 1..planes.len() {
            for k in j + 1..planes.len() {
                let (n1, d1) = planes[i];
                let (n2, d2) = planes[j];
                let (n3, d3) = planes[k];
                let det = n1.dot(n2.cross(n3));
                if det.abs() < 1e-9 {
                    continue;
                }
                let x = (n2.cross(n3) * d1 + n3.cross(n1) * d2 + n1.cross(n2) * d3) / det;
                if a.outside(x, 0.0) <= tol && b.outside(x, 0.0) <= tol {
                    out.push(x);
                }
            }
        }
    }
    out
}

/// The minimum SAT penetration of B into A (positive when overlapping), over all face
/// normals and edge–edge cross products of both shapes in both orientations, unpruned.
pub fn min_sat_penetration(a: &Poly, b: &Poly) -> f64 {
    let mut axes: Vec<DVec3> = a.planes.iter().chain(&b.planes).map(|p| p.0).collect();
    for (p, q) in &a.edges {
        for (s, t) in &b.edges {
            let c = (*q - *p).cross(*t - *s);
            if c.length() > 1e-9 * (*q - *p).length() * (*t - *s).length() {
                axes.push(c.normalize());
            }
        }
    }
    axes.iter()
        .flat_map(|u| [*u, -*u])
        .map(|u| a.max_dot(u) + b.max_dot(-u))
        .fold(f64::INFINITY, f64::min)
}

/// Area of the convex hull of points projected on the plane orthogonal to `n` (gift wrap).
pub fn projected_area(points: &[DVec3], n: DVec3) -> f64 {
    let (t0, t1) = n.any_orthonormal_pair();
    let mut p: Vec<(f64, f64)> = points.iter().map(|x| (x.dot(t0), x.dot(t1))).collect();
    p.sort_by(|a, b| a.partial_cmp(b).unwrap());
    p.dedup();
    if p.len() < 3 {
        return 0.0;
    }
    let cross = |o: (f64, f64), a: (f64, f64), b: (f64, f64)| {
        (a.0 - o.0) * (b.1 - o.1) - (a.1 - o.1) * (b.0 - o.0)
    };
    let mut hull: Vec<(f64, f64)> = Vec::new();
    for pass in 0..2 {
        let start = hull.len();
        let iter: Box<dyn Iterator<Item = &(f64, f64)>> = if pass == 0 {
            Box::new(p.iter())
        } else {
            Box::new(p.iter().rev())
        };
        for &q in iter {
            while hull.len() >= start + 2
                && cross(hull[hull.len() - 2], hull[hull.len() - 1], q) <= 0.0
            {
                hull.pop();
            }
            hull.push(q);
        }
        hull.pop();
    }
    let mut area = 0.0;
    for i in 0..hull.len() {
        let (a, b) = (hull[i], hull[(i + 1) % hull.len()]);
        area += a.0 * b.1 - a.1 * b.0;
    }
    0.5 * area.abs()
}

/// How a configuration was built.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Kind {
    /// Random orientation, B moved along the contact normal to a small depth.
    Random,
    /// Random orientation, B moved along the contact normal until it just touches.
    Touching,
    /// A face of B flat against a face of A (coplanar faces), at a small depth or touching.
    FaceOn,
    /// An edge of B parallel to an edge of A, then moved to a small depth.
    ParallelEdges,
}

pub fn kind() -> impl Strategy<Value = Kind> {
    prop_oneof![
        Just(Kind::Random),
        Just(Kind::Touching),
        Just(Kind::FaceOn),
        Just(Kind::ParallelEdges)
    ]
}

pub fn unit() -> impl Strategy<Value = Vec3> {
    (-1.0..1.0 as Real, -1.0..1.0 as Real, -1.0..1.0 as Real)
        .prop_filter("non-zero", |(x, y, z)| x * x + y * y + z * z > 1e-2)
        .prop_map(|(x, y, z)| Vec3::new(x, y, z).normalize())
}

pub fn rotation() -> impl Strategy<Value = Quat> {
    (unit(), -3.2..3.2 as Real).prop_map(|(axis, angle)| Quat::from_axis_angle(axis, angle))
}

pub fn hull(n: std::ops::Range<usize>) -> impl Strategy<Value = Shape> {
    prop::collection::vec((unit(), 0.4..1.0 as Real), n).prop_filter_map("flat hull", |pts| {
        let pts: Vec<Vec3> = pts.into_iter().map(|(u, r)| u * r).collect();
        let h = ConvexHull::new(&pts).ok()?;
        (h.volume() > 0.05).then_some(Shape::ConvexHull(h))
    })
}

pub fn cuboid() -> impl Strategy<Value = Shape> {
    (0.05..1.0 as Real, 0.05..1.0 as Real, 0.05..1.0 as Real)
        .prop_map(|(x, y, z)| Shape::Cuboid(Cuboid::new(Vec3::new(x, y, z)).unwrap()))
}

/// One random configuration's parameters.
#[derive(Debug, Clone)]
pub struct Params {
    pub kind: Kind,
    pub rot_a: Quat,
    pub rot_b: Quat,
    pub dir: Vec3,
    pub depth: Real,
    /// Picks faces or edges (as fractions of their counts) and the spin about them.
    pub pick: (Real, Real, Real),
    /// World offset of the pair (0 or far from the origin).
    pub far: Vec3,
}

pub fn params() -> impl Strategy<Value = Params> {
    (
        kind(),
        rotation(),
        rotation(),
        unit(),
        0.001..0.05 as Real,
        (0.0..1.0 as Real, 0.0..1.0 as Real, -3.2..3.2 as Real),
        prop_oneof![Just(0.0 as Real), Just(1.0e3 as Real)],
        unit(),
    )
        .prop_map(
            |(kind, rot_a, rot_b, dir, depth, pick, far, far_dir)| Params {
                kind,
                rot_a,
                rot_b,
                dir,
                depth,
                pick,
                far: far_dir * far,
            },
        )
}

/// The local faces (normal, offset, vertex loop) and edges of a polytope shape.
pub fn local_faces(s: &Shape) -> Vec<(Vec3, Real, Vec<Vec3>)> {
    let pose = Isometry::IDENTITY;
    let p = Poly::new(s, &pose);
    p.planes
        .iter()
        .map(|(n, d)| {
            let on: Vec<Vec3> = p
                .verts
                .iter()
                .filter(|v| (n.dot(**v) - d).abs() < 1e-6)
                .map(|v| v3(*v))
                .collect();
            (v3(*n), *d as Real, on)
        })
        .collect()
}

pub fn local_edges(s: &Shape) -> Vec<(Vec3, Vec3)> {
    let p = Poly::new(s, &Isometry::IDENTITY);
    p.edges.iter().map(|(a, b)| (v3(*a), v3(*b))).collect()
}

pub fn pick<T: Clone>(v: &[T], f: Real) -> T {
    v[((f * v.len() as Real) as usize).min(v.len() - 1)].clone()
}

/// World poses of A and B for `params`, or `None` when the construction degenerates.
pub fn configure(a: &Shape, b: &Shape, pr: &Params) -> Option<(Isometry, Isometry)> {
    let to_depth = |pose_ab: Isometry, depth: Real| -> Option<Isometry> {
        let c = query::contact(a, &Isometry::IDENTITY, b, &pose_ab, 100.0).ok()??;
        let mut p = pose_ab;
        p.translation -= c.normal * (c.distance + depth);
        Some(p)
    };
    let pose_ab = match pr.kind {
        Kind::Random => to_depth(Isometry::new(pr.dir * 2.0, pr.rot_b), pr.depth)?,
        Kind::Touching => to_depth(Isometry::new(pr.dir * 2.0, pr.rot_b), 0.0)?,
        Kind::FaceOn => {
            let (na, off, loop_a) = pick(&local_faces(a), pr.pick.0);
            let (nb, _, loop_b) = pick(&local_faces(b), pr.pick.1);
            let rot = Quat::from_axis_angle(na, pr.pick.2) * Quat::from_rotation_arc(nb, -na);
            let ca = loop_a.iter().fold(Vec3::ZERO, |s, v| s + *v) / loop_a.len() as Real;
            let cb = loop_b.iter().fold(Vec3::ZERO, |s, v| s + *v) / loop_b.len() as Real;
            let lowest = b
                .as_convex()?
                .support_world(&Isometry::from_rotation(rot), -na)
                .dot(na);
            // Face centroid over face centroid, shifted sideways a little, B's face `depth`
            // below A's (or exactly on it: coplanar and touching).
            let depth = if pr.depth < 0.01 { 0.0 } else { pr.depth };
            let side = (pr.dir - na * pr.dir.dot(na)) * 0.2;
            let mut t = ca - rot * cb + side;
            t += na * (off - depth - lowest - na.dot(t));
            Isometry::new(t, rot)
        }
        Kind::ParallelEdges => {
            let (p, q) = pick(&local_edges(a), pr.pick.0);
            let (s, t) = pick(&local_edges(b), pr.pick.1);
            let (da, db) = ((q - p).try_normalize()?, (t - s).try_normalize()?);
            let rot = Quat::from_axis_angle(da, pr.pick.2) * Quat::from_rotation_arc(db, da);
            // Edge midpoint over edge midpoint, B outside along a random direction
            // orthogonal to the edge, then moved to a small depth.
            let out = (pr.dir - da * pr.dir.dot(da)).try_normalize()?;
            let tr = (p + q) * 0.5 - rot * ((s + t) * 0.5) + out * 2.0;
            to_depth(Isometry::new(tr, rot), pr.depth)?
        }
    };
    let pose_a = Isometry::new(pr.far, pr.rot_a);
    Some((pose_a, pose_a.mul(&pose_ab)))
}

/// Checks the contacts (world frame, query convention: normal from A to B) of A at
/// `pose_a` and B at `pose_b` against the intersection polytope. Returns the manifold's
/// depth error against the minimum SAT penetration.
pub fn check_against_polytope(
    a: &Shape,
    pose_a: &Isometry,
    b: &Shape,
    pose_b: &Isometry,
    contacts: &[Contact],
    kind: Kind,
    tol: f64,
) -> Result<(), TestCaseError> {
    let (pa, pb) = (Poly::new(a, pose_a), Poly::new(b, pose_b));
    let mtd = min_sat_penetration(&pa, &pb);
    let inter = intersection_vertices(&pa, &pb, tol);
    if mtd > tol {
        prop_assert!(
            !inter.is_empty(),
            "overlap {mtd} but no intersection vertex"
        );
        prop_assert!(!contacts.is_empty(), "overlap {mtd} but no contact");
    }
    if contacts.is_empty() {
        // Only when apart or touching.
        prop_assert!(mtd <= tol, "no contact at depth {mtd}");
        return Ok(());
    }
    let deepest = contacts
        .iter()
        .map(|c| -r(c.distance))
        .fold(f64::NEG_INFINITY, f64::max);
    // The manifold's depth is the minimum SAT penetration, up to the clipping's documented
    // preference for faces over edges (`FACE_PREFERENCE`: 1e-3 (1 + depth)).
    let depth_tol = tol + 1.0e-3 * (1.0 + mtd.abs());
    prop_assert!(
        (deepest - mtd).abs() <= depth_tol,
        "{kind:?}: manifold depth {deepest} vs minimum SAT penetration {mtd}"
    );
    let n = d3(contacts[0].normal);
    for c in contacts {
        prop_assert!(c.distance.is_finite() && c.normal.is_finite());
        prop_assert!(
            (d3(c.normal) - n).length() < 1e-3,
            "one normal per manifold"
        );
        let (xa, xb) = (d3(c.point_a), d3(c.point_b));
        let dist = r(c.distance);
        prop_assert!(
            ((xb - xa).dot(n) - dist).abs() < tol,
            "point_b = point_a + n d"
        );
        // Each witness point on its own shape's surface and inside the other shape, up to
        // its own depth: clipping keeps the incident face inside the reference face's side
        // planes, which leave the other shape by at most the depth below that face.
        let slack = tol + dist.abs();
        let thickness = dist.abs() + tol;
        prop_assert!(
            pa.outside(xa, 0.0).abs() <= tol || (pa.flat && pa.outside(xa, 0.0) <= tol),
            "{kind:?}: point_a {xa} off A's surface by {}",
            pa.outside(xa, 0.0)
        );
        prop_assert!(
            pb.outside(xb, 0.0).abs() <= tol || (pb.flat && pb.outside(xb, 0.0) <= tol),
            "{kind:?}: point_b {xb} off B's surface by {}",
            pb.outside(xb, 0.0)
        );
        prop_assert!(
            pb.outside(xa, thickness) <= slack,
            "{kind:?}: point_a {xa} outside B by {}",
            pb.outside(xa, 0.0)
        );
        prop_assert!(
            pa.outside(xb, thickness) <= slack,
            "{kind:?}: point_b {xb} outside A by {}",
            pa.outside(xb, 0.0)
        );
    }
    let boxes = matches!((a, b), (Shape::Cuboid(_), Shape::Cuboid(_)));
    // Face on face: the normal is a face normal of both boxes (a FaceOn configuration whose
    // minimum penetration is lateral, e.g. a long thin box across a corner of the other, has
    // an edge or a vertex of one box on a side face of the other, whose region is a segment
    // or a point).
    let parallel = |p: &Poly| p.planes.iter().any(|(m, _)| m.dot(n).abs() > 1.0 - 1.0e-5);
    if kind == Kind::FaceOn && mtd > 0.005 && boxes && parallel(&pa) && parallel(&pb) {
        // Box face on box face (right dihedral angles, so A ∩ B projects onto the overlap
        // of the two faces): the manifold spans the overlap, up to the reduction to four.
        let pts: Vec<DVec3> = contacts.iter().map(|c| d3(c.point_b)).collect();
        let got = projected_area(&pts, n);
        let want = projected_area(&inter, n);
        prop_assert!(
            got >= 0.4 * want - tol,
            "{kind:?}: manifold area {got} of {want}"
        );
    }
    Ok(())
}

/// Length tolerance for shapes of size ~1 at `far` from the origin.
pub fn tolerance(far: Vec3) -> f64 {
    let eps = r(Real::EPSILON);
    2.0e-4_f64.max(2.0e3 * eps) + 16.0 * eps * r(far.length())
}

/// The dispatcher's manifold (fresh) and the full-SAT manifold, both checked.
pub fn check_pair(a: &Shape, b: &Shape, pr: &Params) -> Result<(), TestCaseError> {
    check_pair_tilted(a, b, pr, Quat::IDENTITY)
}

/// [`check_pair`] with B's configured orientation turned by `tilt` about its origin (nearly
/// parallel edges or faces from a small tilt of a `ParallelEdges` or `FaceOn` configuration).
pub fn check_pair_tilted(
    a: &Shape,
    b: &Shape,
    pr: &Params,
    tilt: Quat,
) -> Result<(), TestCaseError> {
    let Some((pose_a, mut pose_b)) = configure(a, b, pr) else {
        return Ok(());
    };
    pose_b.rotation = (tilt * pose_b.rotation).normalize();
    let tol = tolerance(pr.far);
    // Touching contacts are kept by a prediction of the tolerance.
    let prediction = if matches!(pr.kind, Kind::Touching) {
        tol as Real
    } else {
        0.0
    };
    let d = Dispatcher::new(ManifoldConfig {
        prediction,
        ..Default::default()
    });
    let mut m = ContactManifold::new();
    d.update_manifold(a, &pose_a, b, &pose_b, &mut m).unwrap();
    prop_assert!(m.len() <= 4);
    let contacts: Vec<Contact> = m
        .points
        .iter()
        .map(|p| Contact {
            distance: p.distance,
            point_a: p.point_a(),
            point_b: p.point_b,
            normal: -p.normal,
        })
        .collect();
    check_against_polytope(
        a,
        &pose_a,
        b,
        &pose_b,
        &contacts,
        pr.kind,
        tol + r(prediction),
    )
    .map_err(|e| {
        TestCaseError::fail(format!(
            "dispatcher, {} against {}: {e}\n{contacts:?}",
            a.kind_name(),
            b.kind_name()
        ))
    })?;
    // The full SAT with Gauss-map pruning (the triangle path, and the guided path's oracle).
    fn view(s: &Shape) -> Polyhedron<'_> {
        match s {
            Shape::Cuboid(c) => Polyhedron::from_cuboid(c),
            Shape::ConvexHull(h) => Polyhedron::from_hull(h),
            Shape::Triangle(t) => Polyhedron::from_triangle(t),
            _ => unreachable!(),
        }
    }
    let pose_ab = pose_a.inv_mul(&pose_b);
    let sat: Vec<Contact> = polyhedron_manifold(&view(a), &view(b), &pose_ab, prediction)
        .into_iter()
        .map(|(c, _)| c.transformed(&pose_a))
        .collect();
    check_against_polytope(a, &pose_a, b, &pose_b, &sat, pr.kind, tol + r(prediction)).map_err(
        |e| {
            TestCaseError::fail(format!(
                "full SAT, {} against {}: {e}\n{sat:?}",
                a.kind_name(),
                b.kind_name()
            ))
        },
    )
}

/// The hull of `points` (a regression case's hull, from the vertices proptest printed).
pub fn hull_of(points: &[Vec3]) -> Shape {
    Shape::ConvexHull(ConvexHull::new(points).unwrap())
}

/// The deepest point's signed distance of a manifold, `None` for an empty one.
pub fn deepest(cs: &[Contact]) -> Option<Real> {
    cs.iter().map(|c| c.distance).reduce(Real::min)
}

/// Fails unless the deepest points of `base` and `got` (when both have one) agree: both are
/// the minimum penetration up to the face preference (`1e-3 (1 + d)`) and `tol`. `what`
/// names `got` in the message.
pub fn check_same_depth(
    base: &[Contact],
    got: &[Contact],
    tol: f64,
    what: &str,
) -> Result<(), TestCaseError> {
    if let (Some(d0), Some(d1)) = (deepest(base), deepest(got)) {
        let slack = tol + 2.0e-3 * (1.0 + r(d0).abs());
        prop_assert!(
            (r(d0) - r(d1)).abs() <= slack,
            "{what}: depth {d1} against {d0}"
        );
    }
    Ok(())
}

/// `cases` cases from the fixed seed `seed`, no persisted failures: CI runs the same cases on
/// every machine (the project's determinism rule).
pub fn fixed_seed(cases: u32, seed: u64) -> ProptestConfig {
    ProptestConfig {
        cases,
        rng_seed: RngSeed::Fixed(seed),
        failure_persistence: None,
        ..ProptestConfig::default()
    }
}

/// The two proptest cases of a property of hull pairs checked by `$check(a, b, params)`:
/// `$hull_hull` on two random hulls, `$box_hull` on a box and a hull in both orders, 128
/// cases each from the fixed seed `$seed`.
#[allow(unused_macros)]
macro_rules! hull_pair_cases {
    ($check:ident, $seed:expr, $hull_hull:ident, $box_hull:ident) => {
        proptest! {
            #![proptest_config(fixed_seed(128, $seed))]

            #[test]
            fn $hull_hull(a in hull(6..14), b in hull(6..14), pr in params()) {
                $check(&a, &b, &pr)?;
            }

            #[test]
            fn $box_hull(a in cuboid(), b in hull(6..14), pr in params()) {
                $check(&a, &b, &pr)?;
                $check(&b, &a, &pr)?;
            }
        }
    };
}
#[allow(unused_imports)]
pub(crate) use hull_pair_cases;
