//! The incremental, truncated signed distance field of the online map.
//!
//! Only occupancy changes move the field, and only within the truncation distance `R` of the
//! voxel that changed; so an update recomputes the *exact* truncated field in the box `T` of the
//! changed voxels grown by `R`, from the sites in `T` grown by `R` once more (every site within
//! `R` of a voxel of `T` lies there). The transform is separable (Felzenszwalb & Huttenlocher
//! 2012: `D(q) = min_j D_xy(q + j e_z) + j²`, and so on per axis), and truncated: a site farther
//! than `R` along one axis is farther than `R` in all, so each 1-D pass is the minimum over the
//! `2R + 1` offsets `|j| ≤ R` only. That form runs along whole rows of `T` at once (contiguous
//! memory, one `min` per offset and voxel, no gathers), skips rows without a site within reach,
//! and keeps squared distances in `f32` (integers up to `3 · 64²`, exact). Values above `R²`
//! stand for "beyond the truncation", which is all the field reads of them. The inside distance
//! of an occupied voxel (to the nearest non-occupied one) is a local search instead: surfaces
//! seen by a sensor are thin, so it is almost always one voxel (a free face neighbour). The
//! result equals a full recomputation voxel for voxel (property test).

use crate::ring::Ring;
use crate::traversal::VoxelKey;

/// Signed distances per slot of the ring, truncated at `r` voxels, and reusable buffers.
#[derive(Debug, Clone)]
pub(crate) struct DistanceField {
    /// Truncation distance in voxels.
    pub r: i64,
    /// Signed distance per slot, metres: `res · (min(√D_occ, r) − min(√D_free, r))`, with
    /// `D_occ` (`D_free`) the squared distance in voxels to the nearest occupied (non-occupied)
    /// voxel centre, everything outside the window counting as non-occupied.
    pub dist: Vec<f64>,
    /// Voxels recomputed so far (for reports and benches).
    pub recomputed_count: u64,
    /// Pass buffers: after the x pass (`T_x × S_y × S_z`), after the y pass (`T_x × T_y × S_z`),
    /// a row of the z pass, and one row of occupancy.
    pass_x: Vec<f32>,
    pass_y: Vec<f32>,
    row: Vec<f32>,
    occ_row: Vec<bool>,
    /// Whether a row of `pass_x` / `pass_y` holds a value within reach.
    live_x: Vec<bool>,
    live_y: Vec<bool>,
}

/// A box of voxel keys, inclusive on both ends.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct KeyBox {
    pub lo: VoxelKey,
    pub hi: VoxelKey,
}

impl KeyBox {
    /// The box of one voxel.
    pub fn point(k: VoxelKey) -> Self {
        Self { lo: k, hi: k }
    }

    /// Grows the box to hold `k`.
    pub fn include(&mut self, k: &VoxelKey) {
        for (i, &c) in k.iter().enumerate() {
            self.lo[i] = self.lo[i].min(c);
            self.hi[i] = self.hi[i].max(c);
        }
    }

    /// The box grown by `r` voxels on every side and clipped to the window (`None` if empty).
    pub fn grown_within(&self, r: i64, ring: &Ring) -> Option<KeyBox> {
        let (wl, wh) = (ring.low, ring.high());
        let mut b = *self;
        for i in 0..3 {
            b.lo[i] = (self.lo[i] - r).max(wl[i]);
            b.hi[i] = (self.hi[i] + r).min(wh[i]);
            if b.lo[i] > b.hi[i] {
                return None;
            }
        }
        Some(b)
    }

    fn len(&self, i: usize) -> usize {
        (self.hi[i] - self.lo[i] + 1) as usize
    }
}

impl DistanceField {
    /// A field for `slots` slots, truncated at `r` voxels, for a window without occupied voxels
    /// (every value `r · res`).
    pub fn new(slots: usize, r: i64, res: f64) -> Self {
        Self {
            r,
            dist: vec![r as f64 * res; slots],
            recomputed_count: 0,
            pass_x: Vec::new(),
            pass_y: Vec::new(),
            row: Vec::new(),
            occ_row: Vec::new(),
            live_x: Vec::new(),
            live_y: Vec::new(),
        }
    }

