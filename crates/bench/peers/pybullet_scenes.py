#!/usr/bin/env python3
"""Bullet peer of ``carom-bench scenes``: runs one exported scene in pybullet.

Reads a scene exported by ``carom-bench export-scene`` (JSON, see
``crates/bench/src/scenes/export.rs``), builds it in a DIRECT pybullet world with Bullet's
benchmark settings (``shared/bench/SCENES.md``: 5 iterations or the scene's, erp 0.2,
split impulse, friction ERP, no cone friction, linear slop 0, warm starting 0.85,
contact breaking threshold 0.02, gravity and step of the scene), steps it, times every
``stepSimulation`` and, for the ray scene, ``rayTestBatch`` single-threaded and with all
threads, and prints one JSON object on stdout: ``step_ms``, ``ray_ms``, ``ray_ms_mt``,
``hits`` and the final ``positions``/``velocities`` of the dynamic bodies (scene order).

Deviations from Bullet's own demo (pybullet's API has no equivalent):
- Bodies are maximal-coordinate rigid bodies in pybullet's btMultiBodyDynamicsWorld; its
  pair AABBs have no margin (gDbvtMargin 0.05 in the demo) and cannot be changed.
- Ragdoll joints are point-to-point constraints at frame A's pivot: pybullet cannot create
  hinge or cone-twist constraints between rigid bodies, so the joints have no limits.
- Capsules are along Z in pybullet: each capsule body's frame is turned by Rx(-90 deg) so the
  capsule lies along the scene's Y; positions, inertia and joint pivots are mapped accordingly.
- Boxes and hulls get collisionMargin 0.04 (Bullet's default); hulls then grow by 0.04 outside
  the scene's points, as in Bullet (the scene's Carom hulls have no margin).
- Sleeping uses pybullet's thresholds (per-body deactivation times of the ragdolls are not
  settable); the physics step is single-threaded (pybullet's wheel has no threaded solver).
"""

import argparse
import json
import math
import sys
import time

import pybullet as p

# Rx(-90 deg): maps the local Z axis (pybullet's capsule axis) onto Y.
CAPSULE_FIX = (-math.sqrt(0.5), 0.0, 0.0, math.sqrt(0.5))


def qmul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (
        aw * bx + ax * bw + ay * bz - az * by,
        aw * by - ax * bz + ay * bw + az * bx,
        aw * bz + ax * by - ay * bx + az * bw,
        aw * bw - ax * bx - ay * by - az * bz,
    )


def qrot(q, v):
    """Rotates vector v by unit quaternion q."""
    x, y, z, w = qmul(qmul(q, (v[0], v[1], v[2], 0.0)), (-q[0], -q[1], -q[2], q[3]))
    return (x, y, z)


def qinv(q):
    return (-q[0], -q[1], -q[2], q[3])


def make_shape(s):
    """A pybullet collision shape for one exported shape."""
    t = s["type"]
    if t == "box":
        return p.createCollisionShape(p.GEOM_BOX, halfExtents=s["half_extents"])
    if t == "sphere":
        return p.createCollisionShape(p.GEOM_SPHERE, radius=s["radius"])
    if t == "capsule":
        return p.createCollisionShape(
            p.GEOM_CAPSULE, radius=s["radius"], height=2.0 * s["half_height"]
        )
    if t == "hull":
        return p.createCollisionShape(p.GEOM_MESH, vertices=s["points"])
    if t == "mesh":
        flat = [i for tri in s["indices"] for i in tri]
        return p.createCollisionShape(p.GEOM_MESH, vertices=s["vertices"], indices=flat)
    if t == "plane":
        return p.createCollisionShape(p.GEOM_PLANE, planeNormal=s["normal"])
    raise ValueError(f"unknown shape type {t!r}")


def configure(scene):
    """Bullet's benchmark world settings (SCENES.md, section 0 and scene 8's overrides)."""
    solver = scene["solver"]
    p.setGravity(*scene["gravity"])
    p.setPhysicsEngineParameter(
        fixedTimeStep=scene["dt"],
        numSubSteps=0,
        numSolverIterations=solver["iterations"],
        erp=solver["erp"],
        contactERP=solver["erp2"],
        frictionERP=0.2,
        globalCFM=solver["global_cfm"],
        useSplitImpulse=1,
        splitImpulsePenetrationThreshold=-0.04,
        contactBreakingThreshold=0.02,
        enableConeFriction=0,
        restitutionVelocityThreshold=0.2,
        solverResidualThreshold=0.0,
        contactSlop=0.0,
        warmStartingFactor=0.85,
        minimumSolverIslandSize=128,
    )


