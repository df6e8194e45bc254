//! Node and tetrahedron reordering for memory locality: reverse Cuthill–McKee on the node
//! graph (nodes adjacent when they share a tetrahedron edge), then tetrahedra sorted by their
//! smallest node.

use std::collections::VecDeque;

use crate::quality::TET_EDGES;
use crate::TetMesh;

/// The node graph of a mesh in compressed sparse row form: the neighbours of node `i` are
/// `adj[offsets[i]..offsets[i + 1]]`, sorted.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct NodeGraph {
    /// Row offsets, `nodes + 1` entries.
    pub offsets: Vec<usize>,
    /// Neighbour lists.
    pub adj: Vec<u32>,
}

impl NodeGraph {
    /// Builds the graph of tetrahedron edges over `nodes` nodes.
    ///
    /// ```
    /// let g = qdem_mesh::NodeGraph::from_tets(5, &[[0, 1, 2, 3], [1, 2, 3, 4]]);
    /// assert_eq!(g.neighbours(1), &[0, 2, 3, 4]);
    /// assert_eq!(g.neighbours(4), &[1, 2, 3]);
    /// ```
    ///
    /// # Panics
    /// If a tetrahedron refers to a node `>= nodes`.
    pub fn from_tets(nodes: usize, tets: &[[u32; 4]]) -> NodeGraph {
        // Each undirected edge once as (low, high), sorted; rows then fill in sorted order:
        // node a first receives its lower neighbours (ascending), then its higher ones.
        let mut edges: Vec<(u32, u32)> = Vec::with_capacity(tets.len() * 6);
        for t in tets {
            for &(a, b) in &TET_EDGES {
                let (a, b) = (t[a].min(t[b]), t[a].max(t[b]));
                if a != b {
                    edges.push((a, b));
                }
            }
        }
        edges.sort_unstable();
        edges.dedup();
        let mut offsets = vec![0usize; nodes + 1];
        for &(a, b) in &edges {
            offsets[a as usize + 1] += 1;
            offsets[b as usize + 1] += 1;
        }
        for i in 0..nodes {
            offsets[i + 1] += offsets[i];
        }
        let mut fill = offsets[..nodes].to_vec();
        let mut adj = vec![0u32; offsets[nodes]];
        for &(a, b) in &edges {
            adj[fill[a as usize]] = b;
            fill[a as usize] += 1;
            adj[fill[b as usize]] = a;
            fill[b as usize] += 1;
        }
        NodeGraph { offsets, adj }
    }

    /// The neighbours of node `i`.
    pub fn neighbours(&self, i: usize) -> &[u32] {
        &self.adj[self.offsets[i]..self.offsets[i + 1]]
    }

    fn degree(&self, i: usize) -> usize {
        self.offsets[i + 1] - self.offsets[i]
    }

    /// Breadth-first levels from `start`: returns the visit order and the number of levels;
    /// `level` must hold `u32::MAX` for every node of the component and is left filled.
    fn bfs(&self, start: usize, level: &mut [u32], order: &mut Vec<u32>) -> u32 {
        order.clear();
        level[start] = 0;
        order.push(start as u32);
        let mut head = 0;
        let mut depth = 0;
        while head < order.len() {
            let i = order[head] as usize;
            head += 1;
            depth = depth.max(level[i]);
            for &j in self.neighbours(i) {
                if level[j as usize] == u32::MAX {
                    level[j as usize] = level[i] + 1;
                    order.push(j);
                }
            }
        }
        depth + 1
    }

    /// The reverse Cuthill–McKee order: `order[k]` is the old index of the node placed at `k`.
    /// Each connected component starts from a pseudo-peripheral node (George–Liu).
    pub fn rcm_order(&self) -> Vec<u32> {
        let n = self.offsets.len() - 1;
        let mut placed = vec![false; n];
        let mut level = vec![u32::MAX; n];
        let mut comp = Vec::new();
        let mut result: Vec<u32> = Vec::with_capacity(n);
        let mut queue = VecDeque::new();
        let mut nbrs: Vec<u32> = Vec::new();
        for seed in 0..n {
            if placed[seed] {
                continue;
            }
            // Pseudo-peripheral node: repeat BFS from a min-degree node of the last level
            // while the number of levels grows.
            let mut start = seed;
            let mut depth = self.bfs(start, &mut level, &mut comp);
            for _ in 0..8 {
                let last = comp.iter().map(|&i| level[i as usize]).max().unwrap_or(0);
                let cand = comp
                    .iter()
                    .copied()
                    .filter(|&i| level[i as usize] == last)
                    .min_by_key(|&i| (self.degree(i as usize), i))
                    .map_or(start, |i| i as usize);
                for &i in &comp {
                    level[i as usize] = u32::MAX;
                }
                let d = self.bfs(cand, &mut level, &mut comp);
                if d > depth {
                    depth = d;
                    start = cand;
                } else {
                    break;
                }
            }
            for &i in &comp {
                level[i as usize] = u32::MAX;
            }
            // Cuthill–McKee from `start`: neighbours by increasing degree.
            placed[start] = true;
            queue.push_back(start as u32);
            while let Some(i) = queue.pop_front() {
                result.push(i);
                nbrs.clear();
                nbrs.extend(
                    self.neighbours(i as usize)
                        .iter()
                        .copied()
                        .filter(|&j| !placed[j as usize]),
                );
                nbrs.sort_unstable_by_key(|&j| (self.degree(j as usize), j));
                for &j in &nbrs {
                    placed[j as usize] = true;
                    queue.push_back(j);
                }
            }
        }
        result.reverse();
        result
    }
}

