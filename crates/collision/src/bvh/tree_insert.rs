//! Leaf insertion into the [`DynamicTree`]: sibling choice by the Manhattan-distance descent
//! (Bullet's `btDbvt`) or by the surface-area heuristic with branch and bound, and tree
//! rotations (Box2D v3 `b2FindBestSibling`, `b2RotateNodes`; Catto, GDC 2019).

use super::dynamic_tree::{DynamicTree, InsertStrategy, NULL};
use crate::math::{Aabb, Real};

/// Bullet's `Proximity`: Manhattan distance between box centres (times two).
#[inline]
fn proximity(a: &Aabb, b: &Aabb) -> Real {
    let d = (a.min + a.max) - (b.min + b.max);
    d.x.abs() + d.y.abs() + d.z.abs()
}

impl DynamicTree {
    /// Inserts the detached leaf `leaf` (its box already set) into the subtree at `start`
    /// (the root when `start` is the root or `NULL`), then refits up to the root.
    pub(crate) fn insert_leaf(&mut self, leaf: u32, start: u32) {
        if self.root == NULL {
            self.root = leaf;
            self.nodes[leaf as usize].parent = NULL;
            return;
        }
        let start = if start == NULL { self.root } else { start };
        let leaf_box = self.nodes[leaf as usize].aabb;
        let sibling = match self.strategy {
            InsertStrategy::SurfaceArea => self.find_best_sibling(start, &leaf_box),
            InsertStrategy::Manhattan => self.select_manhattan(start, &leaf_box),
        };
        let old_parent = self.nodes[sibling as usize].parent;
        let new_parent = self.allocate_node();
        {
            let sib_box = self.nodes[sibling as usize].aabb;
            let sib_height = self.nodes[sibling as usize].height;
            let p = &mut self.nodes[new_parent as usize];
            p.parent = old_parent;
            p.aabb = leaf_box.merge(&sib_box);
            p.height = sib_height + 1;
            p.child1 = sibling;
            p.child2 = leaf;
            p.user = 0;
        }
        self.nodes[sibling as usize].parent = new_parent;
        self.nodes[leaf as usize].parent = new_parent;
        if old_parent == NULL {
            self.root = new_parent;
        } else {
            let op = &mut self.nodes[old_parent as usize];
            if op.child1 == sibling {
                op.child1 = new_parent;
            } else {
                op.child2 = new_parent;
            }
        }
        let rotate = self.strategy == InsertStrategy::SurfaceArea;
        self.refit_upwards(old_parent, rotate);
    }

    /// The talk's `insertleaf` descent: go to the child nearer in Manhattan distance.
    fn select_manhattan(&self, start: u32, leaf_box: &Aabb) -> u32 {
        let mut index = start;
        while !self.nodes[index as usize].is_leaf() {
            let n = &self.nodes[index as usize];
            let d1 = proximity(leaf_box, &self.nodes[n.child1 as usize].aabb);
            let d2 = proximity(leaf_box, &self.nodes[n.child2 as usize].aabb);
            index = if d1 < d2 { n.child1 } else { n.child2 };
        }
        index
    }

    /// Branch-and-bound search for the sibling minimising the SAH cost of inserting
    /// `leaf_box`: the area of the new parent plus the area growth of every ancestor
    /// ("inherited cost"). A subtree is entered only if its lower bound can beat the best
    /// cost found so far (Box2D v3 `b2FindBestSibling`, with surface area instead of perimeter).
    fn find_best_sibling(&self, start: u32, leaf_box: &Aabb) -> u32 {
        let area_d = leaf_box.surface_area();
        let center_d = leaf_box.center();
        let root_box = self.nodes[start as usize].aabb;
        let mut area_base = root_box.surface_area();
        let mut direct_cost = root_box.merge(leaf_box).surface_area();
        let mut inherited: Real = 0.0;
        let mut best = start;
        let mut best_cost = direct_cost;
        let mut index = start;
        while !self.nodes[index as usize].is_leaf() {
            let n = &self.nodes[index as usize];
            let (c1, c2) = (n.child1, n.child2);
            // Cost of making `index` the sibling.
            let cost = direct_cost + inherited;
            if cost < best_cost {
                best = index;
                best_cost = cost;
            }
            inherited += direct_cost - area_base;

            let child_cost = |c: u32, best: &mut u32, best_cost: &mut Real| {
                let node = &self.nodes[c as usize];
                let direct = node.aabb.merge(leaf_box).surface_area();
                if node.is_leaf() {
                    let cost = direct + inherited;
                    if cost < *best_cost {
                        *best = c;
                        *best_cost = cost;
                    }
                    (true, direct, 0.0, Real::INFINITY)
                } else {
                    let area = node.aabb.surface_area();
                    // Lower bound for any node below c: its direct cost is at least area_d.
                    let lower = inherited + direct + (area_d - area).min(0.0);
                    (false, direct, area, lower)
                }
            };
            let (leaf1, direct1, area1, mut lower1) = child_cost(c1, &mut best, &mut best_cost);
            let (leaf2, direct2, area2, mut lower2) = child_cost(c2, &mut best, &mut best_cost);
            if leaf1 && leaf2 {
                break;
            }
            if best_cost <= lower1 && best_cost <= lower2 {
                break;
            }
            if lower1 == lower2 && !leaf1 {
                // Tie: descend towards the nearer centre.
                lower1 = (self.nodes[c1 as usize].aabb.center() - center_d).length_squared();
                lower2 = (self.nodes[c2 as usize].aabb.center() - center_d).length_squared();
            }
            if lower1 < lower2 && !leaf1 {
                index = c1;
                area_base = area1;
                direct_cost = direct1;
            } else {
                index = c2;
                area_base = area2;
                direct_cost = direct2;
            }
        }
        best
    }