def build(scene, sleeping):
    """Creates every body and joint; returns (body ids, capsule flags, dynamic ids)."""
    shapes = [make_shape(s) for s in scene["shapes"]]
    kinds = [s["type"] for s in scene["shapes"]]
    ids, capsule, dynamic = [], [], []
    state = p.ACTIVATION_STATE_ENABLE_SLEEPING if sleeping else p.ACTIVATION_STATE_DISABLE_SLEEPING
    for b in scene["bodies"]:
        kind = kinds[b["shape"]]
        is_capsule = kind == "capsule"
        rot = tuple(b["rotation"])
        if is_capsule:
            rot = qmul(rot, CAPSULE_FIX)
        bid = p.createMultiBody(
            baseMass=b["mass"],
            baseCollisionShapeIndex=shapes[b["shape"]],
            basePosition=b["position"],
            baseOrientation=rot,
            useMaximalCoordinates=True,
        )
        extra = {}
        if b["mass"] > 0.0:
            ix, iy, iz = b["inertia"]
            # In the turned capsule frame local Y and Z swap roles.
            extra["localInertiaDiagonal"] = (ix, iz, iy) if is_capsule else (ix, iy, iz)
            extra["mass"] = b["mass"]
            extra["activationState"] = state
        if kind in ("box", "hull"):
            extra["collisionMargin"] = 0.04
        p.changeDynamics(
            bid,
            -1,
            lateralFriction=b["friction"],
            restitution=b["restitution"],
            linearDamping=b["linear_damping"],
            angularDamping=b["angular_damping"],
            rollingFriction=0.0,
            spinningFriction=0.0,
            **extra,
        )
        ids.append(bid)
        capsule.append(is_capsule)
        if b["mass"] > 0.0:
            dynamic.append(bid)
    for j in scene["joints"]:
        a, b = j["body_a"], j["body_b"]
        pivot_a = tuple(j["frame_a"]["position"])
        pivot_b = tuple(j["frame_b"]["position"])
        if capsule[a]:
            pivot_a = qrot(qinv(CAPSULE_FIX), pivot_a)
        if capsule[b]:
            pivot_b = qrot(qinv(CAPSULE_FIX), pivot_b)
        cid = p.createConstraint(
            ids[a], -1, ids[b], -1, p.JOINT_POINT2POINT, [0, 0, 0], pivot_a, pivot_b
        )
        p.changeConstraint(cid, maxForce=1e9)
        if j["disable_collisions"]:
            p.setCollisionFilterPair(ids[a], ids[b], -1, -1, 0)
    return dynamic


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("scene", help="scene JSON exported by carom-bench export-scene")
    ap.add_argument("--steps", type=int, default=600)
    ap.add_argument("--sleeping", choices=["on", "off"], default="off")
    args = ap.parse_args()
    with open(args.scene) as f:
        scene = json.load(f)
    p.connect(p.DIRECT)
    configure(scene)
    dynamic = build(scene, args.sleeping == "on")
    froms = [r[0] for r in scene["rays"]]
    tos = [r[1] for r in scene["rays"]]
    step_ms, ray_ms, ray_ms_mt, hits = [], [], [], 0
    clock = time.perf_counter
    for _ in range(args.steps):
        t0 = clock()
        p.stepSimulation()
        step_ms.append((clock() - t0) * 1e3)
        if froms:
            t0 = clock()
            res = p.rayTestBatch(froms, tos, numThreads=1)
            ray_ms.append((clock() - t0) * 1e3)
            t0 = clock()
            p.rayTestBatch(froms, tos, numThreads=0)
            ray_ms_mt.append((clock() - t0) * 1e3)
            hits = sum(1 for r in res if r[0] >= 0)
    positions, velocities = [], []
    for bid in dynamic:
        pos, _ = p.getBasePositionAndOrientation(bid)
        lin, _ = p.getBaseVelocity(bid)
        positions.append(list(pos))
        velocities.append(list(lin))
    json.dump(
        {
            "engine": "bullet",
            "version": "pybullet " + str(p.getAPIVersion()),
            "step_ms": step_ms,
            "ray_ms": ray_ms,
            "ray_ms_mt": ray_ms_mt,
            "hits": hits,
            "positions": positions,
            "velocities": velocities,
        },
        sys.stdout,
    )
    sys.stdout.write("\n")
    p.disconnect()


if __name__ == "__main__":
    main()
