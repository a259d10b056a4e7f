//! Bullet's eight benchmark scenes (`BenchmarkDemo.cpp`, specified in
//! `shared/bench/SCENES.md`): counts, sizes, masses, poses and joints exactly as specified.
//! Where Carom's shapes differ from Bullet's (margins), the scene keeps the user-visible
//! geometry: boxes are exact (Bullet's margin is inside too), hulls have no extra margin.

use crate::data;
use crate::glibc_rand::GlibcRand;
use crate::scene::{JointDesc, JointKind, Scene, SceneBody, SolverSettings};
use carom_collision::math::{consts::PI, Isometry, Quat, Real, Vec3};
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Plane, Shape, Sphere, TriMesh};
use std::sync::Arc;

/// The scene names, in Bullet's order.
pub const SCENE_NAMES: [&str; 8] = [
    "3000 fall",
    "1000 stack",
    "136 ragdolls",
    "1000 convex",
    "prim-trimesh",
    "convex-trimesh",
    "raytests",
    "convex pack",
];

/// Builds scene `1..=8` by number.
pub fn scene(number: usize) -> Option<Scene> {
    Some(match number {
        1 => falling_boxes(),
        2 => stacked_boxes(),
        3 => ragdolls(),
        4 => convex_stack(),
        5 => prim_vs_mesh(),
        6 => convex_vs_mesh(),
        7 => raytests(),
        8 => convex_pack(),
        _ => return None,
    })
}

fn shape(s: impl Into<Shape>) -> Arc<Shape> {
    Arc::new(s.into())
}

fn at(x: Real, y: Real, z: Real) -> Isometry {
    Isometry::from_translation(Vec3::new(x, y, z))
}

fn base(name: &'static str) -> Scene {
    Scene {
        name,
        gravity: Vec3::new(0.0, -10.0, 0.0),
        dt: 1.0 / 60.0,
        bodies: Vec::new(),
        joints: Vec::new(),
        rays: Vec::new(),
        solver: SolverSettings::default(),
    }
}

/// The ground of scenes 1–4: a static box, half extents (250, 50, 250), top face at y = 0.
fn ground_box() -> SceneBody {
    let ground = Cuboid::new(Vec3::new(250.0, 50.0, 250.0)).expect("valid size");
    SceneBody::new(shape(ground), at(0.0, -50.0, 0.0), 0.0)
}

/// Scene 1, "3000 fall": 3008 boxes (47 layers of 8 × 8), half extents 1, mass 2.
pub fn falling_boxes() -> Scene {
    let mut s = base("3000 fall");
    s.bodies.push(ground_box());
    let cube = shape(Cuboid::new(Vec3::ONE).expect("valid size"));
    let mut offset: Real = -12.0;
    for k in 0..47 {
        for i in 0..8 {
            for j in 0..8 {
                let p = at(
                    offset + 3.0 * i as Real,
                    2.0 + 3.0 * k as Real,
                    offset + 3.0 * j as Real,
                );
                s.bodies.push(SceneBody::new(cube.clone(), p, 2.0));
            }
        }
        offset -= 0.35;
    }
    s
}

/// Scene 2, "1000 stack": a 650-box pyramid, three 78-box walls and a 192-box tower.
pub fn stacked_boxes() -> Scene {
    let mut s = base("1000 stack");
    s.bodies.push(ground_box());
    // Pyramid.
    let cube = shape(Cuboid::new(Vec3::ONE).expect("valid size"));
    let pitch: Real = 2.0401;
    let (mut ox, mut oz, mut y): (Real, Real, Real) = (-12.2406, -12.2406, 1.0);
    for size in (1..=12).rev() {
        for i in 0..size {
            for j in 0..size {
                let p = at(-20.0 + ox + pitch * i as Real, y, oz + pitch * j as Real);
                s.bodies.push(SceneBody::new(cube.clone(), p, 1.0));
            }
        }
        ox += 1.02;
        oz += 1.02;
        y += pitch;
    }
    // Three walls in the y–z plane.
    for wall_x in [-2.0, 4.0, 10.0] {
        let cube = shape(Cuboid::new(Vec3::ONE).expect("valid size"));
        for row in 0..12 {
            for i in 0..(12 - row) {
                let p = at(
                    wall_x,
                    1.0 + 2.0 * row as Real,
                    -12.0 + row as Real + 2.0 * i as Real,
                );
                s.bodies.push(SceneBody::new(cube.clone(), p, 1.0));
            }
        }
    }
    // Circular tower.
    let cube = shape(Cuboid::new(Vec3::ONE).expect("valid size"));
    let radius = 1.3 * 24.0 / PI;
    let mut q = Quat::from_xyzw(0.0, 1.0, 0.0, 0.0);
    for ring in 0..8 {
        let y = 1.0 + 2.0 * ring as Real;
        for _ in 0..24 {
            let p = Vec3::new(25.0, 0.0, 0.0) + q * Vec3::new(0.0, y, radius);
            s.bodies
                .push(SceneBody::new(cube.clone(), Isometry::new(p, q), 1.0));
            q = (q * Quat::from_rotation_y(PI / 12.0)).normalize();
        }
        q = (q * Quat::from_rotation_y(PI / 24.0)).normalize();
    }
    s
}

