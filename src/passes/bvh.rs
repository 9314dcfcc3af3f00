//! The compute backend's acceleration structure: a four-wide BVH over every
//! object's cells in the GPU's world frame, built on the host and walked by
//! `glsl/traverse_compute.glsl`.
//!
//! Built top down with binned SAH (Wald 2007, "On fast construction of
//! SAH-based bounding volume hierarchies"): each node's cells are split in
//! two at the cheapest of [`BINS`] - 1 planes along their centroids' widest
//! axis, and each half again, giving up to four children. Where SAH could
//! make the tree deeper than the shader's stack holds, a subtree is split
//! at centroid quartiles instead, which bounds the depth (see
//! [`MAX_DEPTH`]). Leaves hold at most [`MAX_LEAF`] cells.

use bytemuck::{Pod, Zeroable};

use crate::shader_interface::{BVH_EMPTY, BVH_FIRST_MASK, BVH_LEAF, BVH_LEAF_SHIFT, BVH_STACK};

/// Children per node.
pub const WIDTH: usize = 4;
/// Cells a leaf holds at most.
pub const MAX_LEAF: usize = 1;
/// SAH bins per split.
pub const BINS: usize = 12;
/// Inner-node levels the tree has at most: the traversal pops one node and
/// pushes up to four, so a tree of `D` levels needs `3 D + 1` stack entries.
pub const MAX_DEPTH: u32 = (BVH_STACK - 1) / 3;

/// One node as the shader reads it (`BvhNode`): its four children's boxes,
/// structure of arrays, and what each child is (an inner node's index, a
/// leaf's `BVH_LEAF | (count - 1) << BVH_LEAF_SHIFT | first`, or
/// `BVH_EMPTY`). An empty slot's box is empty (lo > hi).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Pod, Zeroable)]
pub struct GpuBvhNode {
    /// Smallest x of each child's box.
    pub lo_x: [f32; 4],
    /// Smallest y.
    pub lo_y: [f32; 4],
    /// Smallest z.
    pub lo_z: [f32; 4],
    /// Largest x.
    pub hi_x: [f32; 4],
    /// Largest y.
    pub hi_y: [f32; 4],
    /// Largest z.
    pub hi_z: [f32; 4],
    /// The children.
    pub child: [u32; 4],
}

/// A leaf's cell as the shader reads it (`BvhPrimitive`).
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq, Pod, Zeroable)]
pub struct GpuBvhPrimitive {
    /// The object (index into the object table).
    pub object: u32,
    /// The cell (index into the cell table).
    pub cell: u32,
}

/// A cell to place in the tree: its box in the GPU's world frame.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BvhBox {
    /// Smallest corner.
    pub lo: [f32; 3],
    /// Largest corner.
    pub hi: [f32; 3],
    /// What the leaf holds for it.
    pub primitive: GpuBvhPrimitive,
}

impl BvhBox {
    fn centroid(&self) -> [f32; 3] {
        [0, 1, 2].map(|k| 0.5 * (self.lo[k] + self.hi[k]))
    }
}

/// A built tree: node 0 is the root.
#[derive(Clone, Debug, Default)]
pub struct Bvh {
    /// The nodes, root first.
    pub nodes: Vec<GpuBvhNode>,
    /// The leaves' cells, each leaf's contiguous.
    pub primitives: Vec<GpuBvhPrimitive>,
    /// Inner-node levels (1 for a root with only leaves).
    pub depth: u32,
}

/// A box being grown.
#[derive(Clone, Copy)]
struct Bounds {
    lo: [f32; 3],
    hi: [f32; 3],
}

impl Bounds {
    const EMPTY: Bounds = Bounds { lo: [f32::INFINITY; 3], hi: [f32::NEG_INFINITY; 3] };

    fn grow(&mut self, lo: [f32; 3], hi: [f32; 3]) {
        for k in 0..3 {
            self.lo[k] = self.lo[k].min(lo[k]);
            self.hi[k] = self.hi[k].max(hi[k]);
        }
    }

    /// Half the surface area (0 when empty): SAH compares ratios.
    fn half_area(&self) -> f32 {
        let e = [0, 1, 2].map(|k| (self.hi[k] - self.lo[k]).max(0.0));
        e[0] * e[1] + e[1] * e[2] + e[2] * e[0]
    }
}

/// Inner levels that quartile splits need below a node of `n` cells.
fn quartile_levels(n: usize) -> u32 {
    if n <= MAX_LEAF {
        0
    } else {
        1 + quartile_levels(n.div_ceil(WIDTH))
    }
}

struct Builder {
    items: Vec<BvhBox>,
    nodes: Vec<GpuBvhNode>,
    primitives: Vec<GpuBvhPrimitive>,
    depth: u32,
}

