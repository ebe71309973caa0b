//! A union–find whose members carry a parity relative to their root: the
//! sense of an AoP (ψ or ψ + π) joined by continuity in SMSfP's oriented
//! AoP (`smsfp/orientation`). The specular labelling's pieces (`specular`)
//! join only members of one parity.

/// Union–find whose members carry a parity relative to their root.
pub(crate) struct ParityUnion {
    parent: Vec<u32>,
    /// Parity relative to `parent`.
    parity: Vec<bool>,
}

impl ParityUnion {
    pub(crate) fn new(n: usize) -> Self {
        ParityUnion {
            parent: (0..n as u32).collect(),
            parity: vec![false; n],
        }
    }

    /// Root of `i` and `i`'s parity relative to it (paths compressed).
    pub(crate) fn find(&mut self, i: usize) -> (usize, bool) {
        // First walk: the root and `i`'s parity relative to it.
        let (mut root, mut parity) = (i, false);
        while self.parent[root] as usize != root {
            parity ^= self.parity[root];
            root = self.parent[root] as usize;
        }
        // Second walk: every node on the path points at the root, with its
        // parity relative to it (what is left of `i`'s after the nodes below).
        let (mut k, mut left) = (i, parity);
        while k != root {
            let (next, own) = (self.parent[k] as usize, self.parity[k]);
            self.parent[k] = root as u32;
            self.parity[k] = left;
            left ^= own;
            k = next;
        }
        (root, parity)
    }

    /// Records that `a` and `b` differ in parity when `differ`; a relation
    /// contradicting the pieces already joined is ignored.
    pub(crate) fn join(&mut self, a: usize, b: usize, differ: bool) {
        let (ra, pa) = self.find(a);
        let (rb, pb) = self.find(b);
        if ra != rb {
            self.parent[rb] = ra as u32;
            self.parity[rb] = pa ^ pb ^ differ;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parities_survive_path_compression() {
        let mut u = ParityUnion::new(4);
        u.join(0, 1, true);
        u.join(1, 2, true);
        u.join(3, 2, false);
        // Before and after the paths are compressed.
        for _ in 0..2 {
            let parities: Vec<bool> = (0..4).map(|k| u.find(k).1).collect();
            assert_eq!(parities, [false, true, false, false]);
        }
        assert_eq!(u.find(0).0, 3);
    }
}
