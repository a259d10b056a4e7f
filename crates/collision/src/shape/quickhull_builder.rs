//! The triangle hull that quickhull grows (see `quickhull`): faces with adjacency, shared
//! planes for coplanar faces, conflict lists, the horizon search and the initial tetrahedron.
//!
//! C. B. Barber, D. P. Dobkin & H. Huhdanpaa, "The Quickhull Algorithm for Convex Hulls" (1996);
//! D. Gregorius, "Implementing Quickhull" (GDC 2014).

use super::quickhull::{Failure, NONE};
use crate::error::CaromError;
use crate::math::{Real, Vec3};

/// A triangle of the hull under construction.
pub(super) struct Face {
    /// Vertices (point indices), counter-clockwise seen from outside.
    pub(super) v: [u32; 3],
    /// `adj[i]`: the face across the edge `v[i] → v[(i + 1) % 3]`.
    pub(super) adj: [u32; 3],
    /// Its plane, in `Builder::planes` (shared by coplanar neighbours).
    pub(super) plane: u32,
    /// Outside points assigned to this face.
    pub(super) conflict: Vec<u32>,
    /// False once removed from the hull.
    pub(super) alive: bool,
}

/// A plane shared by a group of coplanar faces (Gregorius merges such faces; sharing one
/// plane, the best-conditioned one, keeps their visibility tests consistent in the same way).
#[derive(Clone, Copy)]
pub(super) struct Plane {
    /// Unit outward normal.
    pub(super) normal: Vec3,
    /// Offset: `normal · x = offset` on the plane.
    pub(super) offset: Real,
    /// Twice the area of the triangle it was computed from (larger is better conditioned).
    area: Real,
}

/// The plane of triangle `(a, b, c)`, or `None` if it has no area. The normal is the cross
/// product of the two shortest edges, the most accurate choice.
fn triangle_plane(a: Vec3, b: Vec3, c: Vec3) -> Option<Plane> {
    let (e0, e1, e2) = (b - a, c - b, a - c);
    let (l0, l1, l2) = (
        e0.length_squared(),
        e1.length_squared(),
        e2.length_squared(),
    );
    let n = if l0 >= l1 && l0 >= l2 {
        e1.cross(e2)
    } else if l1 >= l2 {
        e2.cross(e0)
    } else {
        e0.cross(e1)
    };
    let area = n.length();
    let n = n.try_normalize()?;
    Some(Plane {
        normal: n,
        offset: n.dot((a + b + c) * (1.0 / 3.0)),
        area,
    })
}

/// The triangle hull under construction.
pub(super) struct Builder<'a> {
    pts: &'a [Vec3],
    tol: Real,
    pub(super) faces: Vec<Face>,
    pub(super) planes: Vec<Plane>,
    /// Per face: `stamp` if found visible in the current step, `stamp + 1` if not.
    mark: Vec<u32>,
    /// Per point: `stamp` if it is on the current horizon.
    on_horizon: Vec<u32>,
    stamp: u32,
}

impl<'a> Builder<'a> {
    /// The initial tetrahedron, with every other point assigned to a face it is above.
    pub(super) fn new(
        pts: &'a [Vec3],
        tol: Real,
        flat_tol: Real,
    ) -> std::result::Result<Self, Failure> {
        let [a, b, c, d] = initial_simplex(pts, flat_tol)?;
        let mut hull = Builder {
            pts,
            tol,
            faces: Vec::new(),
            planes: Vec::new(),
            mark: Vec::new(),
            on_horizon: vec![0; pts.len()],
            stamp: 0,
        };
        // (a, b, c) faces away from d; the other faces follow from consistent orientation.
        let tris = [[a, b, c], [b, a, d], [c, b, d], [a, c, d]];
        for t in tris {
            hull.push_face(t, None)?;
        }
        for f in 0..4 {
            for i in 0..3 {
                let (u, v) = (tris[f][i], tris[f][(i + 1) % 3]);
                let twin = (0..4)
                    .find(|&g| (0..3).any(|j| tris[g][j] == v && tris[g][(j + 1) % 3] == u))
                    .ok_or(Failure::Numerical)?;
                hull.faces[f].adj[i] = twin as u32;
            }
        }
        let new_faces = [0, 1, 2, 3];
        for i in 0..pts.len() as u32 {
            if ![a, b, c, d].contains(&i) {
                hull.assign(i, &new_faces);
            }
        }
        Ok(hull)
    }

    /// Whether `p`, known to be within the tolerance of the plane of face `f`, lies within the
    /// triangle (up to the tolerance) seen along its normal.
    fn on_face(&self, f: u32, p: Vec3) -> bool {
        let face = &self.faces[f as usize];
        let normal = self.planes[face.plane as usize].normal;
        (0..3).all(|k| {
            let u = self.pts[face.v[k] as usize];
            let v = self.pts[face.v[(k + 1) % 3] as usize];
            (v - u).cross(p - u).dot(normal) >= -self.tol * (v - u).length()
        })
    }

