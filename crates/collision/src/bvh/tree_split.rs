//! Splitting the [`DynamicTree`] pair descents into independent node-pair tasks for a
//! parallel sweep: one breadth-first expansion ([`split_pair_tasks`]) shared by the
//! self-pair sweep and the tree-vs-tree descent, which differ only in the rule that picks
//! the node to split when both nodes of a pair are internal. (The descents are Bullet's
//! `btDbvt::collideTT`; Box2D v3 cuts its pair update into tasks in
//! `b2UpdateBroadPhasePairs`; the breadth-first cut into a task list is ours.)

use super::dynamic_tree::{DynamicTree, Node, NULL};

impl DynamicTree {
    /// Splits the self-pair descent ([`DynamicTree::self_pairs_with`]) at the top levels of
    /// the tree into independent node-pair tasks for [`DynamicTree::self_pairs_from`], for a
    /// parallel sweep. The node pairs are expanded by the descent's own rules (of two
    /// internal nodes, the taller one is split), level by level, until there are at least
    /// `min_tasks` or nothing is left to expand, so the tasks report together exactly the
    /// pairs of the whole descent, each once. The list depends only on the tree, never on
    /// the thread count.
    pub(crate) fn self_pair_tasks(
        &self,
        min_tasks: usize,
        tasks: &mut Vec<(u32, u32)>,
        scratch: &mut Vec<(u32, u32)>,
    ) {
        split_pair_tasks::<true>(
            self,
            self,
            |na, nb| na.height >= nb.height,
            min_tasks,
            tasks,
            scratch,
        );
    }

    /// Splits the tree-vs-tree descent ([`DynamicTree::query_tree_with`] of `self` against
    /// `other`) into independent node-pair tasks for [`DynamicTree::query_tree_from`], like
    /// [`DynamicTree::self_pair_tasks`]: expanded by the descent's rules (of two internal
    /// nodes, the one with the larger box is split), level by level, until there are at
    /// least `min_tasks` or nothing is left to expand. Only node pairs whose boxes intersect
    /// are kept.
    pub(crate) fn tree_pair_tasks(
        &self,
        other: &DynamicTree,
        min_tasks: usize,
        tasks: &mut Vec<(u32, u32)>,
        scratch: &mut Vec<(u32, u32)>,
    ) {
        split_pair_tasks::<false>(
            self,
            other,
            |na, nb| na.aabb.surface_area() >= nb.aabb.surface_area(),
            min_tasks,
            tasks,
            scratch,
        );
    }
}

