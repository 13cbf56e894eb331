//! Ring-buffer indexing of a rolling window of voxels.

use trust_geometry::{Aabb, Vec3};

use crate::traversal::VoxelKey;
#[cfg(test)]
use crate::traversal::{VoxelTraversal, voxel_key};

/// A window of `dims` voxels whose low corner is the voxel `low`, stored in a fixed buffer: the
/// voxel `k` lives in slot `(k mod dims)` per axis, so moving the window re-labels slots instead
/// of copying the grid (only the slots that change hands are cleared).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Ring {
    pub dims: [usize; 3],
    pub low: VoxelKey,
    pub res: f64,
}

impl Ring {
    /// Number of slots.
    pub fn len(&self) -> usize {
        self.dims[0] * self.dims[1] * self.dims[2]
    }

    /// The highest key inside the window, per axis.
    pub fn high(&self) -> VoxelKey {
        [
            self.low[0] + self.dims[0] as i64 - 1,
            self.low[1] + self.dims[1] as i64 - 1,
            self.low[2] + self.dims[2] as i64 - 1,
        ]
    }

    /// True if voxel `k` is inside the window.
    #[inline]
    pub fn contains(&self, k: &VoxelKey) -> bool {
        (0..3).all(|i| k[i] >= self.low[i] && k[i] < self.low[i] + self.dims[i] as i64)
    }

    /// The slot of coordinate `k` along axis `i`.
    #[inline]
    pub fn axis_slot(&self, i: usize, k: i64) -> usize {
        k.rem_euclid(self.dims[i] as i64) as usize
    }

    /// The slot of voxel `k` (inside the window or not: slots repeat with period `dims`).
    #[inline]
    pub fn slot(&self, k: &VoxelKey) -> usize {
        self.axis_slot(0, k[0])
            + self.dims[0] * (self.axis_slot(1, k[1]) + self.dims[1] * self.axis_slot(2, k[2]))
    }

    /// The key of the voxel inside the window stored in `slot`.
    pub fn key_of_slot(&self, slot: usize) -> VoxelKey {
        let d = self.dims;
        let s = [slot % d[0], (slot / d[0]) % d[1], slot / (d[0] * d[1])];
        let mut k = [0i64; 3];
        for i in 0..3 {
            let n = d[i] as i64;
            k[i] = self.low[i] + (s[i] as i64 - self.low[i]).rem_euclid(n);
        }
        k
    }

    /// The slot indexer of the window as it is now (division-free slots for keys near it).
    pub fn indexer(&self) -> Indexer {
        let mut low_slot = [0; 3];
        for (i, s) in low_slot.iter_mut().enumerate() {
            *s = self.axis_slot(i, self.low[i]);
        }
        Indexer {
            ring: *self,
            low_slot,
        }
    }

    /// The region the window's voxels cover.
    pub fn world_box(&self) -> Aabb {
        let h = self.high();
        Aabb {
            min: Vec3::new(
                self.low[0] as f64 * self.res,
                self.low[1] as f64 * self.res,
                self.low[2] as f64 * self.res,
            ),
            max: Vec3::new(
                (h[0] + 1) as f64 * self.res,
                (h[1] + 1) as f64 * self.res,
                (h[2] + 1) as f64 * self.res,
            ),
        }
    }

    /// Centre of voxel `k`.
    pub fn center(&self, k: &VoxelKey) -> Vec3 {
        Vec3::new(
            (k[0] as f64 + 0.5) * self.res,
            (k[1] as f64 + 0.5) * self.res,
            (k[2] as f64 + 0.5) * self.res,
        )
    }
}

/// A [`Ring`] with the slots of its low corner: the slot of a coordinate inside the window is
/// then an add and a conditional subtract, not a division (`rem_euclid` on `i64`). Valid until
/// the window moves.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Indexer {
    pub ring: Ring,
    low_slot: [usize; 3],
}

impl Indexer {
    /// [`Ring::axis_slot`]: the same value, without a division for `k` inside the window.
    #[inline]
    pub fn axis_slot(&self, i: usize, k: i64) -> usize {
        let n = self.ring.dims[i];
        let off = k.wrapping_sub(self.ring.low[i]);
        if (0..n as i64).contains(&off) {
            let s = self.low_slot[i] + off as usize;
            if s >= n { s - n } else { s }
        } else {
            self.ring.axis_slot(i, k)
        }
    }

    /// The slot of `k` if it lies inside the window.
    #[inline]
    pub fn slot_in(&self, k: &VoxelKey) -> Option<usize> {
        let d = self.ring.dims;
        let mut s = [0usize; 3];
        for i in 0..3 {
            let off = k[i].wrapping_sub(self.ring.low[i]);
            if !(0..d[i] as i64).contains(&off) {
                return None;
            }
            let v = self.low_slot[i] + off as usize;
            s[i] = if v >= d[i] { v - d[i] } else { v };
        }
        Some(s[0] + d[0] * (s[1] + d[1] * s[2]))
    }
}

