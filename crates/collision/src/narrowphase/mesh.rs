//! Convex shapes against triangle meshes, heightfields and compounds: the midphase finds the
//! triangles (mesh BVH or heightfield grid, see [`ContactTriangles`]) or children overlapping
//! the convex's box, each gives contacts, merged into one manifold (reduced by
//! [`super::ContactManifold::replace_all`]).
//!
//! Internal-edge correction (Coumans, "Contact Generation", "Internal edges and contact
//! normals"; Bullet's `btInternalEdgeUtility`, Jolt's active edges, Box3D's mesh edge flags):
//! with the mesh's precomputed edge kinds and dihedral angles, a contact normal is changed
//! only when it lies outside the Voronoi region of the feature it touches: on flat and
//! concave edges (and the face interior) it becomes the face normal, on real convex edges
//! it may turn up to the dihedral angle.

use super::contact::{ContactList, FeatureId};
#[cfg(test)]
use super::mesh_hull::{posed_hull, EdgeScratch};
use super::mesh_hull::{triangle_hull_manifold, PlacedHull};
use super::mesh_round::RoundInMesh;
use super::polyhedron::Polyhedron;
use crate::math::Aabb;
use crate::math::{Isometry, Real, Vec3};
use crate::query::closest_points::closest_point_segment;
use crate::query::Contact;
use crate::shape::{
    ConvexHull, ConvexRef, EdgeKind, HeightField, MeshEdge, SupportMap, TriMesh, Triangle,
};
use smallvec::SmallVec;
use std::cell::RefCell;

/// A triangle soup with a midphase and precomputed (or derivable) edge convexity: what
/// convex-vs-triangles contact generation needs. Implemented by [`TriMesh`] (BVH, edges
/// computed at construction) and [`HeightField`] (grid cells, edges from the grid).
pub trait ContactTriangles {
    /// Calls `f` with every triangle whose box overlaps `aabb` (local frame), in a
    /// deterministic order.
    fn for_each_candidate(&self, aabb: &Aabb, f: &mut dyn FnMut(u32));
    /// The corners of triangle `t`.
    fn corners(&self, t: u32) -> [Vec3; 3];
    /// Adjacency and convexity of the edges of triangle `t`.
    fn triangle_edges(&self, t: u32) -> [MeshEdge; 3];
    /// Appends to `out` the triangles [`ContactTriangles::for_each_candidate`] gives for
    /// `aabb`, in ascending order. [`TriMesh`] answers from a per-thread cache when it can
    /// (the same triangles: see `QueryCache` in this module).
    fn candidates_sorted(&self, aabb: &Aabb, out: &mut SmallVec<[u32; 64]>) {
        let start = out.len();
        self.for_each_candidate(aabb, &mut |t| out.push(t));
        out[start..].sort_unstable();
    }
}

/// Entries of the per-thread [`QueryCache`]: `CACHE_BUCKETS` buckets of `CACHE_WAYS`.
const CACHE_BUCKETS: usize = 512;
/// Entries per bucket of the [`QueryCache`].
const CACHE_WAYS: usize = 8;
/// A cache entry holding more triangles than this is not kept (a box that large gains
/// nothing over the BVH walk).
const CACHE_MAX_TRIANGLES: usize = 96;
/// Side of the cells (mesh frame) that pick a query's bucket from its box's centre.
const CACHE_CELL: Real = 8.0;

/// One cached box query: the triangles of mesh `stamp` whose boxes overlap `big`, ascending,
/// each with its box (`Aabb::from_points` of its corners, as the midphase's leaf test).
#[derive(Debug)]
struct CacheEntry {
    /// [`TriMesh::stamp`] of the mesh, 0 for an empty entry (stamps start at 1).
    stamp: u64,
    big: Aabb,
    tris: Vec<(u32, Aabb)>,
}