impl Bvh {
    /// The tree over `boxes`. Panics beyond `BVH_FIRST_MASK` cells (the
    /// child word's room), far more than a scene's tables hold.
    pub fn build(boxes: Vec<BvhBox>) -> Bvh {
        assert!(boxes.len() < BVH_FIRST_MASK as usize, "{} cells exceed the BVH's index room", boxes.len());
        let n = boxes.len();
        let mut b = Builder { items: boxes, nodes: Vec::new(), primitives: Vec::with_capacity(n), depth: 0 };
        b.node(0..n, 1);
        Bvh { nodes: b.nodes, primitives: b.primitives, depth: b.depth }
    }

    /// Bytes of the node and primitive tables.
    pub fn bytes(&self) -> u64 {
        (std::mem::size_of_val(self.nodes.as_slice()) + std::mem::size_of_val(self.primitives.as_slice())) as u64
    }
}

impl Builder {
    /// Builds the inner node of `range` at `depth` and returns its index.
    fn node(&mut self, range: std::ops::Range<usize>, depth: u32) -> u32 {
        self.depth = self.depth.max(depth);
        let index = self.nodes.len();
        self.nodes.push(GpuBvhNode {
            lo_x: [f32::INFINITY; 4],
            lo_y: [f32::INFINITY; 4],
            lo_z: [f32::INFINITY; 4],
            hi_x: [f32::NEG_INFINITY; 4],
            hi_y: [f32::NEG_INFINITY; 4],
            hi_z: [f32::NEG_INFINITY; 4],
            child: [BVH_EMPTY; 4],
        });
        // SAH while the depth left allows finishing with quartile splits.
        let sah = depth + quartile_levels(range.len()) <= MAX_DEPTH;
        let groups = if range.len() <= MAX_LEAF {
            vec![range]
        } else {
            let mid = self.split(range.clone(), sah);
            let mut groups = Vec::with_capacity(WIDTH);
            for half in [range.start..mid, mid..range.end] {
                if half.len() > MAX_LEAF {
                    let m = self.split(half.clone(), sah);
                    groups.extend([half.start..m, m..half.end]);
                } else {
                    groups.push(half);
                }
            }
            groups
        };
        for (slot, group) in groups.into_iter().enumerate().filter(|(_, g)| !g.is_empty()) {
            let mut bounds = Bounds::EMPTY;
            for b in &self.items[group.clone()] {
                bounds.grow(b.lo, b.hi);
            }
            let child = if group.len() <= MAX_LEAF {
                let first = self.primitives.len() as u32;
                self.primitives.extend(self.items[group.clone()].iter().map(|b| b.primitive));
                BVH_LEAF | ((group.len() as u32 - 1) << BVH_LEAF_SHIFT) | first
            } else {
                self.node(group, depth + 1)
            };
            let node = &mut self.nodes[index];
            node.lo_x[slot] = bounds.lo[0];
            node.lo_y[slot] = bounds.lo[1];
            node.lo_z[slot] = bounds.lo[2];
            node.hi_x[slot] = bounds.hi[0];
            node.hi_y[slot] = bounds.hi[1];
            node.hi_z[slot] = bounds.hi[2];
            node.child[slot] = child;
        }
        index as u32
    }