/// Ragdoll body parts: (radius, height, local position, rotation about Z in radians).
const PARTS: [(Real, Real, [Real; 3], Real); 11] = [
    (0.15, 0.20, [0.0, 1.0, 0.0], 0.0),    // pelvis
    (0.15, 0.28, [0.0, 1.2, 0.0], 0.0),    // spine
    (0.10, 0.05, [0.0, 1.6, 0.0], 0.0),    // head
    (0.07, 0.45, [-0.18, 0.65, 0.0], 0.0), // left upper leg
    (0.05, 0.37, [-0.18, 0.2, 0.0], 0.0),  // left lower leg
    (0.07, 0.45, [0.18, 0.65, 0.0], 0.0),  // right upper leg
    (0.05, 0.37, [0.18, 0.2, 0.0], 0.0),   // right lower leg
    (0.05, 0.33, [-0.35, 1.45, 0.0], 1.0), // left upper arm (Rz +90°)
    (0.04, 0.25, [-0.7, 1.45, 0.0], 1.0),  // left lower arm
    (0.05, 0.33, [0.35, 1.45, 0.0], -1.0), // right upper arm (Rz −90°)
    (0.04, 0.25, [0.7, 1.45, 0.0], -1.0),  // right lower arm
];

fn ragdoll(s: &mut Scene, origin: Vec3, scale: Real) {
    let first = s.bodies.len();
    for (r, h, p, rot) in PARTS {
        // btCapsuleShape(r, h): h is the distance between the hemisphere centres.
        let capsule = shape(Capsule::new(r * scale, 0.5 * h * scale).expect("valid size"));
        let pose = Isometry::new(
            origin + Vec3::from_array(p) * scale,
            Quat::from_rotation_z(rot * PI / 2.0),
        );
        let mut body = SceneBody::new(capsule, pose, 1.0);
        body.linear_damping = 0.05;
        body.angular_damping = 0.85;
        s.bodies.push(body);
    }
    let frame = |rot: Quat, p: [Real; 3]| Isometry::new(Vec3::from_array(p) * scale, rot);
    let ry = Quat::from_rotation_y(PI / 2.0);
    let rz = Quat::from_rotation_z;
    let hinge = |low, high| JointKind::Hinge { low, high };
    let cone = |swing1, swing2, twist| JointKind::ConeTwist {
        swing1,
        swing2,
        twist,
    };
    let q = PI / 4.0;
    let h = PI / 2.0;
    let joints = [
        (
            0,
            1,
            frame(ry, [0.0, 0.15, 0.0]),
            frame(ry, [0.0, -0.15, 0.0]),
            hinge(-q, h),
        ),
        (
            1,
            2,
            frame(rz(h), [0.0, 0.30, 0.0]),
            frame(rz(h), [0.0, -0.14, 0.0]),
            cone(q, q, h),
        ),
        (
            0,
            3,
            frame(rz(-5.0 * q), [-0.18, -0.10, 0.0]),
            frame(rz(-5.0 * q), [0.0, 0.225, 0.0]),
            cone(q, q, 0.0),
        ),
        (
            3,
            4,
            frame(ry, [0.0, -0.225, 0.0]),
            frame(ry, [0.0, 0.185, 0.0]),
            hinge(0.0, h),
        ),
        (
            0,
            5,
            frame(rz(q), [0.18, -0.10, 0.0]),
            frame(rz(q), [0.0, 0.225, 0.0]),
            cone(q, q, 0.0),
        ),
        (
            5,
            6,
            frame(ry, [0.0, -0.225, 0.0]),
            frame(ry, [0.0, 0.185, 0.0]),
            hinge(0.0, h),
        ),
        (
            1,
            7,
            frame(rz(PI), [-0.2, 0.15, 0.0]),
            frame(rz(h), [0.0, -0.18, 0.0]),
            cone(h, h, 0.0),
        ),
        (
            7,
            8,
            frame(ry, [0.0, 0.18, 0.0]),
            frame(ry, [0.0, -0.14, 0.0]),
            hinge(-h, 0.0),
        ),
        (
            1,
            9,
            frame(rz(0.0), [0.2, 0.15, 0.0]),
            frame(rz(h), [0.0, -0.18, 0.0]),
            cone(h, h, 0.0),
        ),
        (
            9,
            10,
            frame(ry, [0.0, 0.18, 0.0]),
            frame(ry, [0.0, -0.14, 0.0]),
            hinge(-h, 0.0),
        ),
    ];
    for (a, b, frame_a, frame_b, kind) in joints {
        s.joints.push(JointDesc {
            body_a: first + a,
            body_b: first + b,
            frame_a,
            frame_b,
            kind,
            disable_collisions: true,
        });
    }
}