/// A per-thread cache of mesh box queries for contact generation. parry's shape–trimesh
/// manifolds (`TriMeshShapeContactManifoldsWorkspace`) keep, per pair, the triangles of a
/// loosened box and query again only when the shape's box leaves it; here the cache is
/// keyed by the mesh and the box's position instead of the pair, so it needs no per-pair
/// storage and no change to the manifolds.
///
/// A miss runs the BVH query on the box grown by a margin (`big`) and keeps the result. A
/// later query on the same mesh whose box lies inside `big` is answered by testing the kept
/// triangles' boxes against it. That is exactly the set the BVH gives: the midphase returns
/// the triangles whose own box (`Aabb::from_points`) intersects the query box (its
/// quantised node boxes are conservative, so none is missed), and a triangle whose box meets
/// the query box meets `big` too, so it is in the kept list, where the same box test
/// decides. So the contacts, and the simulation, do not depend on the cache's contents
/// (which differ between threads). Entries are keyed by the mesh's [`TriMesh::stamp`],
/// which changes when the mesh is rebuilt or its vertices move.
///
/// Memory: the entries are allocated at a thread's first query; an entry's list grows to
/// the longest it has held (at most [`CACHE_MAX_TRIANGLES`]) and is reused, so the steady
/// state allocates nothing (as the EPA and clipping scratch buffers).
struct QueryCache {
    /// `CACHE_BUCKETS * CACHE_WAYS` entries (empty until the first query).
    entries: Vec<CacheEntry>,
    /// Per bucket, the way the next miss replaces (round robin).
    next: Vec<u8>,
}

impl QueryCache {
    fn new() -> QueryCache {
        QueryCache {
            entries: Vec::new(),
            next: Vec::new(),
        }
    }

    /// The triangles of `mesh` whose boxes intersect `aabb`, ascending, appended to `out`:
    /// those of `mesh.view().for_each_triangle_in_aabb(aabb, ..)` sorted.
    fn candidates(&mut self, mesh: &TriMesh, aabb: &Aabb, out: &mut SmallVec<[u32; 64]>) {
        let c = aabb.center();
        let half = aabb.half_extents();
        let reach = half.max_element();
        if !(c.is_finite() && reach.is_finite() && reach >= 0.0) {
            return uncached(mesh, aabb, out);
        }
        if self.entries.is_empty() {
            self.entries
                .resize_with(CACHE_BUCKETS * CACHE_WAYS, || CacheEntry {
                    stamp: 0,
                    big: Aabb::EMPTY,
                    tris: Vec::new(),
                });
            self.next.resize(CACHE_BUCKETS, 0);
        }
        let stamp = mesh.stamp();
        // Truncated cell coordinates (saturating casts; cells near 0 are merged, which
        // only affects which bucket is used).
        let cell = (c / CACHE_CELL).to_array().map(|x| x as i32 as u32 as u64);
        let h = stamp
            .wrapping_mul(0x9E37_79B9_7F4A_7C15)
            .wrapping_add(cell[0].wrapping_mul(0xC2B2_AE3D_27D4_EB4F))
            .wrapping_add(cell[1].wrapping_mul(0x1656_67B1_9E37_79F9))
            .wrapping_add(cell[2].wrapping_mul(0x27D4_EB2F_1656_67C5));
        let bucket = ((h >> 32) as usize) % CACHE_BUCKETS;
        let ways = &mut self.entries[bucket * CACHE_WAYS..(bucket + 1) * CACHE_WAYS];
        if let Some(e) = ways
            .iter()
            .find(|e| e.stamp == stamp && e.big.contains(aabb))
        {
            out.extend(
                e.tris
                    .iter()
                    .filter(|(_, b)| b.intersects(aabb))
                    .map(|&(t, _)| t),
            );
            return;
        }
        let way = self.next[bucket] as usize;
        self.next[bucket] = ((way + 1) % CACHE_WAYS) as u8;
        let e = &mut ways[way];
        // The margin: half the box's largest half extent plus 5 cm, so a body moving less
        // than that per step re-uses the entry (a margin twice as large gives fewer misses
        // but longer lists to filter: the same instruction count on scenes 5 and 6).
        let big = aabb.expanded(0.05 + 0.5 * reach);
        e.stamp = 0;
        e.tris.clear();
        let mut full = true;
        mesh.view().for_each_triangle_in_aabb(&big, |t| {
            if e.tris.len() == CACHE_MAX_TRIANGLES {
                full = false;
                return false;
            }
            e.tris
                .push((t, Aabb::from_points(mesh.triangle(t as usize))));
            true
        });
        if !full {
            e.tris.clear();
            return uncached(mesh, aabb, out);
        }
        e.tris.sort_unstable_by_key(|&(t, _)| t);
        e.stamp = stamp;
        e.big = big;
        out.extend(
            e.tris
                .iter()
                .filter(|(_, b)| b.intersects(aabb))
                .map(|&(t, _)| t),
        );
    }
}

