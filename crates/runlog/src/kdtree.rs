//! A small k-d tree over a static point cloud: exact nearest-point distances in `O(log m)` per
//! query on average, built in `O(m log m)`.
//!
//! Why a k-d tree and not a uniform hash grid: a grid answers quickly only when the nearest point
//! is a few cells away; its cost grows with the cube of the distance in cells, so a cloud with
//! one point 1000 m from the vehicle made the audit scan a hundred shells of cells per state. A
//! k-d tree needs no cell size (no tuning to the cloud's density), is exact at every distance,
//! and its queries prune whole half-spaces, whatever the spread of the points. It is written
//! here (the run-log crate depends on nothing of the planner, so it cannot use
//! `trust-world`'s tree, and the audit shares no geometry code with the simulator on purpose).
//!
//! Layout: the points are reordered in place so that every sub-slice is a subtree whose median
//! (at the slice's middle) splits it along the axis of the sub-slice's largest spread; that
//! axis is stored beside the median. Slices of at most 8 points are scanned.

/// Slices this small are scanned rather than split.
const LEAF_SIZE: usize = 8;

/// A k-d tree of 3-D points (module docs).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PointTree {
    points: Vec<[f64; 3]>,
    axes: Vec<u8>,
}

fn dist2(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    d[0] * d[0] + d[1] * d[1] + d[2] * d[2]
}

fn build(points: &mut [[f64; 3]], axes: &mut [u8]) {
    if points.len() <= LEAF_SIZE {
        return;
    }
    let mut lo = [f64::INFINITY; 3];
    let mut hi = [f64::NEG_INFINITY; 3];
    for p in points.iter() {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let axis = (0..3)
        .max_by(|&a, &b| (hi[a] - lo[a]).total_cmp(&(hi[b] - lo[b])))
        .unwrap_or(0);
    let mid = points.len() / 2;
    points.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
    axes[mid] = axis as u8;
    let (left, right) = points.split_at_mut(mid);
    let (left_axes, right_axes) = axes.split_at_mut(mid);
    build(left, left_axes);
    build(&mut right[1..], &mut right_axes[1..]);
}

impl PointTree {
    /// Builds the tree of `points` (finite coordinates; they are reordered).
    pub fn new(mut points: Vec<[f64; 3]>) -> Self {
        let mut axes = vec![0u8; points.len()];
        build(&mut points, &mut axes);
        PointTree { points, axes }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree has no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// Distance from `p` to the nearest point (`+∞` for an empty tree).
    pub fn nearest_distance(&self, p: &[f64; 3]) -> f64 {
        let mut best = f64::INFINITY;
        self.search(0, self.points.len(), p, &mut best);
        best.sqrt()
    }

    fn search(&self, from: usize, to: usize, p: &[f64; 3], best: &mut f64) {
        let slice = &self.points[from..to];
        if slice.len() <= LEAF_SIZE {
            for q in slice {
                *best = best.min(dist2(p, q));
            }
            return;
        }
        let mid = from + slice.len() / 2;
        let median = &self.points[mid];
        let axis = self.axes[mid] as usize;
        *best = best.min(dist2(p, median));
        let offset = p[axis] - median[axis];
        let (near, far) = if offset < 0.0 {
            ((from, mid), (mid + 1, to))
        } else {
            ((mid + 1, to), (from, mid))
        };
        self.search(near.0, near.1, p, best);
        if offset * offset < *best {
            self.search(far.0, far.1, p, best);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A deterministic stream of numbers in [0, 1) (a 64-bit LCG's high bits).
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        (*seed >> 11) as f64 / (1u64 << 53) as f64
    }

    #[test]
    fn the_tree_finds_the_same_nearest_distance_as_a_scan() {
        let mut seed = 7;
        for n in [0, 1, 5, 9, 100, 2000] {
            let points: Vec<[f64; 3]> = (0..n)
                .map(|i| {
                    // Clustered and spread, with duplicates.
                    let s = if i % 3 == 0 { 1.0 } else { 50.0 };
                    [
                        s * uniform(&mut seed),
                        s * uniform(&mut seed),
                        (i % 4) as f64,
                    ]
                })
                .collect();
            let tree = PointTree::new(points.clone());
            assert_eq!(tree.len(), n);
            for _ in 0..200 {
                let q = [
                    120.0 * uniform(&mut seed) - 30.0,
                    120.0 * uniform(&mut seed) - 30.0,
                    10.0 * uniform(&mut seed) - 3.0,
                ];
                let scan = points
                    .iter()
                    .map(|p| dist2(p, &q))
                    .fold(f64::INFINITY, f64::min)
                    .sqrt();
                assert_eq!(tree.nearest_distance(&q), scan, "n = {n}, q = {q:?}");
            }
        }
    }

    #[test]
    fn a_far_point_costs_no_more_than_a_near_one() {
        let mut points: Vec<[f64; 3]> = (0..1000)
            .map(|i| [(i % 10) as f64, (i / 10 % 10) as f64, (i / 100) as f64])
            .collect();
        points.push([1000.0, 0.0, 0.0]);
        let tree = PointTree::new(points);
        assert!((tree.nearest_distance(&[1000.0, 0.0, 3.0]) - 3.0).abs() < 1e-12);
        assert!((tree.nearest_distance(&[-5.0, 0.0, 0.0]) - 5.0).abs() < 1e-12);
    }
}
