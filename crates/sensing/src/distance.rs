//! The incremental, truncated signed distance field of the online map.
//!
//! Only occupancy changes move the field, and only within the truncation distance `R` of the
//! voxel that changed; so an update recomputes the *exact* truncated field in the box `T` of the
//! changed voxels grown by `R`, from the sites in `T` grown by `R` once more (every site within
//! `R` of a voxel of `T` lies there). The transform is the separable one of Felzenszwalb &
//! Huttenlocher (2012), through `trust_geometry::edt_1d_with_scratch`, restricted to the lines
//! that reach `T`. The inside distance of an occupied voxel (to the nearest non-occupied one) is
//! a local search instead: surfaces seen by a sensor are thin, so it is almost always one voxel
//! (a free face neighbour). The result equals a full recomputation voxel for voxel (property
//! test).

use trust_geometry::{EdtScratch, edt_1d_with_scratch};

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
    outside: Vec<f64>,
    line: Vec<f64>,
    out: Vec<f64>,
    scratch: EdtScratch,
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
            outside: Vec::new(),
            line: Vec::new(),
            out: Vec::new(),
            scratch: EdtScratch::default(),
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
        let mut outside = std::mem::take(&mut self.outside);
        self.transform(ring, occupied, &s, &t, false, &mut outside);
        let sd = [s.len(0), s.len(1), s.len(2)];
        let r = self.r as f64;
        let res = ring.res;
        let xs: Vec<usize> = (t.lo[0]..=t.hi[0]).map(|x| ring.axis_slot(0, x)).collect();
        for z in t.lo[2]..=t.hi[2] {
            let sz = ring.axis_slot(2, z);
            let lz = (z - s.lo[2]) as usize;
            for y in t.lo[1]..=t.hi[1] {
                let sy = ring.axis_slot(1, y);
                let ly = (y - s.lo[1]) as usize;
                let row = ring.dims[0] * (sy + ring.dims[1] * sz);
                let lrow = sd[0] * (ly + sd[1] * lz);
                for (ix, &sx) in xs.iter().enumerate() {
                    let l = lrow + (t.lo[0] - s.lo[0]) as usize + ix;
                    let d_occ = outside[l].sqrt().min(r);
                    let d_free = if occupied[row + sx] {
                        let k = [t.lo[0] + ix as i64, y, z];
                        inside_sq(ring, occupied, &k, self.r).sqrt().min(r)
                    } else {
                        0.0
                    };
                    self.dist[row + sx] = res * (d_occ - d_free);
                }
            }
        }
        self.recomputed_count += (t.len(0) * t.len(1) * t.len(2)) as u64;
        self.outside = outside;
    }

    /// The squared distance transform (voxel units) over the box `s`, exact on the lines that
    /// reach `t`: to the occupied voxels (`inside == false`) or to the non-occupied ones and the
    /// outside of the window (`inside == true`). `buf` gets `s`'s layout (x fastest).
    fn transform(
        &mut self,
        ring: &Ring,
        occupied: &[bool],
        s: &KeyBox,
        t: &KeyBox,
        inside: bool,
        buf: &mut Vec<f64>,
    ) {
        let sd = [s.len(0), s.len(1), s.len(2)];
        buf.clear();
        buf.resize(sd[0] * sd[1] * sd[2], f64::INFINITY);
        let (wl, wh) = (ring.low, ring.high());
        // Border sites just outside the window, for the inside transform, on the axes where
        // the box reaches the window's faces.
        let border =
            |i: usize| -> (bool, bool) { (inside && s.lo[i] == wl[i], inside && s.hi[i] == wh[i]) };
        let xs: Vec<usize> = (s.lo[0]..=s.hi[0]).map(|x| ring.axis_slot(0, x)).collect();
        // Pass 1, along x, on every line of `s`: distance to the nearest site on the line.
        let (bx_lo, bx_hi) = border(0);
        for lz in 0..sd[2] {
            let sz = ring.axis_slot(2, s.lo[2] + lz as i64);
            for ly in 0..sd[1] {
                let sy = ring.axis_slot(1, s.lo[1] + ly as i64);
                let row = ring.dims[0] * (sy + ring.dims[1] * sz);
                let base = sd[0] * (ly + sd[1] * lz);
                let line = &mut buf[base..base + sd[0]];
                // Forward sweep: distance to the last site at or before x.
                let mut last: Option<i64> = bx_lo.then_some(-1);
                for (lx, &sx) in xs.iter().enumerate() {
                    if occupied[row + sx] != inside {
                        last = Some(lx as i64);
                    }
                    if let Some(p) = last {
                        let d = (lx as i64 - p) as f64;
                        line[lx] = d * d;
                    }
                }
                // Backward sweep: the next site at or after x.
                let mut next: Option<i64> = bx_hi.then_some(sd[0] as i64);
                for lx in (0..sd[0]).rev() {
                    if line[lx] == 0.0 {
                        next = Some(lx as i64);
                    } else if let Some(p) = next {
                        let d = (p - lx as i64) as f64;
                        line[lx] = line[lx].min(d * d);
                    }
                }
            }
        }
        // Passes 2 (along y) and 3 (along z), only on the lines that reach `t`.
        let tx = ((t.lo[0] - s.lo[0]) as usize, (t.hi[0] - s.lo[0]) as usize);
        let ty = ((t.lo[1] - s.lo[1]) as usize, (t.hi[1] - s.lo[1]) as usize);
        let (by_lo, by_hi) = border(1);
        for lz in 0..sd[2] {
            for lx in tx.0..=tx.1 {
                let base = lx + sd[0] * sd[1] * lz;
                self.line_pass(buf, base, sd[0], sd[1], by_lo, by_hi);
            }
        }
        let (bz_lo, bz_hi) = border(2);
        for ly in ty.0..=ty.1 {
            for lx in tx.0..=tx.1 {
                let base = lx + sd[0] * ly;
                self.line_pass(buf, base, sd[0] * sd[1], sd[2], bz_lo, bz_hi);
            }
        }
    }

    /// One 1-D transform of the `n` values of `buf` at `base + k * stride`, with border sites
    /// (value 0) one step before the first and after the last value when asked.
    fn line_pass(
        &mut self,
        buf: &mut [f64],
        base: usize,
        stride: usize,
        n: usize,
        border_lo: bool,
        border_hi: bool,
    ) {
        let pad = usize::from(border_lo);
        let len = n + pad + usize::from(border_hi);
        self.line.clear();
        if border_lo {
            self.line.push(0.0);
        }
        let (mut all_zero, mut all_inf) = (true, true);
        for k in 0..n {
            let v = buf[base + k * stride];
            all_zero &= v == 0.0;
            all_inf &= v == f64::INFINITY;
            self.line.push(v);
        }
        if border_hi {
            self.line.push(0.0);
        }
        // Lines the transform leaves unchanged.
        if all_zero || (all_inf && !border_lo && !border_hi) {
            return;
        }
        self.out.clear();
        self.out.resize(len, 0.0);
        edt_1d_with_scratch(&self.line, &mut self.out, &mut self.scratch);
        for k in 0..n {
            buf[base + k * stride] = self.out[k + pad];
        }
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
