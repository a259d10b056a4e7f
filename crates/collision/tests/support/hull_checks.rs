//! Invariant checks and fixtures shared by the convex hull tests.

use carom_collision::math::{real, Mat3, Real, Vec3, EPSILON};
use carom_collision::shape::{polyhedron_mass_properties, ConvexHull};

/// Largest coordinate magnitude of `points` about their bounding-box centre.
pub fn extent(points: &[Vec3]) -> Real {
    let (lo, hi) = points.iter().fold(
        (Vec3::splat(Real::MAX), Vec3::splat(Real::MIN)),
        |(lo, hi), p| (lo.min(*p), hi.max(*p)),
    );
    ((hi - lo) * 0.5).max_element()
}

/// Length tolerance for checks on a hull of `points`: relative to its size, plus the rounding
/// of plane offsets far from the origin.
pub fn tolerance(points: &[Vec3]) -> Real {
    let far = points
        .iter()
        .fold(0.0 as Real, |m, p| m.max(p.abs().max_element()));
    1000.0 * EPSILON * extent(points) + 16.0 * EPSILON * far
}

/// A small deterministic generator (64-bit LCG) for fixed test clouds.
pub struct Lcg(pub u64);

impl Lcg {
    pub fn unit(&mut self) -> f64 {
        self.0 = self
            .0
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    pub fn symmetric(&mut self) -> f64 {
        2.0 * self.unit() - 1.0
    }
    pub fn point(&mut self) -> Vec3 {
        Vec3::new(
            real(self.symmetric()),
            real(self.symmetric()),
            real(self.symmetric()),
        )
    }
}

/// Checks every invariant of a hull built from `points`; returns the number of hull vertices.
pub fn check_hull(points: &[Vec3], hull: &ConvexHull) -> usize {
    let tol = tolerance(points);
    let verts = hull.vertices();
    // Hull vertices are distinct input points.
    for (i, v) in verts.iter().enumerate() {
        assert!(points.contains(v), "vertex {i} {v:?} is not an input point");
        assert!(!verts[..i].contains(v), "vertex {i} {v:?} repeated");
    }
    // Every input point is inside or on the hull.
    for face in hull.faces() {
        assert!(
            (face.normal.length() - 1.0).abs() < 1e-3,
            "normal {:?}",
            face.normal
        );
        for p in points {
            let d = face.normal.dot(*p) - face.offset;
            assert!(d <= tol, "point {p:?} is {d} outside face {face:?}");
        }
    }
    // Faces are planar, convex and without collinear vertices.
    for (f, face) in hull.faces().iter().enumerate() {
        let loop_ = hull.face_vertices(f);
        let n = loop_.len();
        assert!(n >= 3, "face {f} has {n} vertices");
        for k in 0..n {
            let u = verts[loop_[(k + n - 1) % n] as usize];
            let v = verts[loop_[k] as usize];
            let w = verts[loop_[(k + 1) % n] as usize];
            let d = face.normal.dot(v) - face.offset;
            assert!(d.abs() <= tol, "face {f} not planar: vertex off by {d}");
            let turn = (v - u).cross(w - v).dot(face.normal) / (w - u).length();
            assert!(
                turn > EPSILON * extent(points),
                "face {f} vertex {k}: reflex or collinear (turn {turn})"
            );
        }
    }
    // Closed and oriented: every directed edge once, its reverse once; V - E + F = 2.
    let mut directed: Vec<(u32, u32, usize)> = Vec::new();
    for f in 0..hull.faces().len() {
        let l = hull.face_vertices(f);
        for k in 0..l.len() {
            directed.push((l[k], l[(k + 1) % l.len()], f));
        }
    }
    directed.sort_unstable();
    for w in directed.windows(2) {
        assert!((w[0].0, w[0].1) != (w[1].0, w[1].1), "edge {w:?} twice");
    }
    for &(a, b, f) in &directed {
        let twin = directed
            .binary_search_by(|e| (e.0, e.1).cmp(&(b, a)))
            .unwrap_or_else(|_| panic!("edge ({a}, {b}) of face {f} has no twin"));
        let g = directed[twin].2;
        // Adjacent faces were merged if coplanar: some vertex of g lies clearly below f.
        // Measured from a vertex of f: differences of nearby floats are exact.
        let nf = hull.faces()[f].normal;
        let origin = verts[hull.face_vertices(f)[0] as usize];
        let deepest = hull
            .face_vertices(g)
            .iter()
            .map(|&i| nf.dot(verts[i as usize] - origin))
            .fold(0.0 as Real, Real::min);
        let coplanar_tol = 2.0 * EPSILON * extent(points);
        assert!(
            deepest < -coplanar_tol,
            "faces {f} and {g} are coplanar ({deepest})"
        );
    }
    let (v, e, f) = (verts.len(), directed.len() / 2, hull.faces().len());
    assert_eq!(
        v as i64 - e as i64 + f as i64,
        2,
        "Euler: V={v} E={e} F={f}"
    );
    assert_eq!(hull.edges().len(), e);
    // Adjacency is the edge list, both ways.
    for (i, _) in verts.iter().enumerate() {
        for &j in hull.vertex_neighbors(i) {
            let (a, b) = (i.min(j as usize) as u32, i.max(j as usize) as u32);
            assert!(
                hull.edges().contains(&[a, b]),
                "neighbour {i}-{j} is no edge"
            );
            assert!(hull.vertex_neighbors(j as usize).contains(&(i as u32)));
        }
    }
    let degree: usize = (0..v).map(|i| hull.vertex_neighbors(i).len()).sum();
    assert_eq!(degree, 2 * e);
    v
}

/// Volume of a polygon hull (fan triangulation).
pub fn polygons_volume(vertices: &[Vec3], faces: &[Vec<u32>]) -> Real {
    let mut tris = Vec::new();
    for f in faces {
        for k in 1..f.len() - 1 {
            tris.push([f[0], f[k], f[k + 1]]);
        }
    }
    polyhedron_mass_properties(vertices, &tris).0
}

/// Newell plane of a polygon.
pub fn polygon_plane(vertices: &[Vec3], face: &[u32]) -> (Vec3, Real) {
    let mut n = Vec3::ZERO;
    let mut c = Vec3::ZERO;
    for k in 0..face.len() {
        let p = vertices[face[k] as usize];
        let q = vertices[face[(k + 1) % face.len()] as usize];
        n += p.cross(q);
        c += p;
    }
    let n = n.normalize();
    (n, n.dot(c / face.len() as Real))
}

/// The points of a `k × k × k` grid on the surface of a box.
pub fn cube_surface_grid(k: usize, half: Vec3, centre: Vec3) -> Vec<Vec3> {
    let mut pts = Vec::new();
    for i in 0..k {
        for j in 0..k {
            for l in 0..k {
                if [i, j, l].iter().any(|&c| c == 0 || c == k - 1) {
                    let t = |c: usize| real(2.0 * c as f64 / (k - 1) as f64 - 1.0);
                    pts.push(centre + Vec3::new(t(i), t(j), t(l)) * half);
                }
            }
        }
    }
    pts
}

/// Checks that `hull` is the box `centre ± half` with its analytic mass properties.
pub fn assert_box(hull: &ConvexHull, half: Vec3, centre: Vec3, rel: Real) {
    assert_eq!(hull.vertices().len(), 8);
    assert_eq!(hull.faces().len(), 6);
    assert!((0..6).all(|f| hull.face_vertices(f).len() == 4));
    let size = half * 2.0;
    let volume = size.x * size.y * size.z;
    assert!(
        (hull.volume() - volume).abs() <= rel * volume,
        "volume {}",
        hull.volume()
    );
    let mp = hull.mass_properties(2.0);
    let m = 2.0 * volume;
    assert!((mp.mass - m).abs() <= rel * m);
    assert!((mp.center_of_mass - centre).length() <= rel * size.length() + rel * centre.length());
    let expected = Mat3::from_diagonal(Vec3::new(
        m / 12.0 * (size.y * size.y + size.z * size.z),
        m / 12.0 * (size.x * size.x + size.z * size.z),
        m / 12.0 * (size.x * size.x + size.y * size.y),
    ));
    let scale = expected
        .x_axis
        .x
        .max(expected.y_axis.y)
        .max(expected.z_axis.z);
    for i in 0..3 {
        let diff = (mp.inertia.col(i) - expected.col(i)).abs().max_element();
        assert!(
            diff <= 10.0 * rel * scale,
            "inertia {:?} vs {expected:?}",
            mp.inertia
        );
    }
}
