//! The invariant checker of the [`DynamicTree`], used by the tests after every operation
//! (as Box2D's `b2DynamicTree_Validate` and parry's `bvh_validation.rs`).

use super::dynamic_tree::{DynamicTree, NULL};

impl DynamicTree {
    /// Checks every structural invariant and returns a description of the first violation:
    /// parent links match child links, every parent's box contains its children's, heights are
    /// `1 + max(children)` (leaves 0), every node is either reachable from the root or on the
    /// free list (free nodes have height -1), and the leaf count matches.
    pub fn validate(&self) -> Result<(), String> {
        let mut seen = vec![false; self.nodes.len()];
        let mut leaves = 0usize;
        if self.root != NULL {
            if self.nodes[self.root as usize].parent != NULL {
                return Err("root has a parent".into());
            }
            let mut stack = vec![self.root];
            while let Some(i) = stack.pop() {
                let iu = i as usize;
                if iu >= self.nodes.len() {
                    return Err(format!("node index {i} out of range"));
                }
                if seen[iu] {
                    return Err(format!("node {i} reached twice (cycle or shared child)"));
                }
                seen[iu] = true;
                let n = &self.nodes[iu];
                if n.is_leaf() {
                    if n.child2 != NULL || n.height != 0 {
                        return Err(format!("leaf {i}: child2 {} height {}", n.child2, n.height));
                    }
                    leaves += 1;
                    continue;
                }
                for c in [n.child1, n.child2] {
                    let Some(cn) = self.nodes.get(c as usize) else {
                        return Err(format!("node {i}: child {c} out of range"));
                    };
                    if cn.parent != i {
                        return Err(format!(
                            "node {c}: parent {} but is child of {i}",
                            cn.parent
                        ));
                    }
                    if !n.aabb.contains(&cn.aabb) {
                        return Err(format!("node {i} does not contain child {c}"));
                    }
                    stack.push(c);
                }
                let (h1, h2) = (
                    self.nodes[n.child1 as usize].height,
                    self.nodes[n.child2 as usize].height,
                );
                if n.height != 1 + h1.max(h2) {
                    return Err(format!(
                        "node {i}: height {} vs children {h1}, {h2}",
                        n.height
                    ));
                }
            }
        }
        if leaves != self.leaf_count {
            return Err(format!(
                "leaf count {} but {leaves} reachable",
                self.leaf_count
            ));
        }
        let mut f = self.free_list;
        let mut free = 0usize;
        while f != NULL {
            let fu = f as usize;
            if fu >= self.nodes.len() || seen[fu] {
                return Err(format!("free list node {f} invalid or reachable"));
            }
            if self.nodes[fu].height != -1 {
                return Err(format!(
                    "free node {f} has height {}",
                    self.nodes[fu].height
                ));
            }
            seen[fu] = true;
            free += 1;
            f = self.nodes[fu].parent;
        }
        let reachable = seen.iter().filter(|&&s| s).count();
        if reachable != self.nodes.len() {
            return Err(format!(
                "{} nodes neither in the tree nor free ({free} free)",
                self.nodes.len() - reachable
            ));
        }
        Ok(())
    }
}
