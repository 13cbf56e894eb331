//! Voxel traversal of a segment (Amanatides & Woo, "A Fast Voxel Traversal Algorithm for Ray
//! Tracing", Eurographics 1987): the 3-D DDA that visits, in order, every voxel a segment passes.

use trust_geometry::Vec3;
use trust_geometry::scale::{MAX_COORD_M, MAX_SAMPLE_COUNT, MIN_POSITIVE};

use crate::error::{SensingError, check_range};

/// Integer coordinates of a voxel of a grid anchored at the world origin: voxel `k` covers
/// `[k · resolution, (k + 1) · resolution)` along each axis.
pub type VoxelKey = [i64; 3];

/// The key of the voxel containing `p` (finite, within the scale policy).
#[inline]
pub fn voxel_key(p: &Vec3, resolution: f64) -> VoxelKey {
    [
        floor_i64(p.x / resolution),
        floor_i64(p.y / resolution),
        floor_i64(p.z / resolution),
    ]
}

/// `x.floor() as i64` without the call to `floor` (baseline x86-64 has no rounding
/// instruction): truncate, then step down if that rounded up. Equal for every `f64`, the
/// saturating cast included (unit test).
#[inline]
fn floor_i64(x: f64) -> i64 {
    let t = x as i64;
    if (t as f64) > x {
        t.saturating_sub(1)
    } else {
        t
    }
}

/// The voxels the segment `[a, b]` passes, from `a`'s voxel to `b`'s, each once, as an iterator
/// of [`VoxelKey`]s.
///
/// Each step crosses one voxel face (at an edge or corner crossing the axes are stepped one after
/// the other, lowest axis first, so the sequence is face-connected). The number of steps is
/// fixed up front from the end voxels (`Σ |key_b − key_a|`), so the iteration ends exactly at
/// `b`'s voxel whatever the rounding.
#[derive(Debug, Clone)]
pub struct VoxelTraversal {
    key: VoxelKey,
    step: [i64; 3],
    t_max: [f64; 3],
    t_delta: [f64; 3],
    remaining: [u64; 3],
    started: bool,
}

impl VoxelTraversal {
    /// The traversal of `[a, b]` on a grid of `resolution` metres. Errors on a non-finite or
    /// out-of-scale end point, a resolution outside `[1e-9, 1e6]` m, or a segment crossing more
    /// than `1e6` voxels (the scale policy's sample cap).
    pub fn new(a: &Vec3, b: &Vec3, resolution: f64) -> Result<Self, SensingError> {
        check_range(
            "resolution",
            resolution,
            MIN_POSITIVE,
            MAX_COORD_M,
            false,
            "in [1e-9, 1e6] m",
        )?;
        for (name, p) in [("a", a), ("b", b)] {
            for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
                check_range(
                    &format!("{name}.{axis}"),
                    p[i],
                    -MAX_COORD_M,
                    MAX_COORD_M,
                    false,
                    "|x| <= 1e6 m (the scale policy)",
                )?;
            }
        }
        let ka = voxel_key(a, resolution);
        let kb = voxel_key(b, resolution);
        let steps: u128 = (0..3).map(|i| ka[i].abs_diff(kb[i]) as u128).sum();
        if steps >= MAX_SAMPLE_COUNT as u128 {
            return Err(SensingError::Count {
                field: "voxels on the segment".into(),
                value: steps.min(u64::MAX as u128) as u64,
                expected: "< 1e6 (the scale policy's sample cap)",
            });
        }
        Ok(Self::unchecked(a, b, resolution))
    }

    /// [`VoxelTraversal::new`] without the checks (the online map clips its segments to its
    /// window first).
    pub(crate) fn unchecked(a: &Vec3, b: &Vec3, resolution: f64) -> Self {
        let ka = voxel_key(a, resolution);
        let kb = voxel_key(b, resolution);
        let d = b - a;
        let mut step = [0i64; 3];
        let mut t_max = [f64::INFINITY; 3];
        let mut t_delta = [f64::INFINITY; 3];
        let mut remaining = [0u64; 3];
        for i in 0..3 {
            remaining[i] = ka[i].abs_diff(kb[i]);
            if remaining[i] == 0 {
                continue;
            }
            // `remaining > 0` implies `d[i] != 0` with the sign of `kb - ka`.
            if kb[i] > ka[i] {
                step[i] = 1;
                t_max[i] = ((ka[i] + 1) as f64 * resolution - a[i]) / d[i];
                t_delta[i] = resolution / d[i];
            } else {
                step[i] = -1;
                t_max[i] = (ka[i] as f64 * resolution - a[i]) / d[i];
                t_delta[i] = -resolution / d[i];
            }
        }
        Self {
            key: ka,
            step,
            t_max,
            t_delta,
            remaining,
            started: false,
        }
    }
}

impl VoxelTraversal {
    /// Moves to the next voxel; returns the axis stepped and the step (±1), `None` at the end.
    pub(crate) fn step(&mut self) -> Option<(usize, i64)> {
        // The axis whose next face comes first, among those with steps left.
        let mut axis = usize::MAX;
        let mut best = f64::INFINITY;
        for i in 0..3 {
            if self.remaining[i] > 0 && (axis == usize::MAX || self.t_max[i] < best) {
                axis = i;
                best = self.t_max[i];
            }
        }
        if axis == usize::MAX {
            return None;
        }
        self.key[axis] += self.step[axis];
        self.t_max[axis] += self.t_delta[axis];
        self.remaining[axis] -= 1;
        Some((axis, self.step[axis]))
    }
}

impl Iterator for VoxelTraversal {
    type Item = VoxelKey;

