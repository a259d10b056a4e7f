//! Midphase: which triangles of a mesh (or children of a compound, cells of a heightfield)
//! can touch a query, following Coumans' SIGGRAPH 2010 talk ("Midphase culling: detect
//! overlapping triangles (trimesh), detect overlapping child shapes (compound)").
//!
//! - [`Bvh`]: a static, stackless BVH with quantised 16-byte nodes (or unquantised ones),
//!   binned-SAH build and refit.
//! - Triangle queries over a BVH: box overlap, rays (closest, any, all), closest point,
//!   mesh-vs-mesh triangle pairs.

mod build;
mod bvh;
mod mesh_query;
mod pair;
mod traverse;
mod triangle_query;

pub use build::{MAX_LEAF_SIZE, NUM_BINS};
pub use bvh::{Bvh, BvhLayout, Quantization, QuantizedNode, UnquantizedNode, MAX_PRIMITIVES};
pub use mesh_query::{brute_force, triangle_aabbs, MeshPointProjection, MeshRayHit, MeshView};
pub use triangle_query::{closest_point_on_triangle, ray_triangle, TriangleRayHit, WatertightRay};
