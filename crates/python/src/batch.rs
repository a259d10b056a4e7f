//! Batch evaluation of per-item queries, in parallel (rayon) above a size threshold.
//!
//! Callers release the GIL (`py.detach`) around these functions: they only touch Rust data.
//! Results keep the input order, so they do not depend on the thread count.

use carom_collision::math::{Aabb, Isometry, Vec3};
use carom_collision::shape::{Shape, SupportMap};
use carom_collision::Result;
use rayon::prelude::*;

/// Batches at least this long are split across threads.
pub const PARALLEL_MIN: usize = 2048;

/// `f` applied to every item, in order.
pub fn map<T: Sync, U: Send>(items: &[T], f: impl Fn(&T) -> U + Sync + Send) -> Vec<U> {
    if items.len() >= PARALLEL_MIN {
        items.par_iter().map(f).collect()
    } else {
        items.iter().map(f).collect()
    }
}

/// Support points of a convex shape for every direction, in the shape's frame, or in the
/// world when `pose` is given (`dirs` are then world directions). With `core_only`, the
/// support of the core shape (without margin).
pub fn support_points(
    shape: &Shape,
    dirs: &[Vec3],
    pose: Option<Isometry>,
    core_only: bool,
) -> Result<Vec<Vec3>> {
    let what = if core_only { "support_core" } else { "support" };
    let convex = shape.require_convex(what)?;
    let local = |d: Vec3| {
        if core_only {
            convex.support_core(d)
        } else {
            convex.support(d)
        }
    };
    Ok(match pose {
        None => map(dirs, |d| local(*d)),
        Some(p) => map(dirs, |d| {
            p.transform_point(local(p.inverse_transform_vector(*d)))
        }),
    })
}

/// World bounding boxes of a shape at every pose.
pub fn aabbs(shape: &Shape, poses: &[Isometry]) -> Vec<Aabb> {
    map(poses, |p| shape.aabb(p))
}