/// Scene 3, "136 ragdolls": 1496 capsules and 1360 joints in 16 rows.
pub fn ragdolls() -> Scene {
    let mut s = base("136 ragdolls");
    s.bodies.push(ground_box());
    for row in 0..16 {
        let n = 16 - row;
        for i in 0..n {
            let origin = Vec3::new(
                -3.0 * n as Real + 6.0 * i as Real,
                1.0 + 7.0 * row as Real,
                -2.0 * row as Real,
            );
            ragdoll(&mut s, origin, 3.5);
        }
    }
    s
}

/// The Taru hull shared by scenes 4, 6 and 7.
pub fn taru_hull() -> Arc<Shape> {
    shape(ConvexHull::new(&data::taru_points()).expect("the Taru points span a volume"))
}

/// Scene 4, "1000 convex": 960 Taru hulls in 15 layers of 8 × 8, mass 1.
pub fn convex_stack() -> Scene {
    let mut s = base("1000 convex");
    s.bodies.push(ground_box());
    let hull = taru_hull();
    let (mut spacing, mut y, mut offset): (Real, Real, Real) = (1.5, 3.0, -18.0);
    for _ in 0..15 {
        for i in 0..8 {
            for j in 0..8 {
                let pitch = 3.0 + spacing;
                let p = at(offset + i as Real * pitch, y, offset + j as Real * pitch);
                s.bodies.push(SceneBody::new(hull.clone(), p, 1.0));
            }
        }
        offset -= 0.05 * spacing * 7.0;
        spacing *= 1.01;
        y += 3.0 + spacing;
    }
    s
}

/// The landscape: 8 static triangle meshes at (0, −25, 0), friction 0.9.
fn landscape(s: &mut Scene) {
    for part in data::landscape_parts() {
        let mesh = TriMesh::new(part.vertices, part.indices).expect("valid landscape data");
        let mut body = SceneBody::new(shape(mesh), at(0.0, -25.0, 0.0), 0.0);
        body.friction = 0.9;
        s.bodies.push(body);
    }
}

/// The 1000 positions of scenes 5–7: 10 layers of 10 × 10 spread over the landscape.
fn mesh_scene_positions() -> Vec<Vec3> {
    let mut out = Vec::with_capacity(1000);
    let (mut spacing, mut offset, mut y): (Real, Real, Real) = (2.0, -25.0, 20.0);
    for _ in 0..10 {
        for i in 0..10 {
            for j in 0..10 {
                let pitch = 3.0 + spacing;
                let (x, z) = (offset + i as Real * pitch, offset + j as Real * pitch);
                out.push(Vec3::new(5.0 * x, 25.0 + y, 5.0 * z));
            }
        }
        offset -= 0.05 * spacing * 9.0;
        spacing *= 1.1;
        y += 3.0 + spacing;
    }
    out
}

/// Scene 5, "prim-trimesh": 1000 boxes, spheres and capsules (chosen by glibc `rand()`)
/// dropped on the landscape.
pub fn prim_vs_mesh() -> Scene {
    let mut s = base("prim-trimesh");
    landscape(&mut s);
    let mut rand = GlibcRand::new(1);
    for p in mesh_scene_positions() {
        let idx = rand.next() % 9;
        let r = 0.5 * ((idx % 3) + 1) as Real;
        let sh = match idx / 3 {
            0 => shape(Cuboid::new(Vec3::splat(1.5 * r)).expect("valid size")),
            1 => shape(Sphere::new(1.5 * r).expect("valid size")),
            _ => shape(Capsule::new(r, r).expect("valid size")),
        };
        s.bodies
            .push(SceneBody::new(sh, Isometry::from_translation(p), r));
    }
    s
}

/// Scene 6, "convex-trimesh": 1000 Taru hulls dropped on the landscape.
pub fn convex_vs_mesh() -> Scene {
    let mut s = base("convex-trimesh");
    landscape(&mut s);
    let hull = taru_hull();
    for p in mesh_scene_positions() {
        s.bodies.push(SceneBody::new(
            hull.clone(),
            Isometry::from_translation(p),
            1.0,
        ));
    }
    s
}

