//! The contact-bench cases (box–box, hull–hull 8 and 32, capsule–box, sphere–mesh,
//! box–mesh, 64 configurations each at 1 cm of penetration), shared by the criterion bench
//! `contacts` and the instruction-count example `contact_instructions`, so both measure the
//! same inputs.

use crate::common::{pv, Rng};
use carom_collision::math::{Isometry, Real, Vec3};
use carom_collision::query;
use carom_collision::shape::{Capsule, ConvexHull, Cuboid, Shape, Sphere, TriMesh};
use parry3d::math::Vec3 as PVec3;
use parry3d::shape::{SharedShape, TriMeshFlags};

pub const N: usize = 64;
/// The prediction distance of both libraries (carom's `ManifoldConfig::default()`).
pub const PREDICTION: Real = 0.02;

#[allow(clippy::unnecessary_cast)] // a no-op in the f32 build, a conversion in the f64 build
pub fn pf(x: Real) -> f32 {
    x as f32
}

pub struct Case {
    pub name: &'static str,
    pub a: Shape,
    pub b: Shape,
    pub pa: SharedShape,
    pub pb: SharedShape,
    /// B's poses in A's frame (A at the identity).
    pub poses: Vec<Isometry>,
}

/// B at a random orientation, moved along the contact normal to 1 cm of penetration.
fn convex_poses(rng: &mut Rng, a: &Shape, b: &Shape, dist: Real) -> Vec<Isometry> {
    let mut out = Vec::new();
    while out.len() < N {
        let mut p = Isometry::new(rng.unit() * dist, rng.quat());
        let Ok(Some(c)) = query::contact(a, &Isometry::IDENTITY, b, &p, 10.0) else {
            continue;
        };
        p.translation -= c.normal * (c.distance + 0.01);
        out.push(p);
    }
    out
}

/// B resting on random landscape triangles (1 cm of penetration, random orientation).
fn mesh_poses(rng: &mut Rng, mesh: &TriMesh, a: &Shape, b: &Shape) -> Vec<Isometry> {
    let mut out = Vec::new();
    while out.len() < N {
        let t = (rng.next() * mesh.num_triangles() as Real) as usize % mesh.num_triangles();
        let [p, q, r] = mesh.triangle(t);
        let Some(n) = (q - p).cross(r - p).try_normalize() else {
            continue;
        };
        let n = if n.y < 0.0 { -n } else { n };
        let c = (p + q + r) / 3.0;
        let mut pose = Isometry::new(c + n * 2.0, rng.quat());
        let Ok(Some(k)) = query::contact(a, &Isometry::IDENTITY, b, &pose, 10.0) else {
            continue;
        };
        pose.translation -= k.normal * (k.distance + 0.01);
        out.push(pose);
    }
    out
}

fn hull(rng: &mut Rng, n: usize, r: Real) -> (Shape, SharedShape) {
    let p: Vec<Vec3> = (0..n).map(|_| rng.unit() * r).collect();
    let h = ConvexHull::new(&p).unwrap();
    let pts: Vec<PVec3> = h.vertices().iter().map(|v| pv(*v)).collect();
    (
        Shape::ConvexHull(h),
        SharedShape::convex_hull(&pts).unwrap(),
    )
}

pub fn cases() -> Vec<Case> {
    let mut rng = Rng(7);
    let mut out = Vec::new();
    let bx = Shape::Cuboid(Cuboid::new(Vec3::new(0.5, 0.4, 0.6)).unwrap());
    let pbx = || SharedShape::cuboid(0.5, 0.4, 0.6);
    let poses = convex_poses(&mut rng, &bx, &bx, 1.2);
    out.push(Case {
        name: "box-box",
        a: bx.clone(),
        b: bx.clone(),
        pa: pbx(),
        pb: pbx(),
        poses,
    });
    for n in [8, 32] {
        let (ha, pha) = hull(&mut rng, n, 0.6);
        let (hb, phb) = hull(&mut rng, n, 0.6);
        let poses = convex_poses(&mut rng, &ha, &hb, 1.2);
        out.push(Case {
            name: if n == 8 {
                "hull8-hull8"
            } else {
                "hull32-hull32"
            },
            a: ha,
            b: hb,
            pa: pha,
            pb: phb,
            poses,
        });
    }
    let cap = Shape::Capsule(Capsule::new(0.3, 0.5).unwrap());
    let poses = convex_poses(&mut rng, &bx, &cap, 1.2);
    out.push(Case {
        name: "box-capsule",
        a: bx.clone(),
        b: cap,
        pa: pbx(),
        pb: SharedShape::capsule_y(0.5, 0.3),
        poses,
    });
    let part = carom_scenes::data::landscape_parts().swap_remove(0);
    let mesh = TriMesh::new(part.vertices.clone(), part.indices.clone()).unwrap();
    let pmesh = SharedShape::trimesh_with_flags(
        part.vertices.iter().map(|v| pv(*v)).collect(),
        part.indices.clone(),
        TriMeshFlags::FIX_INTERNAL_EDGES,
    )
    .unwrap();
    let sm = Shape::TriMesh(mesh.clone());
    let ball = Shape::Sphere(Sphere::new(0.5).unwrap());
    let poses = mesh_poses(&mut rng, &mesh, &sm, &ball);
    out.push(Case {
        name: "mesh-sphere",
        a: sm.clone(),
        b: ball,
        pa: pmesh.clone(),
        pb: SharedShape::ball(0.5),
        poses,
    });
    let poses = mesh_poses(&mut rng, &mesh, &sm, &bx);
    out.push(Case {
        name: "mesh-box",
        a: sm,
        b: bx,
        pa: pmesh,
        pb: pbx(),
        poses,
    });
    out
}
