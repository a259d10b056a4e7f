//! Analytic contact generation for the dynamics tests (the real narrowphase is issue 6):
//! sphere, box and capsule against the plane y = 0, sphere–sphere, sphere–box, and a
//! face–face clip for stacked, nearly axis-aligned boxes. Plus a tiny persistent cache that
//! carries impulses over by body pair and anchor distance, as a persistent manifold would.
#![allow(dead_code)]

use carom_dynamics::collision::math::{Isometry, Quat, Real, Vec3};
use carom_dynamics::collision::shape::{Capsule, Cuboid, Plane, Shape, Sphere};
use carom_dynamics::*;
use std::sync::Arc;

/// Contacts are generated up to this separation (speculative margin, Box2D's 4 · slop).
pub const MARGIN: Real = 0.02;

pub fn sphere(r: Real) -> Arc<Shape> {
    Arc::new(Sphere::new(r).unwrap().into())
}

pub fn cuboid(h: Vec3) -> Arc<Shape> {
    Arc::new(Cuboid::new(h).unwrap().into())
}

pub fn capsule(r: Real, half: Real) -> Arc<Shape> {
    Arc::new(Capsule::new(r, half).unwrap().into())
}

/// A static ground plane y = 0.
pub fn add_ground(world: &mut DynamicsWorld) -> BodyHandle {
    let plane: Arc<Shape> = Arc::new(Plane::new(Vec3::Y, 0.0).unwrap().into());
    let mut d = BodyDesc::fixed(plane, Isometry::IDENTITY);
    d.friction = 1.0;
    world.create_body(&d).unwrap()
}

fn manifold(world: &DynamicsWorld, a: BodyHandle, b: BodyHandle, n: Vec3) -> ContactManifold {
    let (ia, ib) = (
        world.bodies().info(a).unwrap(),
        world.bodies().info(b).unwrap(),
    );
    let mut m = ContactManifold::new(a, b, n);
    m.friction = mix_friction(ia.friction, ib.friction);
    m.restitution = mix_restitution(ia.restitution, ib.restitution);
    m
}

fn push_world(world: &DynamicsWorld, m: &mut ContactManifold, on_a: Vec3, on_b: Vec3, id: u32) {
    let pa = world.bodies().pose(m.body_a).unwrap();
    let pb = world.bodies().pose(m.body_b).unwrap();
    let sep = (on_b - on_a).dot(m.normal);
    let p = ContactPoint::new(
        pa.inverse_transform_point(on_a),
        pb.inverse_transform_point(on_b),
        sep,
        id,
    );
    m.push(p).unwrap();
}

/// Contact of a body's shape with the ground plane y = 0 (sphere, box, capsule).
pub fn shape_ground(
    world: &DynamicsWorld,
    ground: BodyHandle,
    b: BodyHandle,
) -> Option<ContactManifold> {
    let pose = world.bodies().pose(b).unwrap();
    let shape = world.bodies().info(b).unwrap().shape.clone()?;
    let mut pts: Vec<(Vec3, u32)> = Vec::new(); // deepest surface points of B
    match &*shape {
        Shape::Sphere(s) => pts.push((pose.translation - Vec3::Y * s.radius(), 0)),
        Shape::Capsule(c) => {
            let (p0, p1) = c.segment();
            for (k, p) in [p0, p1].into_iter().enumerate() {
                pts.push((pose.transform_point(p) - Vec3::Y * c.radius(), k as u32));
            }
        }
        Shape::Cuboid(c) => {
            for (k, v) in c.vertices().into_iter().enumerate() {
                pts.push((pose.transform_point(v), k as u32));
            }
        }
        _ => return None,
    }
    pts.retain(|(p, _)| p.y < MARGIN);
    if pts.is_empty() {
        return None;
    }
    pts.sort_by(|x, y| x.0.y.total_cmp(&y.0.y).then(x.1.cmp(&y.1)));
    pts.truncate(4);
    let mut m = manifold(world, ground, b, Vec3::Y);
    for (p, id) in pts {
        push_world(world, &mut m, Vec3::new(p.x, 0.0, p.z), p, id);
    }
    Some(m)
}

