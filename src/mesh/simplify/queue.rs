//! The collapse queue: an indexed 4-ary min-heap holding each live edge at most once.
//!
//! Every edge sits in the heap under its current cost, so a pop always yields a collapse to
//! try. The earlier lazy heap (re-push on every change, skip outdated entries when popped)
//! popped about ten entries per collapse on a scan (nine of them of removed or re-costed
//! edges), each a full sift down a heap too large for the cache; re-keying and removing here
//! sift from the edge's own slot, which is mostly near the leaves and so cheap. Four 24-byte
//! children span about one and a half cache lines, and the tree is half as deep as a binary one.

use std::cmp::Ordering;

/// The collapse of edge `edge`, whose ends have input indices `u` < `v`, with its current cost.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Candidate {
    pub(super) cost: f64,
    pub(super) u: u32,
    pub(super) v: u32,
    pub(super) edge: u32,
}

impl Candidate {
    /// Cheapest first; ties go to lower indices, so the order is total and deterministic.
    fn before(&self, other: &Candidate) -> bool {
        self.cost
            .total_cmp(&other.cost)
            .then(self.u.cmp(&other.u))
            .then(self.v.cmp(&other.v))
            .then(self.edge.cmp(&other.edge))
            == Ordering::Less
    }
}

const ARITY: usize = 4;

/// The slot of an edge that is not in the heap.
const ABSENT: u32 = u32::MAX;

/// Min-heap of [`Candidate`]s, at most one per edge, addressable by edge.
pub(super) struct Queue {
    items: Vec<Candidate>,
    /// Each edge's index in `items`, or [`ABSENT`].
    slot: Vec<u32>,
}

impl Queue {
    /// A heap of `items` (distinct edges below `num_edges`), built in linear time.
    pub(super) fn new(num_edges: usize, items: Vec<Candidate>) -> Queue {
        let mut q = Queue {
            items,
            slot: vec![ABSENT; num_edges],
        };
        for (i, c) in q.items.iter().enumerate() {
            q.slot[c.edge as usize] = i as u32;
        }
        for i in (0..q.items.len().div_ceil(ARITY)).rev() {
            q.sift_down(i);
        }
        q
    }

    /// Adds `c`, or moves its edge to `c`'s cost if it is already queued.
    pub(super) fn set(&mut self, c: Candidate) {
        match self.slot[c.edge as usize] {
            ABSENT => {
                self.items.push(c);
                self.place(self.items.len() - 1);
                self.sift_up(self.items.len() - 1);
            }
            i => {
                let i = i as usize;
                let up = c.before(&self.items[i]);
                self.items[i] = c;
                if up {
                    self.sift_up(i);
                } else {
                    self.sift_down(i);
                }
            }
        }
    }

    /// Takes `edge` out of the queue if it is in it.
    pub(super) fn remove(&mut self, edge: u32) {
        let i = self.slot[edge as usize];
        if i != ABSENT {
            self.take(i as usize);
        }
    }

    /// Removes and returns the cheapest candidate.
    pub(super) fn pop(&mut self) -> Option<Candidate> {
        (!self.items.is_empty()).then(|| self.take(0))
    }

    /// Removes the item at index `i` and restores the heap order.
    fn take(&mut self, i: usize) -> Candidate {
        let out = self.items.swap_remove(i);
        self.slot[out.edge as usize] = ABSENT;
        if i < self.items.len() {
            self.place(i);
            if i > 0 && self.items[i].before(&self.items[(i - 1) / ARITY]) {
                self.sift_up(i);
            } else {
                self.sift_down(i);
            }
        }
        out
    }

    /// Records where the item at index `i` sits.
    fn place(&mut self, i: usize) {
        self.slot[self.items[i].edge as usize] = i as u32;
    }

    fn sift_up(&mut self, mut i: usize) {
        while i > 0 {
            let parent = (i - 1) / ARITY;
            if !self.items[i].before(&self.items[parent]) {
                break;
            }
            self.items.swap(i, parent);
            self.place(i);
            i = parent;
        }
        self.place(i);
    }

    fn sift_down(&mut self, mut i: usize) {
        let n = self.items.len();
        loop {
            let first = ARITY * i + 1;
            if first >= n {
                break;
            }
            let mut best = first;
            for c in first + 1..(first + ARITY).min(n) {
                if self.items[c].before(&self.items[best]) {
                    best = c;
                }
            }
            if !self.items[best].before(&self.items[i]) {
                break;
            }
            self.items.swap(i, best);
            self.place(i);
            i = best;
        }
        if i < n {
            self.place(i);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn item(k: u32) -> Candidate {
        Candidate {
            cost: ((k * 7919) % 31) as f64,
            u: k % 5,
            v: k,
            edge: k,
        }
    }

    fn sorted(mut items: Vec<Candidate>) -> Vec<Candidate> {
        items.sort_by(|a, b| {
            a.cost
                .total_cmp(&b.cost)
                .then(a.u.cmp(&b.u))
                .then(a.v.cmp(&b.v))
        });
        items
    }

    #[test]
    fn pops_in_cost_then_index_order() {
        let costs: Vec<Candidate> = (0..200).map(item).collect();
        let mut q = Queue::new(200, costs[..120].to_vec());
        for &c in &costs[120..] {
            q.set(c);
        }
        let popped: Vec<Candidate> = std::iter::from_fn(|| q.pop()).collect();
        assert_eq!(popped, sorted(costs));
    }

    #[test]
    fn rekeyed_and_removed_edges_pop_once_at_their_last_cost() {
        let mut expected: Vec<Candidate> = (0..300).map(item).collect();
        let mut q = Queue::new(300, expected.clone());
        for k in (0..300).step_by(7) {
            q.remove(k);
            q.remove(k); // removing twice is harmless
        }
        for k in (0..300u32).step_by(3) {
            let c = Candidate {
                cost: ((k * 31) % 17) as f64 - 3.0,
                ..item(k)
            };
            q.set(c);
            expected[k as usize] = c;
        }
        // Every removed edge that was not re-keyed afterwards is gone.
        expected.retain(|c| c.edge % 7 != 0 || c.edge % 3 == 0);
        let popped: Vec<Candidate> = std::iter::from_fn(|| q.pop()).collect();
        assert_eq!(popped, sorted(expected));
    }

    #[test]
    fn random_raises_lowers_removals_and_pops_match_a_sorted_list() {
        // A naive reference: the current candidate of every queued edge, minimum popped.
        let mut reference: Vec<Option<Candidate>> = vec![None; 64];
        let mut q = Queue::new(64, Vec::new());
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |n: u64| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            state % n
        };
        for _ in 0..20_000 {
            let edge = next(64) as u32;
            match next(10) {
                0..=5 => {
                    let c = Candidate {
                        cost: next(40) as f64,
                        u: next(3) as u32,
                        v: 7,
                        edge,
                    };
                    q.set(c);
                    reference[edge as usize] = Some(c);
                }
                6 => {
                    q.remove(edge);
                    reference[edge as usize] = None;
                }
                _ => {
                    let expected = reference.iter().flatten().copied().reduce(|a, b| {
                        if b.before(&a) {
                            b
                        } else {
                            a
                        }
                    });
                    assert_eq!(q.pop(), expected);
                    if let Some(c) = expected {
                        reference[c.edge as usize] = None;
                    }
                }
            }
        }
    }
}