    /// Tree rotation at node `a` (Box2D v3 `b2RotateNodes`): swaps a child of `a` with a
    /// grandchild (or two grandchildren) when that lowers the summed area of the changed
    /// internal nodes. Keeps boxes and heights of `a`'s children exact; the caller refits `a`.
    pub(crate) fn rotate(&mut self, a: u32) {
        let na = self.nodes[a as usize];
        if na.height < 2 {
            return;
        }
        let (b, c) = (na.child1, na.child2);
        let (nb, nc) = (self.nodes[b as usize], self.nodes[c as usize]);
        if nb.height == 0 {
            // Only C can be rotated: swap B with F or G (children of C).
            self.rotate_child_with_grandchild(a, b, c);
        } else if nc.height == 0 {
            self.rotate_child_with_grandchild(a, c, b);
        } else {
            let (d, e) = (nb.child1, nb.child2);
            let (f, g) = (nc.child1, nc.child2);
            let bx = |i: u32| self.nodes[i as usize].aabb;
            let area_b = nb.aabb.surface_area();
            let area_c = nc.aabb.surface_area();
            let base = area_b + area_c;
            // (cost, kind): 1 = B<->F, 2 = B<->G, 3 = C<->D, 4 = C<->E, 5 = D<->F, 6 = D<->G.
            let options = [
                (area_b + bx(b).merge(&bx(g)).surface_area(), 1),
                (area_b + bx(b).merge(&bx(f)).surface_area(), 2),
                (bx(c).merge(&bx(e)).surface_area() + area_c, 3),
                (bx(c).merge(&bx(d)).surface_area() + area_c, 4),
                (
                    bx(f).merge(&bx(e)).surface_area() + bx(d).merge(&bx(g)).surface_area(),
                    5,
                ),
                (
                    bx(g).merge(&bx(e)).surface_area() + bx(f).merge(&bx(d)).surface_area(),
                    6,
                ),
            ];
            let mut best = (base, 0);
            for o in options {
                if o.0 < best.0 {
                    best = o;
                }
            }
            match best.1 {
                1 => self.swap_nodes(b, f),
                2 => self.swap_nodes(b, g),
                3 => self.swap_nodes(c, d),
                4 => self.swap_nodes(c, e),
                5 => self.swap_nodes(d, f),
                6 => self.swap_nodes(d, g),
                _ => return,
            }
            self.refit_node(b);
            self.refit_node(c);
        }
    }

    /// Rotation when `leaf_child` (a child of `a`) is a leaf and `inner` its internal sibling.
    fn rotate_child_with_grandchild(&mut self, _a: u32, leaf_child: u32, inner: u32) {
        let ni = self.nodes[inner as usize];
        let (f, g) = (ni.child1, ni.child2);
        let bx = |i: u32| self.nodes[i as usize].aabb;
        let base = ni.aabb.surface_area();
        let cost_f = bx(leaf_child).merge(&bx(g)).surface_area(); // swap leaf with F
        let cost_g = bx(leaf_child).merge(&bx(f)).surface_area(); // swap leaf with G
        if base <= cost_f && base <= cost_g {
            return;
        }
        if cost_f < cost_g {
            self.swap_nodes(leaf_child, f);
        } else {
            self.swap_nodes(leaf_child, g);
        }
        self.refit_node(inner);
    }

    /// Exchanges the positions of two nodes in different parents (no refit).
    fn swap_nodes(&mut self, x: u32, y: u32) {
        let px = self.nodes[x as usize].parent;
        let py = self.nodes[y as usize].parent;
        debug_assert!(px != py && px != NULL && py != NULL);
        let replace = |n: &mut super::dynamic_tree::Node, old: u32, new: u32| {
            if n.child1 == old {
                n.child1 = new;
            } else {
                n.child2 = new;
            }
        };
        replace(&mut self.nodes[px as usize], x, y);
        replace(&mut self.nodes[py as usize], y, x);
        self.nodes[x as usize].parent = py;
        self.nodes[y as usize].parent = px;
    }

    /// Recomputes the box and height of internal node `i` from its children.
    fn refit_node(&mut self, i: u32) {
        let n = self.nodes[i as usize];
        if n.is_leaf() {
            return;
        }
        let (c1, c2) = (self.nodes[n.child1 as usize], self.nodes[n.child2 as usize]);
        let node = &mut self.nodes[i as usize];
        node.aabb = c1.aabb.merge(&c2.aabb);
        node.height = 1 + c1.height.max(c2.height);
    }
}