/// Sphere–sphere contact (normal from A to B).
pub fn sphere_sphere(
    world: &DynamicsWorld,
    a: BodyHandle,
    b: BodyHandle,
    margin: Real,
) -> Option<ContactManifold> {
    let radius = |h| match &*world.bodies().info(h).unwrap().shape.clone().unwrap() {
        Shape::Sphere(s) => s.radius(),
        _ => panic!("not a sphere"),
    };
    let (ca, cb) = (
        world.bodies().pose(a).unwrap().translation,
        world.bodies().pose(b).unwrap().translation,
    );
    let (ra, rb) = (radius(a), radius(b));
    let d = cb - ca;
    let dist = d.length();
    if dist - ra - rb > margin || dist < 1e-9 {
        return None;
    }
    let n = d / dist;
    let mut m = manifold(world, a, b, n);
    push_world(world, &mut m, ca + n * ra, cb - n * rb, 0);
    Some(m)
}

/// Box (A) – sphere (B) contact.
pub fn box_sphere(world: &DynamicsWorld, a: BodyHandle, b: BodyHandle) -> Option<ContactManifold> {
    let pa = world.bodies().pose(a).unwrap();
    let he = match &*world.bodies().info(a).unwrap().shape.clone().unwrap() {
        Shape::Cuboid(c) => c.half_extents(),
        _ => panic!("not a box"),
    };
    let r = match &*world.bodies().info(b).unwrap().shape.clone().unwrap() {
        Shape::Sphere(s) => s.radius(),
        _ => panic!("not a sphere"),
    };
    let cb = world.bodies().pose(b).unwrap().translation;
    let local = pa.inverse_transform_point(cb);
    let closest = local.clamp(-he, he);
    let d = local - closest;
    let dist = d.length();
    if dist < 1e-6 || dist - r > MARGIN {
        return None;
    }
    let n = pa.transform_vector(d / dist);
    let on_a = pa.transform_point(closest);
    let mut m = manifold(world, a, b, n);
    push_world(world, &mut m, on_a, cb - n * r, 0);
    Some(m)
}

/// Face–face contact of box B resting on box A (B's lowest face against A's top face,
/// clipped to A's top face; the normal is A's up axis). Good for upright stacks.
pub fn box_on_box(world: &DynamicsWorld, a: BodyHandle, b: BodyHandle) -> Option<ContactManifold> {
    let he = |h| match &*world.bodies().info(h).unwrap().shape.clone().unwrap() {
        Shape::Cuboid(c) => c.half_extents(),
        _ => panic!("not a box"),
    };
    let (ha, hb) = (he(a), he(b));
    let (pa, pb) = (
        world.bodies().pose(a).unwrap(),
        world.bodies().pose(b).unwrap(),
    );
    let n = pa.transform_vector(Vec3::Y);
    // B's face most opposed to n.
    let mut best = (Real::INFINITY, 0usize, 1.0);
    for axis in 0..3 {
        let d = pb.transform_vector(Vec3::AXES[axis]).dot(n);
        for s in [1.0, -1.0] {
            if d * s < best.0 {
                best = (d * s, axis, s);
            }
        }
    }
    let (_, axis, s) = best;
    let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
    let mut poly: Vec<Vec3> = [(-1.0, -1.0), (1.0, -1.0), (1.0, 1.0), (-1.0, 1.0)]
        .iter()
        .map(|&(x, y): &(Real, Real)| {
            let mut c = Vec3::ZERO;
            c[axis] = s * hb[axis];
            c[u] = x * hb[u];
            c[v] = y * hb[v];
            pa.inverse_transform_point(pb.transform_point(c))
        })
        .collect();
    for (k, sign) in [(0usize, 1.0), (0, -1.0), (2, 1.0), (2, -1.0)] {
        poly = clip(&poly, k, sign, ha[k]);
        if poly.is_empty() {
            return None;
        }
    }
    let mut pts: Vec<(Real, Vec3)> = poly
        .into_iter()
        .map(|p| (p.y - ha.y, p))
        .filter(|(sep, _)| *sep < MARGIN)
        .collect();
    if pts.is_empty() {
        return None;
    }
    reduce(&mut pts);
    let mut m = manifold(world, a, b, n);
    for (k, (_, p)) in pts.iter().enumerate() {
        let on_a = pa.transform_point(Vec3::new(p.x, ha.y, p.z));
        push_world(world, &mut m, on_a, pa.transform_point(*p), k as u32);
    }
    Some(m)
}