impl TetMesh {
    /// The bandwidth of the node numbering: the largest `|i - j|` over tetrahedron edges.
    pub fn bandwidth(&self) -> usize {
        self.tets
            .iter()
            .flat_map(|t| {
                TET_EDGES
                    .iter()
                    .map(move |&(a, b)| t[a].abs_diff(t[b]) as usize)
            })
            .max()
            .unwrap_or(0)
    }

    /// Renumbers the nodes: node `i` becomes node `new_of_old[i]`. Tetrahedra and group node
    /// sets are remapped (groups stay sorted) and the file's node ids follow
    /// ([`crate::FileIds`]); tetrahedron order and orientation are kept.
    ///
    /// # Panics
    /// If `new_of_old` is not a permutation of `0..nodes.len()`.
    pub fn renumber_nodes(&mut self, new_of_old: &[u32]) {
        let n = self.nodes.len();
        assert_eq!(
            new_of_old.len(),
            n,
            "renumber_nodes: permutation has the wrong length"
        );
        let mut nodes = vec![[f64::NAN; 3]; n];
        let mut seen = vec![false; n];
        for (old, &new) in new_of_old.iter().enumerate() {
            assert!(!seen[new as usize], "renumber_nodes: not a permutation");
            seen[new as usize] = true;
            nodes[new as usize] = self.nodes[old];
        }
        self.nodes = nodes;
        let ids = &mut self.file_ids.nodes;
        if !ids.is_empty() {
            let mut renumbered = vec![0; n];
            for (old, &new) in new_of_old.iter().enumerate() {
                renumbered[new as usize] = ids[old];
            }
            *ids = renumbered;
        }
        for t in &mut self.tets {
            *t = t.map(|k| new_of_old[k as usize]);
        }
        for g in &mut self.groups {
            for k in &mut g.nodes {
                *k = new_of_old[*k as usize];
            }
            g.nodes.sort_unstable();
        }
    }

    /// Reorders for locality: nodes by reverse Cuthill–McKee on the node graph, then
    /// tetrahedra sorted by their smallest node (ties by their other nodes). Groups are
    /// remapped and the file ids follow; tetrahedron orientation is kept. Returns nothing; use
    /// [`TetMesh::rcm_permutation`] and [`TetMesh::renumber_nodes`] to keep the permutation.
    ///
    /// # Panics
    /// If a tetrahedron refers to a node index out of range.
    pub fn reorder_for_locality(&mut self) {
        let new_of_old = self.rcm_permutation();
        self.renumber_nodes(&new_of_old);
        // Equal keys are equal tetrahedra, so the order of the tetrahedra does not depend on
        // how ties are broken; the index only carries their file ids along.
        let mut keyed: Vec<([u32; 4], [u32; 4], usize)> = self
            .tets
            .iter()
            .enumerate()
            .map(|(k, t)| {
                let mut s = *t;
                s.sort_unstable();
                (s, *t, k)
            })
            .collect();
        keyed.sort_unstable();
        self.tets = keyed.iter().map(|&(_, t, _)| t).collect();
        let ids = &mut self.file_ids;
        if !ids.tets.is_empty() {
            ids.tets = keyed.iter().map(|&(_, _, k)| ids.tets[k]).collect();
            ids.volumes = keyed.iter().map(|&(_, _, k)| ids.volumes[k]).collect();
        }
    }

    /// The reverse Cuthill–McKee renumbering as `new_of_old` (see
    /// [`TetMesh::renumber_nodes`]).
    pub fn rcm_permutation(&self) -> Vec<u32> {
        let order = NodeGraph::from_tets(self.nodes.len(), &self.tets).rcm_order();
        let mut new_of_old = vec![0u32; order.len()];
        for (new, &old) in order.iter().enumerate() {
            new_of_old[old as usize] = new as u32;
        }
        new_of_old
    }
}
