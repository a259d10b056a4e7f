//! Shapes as bytes (pickling): a short header followed by the `serde` + `postcard` encoding
//! of the core [`Shape`]. Round trips are exact.
//!
//! Bytes bypass the constructors, so [`from_bytes`] re-checks every invariant the
//! constructors establish (sizes, finite values, index ranges, cached data) before the shape
//! is used: corrupted bytes give a `CaromError`, never a panic. (Like pickle itself, do not
//! load bytes from untrusted sources: a maliciously deep nesting can still exhaust the stack
//! while decoding.)

use carom_collision::math::{check_isometry, Aabb};
use carom_collision::shape::serde_check;
use carom_collision::shape::{
    Capsule, Cone, ConvexHull, Cuboid, Cylinder, Plane, Scaled, Shape, Sphere, SupportMap, Triangle,
};
use carom_collision::{CaromError, Result};

/// Header of the byte format: a tag and a format version.
const MAGIC: &[u8] = b"CAROMSHAPE\x01";

/// Deepest nesting of compounds and scaled shapes accepted when decoding.
const MAX_DEPTH: usize = 64;

fn parse_err(reason: impl Into<String>) -> CaromError {
    CaromError::Parse {
        what: "carom shape bytes".to_string(),
        reason: reason.into(),
    }
}

/// Encodes a shape.
pub fn to_bytes(shape: &Shape) -> Result<Vec<u8>> {
    let mut out = MAGIC.to_vec();
    let body = postcard::to_allocvec(shape).map_err(|e| parse_err(e.to_string()))?;
    out.extend_from_slice(&body);
    Ok(out)
}

/// Decodes and validates a shape.
pub fn from_bytes(data: &[u8]) -> Result<Shape> {
    let body = data
        .strip_prefix(MAGIC)
        .ok_or_else(|| parse_err("missing header: not bytes made by Shape.to_bytes()"))?;
    serde_check::clear_load_error();
    let decoded: std::result::Result<(Shape, &[u8]), _> = postcard::take_from_bytes(body);
    // A shape's own load check (core `TryFrom`) names the problem; postcard drops the
    // message, so it is taken from where the check recorded it.
    let (shape, rest) = decoded.map_err(|e| match serde_check::take_load_error() {
        Some(err) => parse_err(err.to_string()),
        None => parse_err(e.to_string()),
    })?;
    if !rest.is_empty() {
        return Err(parse_err(format!("{} trailing bytes", rest.len())));
    }
    validate(&shape, 0)?;
    Ok(shape)
}

fn same<T: PartialEq>(rebuilt: T, decoded: &T, what: &str) -> Result<()> {
    if rebuilt == *decoded {
        Ok(())
    } else {
        Err(parse_err(format!("inconsistent {what} data")))
    }
}

/// Checks a decoded shape (also the shapes of a `carom.World` snapshot).
pub fn validate_shape(shape: &Shape) -> Result<()> {
    validate(shape, 0)
}

/// Checks a decoded shape by rebuilding it through its constructor (hulls: index checks).
fn validate(shape: &Shape, depth: usize) -> Result<()> {
    if depth > MAX_DEPTH {
        return Err(parse_err(format!("nesting deeper than {MAX_DEPTH}")));
    }
    match shape {
        Shape::Sphere(s) => same(Sphere::new(s.radius())?, s, "sphere"),
        Shape::Cuboid(s) => same(
            Cuboid::new(s.half_extents())?.with_margin(s.margin())?,
            s,
            "box",
        ),
        Shape::Capsule(s) => same(Capsule::new(s.radius(), s.half_height())?, s, "capsule"),
        Shape::Cylinder(s) => same(
            Cylinder::new(s.radius(), s.half_height())?.with_margin(s.margin())?,
            s,
            "cylinder",
        ),
        Shape::Cone(s) => same(
            Cone::new(s.radius(), s.half_height())?.with_margin(s.margin())?,
            s,
            "cone",
        ),
        Shape::ConvexHull(h) => check_bounds(&h.local_aabb(), "convex hull"),
        Shape::Triangle(t) => same(Triangle::new(t.a, t.b, t.c)?, t, "triangle"),
        Shape::Plane(p) => {
            let rebuilt = Plane::new(p.normal(), p.offset())?;
            if (p.normal().length() - 1.0).abs() > 1e-3 || rebuilt.offset() != p.offset() {
                return Err(parse_err("inconsistent plane data"));
            }
            Ok(())
        }
        // Meshes, heightfields, hulls, scaled shapes and compounds check themselves when
        // deserialised (core `TryFrom` impls); the bounds here are re-checked for safety.
        Shape::TriMesh(m) => check_bounds(&m.local_aabb(), "triangle mesh"),
        Shape::HeightField(h) => check_bounds(&h.local_aabb(), "heightfield"),
        Shape::Compound(c) => {
            for (pose, child) in c.children() {
                check_isometry("child pose", *pose)?;
                validate(child, depth + 1)?;
            }
            check_bounds(&c.local_aabb(), "compound")
        }
        Shape::Scaled(s) => {
            validate(s.inner(), depth + 1)?;
            same(
                Scaled::new(s.inner().clone(), s.scale())?,
                s,
                "scaled shape",
            )
        }
    }
}

/// Errors unless `b` is finite with `min <= max`.
fn check_bounds(b: &Aabb, what: &str) -> Result<()> {
    if b.min.is_finite() && b.max.is_finite() && b.min.cmple(b.max).all() {
        Ok(())
    } else {
        Err(parse_err(format!("inconsistent {what} bounds")))
    }
}

/// The first broken invariant of a hull (which the core's constructor should guarantee),
/// or `None`: at least 4 finite vertices, indices in range, well-formed faces (at least 4)
/// and a positive volume.
pub fn hull_problem(h: &ConvexHull) -> Option<&'static str> {
    let nv = h.vertices().len();
    if nv < 4 || h.vertices().iter().any(|v| !v.is_finite()) {
        return Some("fewer than 4 finite vertices");
    }
    let fvi = h.face_vertex_indices();
    let in_range = |i: u32| (i as usize) < nv;
    if !fvi.iter().all(|&i| in_range(i))
        || !h.triangles().iter().flatten().all(|&i| in_range(i))
        || !h.edges().iter().flatten().all(|&i| in_range(i))
    {
        return Some("a vertex index is out of range");
    }
    for f in h.faces() {
        let end = u64::from(f.first) + u64::from(f.count);
        if f.count < 3 || end > fvi.len() as u64 || !f.normal.is_finite() || !f.offset.is_finite() {
            return Some("a face is malformed");
        }
    }
    if h.faces().len() < 4 || !h.volume().is_finite() || h.volume() <= 0.0 {
        return Some("it has fewer than 4 faces or no volume");
    }
    None
}