/// The breadth-first expansion behind [`DynamicTree::self_pair_tasks`] (`SAME_TREE`, with
/// `tree_a` and `tree_b` the same tree) and [`DynamicTree::tree_pair_tasks`]. `tasks` starts
/// as the root pair (dropped when the two roots of distinct trees do not overlap); each
/// round replaces every node pair by its child pairs whose boxes intersect, in order, until
/// there are at least `min_tasks` or no pair was expanded:
/// - in the same tree, a pair `(n, n)` stands for the pairs within `n`'s subtree and becomes
///   `(c1, c1)`, `(c2, c2)` and, if their boxes intersect, `(c1, c2)`; a leaf alone has none;
/// - a leaf pair is kept as it is;
/// - otherwise the internal node of the pair is split, or, when both are internal, the one
///   `split_a(na, nb)` picks (`true`: the first).
fn split_pair_tasks<const SAME_TREE: bool>(
    tree_a: &DynamicTree,
    tree_b: &DynamicTree,
    split_a: impl Fn(&Node, &Node) -> bool,
    min_tasks: usize,
    tasks: &mut Vec<(u32, u32)>,
    scratch: &mut Vec<(u32, u32)>,
) {
    tasks.clear();
    if tree_a.root == NULL || tree_b.root == NULL {
        return;
    }
    let (nodes_a, nodes_b) = (&tree_a.nodes, &tree_b.nodes);
    let overlap = |a: u32, b: u32| {
        nodes_a[a as usize]
            .aabb
            .intersects(&nodes_b[b as usize].aabb)
    };
    // A subtree always has its own pairs to search; two distinct roots only when they meet.
    if !SAME_TREE && !overlap(tree_a.root, tree_b.root) {
        return;
    }
    tasks.push((tree_a.root, tree_b.root));
    while tasks.len() < min_tasks {
        scratch.clear();
        let mut expanded = false;
        for &(a, b) in tasks.iter() {
            let na = &nodes_a[a as usize];
            if SAME_TREE && a == b {
                if !na.is_leaf() {
                    expanded = true;
                    scratch.push((na.child1, na.child1));
                    scratch.push((na.child2, na.child2));
                    if overlap(na.child1, na.child2) {
                        scratch.push((na.child1, na.child2));
                    }
                }
                continue;
            }
            let nb = &nodes_b[b as usize];
            let split_first = match (na.is_leaf(), nb.is_leaf()) {
                (true, true) => {
                    scratch.push((a, b));
                    continue;
                }
                (true, false) => false,
                (false, true) => true,
                (false, false) => split_a(na, nb),
            };
            expanded = true;
            let pairs = if split_first {
                [(na.child1, b), (na.child2, b)]
            } else {
                [(a, nb.child1), (a, nb.child2)]
            };
            for (x, y) in pairs {
                if overlap(x, y) {
                    scratch.push((x, y));
                }
            }
        }
        std::mem::swap(tasks, scratch);
        if !expanded {
            break;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bvh::InsertStrategy;
    use crate::math::{Aabb, Real, Vec3};

    /// The self-pair splitter as it was before the merge (the oracle).
    fn old_self_pair_tasks(t: &DynamicTree, min_tasks: usize) -> Vec<(u32, u32)> {
        let mut tasks = Vec::new();
        let mut scratch = Vec::new();
        if t.root == NULL {
            return tasks;
        }
        tasks.push((t.root, t.root));
        let nodes = &t.nodes;
        while tasks.len() < min_tasks {
            scratch.clear();
            let mut expanded = false;
            let overlap =
                |a: u32, b: u32| nodes[a as usize].aabb.intersects(&nodes[b as usize].aabb);
            for &(a, b) in tasks.iter() {
                let na = &nodes[a as usize];
                if a == b {
                    if !na.is_leaf() {
                        expanded = true;
                        scratch.push((na.child1, na.child1));
                        scratch.push((na.child2, na.child2));
                        if overlap(na.child1, na.child2) {
                            scratch.push((na.child1, na.child2));
                        }
                    }
                    continue;
                }
                let nb = &nodes[b as usize];
                let split_a = match (na.is_leaf(), nb.is_leaf()) {
                    (true, true) => {
                        scratch.push((a, b));
                        continue;
                    }
                    (true, false) => false,
                    (false, true) => true,
                    (false, false) => na.height >= nb.height,
                };
                expanded = true;
                let pairs = if split_a {
                    [(na.child1, b), (na.child2, b)]
                } else {
                    [(a, nb.child1), (a, nb.child2)]
                };
                for (x, y) in pairs {
                    if overlap(x, y) {
                        scratch.push((x, y));
                    }
                }
            }
            std::mem::swap(&mut tasks, &mut scratch);
            if !expanded {
                break;
            }
        }
        tasks
    }

    /// The tree-vs-tree splitter as it was before the merge (the oracle).
    fn old_tree_pair_tasks(t: &DynamicTree, o: &DynamicTree, min: usize) -> Vec<(u32, u32)> {
        let mut tasks = Vec::new();
        let mut scratch = Vec::new();
        if t.root == NULL || o.root == NULL {
            return tasks;
        }
        let overlap = |a: u32, b: u32| {
            t.nodes[a as usize]
                .aabb
                .intersects(&o.nodes[b as usize].aabb)
        };
        if !overlap(t.root, o.root) {
            return tasks;
        }
        tasks.push((t.root, o.root));
        while tasks.len() < min {
            scratch.clear();
            let mut expanded = false;
            for &(a, b) in tasks.iter() {
                let (na, nb) = (&t.nodes[a as usize], &o.nodes[b as usize]);
                let split_a = match (na.is_leaf(), nb.is_leaf()) {
                    (true, true) => {
                        scratch.push((a, b));
                        continue;
                    }
                    (true, false) => false,
                    (false, true) => true,
                    (false, false) => na.aabb.surface_area() >= nb.aabb.surface_area(),
                };
                expanded = true;
                let pairs = if split_a {
                    [(na.child1, b), (na.child2, b)]
                } else {
                    [(a, nb.child1), (a, nb.child2)]
                };
                for (x, y) in pairs {
                    if overlap(x, y) {
                        scratch.push((x, y));
                    }
                }
            }
            std::mem::swap(&mut tasks, &mut scratch);
            if !expanded {
                break;
            }
        }
        tasks
    }

    /// A tree over `n` boxes from a seeded generator: centres in a cube of side `spread`
    /// around `origin`, half extents up to `size` (zero-size boxes when `size == 0`).
    fn tree(seed: u64, n: usize, origin: Vec3, spread: Real, size: Real) -> DynamicTree {
        let mut s = seed;
        let mut next = || {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            ((s >> 33) as f64 / (1u64 << 31) as f64) as Real
        };
        let strategy = if seed.is_multiple_of(2) {
            InsertStrategy::SurfaceArea
        } else {
            InsertStrategy::Manhattan
        };
        let mut t = DynamicTree::new(strategy, 0.05);
        for i in 0..n {
            let c = origin + Vec3::new(next(), next(), next()) * spread;
            let h = Vec3::new(next(), next(), next()) * size;
            t.create_proxy(Aabb::from_center_half_extents(c, h), i as u32)
                .unwrap();
        }
        t
    }

    /// Trees of many shapes: empty, one leaf, coincident and zero-size boxes, sparse and
    /// dense clouds, touching rows, far from the origin.
    fn trees() -> Vec<DynamicTree> {
        let far = Vec3::new(1.0e5, -2.0e5, 3.0e5);
        let mut touching = DynamicTree::new(InsertStrategy::SurfaceArea, 0.0);
        for i in 0..40 {
            let c = Vec3::new(i as Real, 0.0, 0.0);
            let b = Aabb::from_center_half_extents(c, Vec3::splat(0.5));
            touching.create_proxy(b, i).unwrap();
        }
        vec![
            tree(0, 0, Vec3::ZERO, 1.0, 1.0),
            tree(1, 1, Vec3::ZERO, 1.0, 1.0),
            tree(2, 2, Vec3::ZERO, 0.0, 0.5),
            tree(3, 30, Vec3::ZERO, 0.0, 0.0),
            tree(4, 200, Vec3::ZERO, 20.0, 0.5),
            tree(5, 300, Vec3::ZERO, 60.0, 2.0),
            tree(6, 500, Vec3::ZERO, 8.0, 1.0),
            tree(7, 150, far, 10.0, 0.0),
            tree(8, 257, far, 30.0, 1.5),
            touching,
        ]
    }

    #[test]
    fn split_tasks_match_the_old_splitters() {
        let trees = trees();
        let (mut tasks, mut scratch) = (Vec::new(), Vec::new());
        let mut nonempty = 0;
        for a in &trees {
            for min in [0, 1, 2, 3, 7, 32, 100, 10_000] {
                a.self_pair_tasks(min, &mut tasks, &mut scratch);
                assert_eq!(tasks, old_self_pair_tasks(a, min), "self, min {min}");
                for b in &trees {
                    a.tree_pair_tasks(b, min, &mut tasks, &mut scratch);
                    assert_eq!(tasks, old_tree_pair_tasks(a, b, min), "cross, min {min}");
                    nonempty += usize::from(tasks.len() > 1);
                }
            }
        }
        // The comparison covered real splits, not only trivial lists.
        assert!(nonempty > 100, "{nonempty}");
    }

    #[test]
    fn split_tasks_report_every_pair_once() {
        // Against the brute-force pair sets: the tasks' descents together report every
        // overlapping pair exactly once.
        let trees = trees();
        let (mut tasks, mut scratch, mut stack) = (Vec::new(), Vec::new(), Vec::new());
        let leaves = |t: &DynamicTree| -> Vec<(u32, Aabb)> {
            let mut v: Vec<_> = (0..t.nodes.len())
                .filter(|&i| t.nodes[i].height == 0)
                .map(|i| (t.nodes[i].user, t.nodes[i].aabb))
                .collect();
            v.sort_by_key(|l| l.0);
            v
        };
        for a in &trees {
            let la = leaves(a);
            let mut want = Vec::new();
            for (i, (ua, ba)) in la.iter().enumerate() {
                for (ub, bb) in &la[i + 1..] {
                    if ba.intersects(bb) {
                        want.push((*ua.min(ub), *ua.max(ub)));
                    }
                }
            }
            want.sort_unstable();
            for min in [1, 5, 32, 10_000] {
                a.self_pair_tasks(min, &mut tasks, &mut scratch);
                let mut got = Vec::new();
                for &t in &tasks {
                    a.self_pairs_from(t, &mut stack, |x, y| got.push((x.min(y), x.max(y))));
                }
                got.sort_unstable();
                assert_eq!(got, want, "self, min {min}");
            }
            for b in &trees {
                let lb = leaves(b);
                let mut want = Vec::new();
                for (ua, ba) in &la {
                    for (ub, bb) in &lb {
                        if ba.intersects(bb) {
                            want.push((*ua, *ub));
                        }
                    }
                }
                want.sort_unstable();
                for min in [1, 5, 32] {
                    a.tree_pair_tasks(b, min, &mut tasks, &mut scratch);
                    let mut got = Vec::new();
                    for &t in &tasks {
                        a.query_tree_from(b, t, &mut stack, |x, y| got.push((x, y)));
                    }
                    got.sort_unstable();
                    assert_eq!(got, want, "cross, min {min}");
                }
            }
        }
    }
}