/// Sutherland–Hodgman against `sign * p[k] <= limit`.
fn clip(poly: &[Vec3], k: usize, sign: Real, limit: Real) -> Vec<Vec3> {
    let mut out = Vec::new();
    for i in 0..poly.len() {
        let (p, q) = (poly[i], poly[(i + 1) % poly.len()]);
        let (dp, dq) = (sign * p[k] - limit, sign * q[k] - limit);
        if dp <= 0.0 {
            out.push(p);
        }
        if (dp < 0.0) != (dq < 0.0) && dp != dq {
            out.push(p + (q - p) * (dp / (dp - dq)));
        }
    }
    out
}

/// Keeps at most 4 points: the deepest, the farthest from it, the largest triangle, then
/// the point farthest outside that triangle.
fn reduce(pts: &mut Vec<(Real, Vec3)>) {
    if pts.len() <= 4 {
        return;
    }
    let flat = |p: Vec3| Vec3::new(p.x, 0.0, p.z);
    let i0 = (0..pts.len())
        .min_by(|&i, &j| pts[i].0.total_cmp(&pts[j].0))
        .unwrap();
    let p0 = flat(pts[i0].1);
    let i1 = (0..pts.len())
        .max_by(|&i, &j| {
            (flat(pts[i].1) - p0)
                .length()
                .total_cmp(&(flat(pts[j].1) - p0).length())
        })
        .unwrap();
    let p1 = flat(pts[i1].1);
    let area = |a: Vec3, b: Vec3, c: Vec3| (b - a).cross(c - a).y;
    let i2 = (0..pts.len())
        .max_by(|&i, &j| {
            area(p0, p1, flat(pts[i].1))
                .abs()
                .total_cmp(&area(p0, p1, flat(pts[j].1)).abs())
        })
        .unwrap();
    let p2 = flat(pts[i2].1);
    let orient = area(p0, p1, p2).signum();
    let outside = |p: Vec3| {
        [(p0, p1), (p1, p2), (p2, p0)]
            .iter()
            .map(|&(a, b)| -orient * area(a, b, p))
            .fold(Real::MIN, Real::max)
    };
    let i3 = (0..pts.len())
        .filter(|&i| i != i0 && i != i1 && i != i2)
        .max_by(|&i, &j| outside(flat(pts[i].1)).total_cmp(&outside(flat(pts[j].1))))
        .unwrap();
    *pts = [i0, i1, i2, i3].iter().map(|&i| pts[i]).collect();
}

/// Carries impulses and the friction direction from last step's manifolds (the persistent
/// manifold's job): same body pair, anchors within 2 cm on A.
pub fn warm_from(prev: &[ContactManifold], next: &mut [ContactManifold]) {
    for m in next.iter_mut() {
        let Some(old) = prev
            .iter()
            .find(|o| o.body_a == m.body_a && o.body_b == m.body_b)
        else {
            continue;
        };
        m.tangent = old.tangent;
        for p in m.points_mut() {
            if let Some(q) = old
                .points()
                .iter()
                .find(|q| (q.local_a - p.local_a).length() < 0.02)
            {
                p.normal_impulse = q.normal_impulse;
                p.tangent_impulse = q.tangent_impulse;
            }
        }
    }
}

/// A world with a ground plane and a list of contact generators, stepped with a cache.
pub struct Sim {
    pub world: DynamicsWorld,
    pub ground: BodyHandle,
    pub dt: Real,
    pub ground_bodies: Vec<BodyHandle>,
    pub box_pairs: Vec<(BodyHandle, BodyHandle)>,
    pub sphere_pairs: Vec<(BodyHandle, BodyHandle)>,
    pub box_sphere_pairs: Vec<(BodyHandle, BodyHandle)>,
    pub prev: Vec<ContactManifold>,
    /// Speculative margin of sphere–sphere contacts.
    pub sphere_margin: Real,
    pub last_report: StepReport,
}