/// Walks the voxels of the segment `[a, b]` (3-D DDA, the same voxels in the same order as
/// [`VoxelTraversal`](crate::traversal::VoxelTraversal)) that lie in the window, calling `visit(slot)` until it returns false.
/// `ka` and `kb` are the voxels of `a` and `b` (`voxel_key`; the caller often has them already).
///
/// The fast form of the walk: integer stepping on a flat slot index (one add per step, a
/// wrap-around test on the stepped axis only), the window test kept per axis as a bit mask
/// updated on the stepped axis, exhausted axes parked at `t = +inf` so that choosing the next
/// axis is two comparisons. Equal to the iterator restricted to the window (unit test against
/// it on random segments).
#[inline]
pub(crate) fn walk(
    ix: &Indexer,
    (a, ka): (&Vec3, VoxelKey),
    (b, kb): (&Vec3, VoxelKey),
    mut visit: impl FnMut(usize) -> bool,
) {
    let ring = &ix.ring;
    let res = ring.res;
    let d = b - a;
    let dims = ring.dims;
    let strides = [1, dims[0], dims[0] * dims[1]];
    let (lo, hi) = (ring.low, ring.high());
    let mut t_max = [f64::INFINITY; 3];
    let mut t_delta = [0.0; 3];
    let mut remaining = [0u64; 3];
    let mut up = [true; 3];
    let mut s = [0usize; 3];
    let mut key = ka;
    let mut outside = 0u32;
    for i in 0..3 {
        s[i] = ix.axis_slot(i, ka[i]);
        if ka[i] < lo[i] || ka[i] > hi[i] {
            outside |= 1 << i;
        }
        remaining[i] = ka[i].abs_diff(kb[i]);
        if remaining[i] == 0 {
            continue;
        }
        // `remaining > 0` implies `d[i] != 0` with the sign of `kb - ka` (as the iterator).
        if kb[i] > ka[i] {
            t_max[i] = ((ka[i] + 1) as f64 * res - a[i]) / d[i];
            t_delta[i] = res / d[i];
        } else {
            up[i] = false;
            t_max[i] = (ka[i] as f64 * res - a[i]) / d[i];
            t_delta[i] = -res / d[i];
        }
    }
    let mut slot = s[0] + strides[1] * s[1] + strides[2] * s[2];
    let mut n = remaining[0] + remaining[1] + remaining[2];
    loop {
        if outside == 0 && !visit(slot) {
            return;
        }
        if n == 0 {
            return;
        }
        n -= 1;
        // The axis whose next face comes first, lowest axis on ties (as the iterator).
        let mut axis = if t_max[0] <= t_max[1] && t_max[0] <= t_max[2] {
            0
        } else if t_max[1] <= t_max[2] {
            1
        } else {
            2
        };
        if remaining[axis] == 0 {
            // Only when every axis with steps left has an infinite `t` (a degenerate segment):
            // the iterator's choice, the lowest such axis.
            axis = (0..3).find(|&i| remaining[i] > 0).unwrap_or(axis);
        }
        remaining[axis] -= 1;
        t_max[axis] = if remaining[axis] == 0 {
            f64::INFINITY
        } else {
            t_max[axis] + t_delta[axis]
        };
        let n_axis = dims[axis];
        if up[axis] {
            key[axis] += 1;
            if s[axis] + 1 == n_axis {
                s[axis] = 0;
                slot -= strides[axis] * (n_axis - 1);
            } else {
                s[axis] += 1;
                slot += strides[axis];
            }
        } else {
            key[axis] -= 1;
            if s[axis] == 0 {
                s[axis] = n_axis - 1;
                slot += strides[axis] * (n_axis - 1);
            } else {
                s[axis] -= 1;
                slot -= strides[axis];
            }
        }
        if key[axis] < lo[axis] || key[axis] > hi[axis] {
            outside |= 1 << axis;
        } else {
            outside &= !(1 << axis);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig { cases: 256, ..ProptestConfig::default() })]

        /// The indexer's division-free slots equal the ring's, inside the window and out.
        #[test]
        fn indexer_equals_the_ring(
            k in (-40i64..40, -40i64..40, -40i64..40),
            low in (-30i64..30, -30i64..30, -30i64..30),
            dims in (2usize..16, 2usize..16, 2usize..16),
        ) {
            let ring = Ring { dims: [dims.0, dims.1, dims.2], low: [low.0, low.1, low.2], res: 0.1 };
            let ix = ring.indexer();
            let k = [k.0, k.1, k.2];
            for (i, &c) in k.iter().enumerate() {
                prop_assert_eq!(ix.axis_slot(i, c), ring.axis_slot(i, c));
            }
            let expect = ring.contains(&k).then(|| ring.slot(&k));
            prop_assert_eq!(ix.slot_in(&k), expect);
        }

        /// The fast walk visits exactly the slots of the iterator's voxels inside the window, in
        /// its order, and stops when asked.
        #[test]
        fn walk_equals_the_iterator_in_the_window(
            a in (-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0),
            b in (-2.0f64..2.0, -2.0f64..2.0, -2.0f64..2.0),
            low in (-12i64..4, -12i64..4, -12i64..4),
            dims in (2usize..16, 2usize..16, 2usize..16),
            res in prop_oneof![Just(0.1f64), Just(0.25), 0.05f64..0.5],
            stop in 0usize..40,
        ) {
            let ring = Ring { dims: [dims.0, dims.1, dims.2], low: [low.0, low.1, low.2], res };
            let a = Vec3::new(a.0, a.1, a.2);
            let b = Vec3::new(b.0, b.1, b.2);
            let expect: Vec<usize> = VoxelTraversal::new(&a, &b, res)
                .unwrap()
                .filter(|k| ring.contains(k))
                .map(|k| ring.slot(&k))
                .collect();
            let mut got = Vec::new();
            let ix = ring.indexer();
            walk(&ix, (&a, voxel_key(&a, res)), (&b, voxel_key(&b, res)), |s| { got.push(s); true });
            prop_assert_eq!(&got, &expect);
            let mut first = Vec::new();
            walk(&ix, (&a, voxel_key(&a, res)), (&b, voxel_key(&b, res)), |s| { first.push(s); first.len() < stop });
            let n = stop.max(1).min(expect.len());
            prop_assert_eq!(&first[..], &expect[..n]);
        }
    }
}
