//! Bullet's inertia rules (`shared/bench/SCENES.md`, "Inertia and friction rules"), used by
//! both peers so that Bullet, Rapier and the exported scene agree on every body's inertia:
//! boxes and spheres exact (`btBoxShape`, `btSphereShape::calculateLocalInertia`), capsules
//! and convex hulls the solid box of their local AABB (`btCapsuleShape`,
//! `btPolyhedralConvexShape::calculateLocalInertia`, the hull's half extents plus the 0.04
//! margin). The body origin is the centre of mass, as in Bullet.

use carom_collision::shape::Shape;

/// Bullet's default collision margin, added outside convex hulls.
pub const BULLET_MARGIN: f64 = 0.04;

/// Principal inertia (about the body's local axes) of a solid box with half extents `h`.
pub fn box_inertia(mass: f64, h: [f64; 3]) -> [f64; 3] {
    let [x, y, z] = h.map(|v| 4.0 * v * v);
    [
        mass / 12.0 * (y + z),
        mass / 12.0 * (x + z),
        mass / 12.0 * (x + y),
    ]
}

/// The inertia Bullet gives a body of `mass` with shape `shape`; `None` for shapes the
/// scenes only use for static bodies (meshes, planes).
pub fn bullet_inertia(shape: &Shape, mass: f64) -> Option<[f64; 3]> {
    Some(match shape {
        Shape::Cuboid(c) => {
            let h = c.half_extents();
            box_inertia(mass, [h.x as f64, h.y as f64, h.z as f64])
        }
        Shape::Sphere(s) => {
            let r = s.radius() as f64;
            [0.4 * mass * r * r; 3]
        }
        Shape::Capsule(c) => {
            let (r, hh) = (c.radius() as f64, c.half_height() as f64);
            box_inertia(mass, [r, r + hh, r])
        }
        Shape::ConvexHull(h) => {
            let aabb = h.local_aabb();
            let half = (aabb.max - aabb.min) * 0.5;
            let m = BULLET_MARGIN;
            box_inertia(
                mass,
                [half.x as f64 + m, half.y as f64 + m, half.z as f64 + m],
            )
        }
        _ => return None,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use carom_collision::math::Vec3;
    use carom_collision::shape::{Capsule, Cuboid, Sphere};

    #[test]
    fn matches_the_closed_forms() {
        // Unit cube of mass 6: I = m (a² + b²) / 12 with edges 2 → 6·8/12 = 4.
        let b = Shape::from(Cuboid::new(Vec3::ONE).unwrap());
        assert_eq!(bullet_inertia(&b, 6.0), Some([4.0; 3]));
        let s = Shape::from(Sphere::new(2.0).unwrap());
        let i = bullet_inertia(&s, 5.0).unwrap();
        assert!((i[0] - 8.0).abs() < 1e-9);
        // Capsule r = 1, half height 1: box 2 × 4 × 2.
        let c = Shape::from(Capsule::new(1.0, 1.0).unwrap());
        let i = bullet_inertia(&c, 12.0).unwrap();
        assert!((i[0] - 20.0).abs() < 1e-6 && (i[1] - 8.0).abs() < 1e-6);
        assert!((i[2] - 20.0).abs() < 1e-6);
    }
}
