//! Heightfield: a regular grid of heights, two triangles per cell, with no BVH (the grid is
//! its own acceleration structure; queries live in `midphase::heightfield_query`).

use super::{classify_edge, MassProperties, MeshEdge, BOUNDARY_EDGE, DEFAULT_FLAT_ANGLE};
use crate::error::{CaromError, Result};
use crate::math::{check_finite, check_positive, Aabb, Real, Vec3};
use serde::{Deserialize, Serialize};

/// A heightfield over the XZ plane, Y up, centred on the origin in X and Z.
///
/// Sample `(r, c)` (row `r < rows` along Z, column `c < cols` along X) is the point
/// `(c·dx - (cols-1)·dx/2, heights[r·cols + c], r·dz - (rows-1)·dz/2)`. Cell `(r, c)` holds
/// triangles `2·(r·(cols-1) + c)` and `+1`, both facing +Y:
/// `[p(r,c), p(r+1,c), p(r,c+1)]` and `[p(r,c+1), p(r+1,c), p(r+1,c+1)]`.
/// Like Bullet's `btHeightfieldTerrainShape` and parry's `HeightField`.
///
/// Deserialising rebuilds the cached bounds through [`HeightField::new`] and checks them, so
/// inconsistent bytes give a [`CaromError`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "HeightFieldData")]
pub struct HeightField {
    rows: usize,
    cols: usize,
    heights: Vec<Real>,
    dx: Real,
    dz: Real,
    local_aabb: Aabb,
}

/// The serialised form of a [`HeightField`], checked on load by `TryFrom` (the
/// constructor's checks, and the stored bounds must be the rebuilt ones).
#[derive(Deserialize)]
pub struct HeightFieldData {
    rows: usize,
    cols: usize,
    heights: Vec<Real>,
    dx: Real,
    dz: Real,
    local_aabb: Aabb,
}

impl TryFrom<HeightFieldData> for HeightField {
    type Error = CaromError;
    fn try_from(d: HeightFieldData) -> Result<Self> {
        super::serde_check::record((|| {
            let h = HeightField::new(d.rows, d.cols, d.heights, d.dx, d.dz)?;
            if h.local_aabb != d.local_aabb {
                return Err(CaromError::invalid(
                    "local_aabb",
                    d.local_aabb,
                    "inconsistent with the heights",
                ));
            }
            Ok(h)
        })())
    }
}

impl HeightField {
    /// A heightfield of `rows × cols` samples (each at least 2), `heights` row-major
    /// (finite), cell sizes `dx` (along X) and `dz` (along Z), finite and > 0.
    pub fn new(rows: usize, cols: usize, heights: Vec<Real>, dx: Real, dz: Real) -> Result<Self> {
        if rows < 2 || cols < 2 {
            return Err(CaromError::invalid(
                "rows x cols",
                (rows, cols),
                "a heightfield needs at least 2 x 2 samples",
            ));
        }
        let n = rows
            .checked_mul(cols)
            .filter(|&n| n / 2 < u32::MAX as usize / 2);
        if n != Some(heights.len()) {
            return Err(CaromError::invalid(
                "heights.len()",
                heights.len(),
                format!("must equal rows x cols = {rows} x {cols}, below 2^31 triangles"),
            ));
        }
        check_positive("dx", dx)?;
        check_positive("dz", dz)?;
        for (i, &h) in heights.iter().enumerate() {
            check_finite(&format!("heights[{i}]"), h)?;
        }
        let (lo, hi) = heights
            .iter()
            .fold((Real::INFINITY, Real::NEG_INFINITY), |(lo, hi), &h| {
                (lo.min(h), hi.max(h))
            });
        let half = Vec3::new((cols - 1) as Real * dx, 0.0, (rows - 1) as Real * dz) * 0.5;
        let local_aabb = Aabb::new(
            Vec3::new(-half.x, lo, -half.z),
            Vec3::new(half.x, hi, half.z),
        );
        Ok(HeightField {
            rows,
            cols,
            heights,
            dx,
            dz,
            local_aabb,
        })
    }

    /// Number of sample rows (along Z).
    pub fn rows(&self) -> usize {
        self.rows
    }

    /// Number of sample columns (along X).
    pub fn cols(&self) -> usize {
        self.cols
    }

    /// Cell sizes `(dx, dz)`.
    pub fn cell_size(&self) -> (Real, Real) {
        (self.dx, self.dz)
    }

    /// The heights, row-major.
    pub fn heights(&self) -> &[Real] {
        &self.heights
    }