    /// Signed distance of `p` above the plane of face `f`.
    pub(super) fn distance(&self, f: u32, p: Vec3) -> Real {
        let plane = &self.planes[self.faces[f as usize].plane as usize];
        plane.normal.dot(p) - plane.offset
    }

    /// Appends a face (adjacency left unset) with its own plane, or sharing the plane `group`
    /// of a coplanar neighbour (which it refines if it is better conditioned).
    fn push_face(&mut self, v: [u32; 3], group: Option<u32>) -> std::result::Result<u32, Failure> {
        let [a, b, c] = v.map(|i| self.pts[i as usize]);
        let own = triangle_plane(a, b, c).ok_or(Failure::Numerical)?;
        let plane = match group {
            Some(g) => {
                let shared = &mut self.planes[g as usize];
                if own.normal.dot(shared.normal) <= 0.0 {
                    return Err(Failure::Numerical); // folded over its neighbour
                }
                if own.area > shared.area {
                    *shared = own;
                }
                g
            }
            None => {
                self.planes.push(own);
                self.planes.len() as u32 - 1
            }
        };
        self.faces.push(Face {
            v,
            adj: [NONE; 3],
            plane,
            conflict: Vec::new(),
            alive: true,
        });
        self.mark.push(0);
        Ok(self.faces.len() as u32 - 1)
    }

    /// Puts point `i` on the conflict list of the face among `candidates` it is furthest
    /// above, or drops it if it is within the tolerance of all of them.
    fn assign(&mut self, i: u32, candidates: &[u32]) {
        let p = self.pts[i as usize];
        let mut best = (NONE, self.tol);
        for &f in candidates {
            let d = self.distance(f, p);
            if d > best.1 {
                best = (f, d);
            }
        }
        if best.0 != NONE {
            self.faces[best.0 as usize].conflict.push(i);
        }
    }

    /// Adds the point `eye` (outside face `start`): removes the faces it sees and connects it
    /// to their horizon.
    pub(super) fn add_point(
        &mut self,
        start: u32,
        eye: u32,
        pending: &mut Vec<u32>,
    ) -> std::result::Result<(), Failure> {
        let p = self.pts[eye as usize];
        self.stamp = self.stamp.wrapping_add(2);
        if self.stamp == 0 {
            self.mark.iter_mut().for_each(|m| *m = u32::MAX);
            self.on_horizon.iter_mut().for_each(|m| *m = u32::MAX);
            self.stamp = 2;
        }
        let (visible, horizon) = self.find_horizon(start, p);
        // The horizon must be one simple closed loop of at least 3 edges.
        let m = horizon.len();
        if m < 3 {
            return Err(Failure::Numerical);
        }
        for k in 0..m {
            let (f, i) = horizon[k];
            let (g, j) = horizon[(k + 1) % m];
            let end = self.faces[f as usize].v[(i + 1) % 3];
            if end != self.faces[g as usize].v[j] || self.on_horizon[end as usize] == self.stamp {
                return Err(Failure::Numerical);
            }
            self.on_horizon[end as usize] = self.stamp;
        }
        // A new face coplanar with the face across its horizon edge shares that face's plane.
        // If the eye is coplanar with that face but not clearly beyond the edge, it should lie
        // on that face (it only looked visible through a poorly conditioned plane): drop it.
        let mut groups = Vec::with_capacity(m);
        for &(f, i) in &horizon {
            let face = &self.faces[f as usize];
            let (a, b, across) = (face.v[i], face.v[(i + 1) % 3], face.adj[i]);
            let plane = self.faces[across as usize].plane;
            if self.distance(across, p).abs() > self.tol {
                groups.push(None);
                continue;
            }
            let (pa, pb) = (self.pts[a as usize], self.pts[b as usize]);
            let beyond = (pb - pa)
                .cross(p - pa)
                .dot(self.planes[plane as usize].normal);
            if beyond <= self.tol * (pb - pa).length() {
                if !self.on_face(across, p) {
                    // Coplanar with `across` yet beyond one of its other edges: rounding has
                    // made the hull locally inconsistent.
                    return Err(Failure::Numerical);
                }
                self.faces[start as usize].conflict.retain(|&i| i != eye);
                return Ok(());
            }
            groups.push(Some(plane));
        }
        // The cone of new faces from the eye to every horizon edge.
        let first = self.faces.len() as u32;
        for (&(f, i), &group) in horizon.iter().zip(&groups) {
            let face = &self.faces[f as usize];
            let (a, b, across) = (face.v[i], face.v[(i + 1) % 3], face.adj[i]);
            let nf = self.push_face([a, b, eye], group)?;
            let twin = &mut self.faces[across as usize];
            let j = (0..3)
                .find(|&j| twin.v[j] == b && twin.v[(j + 1) % 3] == a)
                .ok_or(Failure::Numerical)?;
            twin.adj[j] = nf;
            self.faces[nf as usize].adj[0] = across;
        }
        let m = m as u32;
        for k in 0..m {
            let nf = &mut self.faces[(first + k) as usize];
            nf.adj[1] = first + (k + 1) % m;
            nf.adj[2] = first + (k + m - 1) % m;
        }
        // Hand the visible faces' outside points to the new faces.
        let new_faces: Vec<u32> = (first..first + m).collect();
        for &f in &visible {
            let face = &mut self.faces[f as usize];
            face.alive = false;
            let conflict = std::mem::take(&mut face.conflict);
            for i in conflict {
                if i != eye {
                    self.assign(i, &new_faces);
                }
            }
        }
        pending.extend(
            new_faces
                .iter()
                .copied()
                .filter(|&f| !self.faces[f as usize].conflict.is_empty()),
        );
        Ok(())
    }

