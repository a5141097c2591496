//! The search tree shared by the T-RRT* planners (planar [`crate::planning::planar`], SE(3)
//! [`crate::planning::spatial`]): nodes with their parent, the pusher of the step reaching them, that step's
//! data, and the cumulative edge cost (RSS 2018: 0.1 on the same pusher, 1 on a switch-over, plus
//! the step's length over L); RRT* re-parenting with the subtree's costs shifted; paths.

use std::ops::{Index, IndexMut};

/// A node: pose `q`, the step reaching it (`pusher`, `edge` data) and the cumulative cost.
#[derive(Clone, Debug)]
pub struct TreeNode<Q, E> {
    pub q: Q,
    pub parent: Option<usize>,
    /// The pusher of the step from the parent (None for the root).
    pub pusher: Option<usize>,
    /// What else the step from the parent needs to be replayed (e.g. the pusher's twist).
    pub edge: E,
    /// Cumulative edge cost from the root.
    pub cost: f64,
    pub children: Vec<usize>,
}

/// The tree (node 0 is the root).
#[derive(Clone, Debug)]
pub struct Tree<Q, E> {
    nodes: Vec<TreeNode<Q, E>>,
}

impl<Q: Clone, E: Clone> Tree<Q, E> {
    pub fn new(root: Q, edge: E) -> Self {
        Self { nodes: vec![TreeNode { q: root, parent: None, pusher: None, edge, cost: 0.0, children: Vec::new() }] }
    }

    pub fn len(&self) -> usize {
        self.nodes.len()
    }

    pub fn is_empty(&self) -> bool {
        self.nodes.is_empty()
    }

    pub fn iter(&self) -> std::slice::Iter<'_, TreeNode<Q, E>> {
        self.nodes.iter()
    }

    pub fn into_nodes(self) -> Vec<TreeNode<Q, E>> {
        self.nodes
    }

    /// Adds a child of `parent`; returns its index.
    pub fn add(&mut self, q: Q, parent: usize, pusher: usize, cost: f64, edge: E) -> usize {
        let i = self.nodes.len();
        self.nodes.push(TreeNode { q, parent: Some(parent), pusher: Some(pusher), edge, cost, children: Vec::new() });
        self.nodes[parent].children.push(i);
        i
    }

    /// Whether `a` is an ancestor of `b`.
    pub fn is_ancestor(&self, a: usize, mut b: usize) -> bool {
        while let Some(p) = self.nodes[b].parent {
            if p == a {
                return true;
            }
            b = p;
        }
        false
    }

    /// RRT* rewiring: node `k` is reached from `parent` instead, at cumulative cost `cost` and
    /// with the step data `edge` (its pusher is kept, so its subtree's costs all drop by the same
    /// amount). Refused (false) for the root, when `k` is an ancestor of `parent` (a cycle) or
    /// when it would not be cheaper.
    pub fn reparent(&mut self, k: usize, parent: usize, cost: f64, edge: E) -> bool {
        let Some(old) = self.nodes[k].parent else { return false };
        if k == parent || old == parent || !(cost < self.nodes[k].cost - 1e-12) || self.is_ancestor(k, parent) {
            return false;
        }
        let delta = self.nodes[k].cost - cost;
        self.nodes[old].children.retain(|&x| x != k);
        self.nodes[k].parent = Some(parent);
        self.nodes[k].edge = edge;
        self.nodes[parent].children.push(k);
        let mut stack = vec![k];
        while let Some(n) = stack.pop() {
            self.nodes[n].cost -= delta;
            stack.extend(self.nodes[n].children.iter().copied());
        }
        true
    }

    /// The path from the root to node `i`: (pose, pusher, step data) of each node.
    pub fn path_to(&self, mut i: usize) -> Vec<(Q, Option<usize>, E)> {
        let mut out = vec![(self.nodes[i].q.clone(), self.nodes[i].pusher, self.nodes[i].edge.clone())];
        while let Some(p) = self.nodes[i].parent {
            i = p;
            out.push((self.nodes[i].q.clone(), self.nodes[i].pusher, self.nodes[i].edge.clone()));
        }
        out.reverse();
        out
    }

    /// Keeps in `best` the cheaper of it and node `i` (a goal node the planner just reached).
    pub fn keep_cheaper(&self, best: &mut Option<usize>, i: usize) {
        if best.is_none_or(|b| self.nodes[i].cost < self.nodes[b].cost) {
            *best = Some(i);
        }
    }

    /// The cheapest node for which `goal` holds (rewiring may have made a later goal node
    /// cheaper than the first one found).
    pub fn cheapest(&self, goal: impl Fn(&Q) -> bool) -> Option<usize> {
        (0..self.nodes.len()).filter(|&i| goal(&self.nodes[i].q)).min_by(|&a, &b| self.nodes[a].cost.total_cmp(&self.nodes[b].cost))
    }
}

impl<Q, E> Index<usize> for Tree<Q, E> {
    type Output = TreeNode<Q, E>;
    fn index(&self, i: usize) -> &Self::Output {
        &self.nodes[i]
    }
}

impl<Q, E> IndexMut<usize> for Tree<Q, E> {
    fn index_mut(&mut self, i: usize) -> &mut Self::Output {
        &mut self.nodes[i]
    }
}

/// The edge cost of a step (RSS 2018): `same` when the child keeps its parent's pusher,
/// `switch` on a switch-over (or from the root), plus `length_weight · length / l`.
pub fn edge_cost(same: f64, switch: f64, length_weight: f64, l: f64, parent_pusher: Option<usize>, pusher: usize, length: f64) -> f64 {
    (if parent_pusher == Some(pusher) { same } else { switch }) + length_weight * length / l
}

/// The pusher indices `0..n` with `first` (the parent's pusher) first.
pub fn pusher_order(n: usize, first: Option<usize>) -> Vec<usize> {
    let mut order: Vec<usize> = first.into_iter().filter(|&p| p < n).collect();
    order.extend((0..n).filter(|i| Some(*i) != first));
    order
}

/// How many times a path changes pusher (the first push is not a switch-over).
pub fn switch_overs<Q, E>(path: &[(Q, Option<usize>, E)]) -> usize {
    path.windows(2).skip(1).filter(|w| w[0].1 != w[1].1).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reparenting_shifts_the_subtree_and_refuses_cycles() {
        let mut t: Tree<u32, ()> = Tree::new(0, ());
        let a = t.add(1, 0, 0, 5.0, ());
        let b = t.add(2, a, 0, 6.0, ());
        let c = t.add(3, 0, 1, 1.0, ());
        assert!(t.reparent(a, c, 2.0, ()));
        assert_eq!((t[a].parent, t[a].cost, t[b].cost), (Some(c), 2.0, 3.0));
        assert!(!t.reparent(c, b, 0.5, ()), "b descends from c: a cycle");
        assert!(!t.reparent(a, c, 2.5, ()), "not cheaper");
        assert!(!t.reparent(0, c, -1.0, ()), "the root has no parent");
        assert_eq!(t.path_to(b).iter().map(|x| x.0).collect::<Vec<_>>(), vec![0, 3, 1, 2]);
        assert_eq!(t.cheapest(|q| *q >= 2), Some(c));
        assert_eq!(t.cheapest(|q| *q == 2), Some(b));
        assert_eq!(pusher_order(3, Some(2)), vec![2, 0, 1]);
        assert_eq!(pusher_order(2, Some(7)), vec![0, 1]);
    }
}
