//! A hull's vertices in structure-of-arrays blocks of four lanes, for the support scan.
//!
//! GJK and EPA spend most of their time in support queries; on a hull of up to
//! [`super::ConvexHull::HILL_CLIMB_MIN_VERTICES`] vertices a query is a scan for the largest
//! dot product. Four vertices per step (`wide`'s `f32x4`, or `f64x4` in the f64 build) cut
//! the scan's instructions about fourfold. The dot products are evaluated in the same order
//! as `Vec3::dot` (`x·dx + y·dy + z·dz`, no fused multiply-add), and ties go to the lowest
//! index, so the answer is the scalar scan's whenever the dot products are finite.

use crate::math::{Real, Vec3};

/// Maps the scalar type to its four-lane vector.
pub(crate) trait Lanes {
    /// Four lanes of `Self`.
    type W;
}

impl Lanes for f32 {
    type W = wide::f32x4;
}

impl Lanes for f64 {
    type W = wide::f64x4;
}

/// Four lanes of [`Real`].
type W = <Real as Lanes>::W;

/// Four vertices, one per lane; the last block is padded with copies of vertex 0 (whose
/// dot product then ties with vertex 0's, so a padding lane never wins).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Block {
    x: W,
    y: W,
    z: W,
}

/// The vertices as blocks of four (see [`Block`]).
pub(crate) fn blocks(vertices: &[Vec3]) -> Vec<Block> {
    let first = vertices.first().copied().unwrap_or(Vec3::ZERO);
    vertices
        .chunks(4)
        .map(|c| {
            let v = |l: usize| c.get(l).copied().unwrap_or(first);
            let lanes = [v(0), v(1), v(2), v(3)];
            Block {
                x: W::new(lanes.map(|p| p.x)),
                y: W::new(lanes.map(|p| p.y)),
                z: W::new(lanes.map(|p| p.z)),
            }
        })
        .collect()
}

/// The index of the vertex with the largest `v · dir`, the first one on ties (vertex 0 for
/// a zero or NaN `dir`): the scalar scan's answer, four vertices at a time.
#[inline]
pub(crate) fn support_index(blocks: &[Block], dir: Vec3) -> usize {
    let (dx, dy, dz) = (W::splat(dir.x), W::splat(dir.y), W::splat(dir.z));
    let Some((b0, rest)) = blocks.split_first() else {
        return 0;
    };
    let mut best = b0.x * dx + b0.y * dy + b0.z * dz;
    let mut best_idx = W::new([0.0, 1.0, 2.0, 3.0]);
    let mut idx = best_idx;
    let four = W::splat(4.0);
    for b in rest {
        idx += four;
        let d = b.x * dx + b.y * dy + b.z * dz;
        // Strictly greater: within a lane the earliest index keeps a tie.
        let gt = d.simd_gt(best);
        best = gt.bitselect(d, best);
        best_idx = gt.bitselect(idx, best_idx);
    }
    let (v, i) = (best.to_array(), best_idx.to_array());
    let mut k = 0;
    for l in 1..4 {
        if v[l] > v[k] || (v[l] == v[k] && i[l] < i[k]) {
            k = l;
        }
    }
    i[k] as usize
}

/// The box of the vertices rotated by the matrix with columns `cx`, `cy`, `cz` (the
/// rotation of a pose), as `(min, max)`: the world box of a hull about its translation, four
/// vertices per step. Each coordinate is evaluated as `cx[i]·x + cy[i]·y + cz[i]·z` in that
/// order, as `Mat3 * Vec3` does, so the box is the scalar scan's bit for bit; padding lanes
/// repeat vertex 0, which changes no extreme.
#[inline]
pub(crate) fn rotated_bounds(blocks: &[Block], cx: Vec3, cy: Vec3, cz: Vec3) -> (Vec3, Vec3) {
    let rows = [
        (W::splat(cx.x), W::splat(cy.x), W::splat(cz.x)),
        (W::splat(cx.y), W::splat(cy.y), W::splat(cz.y)),
        (W::splat(cx.z), W::splat(cy.z), W::splat(cz.z)),
    ];
    let mut lo = [W::splat(Real::INFINITY); 3];
    let mut hi = [W::splat(Real::NEG_INFINITY); 3];
    for b in blocks {
        for k in 0..3 {
            let (a, c, d) = rows[k];
            let p = a * b.x + c * b.y + d * b.z;
            lo[k] = lo[k].fast_min(p);
            hi[k] = hi[k].fast_max(p);
        }
    }
    let reduce =
        |v: W, f: fn(Real, Real) -> Real| v.to_array().into_iter().reduce(f).unwrap_or(0.0);
    (
        Vec3::new(
            reduce(lo[0], Real::min),
            reduce(lo[1], Real::min),
            reduce(lo[2], Real::min),
        ),
        Vec3::new(
            reduce(hi[0], Real::max),
            reduce(hi[1], Real::max),
            reduce(hi[2], Real::max),
        ),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The scalar scan: the first vertex with the largest dot product.
    fn scalar(v: &[Vec3], dir: Vec3) -> usize {
        let mut best = 0;
        for (i, p) in v.iter().enumerate().skip(1) {
            if p.dot(dir) > v[best].dot(dir) {
                best = i;
            }
        }
        best
    }

    #[test]
    fn lanes_agree_with_the_scalar_scan_ties_included() {
        // A seeded cloud (every count 1..=13, so every padding), plus ties: duplicated
        // points, a cube (faces and edges tie along the axes), and far from the origin.
        let mut s = 0x1234_5678_u64;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 11) as f64 / (1u64 << 53) as f64) as Real * 2.0 - 1.0
        };
        let cube: Vec<Vec3> = (0..8)
            .map(|i| Vec3::new((i & 1) as Real, ((i >> 1) & 1) as Real, (i >> 2) as Real))
            .collect();
        let mut clouds = vec![
            cube.clone(),
            cube.iter().map(|p| *p + Vec3::splat(1000.0)).collect(),
        ];
        for n in 1..=13 {
            let mut c: Vec<Vec3> = (0..n).map(|_| Vec3::new(next(), next(), next())).collect();
            c.push(c[n / 2]);
            clouds.push(c);
        }
        let mut dirs = vec![
            Vec3::ZERO,
            Vec3::X,
            -Vec3::Y,
            Vec3::Z,
            Vec3::ONE,
            Vec3::new(1.0, 1.0, 0.0),
        ];
        dirs.extend((0..50).map(|_| Vec3::new(next(), next(), next())));
        for c in &clouds {
            let b = blocks(c);
            for &d in &dirs {
                assert_eq!(support_index(&b, d), scalar(c, d), "{c:?} {d:?}");
            }
            assert_eq!(support_index(&b, Vec3::splat(Real::NAN)), 0);
            // The rotated box equals the scalar one bit for bit (every padding count).
            for k in 0..20 {
                let axis = Vec3::new(next(), next(), next()).normalize_or(Vec3::Y);
                let q = crate::math::Quat::from_axis_angle(axis, 3.0 * k as Real);
                let m = crate::math::Mat3::from_quat(q);
                let (mut lo, mut hi) = (Vec3::splat(Real::INFINITY), Vec3::splat(-Real::INFINITY));
                for p in c {
                    let w = m * *p;
                    lo = lo.min(w);
                    hi = hi.max(w);
                }
                assert_eq!(rotated_bounds(&b, m.x_axis, m.y_axis, m.z_axis), (lo, hi));
            }
        }
        assert_eq!(support_index(&[], Vec3::X), 0);
    }
}
