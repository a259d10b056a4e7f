//! Bounding-volume hierarchies: the spatial data structures every later stage shares.
//!
//! - [`Bvh`]: a static, stackless BVH with quantised 16-byte nodes (or unquantised ones),
//!   binned-SAH build, refit, and its traversals (box, ray, point, BVH-vs-BVH). Triangle
//!   meshes own one; the midphase's triangle queries run on it. The layout is Bullet's
//!   `btQuantizedBvh` as presented in Coumans' SIGGRAPH 2010 talk. The quantised layout also
//!   keeps its tree collapsed to 4-wide nodes ([`WideNode`], one cache line each) for
//!   closest-hit rays.
//! - [`DynamicTree`]: the incrementally updated AABB tree of Bullet's `btDbvt` and Box2D's
//!   `b2DynamicTree`. The tree broadphase is built on it, and compound shapes keep their
//!   children in one (Bullet's `btCompoundShape`), so children can be added, moved and removed.
//!   [`WideTree`] is its 4-wide copy for batches of box queries (the broadphase's moved proxies).
//!
//! The module sits right after `math` and before `shape`: shapes own hierarchies, and both
//! the broadphase and the midphase query them, so the structures cannot live in either.

mod build;
mod dynamic_tree;
mod pair;
mod quantize;
#[cfg(test)]
mod refit_tests;
mod static_bvh;
mod traverse;
mod tree_insert;
mod tree_query;
mod tree_split;
mod tree_validate;
mod tree_wide;
mod wide;

pub use build::{MAX_LEAF_SIZE, NUM_BINS};
pub use dynamic_tree::{DynamicTree, InsertStrategy, TreeProxy};
pub use quantize::Quantization;
pub use static_bvh::{Bvh, BvhLayout, QuantizedNode, UnquantizedNode, MAX_PRIMITIVES};
pub use tree_query::HalfSpace;
pub use tree_wide::WideTree;
pub use wide::{WideNode, WideRealNode};
