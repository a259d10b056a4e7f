//! Exports a [`Scene`] as plain JSON for the pybullet peer (`peers/pybullet_scenes.py`) and
//! for `carom-bench export-scene`: shapes once each (bodies sharing an `Arc<Shape>` share the
//! entry, as Bullet shares its shapes), bodies with Bullet's inertia (see
//! [`super::inertia`]), joints with their frames, rays and solver settings.
//!
//! Format: `{name, gravity, dt, solver: {iterations, erp, erp2, global_cfm}, shapes: [{type:
//! box|sphere|capsule|hull|mesh|plane, …}], bodies: [{shape, position, rotation (x, y, z, w),
//! mass, inertia, friction, restitution, linear_damping, angular_damping}], joints: [{body_a,
//! body_b, frame_a, frame_b, kind: hinge|cone_twist, limits, disable_collisions}], rays:
//! [[from, to]]}`. Capsules are along local Y with `half_height` = half the segment.

use super::inertia::bullet_inertia;
use carom_collision::math::{Isometry, Vec3};
use carom_collision::shape::Shape;
use carom_scenes::{JointKind, Scene};
use serde_json::{json, Value};
use std::sync::Arc;

fn v3(v: Vec3) -> Value {
    json!([v.x as f64, v.y as f64, v.z as f64])
}

fn frame(p: &Isometry) -> Value {
    let q = p.rotation;
    json!({
        "position": v3(p.translation),
        "rotation": [q.x as f64, q.y as f64, q.z as f64, q.w as f64],
    })
}

fn shape_json(shape: &Shape) -> Result<Value, String> {
    Ok(match shape {
        Shape::Cuboid(c) => json!({"type": "box", "half_extents": v3(c.half_extents())}),
        Shape::Sphere(s) => json!({"type": "sphere", "radius": s.radius() as f64}),
        Shape::Capsule(c) => json!({
            "type": "capsule",
            "radius": c.radius() as f64,
            "half_height": c.half_height() as f64,
        }),
        Shape::ConvexHull(h) => json!({
            "type": "hull",
            "points": h.vertices().iter().map(|&v| v3(v)).collect::<Vec<_>>(),
        }),
        Shape::TriMesh(m) => json!({
            "type": "mesh",
            "vertices": m.vertices().iter().map(|&v| v3(v)).collect::<Vec<_>>(),
            "indices": m.indices(),
        }),
        Shape::Plane(p) => json!({
            "type": "plane",
            "normal": v3(p.normal()),
            "offset": p.offset() as f64,
        }),
        other => return Err(format!("cannot export a {} shape", other.kind_name())),
    })
}

/// The scene as JSON (see the module docs for the format).
pub fn scene_json(scene: &Scene) -> Result<Value, String> {
    let mut shapes: Vec<Value> = Vec::new();
    let mut seen: Vec<*const Shape> = Vec::new();
    let mut bodies = Vec::with_capacity(scene.bodies.len());
    for b in &scene.bodies {
        let ptr = Arc::as_ptr(&b.shape);
        let index = match seen.iter().position(|&p| p == ptr) {
            Some(i) => i,
            None => {
                shapes.push(shape_json(&b.shape)?);
                seen.push(ptr);
                seen.len() - 1
            }
        };
        let inertia = if b.is_static() {
            [0.0; 3]
        } else {
            bullet_inertia(&b.shape, b.mass as f64)
                .ok_or_else(|| format!("dynamic {} has no inertia", b.shape.kind_name()))?
        };
        let pose = frame(&b.pose);
        bodies.push(json!({
            "shape": index,
            "position": pose["position"],
            "rotation": pose["rotation"],
            "mass": b.mass as f64,
            "inertia": inertia,
            "friction": b.friction as f64,
            "restitution": b.restitution as f64,
            "linear_damping": b.linear_damping as f64,
            "angular_damping": b.angular_damping as f64,
        }));
    }
    let joints: Vec<Value> = scene
        .joints
        .iter()
        .map(|j| {
            let (kind, limits) = match j.kind {
                JointKind::Hinge { low, high } => ("hinge", vec![low as f64, high as f64]),
                JointKind::ConeTwist {
                    swing1,
                    swing2,
                    twist,
                } => (
                    "cone_twist",
                    vec![swing1 as f64, swing2 as f64, twist as f64],
                ),
            };
            json!({
                "body_a": j.body_a,
                "body_b": j.body_b,
                "frame_a": frame(&j.frame_a),
                "frame_b": frame(&j.frame_b),
                "kind": kind,
                "limits": limits,
                "disable_collisions": j.disable_collisions,
            })
        })
        .collect();
    let s = &scene.solver;
    Ok(json!({
        "name": scene.name,
        "gravity": v3(scene.gravity),
        "dt": scene.dt as f64,
        "solver": {
            "iterations": s.iterations,
            "erp": s.erp as f64,
            "erp2": s.erp2 as f64,
            "global_cfm": s.global_cfm as f64,
        },
        "shapes": shapes,
        "bodies": bodies,
        "joints": joints,
        "rays": scene.rays.iter().map(|&(a, b)| json!([v3(a), v3(b)])).collect::<Vec<_>>(),
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn export_keeps_counts_and_shares_shapes() {
        for n in 1..=8 {
            let scene = carom_scenes::bullet::scene(n).unwrap();
            let j = scene_json(&scene).unwrap();
            assert_eq!(j["bodies"].as_array().unwrap().len(), scene.bodies.len());
            assert_eq!(j["joints"].as_array().unwrap().len(), scene.joints.len());
            assert_eq!(j["rays"].as_array().unwrap().len(), scene.rays.len());
            // Every body's shape index is valid, and the pose round-trips.
            let shapes = j["shapes"].as_array().unwrap().len();
            for (b, jb) in scene.bodies.iter().zip(j["bodies"].as_array().unwrap()) {
                assert!((jb["shape"].as_u64().unwrap() as usize) < shapes);
                let y = jb["position"][1].as_f64().unwrap();
                assert!((y - b.pose.translation.y as f64).abs() < 1e-6);
            }
        }
        // Scene 1: the ground and one shared cube.
        let j = scene_json(&carom_scenes::bullet::scene(1).unwrap()).unwrap();
        assert_eq!(j["shapes"].as_array().unwrap().len(), 2);
    }
}
