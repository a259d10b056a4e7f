//! Compound shape: child shapes at local poses, kept in a dynamic AABB tree
//! ([`crate::bvh::DynamicTree`]) over the children's boxes, as Bullet's `btCompoundShape`
//! keeps a `btDbvt`. Children can be added, moved and removed; the child-overlap queries are
//! in `midphase::compound_query`.

use super::{MassProperties, Shape};
use crate::bvh::{DynamicTree, InsertStrategy, TreeProxy};
use crate::error::{CaromError, Result};
use crate::math::{check_isometry, Aabb, Isometry, Real, Vec3};
use serde::{Deserialize, Serialize};
use std::sync::Arc;

/// A rigid assembly of child shapes, each at a pose in the compound's frame.
///
/// Child `i` is `children()[i]`; its leaf in the tree carries `i` as user data. Removing a
/// child moves the last child into its index (as `Vec::swap_remove`).
#[derive(Debug, Clone, Serialize, Deserialize)]
#[serde(try_from = "CompoundData", into = "CompoundData")]
pub struct Compound {
    children: Vec<(Isometry, Arc<Shape>)>,
    child_aabbs: Vec<Aabb>,
    proxies: Vec<TreeProxy>,
    tree: DynamicTree,
    local_aabb: Aabb,
}

/// The serialised form of a [`Compound`]: its children only (the tree is rebuilt, and the
/// children are validated again, on loading).
#[derive(Serialize, Deserialize)]
struct CompoundData {
    children: Vec<(Isometry, Arc<Shape>)>,
}

impl TryFrom<CompoundData> for Compound {
    type Error = CaromError;
    fn try_from(d: CompoundData) -> Result<Self> {
        super::serde_check::record(Compound::new(d.children))
    }
}

impl From<Compound> for CompoundData {
    fn from(c: Compound) -> Self {
        CompoundData {
            children: c.children,
        }
    }
}

impl PartialEq for Compound {
    /// Compounds are equal when their children (poses and shapes, in order) are.
    fn eq(&self, other: &Self) -> bool {
        self.children == other.children
    }
}

/// Checks one child: valid pose, and not a plane (unbounded).
fn check_child(i: usize, pose: Isometry, shape: &Shape) -> Result<Isometry> {
    let pose = check_isometry(&format!("children[{i}].pose"), pose)?;
    if matches!(*shape, Shape::Plane(_)) {
        return Err(CaromError::Unsupported(format!(
            "children[{i}] is a plane: planes cannot be compound children"
        )));
    }
    Ok(pose)
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
        let mut c = Compound {
            children: Vec::with_capacity(children.len()),
            child_aabbs: Vec::with_capacity(children.len()),
            proxies: Vec::with_capacity(children.len()),
            // Exact leaf boxes (no margin): children move only through explicit edits.
            tree: DynamicTree::new(InsertStrategy::SurfaceArea, 0.0),
            local_aabb: Aabb::new(Vec3::ZERO, Vec3::ZERO),
        };
        for (pose, shape) in children {
            c.add_child(pose, shape)?;
        }
        Ok(c)
    }

    /// Adds a child at `pose` and returns its index (the previous number of children).
    pub fn add_child(&mut self, pose: Isometry, shape: Arc<Shape>) -> Result<u32> {
        let i = self.children.len();
        let pose = check_child(i, pose, &shape)?;
        let aabb = shape.aabb(&pose);
        let proxy = self.tree.create_proxy(aabb, i as u32)?;
        self.local_aabb = if i == 0 {
            aabb
        } else {
            self.local_aabb.merge(&aabb)
        };
        self.children.push((pose, shape));
        self.child_aabbs.push(aabb);
        self.proxies.push(proxy);
        Ok(i as u32)
    }

    /// Removes child `index` and returns it; the last child takes its index. The last
    /// remaining child cannot be removed (a compound is never empty).
    pub fn remove_child(&mut self, index: u32) -> Result<(Isometry, Arc<Shape>)> {
        let i = self.check_index(index)?;
        if self.children.len() == 1 {
            return Err(CaromError::invalid(
                "index",
                index,
                "cannot remove the only child: a compound needs at least one child",
            ));
        }
        self.tree.destroy_proxy(self.proxies[i])?;
        let last = self.children.len() - 1;
        if i != last {
            self.tree.set_user(self.proxies[last], i as u32)?;
        }
        self.proxies.swap_remove(i);
        self.child_aabbs.swap_remove(i);
        let removed = self.children.swap_remove(i);
        self.recompute_bounds();
        Ok(removed)
    }

    /// Moves child `index` to `pose` (compound frame).
    pub fn set_child_pose(&mut self, index: u32, pose: Isometry) -> Result<()> {
        let i = self.check_index(index)?;
        let pose = check_child(i, pose, &self.children[i].1)?;
        let aabb = self.children[i].1.aabb(&pose);
        self.tree.move_proxy(self.proxies[i], aabb, Vec3::ZERO)?;
        self.children[i].0 = pose;
        self.child_aabbs[i] = aabb;
        self.recompute_bounds();
        Ok(())
    }

    fn check_index(&self, index: u32) -> Result<usize> {
        if (index as usize) < self.children.len() {
            Ok(index as usize)
        } else {
            Err(CaromError::invalid(
                "index",
                index,
                format!(
                    "must be below the number of children, {}",
                    self.children.len()
                ),
            ))
        }
    }

    fn recompute_bounds(&mut self) {
        self.local_aabb = self.child_aabbs[1..]
            .iter()
            .fold(self.child_aabbs[0], |acc, b| acc.merge(b));
    }

    /// The children and their poses.
    pub fn children(&self) -> &[(Isometry, Arc<Shape>)] {
        &self.children
    }

    /// Bounding box of each child in the compound's frame.
    pub fn child_aabbs(&self) -> &[Aabb] {
        &self.child_aabbs
    }

    /// The dynamic tree over the children's boxes (leaf user data `i` is child `i`).
    pub fn tree(&self) -> &DynamicTree {
        &self.tree
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
