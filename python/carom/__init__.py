"""Carom: collision detection and rigid-body physics with a Rust core.

Shapes (``Sphere``, ``Box``, ``Capsule``, ``Cylinder``, ``Cone``, ``ConvexHull``,
``Triangle``, ``TriMesh``, ``HeightField``, ``Compound``, ``Plane`` and
``shape.scaled(...)``) and poses
(``Pose``, a position and a unit quaternion ``(x, y, z, w)`` as in pybullet). Arrays go in
and come out as float64 numpy arrays; anything ``numpy.asarray`` turns into numbers is
accepted. Capsules, cylinders and cones lie along the local **Y** axis.

Queries (``distance``, ``contact``, ``intersects``, ``raycast``, ``project_point``,
``shape_cast``, ``time_of_impact``) use a signed distance (negative = penetration) and a
normal from A towards B, so ``point_b = point_a + normal * distance``; given ``(N, 7)`` poses
or ``(N, 3)`` rays/points they return results whose fields are arrays of length N.

Invalid values raise :class:`CaromError` (a ``ValueError``) naming the bad value; wrong
types raise ``TypeError``.

Example::

    >>> import carom
    >>> box = carom.Box([0.5, 1.0, 2.0])
    >>> box.support([[1, 1, 1], [-1, 0, 0]])
    array([[ 0.5,  1. ,  2. ],
           [-0.5,  1. ,  2. ]])
"""

from carom._carom import (
    REAL_BITS,
    Box,
    Capsule,
    CaromError,
    Compound,
    Cone,
    ConvexHull,
    Cylinder,
    Plane,
    Pose,
    Scaled,
    Shape,
    Sphere,
    Triangle,
    TriMesh,
    Contact,
    HeightField,
    MeshRayHits,
    PointProjection,
    RayHit,
    ShapeCastHit,
    contact,
    distance,
    intersects,
    project_point,
    raycast,
    shape_cast,
    time_of_impact,
    __version__,
)
from carom._carom import CollisionWorld, ContactEvents, Contacts, contact_manifold


__all__ = [
    "REAL_BITS",
    "Box",
    "Capsule",
    "CaromError",
    "Compound",
    "Cone",
    "ConvexHull",
    "Cylinder",
    "Plane",
    "Pose",
    "Scaled",
    "Shape",
    "Sphere",
    "Triangle",
    "TriMesh",
    "Contact",
    "HeightField",
    "MeshRayHits",
    "PointProjection",
    "RayHit",
    "ShapeCastHit",
    "contact",
    "distance",
    "intersects",
    "project_point",
    "raycast",
    "shape_cast",
    "time_of_impact",
    "__version__",
    "CollisionWorld",
    "ContactEvents",
    "Contacts",
    "contact_manifold",
]

# Broadphase: pairs of overlapping boxes, incremental broadphases, the dynamic AABB tree.
from carom._carom import BroadPhase, DynamicTree, overlapping_pairs  # noqa: E402

__all__ += ["BroadPhase", "DynamicTree", "overlapping_pairs"]

# Rigid-body simulation: bodies, joints, the step pipeline, numpy state in bulk, contact
# events, ray and shape casts through the world, snapshots.
from carom._carom import World, WorldContacts, WorldRayHit, WorldShapeCastHit  # noqa: E402

__all__ += ["World", "WorldContacts", "WorldRayHit", "WorldShapeCastHit"]