    /// The faces `p` sees (connected to `start`) and the horizon as an ordered list of
    /// `(face, edge)` pairs: visible faces' edges whose other face is not visible, in
    /// counter-clockwise order around the visible region (Gregorius' depth-first search,
    /// entering each face after the edge it was reached through).
    fn find_horizon(&mut self, start: u32, p: Vec3) -> (Vec<u32>, Vec<(u32, usize)>) {
        let stamp = self.stamp;
        let mut visible = vec![start];
        let mut horizon = Vec::new();
        self.mark[start as usize] = stamp;
        // (face, first edge, edges done)
        let mut stack: Vec<(u32, usize, usize)> = vec![(start, 0, 0)];
        while let Some(top) = stack.last_mut() {
            if top.2 == 3 {
                stack.pop();
                continue;
            }
            let (f, i) = (top.0, (top.1 + top.2) % 3);
            top.2 += 1;
            let nb = self.faces[f as usize].adj[i];
            let mark = self.mark[nb as usize];
            if mark == stamp {
                continue;
            }
            if mark != stamp + 1 && self.distance(nb, p) > self.tol {
                self.mark[nb as usize] = stamp;
                visible.push(nb);
                let back = (0..3)
                    .find(|&j| self.faces[nb as usize].adj[j] == f)
                    .unwrap_or(0);
                // Start after the edge we came through (that one leads back, already visible).
                stack.push((nb, back + 1, 0));
            } else {
                self.mark[nb as usize] = stamp + 1;
                horizon.push((f, i));
            }
        }
        (visible, horizon)
    }
}

/// Four points spanning a large tetrahedron, or why there are none (all points within `tol`
/// of one point, line or plane).
fn initial_simplex(pts: &[Vec3], tol: Real) -> std::result::Result<[u32; 4], Failure> {
    let degenerate =
        |reason: &str| Failure::Degenerate(CaromError::degenerate("convex hull", reason));
    // The extreme points along the axes; the pair furthest apart.
    let mut extremes = [0u32; 6];
    for (i, p) in pts.iter().enumerate() {
        for axis in 0..3 {
            if p[axis] < pts[extremes[2 * axis] as usize][axis] {
                extremes[2 * axis] = i as u32;
            }
            if p[axis] > pts[extremes[2 * axis + 1] as usize][axis] {
                extremes[2 * axis + 1] = i as u32;
            }
        }
    }
    let mut best = (0.0 as Real, 0u32, 0u32);
    for &i in &extremes {
        for &j in &extremes {
            let d = (pts[i as usize] - pts[j as usize]).length_squared();
            if d > best.0 {
                best = (d, i, j);
            }
        }
    }
    let (a, b) = (best.1, best.2);
    if best.0.sqrt() <= tol {
        return Err(degenerate(
            "all points coincide (fewer than 4 distinct points)",
        ));
    }
    let (pa, pb) = (pts[a as usize], pts[b as usize]);
    let dir = (pb - pa).normalize();
    let furthest = |score: &dyn Fn(Vec3) -> Real| {
        pts.iter()
            .enumerate()
            .map(|(i, p)| (i as u32, score(*p)))
            .fold(
                (0u32, Real::MIN),
                |best, c| if c.1 > best.1 { c } else { best },
            )
    };
    let (c, dist_c) = furthest(&|p| (p - pa).cross(dir).length());
    if dist_c <= tol {
        return Err(degenerate("all points are collinear: no 3D hull exists"));
    }
    let pc = pts[c as usize];
    let n = triangle_plane(pa, pb, pc).ok_or(Failure::Numerical)?.normal;
    let (d, dist_d) = furthest(&|p| n.dot(p - pa).abs());
    if dist_d <= tol {
        return Err(degenerate("all points are coplanar: no 3D hull exists"));
    }
    // Orient (a, b, c) so that it faces away from d.
    if n.dot(pts[d as usize] - pa) > 0.0 {
        Ok([a, c, b, d])
    } else {
        Ok([a, b, c, d])
    }
}