    /// Partitions `range` (more than one cell) in two and returns where the
    /// second part starts: at the cheapest SAH plane with `sah`, else at the
    /// median centroid along the widest axis. Both parts are non-empty.
    fn split(&mut self, range: std::ops::Range<usize>, sah: bool) -> usize {
        let items = &mut self.items[range.clone()];
        let mut centroids = Bounds::EMPTY;
        for b in items.iter() {
            let c = b.centroid();
            centroids.grow(c, c);
        }
        let extent = [0, 1, 2].map(|k| centroids.hi[k] - centroids.lo[k]);
        let axis = (0..3).fold(0, |a, k| if extent[k] > extent[a] { k } else { a });
        let median = range.start + items.len() / 2;
        if extent[axis] <= 0.0 {
            return median;
        }
        if sah {
            let scale = BINS as f32 / extent[axis];
            let bin = |b: &BvhBox| (((b.centroid()[axis] - centroids.lo[axis]) * scale) as usize).min(BINS - 1);
            let mut counts = [0usize; BINS];
            let mut bounds = [Bounds::EMPTY; BINS];
            for b in items.iter() {
                let i = bin(b);
                counts[i] += 1;
                bounds[i].grow(b.lo, b.hi);
            }
            // Cost of each plane: area × count on either side.
            let mut left = [0.0f32; BINS];
            let (mut acc, mut n) = (Bounds::EMPTY, 0usize);
            for i in 0..BINS - 1 {
                acc.grow(bounds[i].lo, bounds[i].hi);
                n += counts[i];
                left[i] = acc.half_area() * n as f32;
            }
            let (mut acc, mut n) = (Bounds::EMPTY, 0usize);
            let mut best = (f32::INFINITY, 0usize);
            for i in (0..BINS - 1).rev() {
                acc.grow(bounds[i + 1].lo, bounds[i + 1].hi);
                n += counts[i + 1];
                let cost = left[i] + acc.half_area() * n as f32;
                let before: usize = counts[..=i].iter().sum();
                if cost < best.0 && before > 0 && before < items.len() {
                    best = (cost, i);
                }
            }
            if best.0.is_finite() {
                // Partition: cells in bins <= best.1 first.
                let mut front = 0;
                for j in 0..items.len() {
                    if bin(&items[j]) <= best.1 {
                        items.swap(front, j);
                        front += 1;
                    }
                }
                return range.start + front;
            }
        }
        let k = items.len() / 2;
        items.select_nth_unstable_by(k, |a, b| a.centroid()[axis].total_cmp(&b.centroid()[axis]));
        median
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(c: [f32; 3], h: f32, cell: u32) -> BvhBox {
        BvhBox { lo: c.map(|v| v - h), hi: c.map(|v| v + h), primitive: GpuBvhPrimitive { object: cell % 3, cell } }
    }

    /// Every primitive is in exactly one leaf, and every child's box holds
    /// the boxes below it.
    fn check(bvh: &Bvh, boxes: &[BvhBox]) {
        fn visit(bvh: &Bvh, boxes: &[BvhBox], node: u32, seen: &mut Vec<u32>) {
            let n = &bvh.nodes[node as usize];
            for slot in 0..4 {
                let child = n.child[slot];
                if child == BVH_EMPTY {
                    continue;
                }
                let (lo, hi) = ([n.lo_x[slot], n.lo_y[slot], n.lo_z[slot]], [n.hi_x[slot], n.hi_y[slot], n.hi_z[slot]]);
                let mut below = Vec::new();
                if child & BVH_LEAF != 0 {
                    let first = child & BVH_FIRST_MASK;
                    let count = ((child & !BVH_LEAF) >> BVH_LEAF_SHIFT) + 1;
                    assert!(count as usize <= MAX_LEAF);
                    for p in &bvh.primitives[first as usize..(first + count) as usize] {
                        below.push(p.cell);
                        seen.push(p.cell);
                    }
                } else {
                    let mut inner = Vec::new();
                    visit(bvh, boxes, child, &mut inner);
                    below.extend(&inner);
                    seen.extend(inner);
                }
                for cell in below {
                    let b = &boxes[cell as usize];
                    for k in 0..3 {
                        assert!(lo[k] <= b.lo[k] && b.hi[k] <= hi[k], "child box does not hold cell {cell}");
                    }
                }
            }
        }
        let mut seen = Vec::new();
        visit(bvh, boxes, 0, &mut seen);
        seen.sort_unstable();
        assert_eq!(seen, (0..boxes.len() as u32).collect::<Vec<_>>());
        assert!(bvh.depth <= MAX_DEPTH);
    }

    #[test]
    fn every_cell_is_in_one_leaf_under_boxes_that_hold_it() {
        for n in [0usize, 1, 3, 4, 5, 17, 100, 1000] {
            let boxes: Vec<_> = (0..n as u32)
                .map(|i| {
                    let f = i as f32;
                    cube([(f * 0.37).sin() * 10.0, (f * 0.11).cos() * 3.0, f * 0.01], 0.1 + (f * 0.7).sin().abs(), i)
                })
                .collect();
            let bvh = Bvh::build(boxes.clone());
            check(&bvh, &boxes);
            assert_eq!(bvh.primitives.len(), n);
        }
    }

    #[test]
    fn coincident_and_degenerate_boxes_split_by_count_and_the_depth_stays_within_the_stack() {
        // 100,000 boxes at one point: no SAH plane separates them, so
        // quartiles by index; a line of boxes with exponentially growing
        // gaps, where SAH peels one box per level, is capped at MAX_DEPTH.
        let same: Vec<_> = (0..100_000).map(|i| cube([1.0, 2.0, 3.0], 0.5, i)).collect();
        let bvh = Bvh::build(same.clone());
        check(&bvh, &same);
        let peel: Vec<_> = (0..2000).map(|i| cube([1.01f32.powi(i as i32 * 4), 0.0, 0.0], 0.01, i)).collect();
        let bvh = Bvh::build(peel.clone());
        check(&bvh, &peel);
        assert!(3 * bvh.depth < BVH_STACK, "depth {} needs more than {BVH_STACK} stack entries", bvh.depth);
    }
}
