"""The Python half of `make demo`: the same shapes, seen from numpy."""

import numpy as np

import carom


def main() -> None:
    print(f"carom {carom.__version__} (Real = f{carom.REAL_BITS})")
    shapes = {
        "Sphere(0.5)": carom.Sphere(0.5),
        "Box(1, 0.5, 0.25)": carom.Box([1.0, 0.5, 0.25]),
        "Capsule(0.3, 0.5)": carom.Capsule(0.3, 0.5),
        "Cylinder(0.4, 0.6)": carom.Cylinder(0.4, 0.6),
        "Cone(0.5, 0.75)": carom.Cone(0.5, 0.75),
        "ConvexHull(cube corners)": carom.ConvexHull(
            np.array([[x, y, z] for x in (-1, 1) for y in (-1, 1) for z in (-1, 1)], dtype=float)
        ),
        "Capsule scaled (2,1,0.5)": carom.Capsule(0.3, 0.5).scaled([2.0, 1.0, 0.5]),
    }
    pose = carom.Pose([1.0, 2.0, 3.0], [0.0, np.sin(0.25), 0.0, np.cos(0.25)])
    rng = np.random.default_rng(0)
    dirs = rng.normal(size=(100_000, 3))
    for name, shape in shapes.items():
        mass, com, inertia = shape.mass_properties(1000.0)
        lo, hi = shape.aabb(pose)
        pts = shape.support(dirs)
        print(f"{name:<26} volume {shape.volume:9.5f}  mass {mass:10.3f}  "
              f"inertia diag {np.round(np.diag(inertia), 3)}  AABB at pose {np.round(lo, 3)}..{np.round(hi, 3)}")
        print(f"{'':<26} 100k support queries: max |p| = {np.linalg.norm(pts, axis=1).max():.4f}")
    try:
        carom.Sphere(-1.0)
    except carom.CaromError as e:
        print(f"bad input is rejected: {e}")


if __name__ == "__main__":
    main()