    /// Number of triangles (`2 (rows-1) (cols-1)`).
    pub fn num_triangles(&self) -> usize {
        2 * (self.rows - 1) * (self.cols - 1)
    }

    /// The sample point `(r, c)`.
    #[inline]
    pub fn point(&self, r: usize, c: usize) -> Vec3 {
        Vec3::new(
            self.local_aabb.min.x + c as Real * self.dx,
            self.heights[r * self.cols + c],
            self.local_aabb.min.z + r as Real * self.dz,
        )
    }

    /// The corners of triangle `i` (see the type's documentation for the numbering).
    #[inline]
    pub fn triangle(&self, i: usize) -> [Vec3; 3] {
        let cell = i / 2;
        let (r, c) = (cell / (self.cols - 1), cell % (self.cols - 1));
        if i.is_multiple_of(2) {
            [self.point(r, c), self.point(r + 1, c), self.point(r, c + 1)]
        } else {
            [
                self.point(r, c + 1),
                self.point(r + 1, c),
                self.point(r + 1, c + 1),
            ]
        }
    }

    /// The triangle across edge `k` (from corner `k` to `k + 1`) of triangle `t`, from the
    /// grid topology, or `None` on the border.
    pub fn triangle_neighbor(&self, t: usize, k: usize) -> Option<usize> {
        let w = self.cols - 1;
        let cell = t / 2;
        let (r, c) = (cell / w, cell % w);
        let even = t.is_multiple_of(2);
        match (even, k) {
            (true, 0) => (c > 0).then(|| 2 * (cell - 1) + 1),
            (true, 1) => Some(t + 1),
            (true, _) => (r > 0).then(|| 2 * (cell - w) + 1),
            (false, 0) => Some(t - 1),
            (false, 1) => (r + 2 < self.rows).then(|| 2 * (cell + w)),
            (false, _) => (c + 1 < w).then(|| 2 * (cell + 1)),
        }
    }

    /// Adjacency and convexity of the three edges of triangle `t` (as
    /// [`crate::shape::TriMesh::edges`] gives them for meshes; flat below
    /// [`DEFAULT_FLAT_ANGLE`]), computed from the grid on demand, for internal-edge correction.
    pub fn triangle_edges(&self, t: usize) -> [MeshEdge; 3] {
        let tri = self.triangle(t);
        let normal = |v: &[Vec3; 3]| (v[1] - v[0]).cross(v[2] - v[0]).normalize_or_zero();
        let n = normal(&tri);
        std::array::from_fn(|k| {
            let Some(o) = self.triangle_neighbor(t, k) else {
                return BOUNDARY_EDGE;
            };
            let other = self.triangle(o);
            let (p0, p1) = (tri[k], tri[(k + 1) % 3]);
            let far = other
                .into_iter()
                .max_by(|a, b| {
                    let da = (*a - p0).cross(p1 - p0).length_squared();
                    let db = (*b - p0).cross(p1 - p0).length_squared();
                    da.total_cmp(&db)
                })
                .unwrap_or(p0);
            classify_edge(n, normal(&other), p0, far, o as u32, DEFAULT_FLAT_ANGLE)
        })
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    /// Heightfields enclose no volume.
    pub fn volume(&self) -> Real {
        0.0
    }

    /// Zero: heightfields are for static bodies.
    pub fn mass_properties(&self, _density: Real) -> MassProperties {
        MassProperties::ZERO
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn layout_and_validation() {
        let h = HeightField::new(3, 4, (0..12).map(|i| i as Real).collect(), 2.0, 1.0).unwrap();
        assert_eq!(h.num_triangles(), 12);
        let b = h.local_aabb();
        assert_eq!(b.min, Vec3::new(-3.0, 0.0, -1.0));
        assert_eq!(b.max, Vec3::new(3.0, 11.0, 1.0));
        assert_eq!(h.point(1, 2), Vec3::new(1.0, 6.0, 0.0));
        for i in 0..h.num_triangles() {
            let [a, b, c] = h.triangle(i);
            assert!((b - a).cross(c - a).y > 0.0, "triangle {i} faces +Y");
        }
        assert!(HeightField::new(1, 4, vec![0.0; 4], 1.0, 1.0).is_err());
        assert!(HeightField::new(2, 2, vec![0.0; 3], 1.0, 1.0).is_err());
        assert!(HeightField::new(2, 2, vec![0.0; 4], 0.0, 1.0).is_err());
        let e = HeightField::new(2, 2, vec![0.0, Real::NAN, 0.0, 0.0], 1.0, 1.0).unwrap_err();
        assert!(e.to_string().contains("heights[1]"));
    }
}
