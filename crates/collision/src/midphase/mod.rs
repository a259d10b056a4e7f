//! Midphase: which triangles of a mesh (or children of a compound, cells of a heightfield)
//! can touch a query, following Coumans' SIGGRAPH 2010 talk ("Midphase culling: detect
//! overlapping triangles (trimesh), detect overlapping child shapes (compound)").
//!
//! - Triangle queries over a mesh's [`Bvh`] ([`MeshView`], and the methods of
//!   [`crate::shape::TriMesh`]): box overlap, rays (closest, any, all), closest point,
//!   mesh-vs-mesh triangle pairs.
//! - Heightfield queries (the grid is its own structure) and compound child queries.
//!
//! The hierarchies themselves live in [`crate::bvh`] (re-exported here); this module comes
//! right after `shape` and before `query`, whose ray casts and point projections on meshes
//! and heightfields use these traversals.

mod compound_query;
mod heightfield_query;
mod mesh_query;
mod triangle_query;
mod triangle_source;
mod trimesh_query;

pub use crate::bvh::{
    Bvh, BvhLayout, Quantization, QuantizedNode, UnquantizedNode, WideNode, WideRealNode,
    MAX_LEAF_SIZE, MAX_PRIMITIVES, NUM_BINS,
};
pub use crate::shape::triangle_aabbs;
pub use compound_query::{
    brute_force_child_pairs, brute_force_children_in_aabb, child_pair_overlaps,
};
pub use mesh_query::{brute_force, MeshPointProjection, MeshRayHit, MeshView};
pub use triangle_query::{closest_point_on_triangle, ray_triangle, TriangleRayHit, WatertightRay};
pub use triangle_source::TriangleSource;