/// The BVH query of [`QueryCache::candidates`] without the cache.
fn uncached(mesh: &TriMesh, aabb: &Aabb, out: &mut SmallVec<[u32; 64]>) {
    let start = out.len();
    mesh.view().for_each_triangle_in_aabb(aabb, |t| {
        out.push(t);
        true
    });
    out[start..].sort_unstable();
}

thread_local! {
    static QUERY_CACHE: RefCell<QueryCache> = RefCell::new(QueryCache::new());
}

impl ContactTriangles for TriMesh {
    fn for_each_candidate(&self, aabb: &Aabb, f: &mut dyn FnMut(u32)) {
        self.view().for_each_triangle_in_aabb(aabb, |t| {
            f(t);
            true
        });
    }
    #[inline]
    fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangle(t as usize)
    }
    #[inline]
    fn triangle_edges(&self, t: u32) -> [MeshEdge; 3] {
        self.edges()[t as usize]
    }
    fn candidates_sorted(&self, aabb: &Aabb, out: &mut SmallVec<[u32; 64]>) {
        QUERY_CACHE.with(|cell| match cell.try_borrow_mut() {
            Ok(mut cache) => cache.candidates(self, aabb, out),
            // A re-entrant call (none in the library) skips the cache.
            Err(_) => uncached(self, aabb, out),
        });
    }
}

impl ContactTriangles for HeightField {
    fn for_each_candidate(&self, aabb: &Aabb, f: &mut dyn FnMut(u32)) {
        self.for_each_triangle_in_aabb(aabb, |t| {
            f(t);
            true
        });
    }
    #[inline]
    fn corners(&self, t: u32) -> [Vec3; 3] {
        self.triangle(t as usize)
    }
    #[inline]
    fn triangle_edges(&self, t: u32) -> [MeshEdge; 3] {
        HeightField::triangle_edges(self, t as usize)
    }
}

