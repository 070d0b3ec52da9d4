//! Disjoint sets of indices, for points that merge (corners of an SVG mesh's patches joined by
//! empty sides, sides of separate meshes that meet).

/// Disjoint sets of the indices `0..n`.
pub(crate) struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    /// `n` sets of one index each.
    pub(crate) fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
        }
    }

    /// The representative of the set holding `k`.
    pub(crate) fn find(&mut self, mut k: usize) -> usize {
        while self.parent[k] != k {
            self.parent[k] = self.parent[self.parent[k]];
            k = self.parent[k];
        }
        k
    }

    /// Joins the sets of `a` and `b`; the smaller index stays the representative, so that a
    /// merged point takes the attributes of the one met first.
    pub(crate) fn union(&mut self, a: usize, b: usize) {
        let (ra, rb) = (self.find(a), self.find(b));
        let (keep, join) = if ra <= rb { (ra, rb) } else { (rb, ra) };
        self.parent[join] = keep;
    }
}