    /// Sets every value to that of a window without occupied voxels.
    pub fn reset(&mut self, res: f64) {
        self.dist.fill(self.r as f64 * res);
    }

    /// Recomputes the exact field over `target` (clipped to the window) for the occupancy
    /// `occupied` (per slot).
    pub fn recompute(&mut self, ring: &Ring, occupied: &[bool], target: &KeyBox) {
        let Some(t) = target.grown_within(0, ring) else {
            return;
        };
        let Some(s) = t.grown_within(self.r, ring) else {
            return;
        };
        let r = self.r;
        let far = (r * r) as f32;
        let (tx, ty, tz) = (t.len(0), t.len(1), t.len(2));
        let (sx, sy, sz) = (s.len(0), s.len(1), s.len(2));
        let d = ring.dims;
        // Offsets of `T` inside `S`.
        let (ox, oy, oz) = (
            (t.lo[0] - s.lo[0]) as usize,
            (t.lo[1] - s.lo[1]) as usize,
            (t.lo[2] - s.lo[2]) as usize,
        );
        let xs: Vec<usize> = (s.lo[0]..=s.hi[0]).map(|x| ring.axis_slot(0, x)).collect();

        // Pass x: for x in T, every (y, z) of S, the squared distance to the nearest occupied
        // voxel of the row within `r` (+inf if none).
        self.pass_x.clear();
        self.pass_x.resize(tx * sy * sz, f32::INFINITY);
        self.live_x.clear();
        self.live_x.resize(sy * sz, false);
        self.occ_row.resize(sx, false);
        for lz in 0..sz {
            let slot_z = ring.axis_slot(2, s.lo[2] + lz as i64);
            for ly in 0..sy {
                let slot_y = ring.axis_slot(1, s.lo[1] + ly as i64);
                let row = d[0] * (slot_y + d[1] * slot_z);
                let mut any = false;
                for (o, &slot_x) in self.occ_row.iter_mut().zip(&xs) {
                    *o = occupied[row + slot_x];
                    any |= *o;
                }
                if !any {
                    continue;
                }
                let out = &mut self.pass_x[tx * (ly + sy * lz)..][..tx];
                let mut live = false;
                // Forward: the last site at or before x; backward: the next at or after.
                let mut last = i64::MIN / 2;
                for lx in 0..ox + tx {
                    if self.occ_row[lx] {
                        last = lx as i64;
                    }
                    if lx >= ox && lx as i64 - last <= r {
                        let g = (lx as i64 - last) as f32;
                        out[lx - ox] = g * g;
                        live = true;
                    }
                }
                let mut next = i64::MAX / 2;
                for lx in (ox..sx).rev() {
                    if self.occ_row[lx] {
                        next = lx as i64;
                    }
                    if lx < ox + tx && next - lx as i64 <= r {
                        let g = (next - lx as i64) as f32;
                        let o = &mut out[lx - ox];
                        if g * g < *o {
                            *o = g * g;
                        }
                        live = true;
                    }
                }
                self.live_x[ly + sy * lz] = live;
            }
        }

        // Pass y: for (x, y) in T, every z of S: min over |j| <= r of pass_x(y + j) + j².
        self.pass_y.clear();
        self.pass_y.resize(tx * ty * sz, f32::INFINITY);
        self.live_y.clear();
        self.live_y.resize(ty * sz, false);
        for lz in 0..sz {
            for iy in 0..ty {
                let ly = oy + iy;
                let out = &mut self.pass_y[tx * (iy + ty * lz)..][..tx];
                let mut live = false;
                let lo = ly.saturating_sub(r as usize);
                let hi = (ly + r as usize).min(sy - 1);
                for src in lo..=hi {
                    if !self.live_x[src + sy * lz] {
                        continue;
                    }
                    live = true;
                    let j = src as f32 - ly as f32;
                    let add = j * j;
                    let input = &self.pass_x[tx * (src + sy * lz)..][..tx];
                    min_plus(out, input, add);
                }
                self.live_y[iy + ty * lz] = live;
            }
        }

        // Pass z and the field: for (x, y, z) in T, min over |j| <= r of pass_y(z + j) + j².
        let rf = r as f64;
        let res = ring.res;
        self.row.resize(tx, f32::INFINITY);
        for iz in 0..tz {
            let z = t.lo[2] + iz as i64;
            let lz = oz + iz;
            let slot_z = ring.axis_slot(2, z);
            for iy in 0..ty {
                let y = t.lo[1] + iy as i64;
                let slot_y = ring.axis_slot(1, y);
                let row = d[0] * (slot_y + d[1] * slot_z);
                self.row.fill(f32::INFINITY);
                let lo = lz.saturating_sub(r as usize);
                let hi = (lz + r as usize).min(sz - 1);
                for src in lo..=hi {
                    if !self.live_y[iy + ty * src] {
                        continue;
                    }
                    let j = src as f32 - lz as f32;
                    let input = &self.pass_y[tx * (iy + ty * src)..][..tx];
                    min_plus(&mut self.row, input, j * j);
                }
                for (ix, &dsq) in self.row.iter().enumerate() {
                    let slot = row + xs[ox + ix];
                    let d_occ = if dsq <= far {
                        f64::from(dsq).sqrt().min(rf)
                    } else {
                        rf
                    };
                    let d_free = if occupied[slot] {
                        let k = [t.lo[0] + ix as i64, y, z];
                        inside_sq(ring, occupied, &k, self.r).sqrt().min(rf)
                    } else {
                        0.0
                    };
                    self.dist[slot] = res * (d_occ - d_free);
                }
            }
        }
        self.recomputed_count += (tx * ty * tz) as u64;
    }
}