/// World (here: mesh-frame) box of convex `b` at `pose_ab`: closed forms for spheres,
/// capsules and boxes (Arvo's transformed box), else six support queries.
pub fn convex_aabb(b: ConvexRef<'_>, pose_ab: &Isometry) -> crate::math::Aabb {
    match b {
        ConvexRef::Sphere(s) => {
            return Aabb::from_center_half_extents(pose_ab.translation, Vec3::splat(s.radius()))
        }
        ConvexRef::Capsule(c) => {
            let (p, q) = c.segment();
            let (p, q) = (pose_ab.transform_point(p), pose_ab.transform_point(q));
            let r = Vec3::splat(c.radius());
            return Aabb::new(p.min(q) - r, p.max(q) + r);
        }
        ConvexRef::Cuboid(c) => return c.local_aabb().transformed(pose_ab),
        _ => {}
    }
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

/// The closed-form extent of a sphere, capsule or box along any direction, for the plane
/// cull of [`mesh_convex_contacts`]: a triangle whose plane the shape clears by more than the
/// prediction (on either side) is farther than the prediction, so it is skipped before its
/// contact test (the midphase's boxes let through triangles whose planes pass beside the
/// shape, e.g. the neighbours of the one under a body on a slope). Bullet's
/// `btConvexPlaneCollisionAlgorithm` and Box2D's `b2CollidePolygons` reject on the same
/// face axis first. Other shapes have their own first face test (hulls) or none.
#[derive(Debug, Clone, Copy)]
struct PlaneSlab {
    /// Centre (sphere, box) or first segment end (capsule) in the mesh frame.
    p: Vec3,
    /// Second segment end (capsule), else `p`.
    q: Vec3,
    /// Radius (sphere, capsule), 0 for a box.
    r: Real,
    /// The box's half extents along its axes `axes` (zero otherwise).
    half: Vec3,
    axes: [Vec3; 3],
    /// Round-off margin added to the prediction (relative to the shape's position and size).
    tol: Real,
}

impl PlaneSlab {
    fn new(b: ConvexRef<'_>, pose_ab: &Isometry) -> Option<PlaneSlab> {
        let c = pose_ab.translation;
        let (p, q, r, half, axes) = match b {
            ConvexRef::Sphere(s) => (c, c, s.radius(), Vec3::ZERO, [Vec3::ZERO; 3]),
            ConvexRef::Capsule(k) => {
                let (p, q) = k.segment();
                let (p, q) = (pose_ab.transform_point(p), pose_ab.transform_point(q));
                (p, q, k.radius(), Vec3::ZERO, [Vec3::ZERO; 3])
            }
            ConvexRef::Cuboid(x) => {
                let m = pose_ab.rotation_matrix();
                (c, c, 0.0, x.half_extents(), [m.x_axis, m.y_axis, m.z_axis])
            }
            _ => return None,
        };
        let size = r + half.x + half.y + half.z + (q - p).length();
        let tol = 1.0e-4 * (1.0 + size + p.abs().max_element());
        Some(PlaneSlab {
            p,
            q,
            r,
            half,
            axes,
            tol,
        })
    }

    /// The slab of any shape inside the box `lo..hi` (mesh frame): a hull's placed box, whose
    /// extent along a plane's normal bounds every vertex's (a weaker cull than the vertex scan
    /// of the hull's own face test, at a few products instead of one dot product a vertex).
    fn from_box(lo: Vec3, hi: Vec3) -> PlaneSlab {
        let (p, half) = ((lo + hi) * 0.5, (hi - lo) * 0.5);
        let tol = 1.0e-4 * (1.0 + half.x + half.y + half.z + p.abs().max_element());
        PlaneSlab {
            p,
            q: p,
            r: 0.0,
            half,
            axes: [Vec3::X, Vec3::Y, Vec3::Z],
            tol,
        }
    }

    /// True when the shape lies entirely more than `prediction` (plus round-off) above or
    /// below the plane `n · x = off` (`n` unit).
    #[inline]
    fn clear_of_plane(&self, n: Vec3, off: Real, prediction: Real) -> bool {
        let ext = self.r
            + self.half.x * n.dot(self.axes[0]).abs()
            + self.half.y * n.dot(self.axes[1]).abs()
            + self.half.z * n.dot(self.axes[2]).abs();
        let (dp, dq) = (n.dot(self.p) - off, n.dot(self.q) - off);
        let gap = prediction + self.tol + ext;
        (dp > gap && dq > gap) || (dp < -gap && dq < -gap)
    }
}

/// Mixes a triangle or child index into a feature id (deterministic).
#[inline]
pub fn mix_feature(index: u32, id: FeatureId) -> FeatureId {
    index.wrapping_mul(0x9E37_79B1) ^ id
}

/// Applies internal-edge correction to contact `c` (mesh frame, normal from triangle `tri`
/// with edges `edges` towards `b`, `point_a` on the triangle). Returns true when the normal
/// was changed.
pub fn correct_internal_edge(
    edges: &[MeshEdge; 3],
    tri: &Triangle,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: &mut Contact,
) -> bool {
    let Some(face_n) = tri.normal() else {
        return false;
    };
    correct_internal_edge_with(edges, tri, face_n, edge_tolerance(tri), b, pose_ab, c)
}

/// The distance within which a contact point counts as on an edge of `tri` for
/// [`correct_internal_edge`]: relative to the triangle's longest edge.
#[inline]
fn edge_tolerance(tri: &Triangle) -> Real {
    let v = tri.vertices();
    let scale = (v[1] - v[0])
        .length()
        .max((v[2] - v[1]).length())
        .max((v[0] - v[2]).length());
    1.0e-3 * scale + 1.0e-5
}

/// [`correct_internal_edge`] with the triangle's unit normal `face_n` (`tri.normal()`) and
/// [`edge_tolerance`] given, so a triangle's contacts share them (the same values, computed
/// once per triangle instead of once per contact).
#[inline]
fn correct_internal_edge_with(
    edges: &[MeshEdge; 3],
    tri: &Triangle,
    face_n: Vec3,
    tol: Real,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    c: &mut Contact,
) -> bool {
    let n = c.normal;
    let cos_n = n.dot(face_n);
    if !(-1.0e-3..=1.0 - 1.0e-6).contains(&cos_n) {
        return false;
    }
    let v = tri.vertices();
    for k in 0..3 {
        let (p, q) = (v[k], v[(k + 1) % 3]);
        // `closest_point_segment` returns the closest point and its segment parameter; the
        // test is on the distance to that point (comparing the parameter with `tol` counted
        // only contacts near the edge's first vertex as on the edge).
        let (on_edge, _) = closest_point_segment(c.point_a, p, q);
        if (c.point_a - on_edge).length_squared() > tol * tol {
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

/// Contacts of triangles A (a mesh or heightfield) against convex B at `pose_ab` (A's frame,
/// query convention), appended to `out`. `tri_contacts` appends the contacts of one
/// triangle against B; each is then corrected for internal edges. A sphere or capsule B
/// is placed in the mesh's frame once and takes closed-form triangle contacts there (the
/// contacts of the dispatcher's triangle–sphere and triangle–capsule paths, up to
/// round-off; see `mesh_round.rs`): `tri_contacts` then runs only for the capsule cases the
/// closed form leaves undecided (segment through the triangle, sliver triangles).
pub fn mesh_convex_contacts<M: ContactTriangles + ?Sized>(
    mesh: &M,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    tri_contacts: &mut dyn FnMut(&Triangle, &mut ContactList),
    out: &mut ContactList,
) {
    let aabb = convex_aabb(b, pose_ab).expanded(prediction.max(0.0));
    let slab = PlaneSlab::new(b, pose_ab);
    let round = RoundInMesh::new(b, pose_ab);
    contacts_in_box(
        mesh,
        b,
        pose_ab,
        prediction,
        &aabb,
        slab,
        round,
        tri_contacts,
        out,
    );
}

/// [`mesh_convex_contacts`] with B's box (mesh frame, expanded by the prediction) and
/// plane cull (if any) and closed-form round shape (if any) given.
#[allow(clippy::too_many_arguments)]
fn contacts_in_box<M: ContactTriangles + ?Sized>(
    mesh: &M,
    b: ConvexRef<'_>,
    pose_ab: &Isometry,
    prediction: Real,
    aabb: &Aabb,
    slab: Option<PlaneSlab>,
    round: Option<RoundInMesh>,
    tri_contacts: &mut dyn FnMut(&Triangle, &mut ContactList),
    out: &mut ContactList,
) {
    // Triangles in index order, so a mesh and a heightfield with the same triangles give
    // the same sequence of points (and the same reduced manifold).
    let mut tris: SmallVec<[u32; 64]> = SmallVec::new();
    mesh.candidates_sorted(aabb, &mut tris);
    for t in tris {
        let [p, q, r] = mesh.corners(t);
        let tri = Triangle { a: p, b: q, c: r };
        let Some(n) = tri.normal() else {
            continue;
        };
        if !tri.vertices().iter().all(|v| v.is_finite()) {
            continue;
        }
        if slab.is_some_and(|s| s.clear_of_plane(n, n.dot(p), prediction)) {
            continue;
        }
        let start = out.len();
        if !round.is_some_and(|rd| rd.triangle_contacts([p, q, r], n, prediction, out)) {
            tri_contacts(&tri, out);
        }
        if out.len() == start {
            continue;
        }
        let edges = mesh.triangle_edges(t);
        let tol = edge_tolerance(&tri);
        let mut keep = start;
        for i in start..out.len() {
            let (mut c, id) = out[i];
            correct_internal_edge_with(&edges, &tri, n, tol, b, pose_ab, &mut c);
            if c.distance <= prediction && c.distance.is_finite() && c.normal.is_finite() {
                out[keep] = (c, mix_feature(t, id));
                keep += 1;
            }
        }
        out.truncate(keep);
    }
}

/// Triangles A against convex hull B: [`mesh_convex_contacts`] with the triangle–hull
/// separating-axis test of `super::mesh_hull`, the hull placed in the mesh's frame once
/// (vertices, face planes, in a per-thread `PlacedHull` refilled in place) for all the
/// triangles instead of once per triangle. Given the same placed hull the contacts are those of the per-triangle
/// `convex_convex` path bit for bit; the placement by a rotation matrix rounds differently
/// from the quaternion's, by a few ulps.
///
/// The hull's box comes from its SIMD vertex lanes (`ConvexHull::rotated_bounds`, the
/// same box as the placed vertices', bit for bit), and the hull is placed only when some
/// triangle survives the midphase and the box's plane cull (`PlaneSlab::from_box`, which
/// rejects only triangles the hull's own face test rejects): most hull–mesh pairs of a
/// falling body have no candidate triangle, and most candidates' planes pass far from it.
pub fn mesh_hull_contacts<M: ContactTriangles + ?Sized>(
    mesh: &M,
    hull: &ConvexHull,
    pose_ab: &Isometry,
    prediction: Real,
    out: &mut ContactList,
) {
    if hull.vertices().is_empty() {
        return;
    }
    let pb = Polyhedron::from_hull(hull);
    let (lo, hi) = hull.rotated_bounds(pose_ab.rotation);
    let (lo, hi) = (lo + pose_ab.translation, hi + pose_ab.translation);
    let aabb = Aabb::new(lo, hi).expanded(prediction.max(0.0));
    let slab = PlaneSlab::from_box(lo, hi);
    thread_local! {
        static PLACED: RefCell<PlacedHull> = RefCell::new(PlacedHull::new());
    }
    PLACED.with(|cell| {
        // A re-entrant call (none in the library) gets a fresh placement.
        let mut fresh = None;
        let mut guard = cell.try_borrow_mut();
        let placed = match guard.as_deref_mut() {
            Ok(p) => p,
            Err(_) => fresh.insert(PlacedHull::new()),
        };
        let mut is_placed = false;
        let mut tri_contacts = |t: &Triangle, out: &mut ContactList| {
            if !is_placed {
                placed.place(&pb, pose_ab);
                is_placed = true;
            }
            let pa = Polyhedron::from_triangle(t);
            let PlacedHull { posed, scratch } = &mut *placed;
            triangle_hull_manifold(&pa, &pb, posed, pose_ab, prediction, scratch, out);
        };
        let b = ConvexRef::ConvexHull(hull);
        contacts_in_box(
            mesh,
            b,
            pose_ab,
            prediction,
            &aabb,
            Some(slab),
            None,
            &mut tri_contacts,
            out,
        );
    });
}

#[cfg(test)]
#[path = "mesh_tests.rs"]
mod tests;