/// Scene 7, "raytests": scene 6 plus 500 rays from (0, 50, 0) sweeping 720°.
pub fn raytests() -> Scene {
    let mut s = convex_vs_mesh();
    s.name = "raytests";
    let from = Vec3::new(0.0, 50.0, 0.0);
    for i in 0..500 {
        let a = i as Real * (2.0 * 2.0 * PI / 500.0);
        let dir = Quat::from_rotation_y(a) * Vec3::X * 2500.0;
        s.rays.push((from, Vec3::new(dir.x, -1000.0, dir.z)));
    }
    s
}

/// Scene 8, "convex pack": 90 Voronoi cells of a 2 m cube falling on a plane.
pub fn convex_pack() -> Scene {
    let mut s = base("convex pack");
    let mut ground = SceneBody::new(
        shape(Plane::new(Vec3::Y, 0.0).expect("valid plane")),
        Isometry::IDENTITY,
        0.0,
    );
    ground.friction = 0.5;
    s.bodies.push(ground);
    for cell in data::halton_cells() {
        let pts: Vec<Vec3> = cell
            .verts
            .iter()
            .map(|v| Vec3::new(v[0] as Real, v[1] as Real, v[2] as Real))
            .collect();
        let hull = ConvexHull::new(&pts).expect("Halton cells are solid");
        let p = cell.pos;
        let mut body = SceneBody::new(
            shape(hull),
            at(p[0] as Real, p[1] as Real + 3.5, p[2] as Real),
            cell.volume as Real,
        );
        body.friction = 0.6;
        s.bodies.push(body);
    }
    s.solver = SolverSettings {
        iterations: 20,
        erp: 0.8,
        erp2: 0.4,
        global_cfm: 0.015,
    };
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_match_the_specification() {
        let s = falling_boxes();
        assert_eq!(s.dynamic_count(), 3008);
        let top = s
            .bodies
            .iter()
            .map(|b| b.pose.translation.y)
            .fold(0.0, Real::max);
        assert!((top - 140.0).abs() < 1e-4);
        let s = stacked_boxes();
        assert_eq!(s.dynamic_count(), 1076);
        let tower_first = s.bodies[1 + 650 + 234].pose.translation;
        assert!(
            (tower_first - Vec3::new(25.0, 1.0, -9.931)).length() < 1e-3,
            "{tower_first}"
        );
        let s = ragdolls();
        assert_eq!((s.dynamic_count(), s.joints.len()), (1496, 1360));
        let s = convex_stack();
        assert_eq!(s.dynamic_count(), 960);
        let ys: Vec<Real> = s
            .bodies
            .iter()
            .skip(1)
            .step_by(64)
            .map(|b| b.pose.translation.y)
            .collect();
        assert!(
            (ys[1] - 7.515).abs() < 1e-3 && (ys[14] - 67.645).abs() < 1e-2,
            "{ys:?}"
        );
        let s = prim_vs_mesh();
        assert_eq!(s.dynamic_count(), 1000);
        let kinds = |k: &str| {
            s.bodies
                .iter()
                .filter(|b| !b.is_static() && b.shape.kind_name() == k)
                .count()
        };
        assert_eq!(
            (kinds("box"), kinds("sphere"), kinds("capsule")),
            (339, 308, 353)
        );
        let ys: Vec<Real> = s
            .bodies
            .iter()
            .filter(|b| !b.is_static())
            .step_by(100)
            .map(|b| b.pose.translation.y)
            .collect();
        assert!(
            (ys[0] - 45.0).abs() < 1e-4
                && (ys[1] - 50.2).abs() < 1e-3
                && (ys[9] - 101.87).abs() < 1e-2,
            "{ys:?}"
        );
        let s = raytests();
        assert_eq!(s.rays.len(), 500);
        assert!((s.rays[0].1 - Vec3::new(2500.0, -1000.0, 0.0)).length() < 1e-2);
        let s = convex_pack();
        assert_eq!(s.dynamic_count(), 90);
        let total: Real = s.bodies.iter().map(|b| b.mass).sum();
        assert!((total - 8.0).abs() < 1e-3);
        let vol: Real = s.bodies.iter().skip(1).map(|b| b.shape.volume()).sum();
        assert!((vol - 8.0).abs() < 1e-3, "hull volumes {vol}");
        for (body, cell) in s.bodies.iter().skip(1).zip(data::halton_cells()) {
            let v = body.shape.volume() as f64;
            assert!(
                (v - cell.volume).abs() < 1e-4 * cell.volume,
                "{}: hull volume {v} vs {}",
                cell.name,
                cell.volume
            );
        }
    }
}
