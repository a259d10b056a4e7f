//! Collision shapes: one file per shape, a closed [`Shape`] enum, support maps and mass
//! properties.
//!
//! Shapes are immutable and shared behind `Arc`. Convex shapes implement [`SupportMap`];
//! [`Shape::as_convex`] gives a [`ConvexRef`] that dispatches by `match`, without vtables.
//! Capsules, cylinders and cones lie along the local **Y** axis.

mod capsule;
mod compound;
mod cone;
pub(crate) mod convex_hull;
mod cuboid;
mod cylinder;
mod heightfield;
mod hull_lanes;
mod mass;
mod mesh_load;
mod plane;
mod quickhull;
mod quickhull_builder;
mod quickhull_merge;
mod scaled;
pub mod serde_check;
mod sphere;
mod support;
mod triangle;
mod trimesh;
mod trimesh_edges;

pub use capsule::Capsule;
pub use compound::Compound;
pub use cone::Cone;
pub use convex_hull::{ConvexHull, HullFace};
pub use cuboid::{Cuboid, DEFAULT_MARGIN};
pub use cylinder::Cylinder;
pub use heightfield::HeightField;
pub use mass::{polyhedron_mass_properties, MassProperties};
pub use plane::Plane;
pub use quickhull::{quickhull, HullPolygons};
pub use scaled::Scaled;
pub use sphere::Sphere;
pub use support::SupportMap;
pub use triangle::Triangle;
pub use trimesh::{triangle_aabbs, TriMesh, TriMeshOptions};
pub use trimesh_edges::{
    classify_edge, compute_edges, weld_vertices, EdgeKind, MeshEdge, BOUNDARY_EDGE,
    DEFAULT_FLAT_ANGLE, NO_NEIGHBOR,
};

use crate::error::{CaromError, Result};
use crate::math::{check_positive, Aabb, Isometry, Real, Vec3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// Every shape Carom knows, as a closed enum so shape-pair dispatch is an exhaustive `match`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum Shape {
    /// A sphere.
    Sphere(Sphere),
    /// A box (`carom.Box` in Python).
    Cuboid(Cuboid),
    /// A capsule along Y.
    Capsule(Capsule),
    /// A cylinder along Y.
    Cylinder(Cylinder),
    /// A cone along Y.
    Cone(Cone),
    /// A convex hull of points.
    ConvexHull(ConvexHull),
    /// A single triangle.
    Triangle(Triangle),
    /// An infinite plane (static bodies only).
    Plane(Plane),
    /// A triangle mesh.
    TriMesh(TriMesh),
    /// Children at local poses.
    Compound(Compound),
    /// A non-uniformly scaled convex shape.
    Scaled(Scaled),
    /// A heightfield (static bodies).
    HeightField(HeightField),
}

/// The kind of a [`Shape`], without its data.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Serialize, Deserialize)]
pub enum ShapeKind {
    /// [`Sphere`]
    Sphere,
    /// [`Cuboid`]
    Cuboid,
    /// [`Capsule`]
    Capsule,
    /// [`Cylinder`]
    Cylinder,
    /// [`Cone`]
    Cone,
    /// [`ConvexHull`]
    ConvexHull,
    /// [`Triangle`]
    Triangle,
    /// [`Plane`]
    Plane,
    /// [`TriMesh`]
    TriMesh,
    /// [`Compound`]
    Compound,
    /// [`Scaled`]
    Scaled,
    /// [`HeightField`]
    HeightField,
}

