//! Compound shape: child shapes at local poses, with a static BVH over the children's boxes
//! ([`crate::bvh::Bvh`]) for child-overlap queries (`midphase::compound_query`).

use super::{MassProperties, Shape};
use crate::bvh::{Bvh, BvhLayout};
use crate::error::{CaromError, Result};
use crate::math::{check_isometry, Aabb, Isometry, Real};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A rigid assembly of child shapes, each at a pose in the compound's frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Compound {
    children: Vec<(Isometry, Arc<Shape>)>,
    child_aabbs: Vec<Aabb>,
    bvh: Bvh,
    local_aabb: Aabb,
}

impl Compound {
    /// A compound; needs at least one child, valid poses, and no planes (unbounded).
    pub fn new(children: Vec<(Isometry, Arc<Shape>)>) -> Result<Self> {
        if children.is_empty() {
            return Err(CaromError::invalid(
                "children",
                0usize,
                "a compound needs at least one child",
            ));
        }
        let mut checked = Vec::with_capacity(children.len());
        for (i, (pose, shape)) in children.into_iter().enumerate() {
            let pose = check_isometry(&format!("children[{i}].pose"), pose)?;
            if matches!(*shape, Shape::Plane(_)) {
                return Err(CaromError::Unsupported(format!(
                    "children[{i}] is a plane: planes cannot be compound children"
                )));
            }
            checked.push((pose, shape));
        }
        let child_aabbs: Vec<Aabb> = checked.iter().map(|(pose, s)| s.aabb(pose)).collect();
        let bvh = Bvh::new(&child_aabbs, BvhLayout::Unquantized)?;
        Ok(Compound {
            children: checked,
            local_aabb: bvh.root_aabb(),
            child_aabbs,
            bvh,
        })
    }

    /// The children and their poses.
    pub fn children(&self) -> &[(Isometry, Arc<Shape>)] {
        &self.children
    }

    /// Bounding box of each child in the compound's frame.
    pub fn child_aabbs(&self) -> &[Aabb] {
        &self.child_aabbs
    }

    /// The BVH over the children's boxes (primitive `i` is child `i`).
    pub fn bvh(&self) -> &Bvh {
        &self.bvh
    }

    /// Local bounding box.
    pub fn local_aabb(&self) -> Aabb {
        self.local_aabb
    }

    /// Sum of the children's volumes (overlaps are counted twice).
    pub fn volume(&self) -> Real {
        self.children.iter().map(|(_, s)| s.volume()).sum()
    }

    /// Combined mass properties (overlaps counted twice), about the combined centre of mass.
    pub fn mass_properties(&self, density: Real) -> MassProperties {
        let parts: Vec<MassProperties> = self
            .children
            .iter()
            .map(|(pose, s)| s.mass_properties(density).transformed(pose))
            .collect();
        MassProperties::sum(parts.iter())
    }
}
