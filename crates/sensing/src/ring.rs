//! Ring-buffer indexing of a rolling window of voxels.

use trust_geometry::{Aabb, Vec3};

use crate::traversal::{VoxelKey, VoxelTraversal};

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

/// Walks the voxels of the segment `[a, b]` (3-D DDA) that lie in the window, calling
/// `visit(slot, key)` until it returns false; the slot is kept incrementally (no division per
/// voxel).
pub(crate) fn walk(
    ring: &Ring,
    a: &Vec3,
    b: &Vec3,
    mut visit: impl FnMut(usize, VoxelKey) -> bool,
) {
    let mut tr = VoxelTraversal::unchecked(a, b, ring.res);
    let d = ring.dims;
    let (lo, hi) = (ring.low, ring.high());
    let mut key = tr.key();
    let mut s = [
        ring.axis_slot(0, key[0]),
        ring.axis_slot(1, key[1]),
        ring.axis_slot(2, key[2]),
    ];
    loop {
        let inside = (0..3).all(|i| key[i] >= lo[i] && key[i] <= hi[i]);
        if inside && !visit(s[0] + d[0] * (s[1] + d[1] * s[2]), key) {
            return;
        }
        let Some((axis, step)) = tr.step() else {
            return;
        };
        key[axis] += step;
        s[axis] = if step > 0 {
            if s[axis] + 1 == d[axis] {
                0
            } else {
                s[axis] + 1
            }
        } else if s[axis] == 0 {
            d[axis] - 1
        } else {
            s[axis] - 1
        };
    }
}