/// A borrowed convex shape: the subset of [`Shape`] with a support map.
#[derive(Debug, Clone, Copy)]
pub enum ConvexRef<'a> {
    /// A sphere.
    Sphere(&'a Sphere),
    /// A box.
    Cuboid(&'a Cuboid),
    /// A capsule.
    Capsule(&'a Capsule),
    /// A cylinder.
    Cylinder(&'a Cylinder),
    /// A cone.
    Cone(&'a Cone),
    /// A convex hull.
    ConvexHull(&'a ConvexHull),
    /// A triangle.
    Triangle(&'a Triangle),
    /// A scaled convex shape.
    Scaled(&'a Scaled),
}

macro_rules! convex_dispatch {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            ConvexRef::Sphere($s) => $e,
            ConvexRef::Cuboid($s) => $e,
            ConvexRef::Capsule($s) => $e,
            ConvexRef::Cylinder($s) => $e,
            ConvexRef::Cone($s) => $e,
            ConvexRef::ConvexHull($s) => $e,
            ConvexRef::Triangle($s) => $e,
            ConvexRef::Scaled($s) => $e,
        }
    };
}

impl SupportMap for ConvexRef<'_> {
    #[inline]
    fn support(&self, dir: Vec3) -> Vec3 {
        convex_dispatch!(self, s => s.support(dir))
    }
    #[inline]
    fn support_core(&self, dir: Vec3) -> Vec3 {
        convex_dispatch!(self, s => s.support_core(dir))
    }
    #[inline]
    fn margin(&self) -> Real {
        convex_dispatch!(self, s => s.margin())
    }
}

impl<'a> ConvexRef<'a> {
    /// The kind of the referenced shape.
    pub fn kind(&self) -> ShapeKind {
        match self {
            ConvexRef::Sphere(_) => ShapeKind::Sphere,
            ConvexRef::Cuboid(_) => ShapeKind::Cuboid,
            ConvexRef::Capsule(_) => ShapeKind::Capsule,
            ConvexRef::Cylinder(_) => ShapeKind::Cylinder,
            ConvexRef::Cone(_) => ShapeKind::Cone,
            ConvexRef::ConvexHull(_) => ShapeKind::ConvexHull,
            ConvexRef::Triangle(_) => ShapeKind::Triangle,
            ConvexRef::Scaled(_) => ShapeKind::Scaled,
        }
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        convex_dispatch!(self, s => s.local_aabb())
    }
}

macro_rules! shape_dispatch {
    ($self:expr, $s:ident => $e:expr) => {
        match $self {
            Shape::Sphere($s) => $e,
            Shape::Cuboid($s) => $e,
            Shape::Capsule($s) => $e,
            Shape::Cylinder($s) => $e,
            Shape::Cone($s) => $e,
            Shape::ConvexHull($s) => $e,
            Shape::Triangle($s) => $e,
            Shape::Plane($s) => $e,
            Shape::TriMesh($s) => $e,
            Shape::Compound($s) => $e,
            Shape::Scaled($s) => $e,
            Shape::HeightField($s) => $e,
        }
    };
}

impl Shape {
    /// The shape's kind.
    pub fn kind(&self) -> ShapeKind {
        match self {
            Shape::Sphere(_) => ShapeKind::Sphere,
            Shape::Cuboid(_) => ShapeKind::Cuboid,
            Shape::Capsule(_) => ShapeKind::Capsule,
            Shape::Cylinder(_) => ShapeKind::Cylinder,
            Shape::Cone(_) => ShapeKind::Cone,
            Shape::ConvexHull(_) => ShapeKind::ConvexHull,
            Shape::Triangle(_) => ShapeKind::Triangle,
            Shape::Plane(_) => ShapeKind::Plane,
            Shape::TriMesh(_) => ShapeKind::TriMesh,
            Shape::Compound(_) => ShapeKind::Compound,
            Shape::Scaled(_) => ShapeKind::Scaled,
            Shape::HeightField(_) => ShapeKind::HeightField,
        }
    }

    /// A lower-case name of the kind, for messages.
    pub fn kind_name(&self) -> &'static str {
        match self.kind() {
            ShapeKind::Sphere => "sphere",
            ShapeKind::Cuboid => "box",
            ShapeKind::Capsule => "capsule",
            ShapeKind::Cylinder => "cylinder",
            ShapeKind::Cone => "cone",
            ShapeKind::ConvexHull => "convex hull",
            ShapeKind::Triangle => "triangle",
            ShapeKind::Plane => "plane",
            ShapeKind::TriMesh => "triangle mesh",
            ShapeKind::Compound => "compound",
            ShapeKind::Scaled => "scaled shape",
            ShapeKind::HeightField => "heightfield",
        }
    }

    /// The convex view of the shape, or `None` for planes, meshes and compounds.
    #[inline]
    pub fn as_convex(&self) -> Option<ConvexRef<'_>> {
        Some(match self {
            Shape::Sphere(s) => ConvexRef::Sphere(s),
            Shape::Cuboid(s) => ConvexRef::Cuboid(s),
            Shape::Capsule(s) => ConvexRef::Capsule(s),
            Shape::Cylinder(s) => ConvexRef::Cylinder(s),
            Shape::Cone(s) => ConvexRef::Cone(s),
            Shape::ConvexHull(s) => ConvexRef::ConvexHull(s),
            Shape::Triangle(s) => ConvexRef::Triangle(s),
            Shape::Scaled(s) => ConvexRef::Scaled(s),
            Shape::Plane(_) | Shape::TriMesh(_) | Shape::Compound(_) | Shape::HeightField(_) => {
                return None
            }
        })
    }

    /// True for shapes with a support map.
    pub fn is_convex(&self) -> bool {
        self.as_convex().is_some()
    }

    /// Bounding box in the shape's local frame.
    pub fn local_aabb(&self) -> Aabb {
        shape_dispatch!(self, s => s.local_aabb())
    }

    /// Tight world bounding box of the shape placed at `pose`. Exact for convex shapes (six
    /// support queries along the world axes); for meshes and compounds, the children's boxes.
    #[inline]
    pub fn aabb(&self, pose: &Isometry) -> Aabb {
        // Spheres and boxes inline at the call site (the per-body sync of a pile of boxes:
        // no call into the large frame of the other arms); the rest stays out of line.
        match self {
            Shape::Sphere(s) => sphere_aabb(s, pose),
            Shape::Cuboid(s) => cuboid_aabb(s, pose),
            _ => self.aabb_out_of_line(pose),
        }
    }

    /// [`Shape::aabb`] of the shapes it does not inline.
    #[inline(never)]
    fn aabb_out_of_line(&self, pose: &Isometry) -> Aabb {
        match self {
            Shape::Sphere(s) => sphere_aabb(s, pose),
            Shape::Cuboid(s) => cuboid_aabb(s, pose),
            Shape::Cylinder(c) => {
                let (lo, hi) = axial_extents(pose, c.radius(), c.half_height(), false);
                Aabb::new(pose.translation + lo, pose.translation + hi)
            }
            Shape::Cone(c) => {
                let (lo, hi) = axial_extents(pose, c.radius(), c.half_height(), true);
                Aabb::new(pose.translation + lo, pose.translation + hi)
            }
            Shape::HeightField(s) => s.local_aabb().transformed(pose),
            Shape::Plane(p) => {
                let n = pose.transform_vector(p.normal());
                let offset = p.offset() + n.dot(pose.translation);
                match Plane::new(n, offset) {
                    Ok(plane) => plane.local_aabb(),
                    Err(_) => Aabb::new(
                        Vec3::splat(-crate::math::UNBOUNDED),
                        Vec3::splat(crate::math::UNBOUNDED),
                    ),
                }
            }
            Shape::TriMesh(m) => {
                Aabb::from_points(m.vertices().iter().map(|v| pose.transform_point(*v)))
            }
            Shape::Capsule(c) => {
                // The box of the two end spheres (exact): the segment's ends rotated once
                // instead of six support queries (the ragdoll scene is all capsules).
                let half = pose.rotation * Vec3::new(0.0, c.half_height(), 0.0);
                let (a, b) = (pose.translation + half, pose.translation - half);
                let r = Vec3::splat(c.radius());
                Aabb::new(a.min(b) - r, a.max(b) + r)
            }
            Shape::ConvexHull(h) if h.vertices().len() <= ConvexHull::AABB_SCAN_MAX_VERTICES => {
                // One pass rotating every vertex by the matrix is cheaper than six support
                // queries: on the 1000-hull benchmark scene it cut the box update from ~2,700
                // to ~680 instructions per hull, and doing it four vertices at a time on the
                // hull's SIMD lanes to ~410 (callgrind, 60 steps: 40.8M -> 24.8M). Exact for
                // the hull's vertices, like the support queries, and bit for bit the scalar
                // scan's box.
                let (lo, hi) = h.rotated_bounds(pose.rotation);
                Aabb::new(lo + pose.translation, hi + pose.translation)
            }
            Shape::Compound(c) => c
                .children()
                .iter()
                .fold(Aabb::EMPTY, |acc, (child_pose, s)| {
                    acc.merge(&s.aabb(&pose.mul(child_pose)))
                }),
            _ => {
                let convex = self.as_convex().expect("remaining variants are convex");
                let mut min = Vec3::ZERO;
                let mut max = Vec3::ZERO;
                for i in 0..3 {
                    let mut axis = Vec3::ZERO;
                    axis[i] = 1.0;
                    max[i] = convex.support_world(pose, axis)[i];
                    min[i] = convex.support_world(pose, -axis)[i];
                }
                Aabb::new(min, max)
            }
        }
    }

    /// Volume (0 for triangles, planes and open meshes).
    pub fn volume(&self) -> Real {
        match self {
            Shape::Triangle(_) | Shape::Plane(_) | Shape::HeightField(_) => 0.0,
            Shape::Sphere(s) => s.volume(),
            Shape::Cuboid(s) => s.volume(),
            Shape::Capsule(s) => s.volume(),
            Shape::Cylinder(s) => s.volume(),
            Shape::Cone(s) => s.volume(),
            Shape::ConvexHull(s) => s.volume(),
            Shape::TriMesh(s) => s.volume(),
            Shape::Compound(s) => s.volume(),
            Shape::Scaled(s) => s.volume(),
        }
    }

    /// Mass properties for a uniform density (zero mass for triangles and planes).
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        match self {
            Shape::Triangle(_) | Shape::Plane(_) | Shape::HeightField(_) => MassProperties::ZERO,
            Shape::Sphere(s) => s.mass_properties(density),
            Shape::Cuboid(s) => s.mass_properties(density),
            Shape::Capsule(s) => s.mass_properties(density),
            Shape::Cylinder(s) => s.mass_properties(density),
            Shape::Cone(s) => s.mass_properties(density),
            Shape::ConvexHull(s) => s.mass_properties(density),
            Shape::TriMesh(s) => s.mass_properties(density),
            Shape::Compound(s) => s.mass_properties(density),
            Shape::Scaled(s) => s.mass_properties(density),
        }
    }

    /// Mass properties after checking `density` (finite, > 0).
    pub fn checked_mass_properties(&self, density: Real) -> Result<MassProperties> {
        check_positive("density", density)?;
        Ok(self.mass_properties(density))
    }

    /// This shape scaled by `scale` (convex shapes only).
    pub fn scaled(self: &Arc<Self>, scale: Vec3) -> Result<Shape> {
        Ok(Shape::Scaled(Scaled::new(self.clone(), scale)?))
    }

    /// Collision margin of a convex shape (`None` for others).
    pub fn margin(&self) -> Option<Real> {
        self.as_convex().map(|c| c.margin())
    }

    /// Returns an error unless the shape is convex.
    pub fn require_convex(&self, what: &str) -> Result<ConvexRef<'_>> {
        self.as_convex().ok_or_else(|| {
            CaromError::Unsupported(format!(
                "{what} needs a convex shape, not a {}",
                self.kind_name()
            ))
        })
    }
}