impl Sim {
    pub fn new(kind: SolverKind, gravity: Vec3) -> Sim {
        let mut params = WorldParams {
            gravity,
            ..Default::default()
        };
        params.solver.kind = kind;
        let mut world = DynamicsWorld::new(params).unwrap();
        let ground = add_ground(&mut world);
        Sim {
            world,
            ground,
            dt: 1.0 / 60.0,
            ground_bodies: Vec::new(),
            box_pairs: Vec::new(),
            sphere_pairs: Vec::new(),
            box_sphere_pairs: Vec::new(),
            prev: Vec::new(),
            sphere_margin: MARGIN,
            last_report: StepReport::default(),
        }
    }

    pub fn add(&mut self, desc: &BodyDesc) -> BodyHandle {
        let h = self.world.create_body(desc).unwrap();
        self.ground_bodies.push(h);
        h
    }

    pub fn contacts(&self) -> Vec<ContactManifold> {
        let w = &self.world;
        let mut out = Vec::new();
        out.extend(
            self.ground_bodies
                .iter()
                .filter_map(|&b| shape_ground(w, self.ground, b)),
        );
        out.extend(
            self.box_pairs
                .iter()
                .filter_map(|&(a, b)| box_on_box(w, a, b)),
        );
        out.extend(
            self.sphere_pairs
                .iter()
                .filter_map(|&(a, b)| sphere_sphere(w, a, b, self.sphere_margin)),
        );
        out.extend(
            self.box_sphere_pairs
                .iter()
                .filter_map(|&(a, b)| box_sphere(w, a, b)),
        );
        out
    }

    pub fn step(&mut self) {
        let mut contacts = self.contacts();
        warm_from(&self.prev, &mut contacts);
        self.last_report = self.world.step(self.dt, &mut contacts).unwrap();
        self.prev = contacts;
    }

    pub fn pos(&self, h: BodyHandle) -> Vec3 {
        self.world.bodies().pose(h).unwrap().translation
    }
}

/// Box of half extent 0.5 (density 1000) at `p`.
pub fn box_desc(p: Vec3) -> BodyDesc {
    BodyDesc::dynamic(
        cuboid(Vec3::splat(0.5)),
        Isometry::new(p, Quat::IDENTITY),
        1000.0,
    )
}

/// A vertical stack of `n` unit boxes on the ground.
pub fn stack(kind: SolverKind, n: usize) -> (Sim, Vec<BodyHandle>) {
    let mut sim = Sim::new(kind, Vec3::new(0.0, -10.0, 0.0));
    let boxes: Vec<BodyHandle> = (0..n)
        .map(|i| sim.add(&box_desc(Vec3::new(0.0, 0.5 + i as Real, 0.0))))
        .collect();
    sim.box_pairs = boxes.windows(2).map(|w| (w[0], w[1])).collect();
    (sim, boxes)
}

/// A 2D pyramid of `rows` rows of unit boxes, 5 cm apart, each resting on two below.
pub fn pyramid(kind: SolverKind, rows: usize) -> (Sim, Vec<BodyHandle>) {
    let mut sim = Sim::new(kind, Vec3::new(0.0, -10.0, 0.0));
    let pitch: Real = 1.05;
    let mut grid: Vec<Vec<BodyHandle>> = Vec::new();
    for r in 0..rows {
        let count = rows - r;
        let x0 = -0.5 * pitch * (count as Real - 1.0);
        let row: Vec<BodyHandle> = (0..count)
            .map(|j| {
                sim.add(&box_desc(Vec3::new(
                    x0 + pitch * j as Real,
                    0.5 + r as Real,
                    0.0,
                )))
            })
            .collect();
        if r > 0 {
            for (j, &b) in row.iter().enumerate() {
                sim.box_pairs.push((grid[r - 1][j], b));
                sim.box_pairs.push((grid[r - 1][j + 1], b));
            }
        }
        grid.push(row);
    }
    let all = grid.concat();
    // Only the bottom row touches the ground.
    sim.ground_bodies = grid[0].clone();
    (sim, all)
}

/// Largest displacement of `bodies` from `start`.
pub fn max_drift(sim: &Sim, bodies: &[BodyHandle], start: &[Vec3]) -> Real {
    bodies
        .iter()
        .zip(start)
        .map(|(&b, &s)| (sim.pos(b) - s).length())
        .fold(0.0, Real::max)
}

/// Steps in debug builds are costlier: use `debug` steps there and `release` otherwise.
pub fn steps(release: usize, debug: usize) -> usize {
    if cfg!(debug_assertions) {
        debug
    } else {
        release
    }
}