    fn next(&mut self) -> Option<VoxelKey> {
        if !self.started {
            self.started = true;
            return Some(self.key);
        }
        self.step().map(|_| self.key)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.remaining.iter().sum::<u64>() as usize + usize::from(!self.started);
        (n, Some(n))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::BTreeSet;

    /// Whether the segment `[a, b]` meets the voxel's cube grown by `eps`.
    fn segment_meets_voxel(a: &Vec3, b: &Vec3, k: VoxelKey, res: f64, eps: f64) -> bool {
        let (mut t0, mut t1) = (0.0f64, 1.0f64);
        for i in 0..3 {
            let lo = k[i] as f64 * res - eps;
            let hi = (k[i] + 1) as f64 * res + eps;
            let d = b[i] - a[i];
            if d.abs() < 1e-300 {
                if a[i] < lo || a[i] > hi {
                    return false;
                }
                continue;
            }
            let (mut ta, mut tb) = ((lo - a[i]) / d, (hi - a[i]) / d);
            if ta > tb {
                std::mem::swap(&mut ta, &mut tb);
            }
            t0 = t0.max(ta);
            t1 = t1.min(tb);
        }
        t0 <= t1
    }

    fn coord() -> impl Strategy<Value = f64> {
        -3.0f64..3.0
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 32, ..ProptestConfig::default() })]

        /// Every voxel a dense sampling of the segment finds is visited, every visited voxel
        /// meets the segment, consecutive voxels share a face, and the walk ends at `b`'s voxel.
        #[test]
        fn traversal_matches_brute_force_sampling(
            a in (coord(), coord(), coord()), b in (coord(), coord(), coord()), res in 0.05f64..0.7,
        ) {
            let a = Vec3::new(a.0, a.1, a.2);
            let b = Vec3::new(b.0, b.1, b.2);
            let keys: Vec<VoxelKey> = VoxelTraversal::new(&a, &b, res).unwrap().collect();
            let set: BTreeSet<VoxelKey> = keys.iter().copied().collect();
            prop_assert_eq!(set.len(), keys.len(), "a voxel visited twice");
            prop_assert_eq!(keys[0], voxel_key(&a, res));
            prop_assert_eq!(*keys.last().unwrap(), voxel_key(&b, res));
            for w in keys.windows(2) {
                let diff: u64 = (0..3).map(|i| w[0][i].abs_diff(w[1][i])).sum();
                prop_assert_eq!(diff, 1);
            }
            for k in &keys {
                prop_assert!(segment_meets_voxel(&a, &b, *k, res, 1e-9), "{k:?} off the segment");
            }
            let samples = 20_000;
            for s in 0..=samples {
                let p = a + (b - a) * (s as f64 / samples as f64);
                let k = voxel_key(&p, res);
                prop_assert!(set.contains(&k), "sample {s} in {k:?} missed");
            }
        }
    }

    #[test]
    fn floor_i64_equals_floor() {
        let mut xs = vec![
            0.0,
            -0.0,
            0.5,
            -0.5,
            1.0,
            -1.0,
            -1e-300,
            1e-300,
            2.5e15,
            -2.5e15,
            4.5e15 + 0.5,
            9.3e18,
            -9.3e18,
            f64::MAX,
            f64::MIN,
            f64::INFINITY,
            f64::NEG_INFINITY,
            f64::NAN,
        ];
        let mut x: f64 = 1.2345e-7;
        while x < 1e19 {
            xs.extend([
                x,
                -x,
                x.next_up(),
                -x.next_up(),
                x.next_down(),
                -x.next_down(),
            ]);
            x *= 1.37;
        }
        for x in xs {
            assert_eq!(floor_i64(x), x.floor() as i64, "{x:e}");
        }
    }

    #[test]
    fn known_walks() {
        let r = 1.0;
        let walk = |a: Vec3, b: Vec3| VoxelTraversal::new(&a, &b, r).unwrap().collect::<Vec<_>>();
        // Along x: 0.5 → 3.5 visits 0, 1, 2, 3.
        assert_eq!(
            walk(Vec3::new(0.5, 0.5, 0.5), Vec3::new(3.5, 0.5, 0.5)),
            vec![[0, 0, 0], [1, 0, 0], [2, 0, 0], [3, 0, 0]]
        );
        // Backwards, across zero.
        assert_eq!(
            walk(Vec3::new(0.5, 0.5, 0.5), Vec3::new(-1.5, 0.5, 0.5)),
            vec![[0, 0, 0], [-1, 0, 0], [-2, 0, 0]]
        );
        // A point is its voxel.
        assert_eq!(
            walk(Vec3::new(0.2, 0.3, 0.4), Vec3::new(0.2, 0.3, 0.4)),
            vec![[0, 0, 0]]
        );
        // Exactly through a corner: x first, then y.
        assert_eq!(
            walk(Vec3::new(0.5, 0.5, 0.5), Vec3::new(1.5, 1.5, 0.5)),
            vec![[0, 0, 0], [1, 0, 0], [1, 1, 0]]
        );
    }

    #[test]
    fn invalid_input_is_a_typed_error() {
        let o = Vec3::zeros();
        let e = VoxelTraversal::new(&Vec3::new(f64::NAN, 0.0, 0.0), &o, 0.1).unwrap_err();
        assert_eq!(e.to_string(), "a.x must be finite, got NaN");
        let e = VoxelTraversal::new(&o, &o, 0.0).unwrap_err();
        assert!(
            e.to_string().starts_with("resolution = 0 is out of range"),
            "{e}"
        );
        let e = VoxelTraversal::new(&o, &Vec3::new(1e5, 0.0, 0.0), 0.01).unwrap_err();
        assert!(matches!(e, SensingError::Count { .. }), "{e}");
    }
}