macro_rules! impl_from {
    ($($t:ident => $v:ident),*) => {$(
        impl From<$t> for Shape {
            fn from(s: $t) -> Shape { Shape::$v(s) }
        }
    )*};
}
impl_from!(Sphere => Sphere, Cuboid => Cuboid, Capsule => Capsule, Cylinder => Cylinder,
    Cone => Cone, ConvexHull => ConvexHull, Triangle => Triangle, Plane => Plane,
    TriMesh => TriMesh, Compound => Compound, Scaled => Scaled, HeightField => HeightField);

/// The world box of a sphere at `pose`.
#[inline]
fn sphere_aabb(s: &Sphere, pose: &Isometry) -> Aabb {
    Aabb::from_center_half_extents(pose.translation, Vec3::splat(s.radius()))
}

/// The world box of a box at `pose`: Arvo's box of a centred box, the half extents through
/// |R| (the centre is the translation, so no rotation of the local centre).
#[inline]
fn cuboid_aabb(s: &Cuboid, pose: &Isometry) -> Aabb {
    let e = cuboid::rotated_half_extents(pose.rotation, s.half_extents());
    Aabb::new(pose.translation - e, pose.translation + e)
}

/// World-axis extents (offsets of the box's min and max corners from the centre) of a
/// cylinder or cone of base `radius` along its local y axis from `-half_height` to
/// `half_height`, placed at `pose` (the cone's apex at `+half_height`). Closed forms instead
/// of six support queries: a disk of radius `r` with unit normal `a` spans
/// `±r·sqrt(1 − a_i²)` along world axis `i` (the "Bounding box of a disk" of Íñigo Quílez's
/// articles; parry's `Cylinder::aabb` does the same), and the box spans both end disks (the
/// cone's apex is a disk of radius 0). Equal to the support-query box up to round-off.
#[inline]
fn axial_extents(pose: &Isometry, radius: Real, half_height: Real, cone: bool) -> (Vec3, Vec3) {
    let a = pose.rotation * Vec3::Y;
    // `1 − a_i²` as the sum of the two other squares: no cancellation when the axis is
    // nearly aligned with a world axis (`1 − a_y²` would lose the `√ε`-sized radius there).
    let sq = a * a;
    let disk = Vec3::new(
        (sq.y + sq.z).sqrt(),
        (sq.z + sq.x).sqrt(),
        (sq.x + sq.y).sqrt(),
    ) * radius;
    let top = a * half_height;
    if cone {
        // Apex at +h (no disk), base disk at -h.
        (top.min(-top - disk), top.max(-top + disk))
    } else {
        let t = top.abs();
        (-(t + disk), t + disk)
    }
}