/// `out[i] = min(out[i], input[i] + add)` (one step of a truncated 1-D distance pass; written so
/// that it vectorizes).
#[inline]
fn min_plus(out: &mut [f32], input: &[f32], add: f32) {
    for (o, &v) in out.iter_mut().zip(input) {
        let c = v + add;
        *o = if c < *o { c } else { *o };
    }
}

/// Squared distance (voxels) from the occupied voxel `k` to the nearest non-occupied voxel
/// centre or site outside the window, exact when at most `r²` (larger values are only known to
/// exceed `r²`): a face neighbour first, then shells of growing Chebyshev radius until no
/// closer voxel can remain.
fn inside_sq(ring: &Ring, occupied: &[bool], k: &VoxelKey, r: i64) -> f64 {
    let (lo, hi) = (ring.low, ring.high());
    let d = ring.dims;
    let strides = [1, d[0], d[0] * d[1]];
    let s = [
        ring.axis_slot(0, k[0]),
        ring.axis_slot(1, k[1]),
        ring.axis_slot(2, k[2]),
    ];
    let slot = s[0] + strides[1] * s[1] + strides[2] * s[2];
    // The nearest site outside the window lies straight across a face.
    let mut best = (0..3)
        .map(|i| (k[i] - lo[i] + 1).min(hi[i] - k[i] + 1).pow(2))
        .min()
        .unwrap_or(1) as f64;
    if best <= 1.0 {
        return best;
    }
    // Face neighbours (all inside the window here): distance 1, the least possible.
    for i in 0..3 {
        let down = if s[i] == 0 {
            slot + strides[i] * (d[i] - 1)
        } else {
            slot - strides[i]
        };
        let up = if s[i] + 1 == d[i] {
            slot - strides[i] * (d[i] - 1)
        } else {
            slot + strides[i]
        };
        if !occupied[down] || !occupied[up] {
            return 1.0;
        }
    }
    for rho in 1..=r {
        if (rho * rho) as f64 >= best {
            break;
        }
        for dz in -rho..=rho {
            for dy in -rho..=rho {
                let on_shell = dz.abs() == rho || dy.abs() == rho;
                let mut dx = -rho;
                while dx <= rho {
                    let q = [k[0] + dx, k[1] + dy, k[2] + dz];
                    if ring.contains(&q) && !occupied[ring.slot(&q)] {
                        best = best.min((dx * dx + dy * dy + dz * dz) as f64);
                    }
                    dx += if on_shell { 1 } else { 2 * rho };
                }
            }
        }
    }
    best
}
