//! A static k-d tree over 3-D points for nearest-point queries: the true clearance from a
//! points-file static map at the physics rate.

use trust_core::Vec3;

/// A balanced k-d tree stored implicitly in one array: the node of the index range `[lo, hi)`
/// is its middle element, split along `axes[mid]`; the two halves are its subtrees. Built by
/// median selection on the widest axis of each range; deterministic for a given input order.
#[derive(Debug, Clone, Default)]
pub struct PointTree {
    points: Vec<Vec3>,
    axes: Vec<u8>,
}

impl PointTree {
    /// Builds the tree (O(n log n)); the points must be finite.
    pub fn new(mut points: Vec<Vec3>) -> Self {
        let mut axes = vec![0u8; points.len()];
        build(&mut points, &mut axes);
        PointTree { points, axes }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.points.len()
    }

    /// Whether the tree holds no point.
    pub fn is_empty(&self) -> bool {
        self.points.is_empty()
    }

    /// The points, in tree order.
    pub fn points(&self) -> &[Vec3] {
        &self.points
    }

    /// The distance from `q` to the nearest point, and that point; `None` for an empty tree. A
    /// non-finite `q` gives distance `+inf` (never NaN).
    pub fn nearest(&self, q: &Vec3) -> Option<(f64, Vec3)> {
        if self.points.is_empty() {
            return None;
        }
        let mut best = (f64::INFINITY, 0usize);
        self.search(q, 0, self.points.len(), &mut best);
        let d = best.0.sqrt();
        Some((
            if d.is_nan() { f64::INFINITY } else { d },
            self.points[best.1],
        ))
    }

    fn search(&self, q: &Vec3, lo: usize, hi: usize, best: &mut (f64, usize)) {
        if lo >= hi {
            return;
        }
        let mid = lo + (hi - lo) / 2;
        let p = &self.points[mid];
        let d2 = (p - q).norm_squared();
        if d2 < best.0 {
            *best = (d2, mid);
        }
        let axis = self.axes[mid] as usize;
        let delta = q[axis] - p[axis];
        let (near, far) = if delta < 0.0 {
            ((lo, mid), (mid + 1, hi))
        } else {
            ((mid + 1, hi), (lo, mid))
        };
        self.search(q, near.0, near.1, best);
        if delta * delta < best.0 {
            self.search(q, far.0, far.1, best);
        }
    }
}

fn build(points: &mut [Vec3], axes: &mut [u8]) {
    if points.len() <= 1 {
        return;
    }
    let mut lo = points[0];
    let mut hi = points[0];
    for p in points.iter() {
        lo = lo.inf(p);
        hi = hi.sup(p);
    }
    let ext = hi - lo;
    let axis = if ext.x >= ext.y && ext.x >= ext.z {
        0
    } else if ext.y >= ext.z {
        1
    } else {
        2
    };
    let mid = points.len() / 2;
    points.select_nth_unstable_by(mid, |a, b| a[axis].total_cmp(&b[axis]));
    axes[mid] = axis as u8;
    let (left, rest) = points.split_at_mut(mid);
    let (left_axes, rest_axes) = axes.split_at_mut(mid);
    build(left, left_axes);
    build(&mut rest[1..], &mut rest_axes[1..]);
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng as _, SeedableRng};

    #[test]
    fn nearest_matches_brute_force() {
        let mut rng = trust_core::Rng::seed_from_u64(3);
        let mut pt = || {
            Vec3::new(
                rng.random_range(-5.0..5.0),
                rng.random_range(-5.0..5.0),
                rng.random_range(0.0..3.0),
            )
        };
        let points: Vec<Vec3> = (0..2000).map(|_| pt()).collect();
        let queries: Vec<Vec3> = (0..300).map(|_| pt() * 1.5).collect();
        let tree = PointTree::new(points.clone());
        assert_eq!(tree.len(), 2000);
        for q in &queries {
            let brute = points
                .iter()
                .map(|p| (p - q).norm())
                .fold(f64::INFINITY, f64::min);
            let (d, p) = tree.nearest(q).unwrap();
            assert!((d - brute).abs() < 1e-12, "{d} vs {brute}");
            assert!(((p - q).norm() - d).abs() < 1e-12);
        }
        assert!(PointTree::new(Vec::new()).nearest(&Vec3::zeros()).is_none());
    }
}
