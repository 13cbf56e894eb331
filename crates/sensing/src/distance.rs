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
//! and keeps squared distances in bytes (`u16` past `R = 15` voxels), saturating. Values above
//! `R²` stand for "beyond the truncation", which is all the field reads of them. The field keeps
//! per slot a two-byte code of the value (a squared distance, see [`DistanceField::code`]),
//! decoded through a table of `f64` (the same bits as computing each value). The inside distance
//! of an occupied voxel (to the nearest non-occupied one) is a local search instead: surfaces
//! seen by a sensor are thin, so it is almost always one voxel (a free face neighbour). The
//! result equals a full recomputation voxel for voxel (property test).

use crate::ring::{Indexer, Ring};
use crate::traversal::VoxelKey;

/// Signed distances per slot of the ring, truncated at `r` voxels, and reusable buffers.
#[derive(Debug, Clone)]
pub(crate) struct DistanceField {
    /// Truncation distance in voxels.
    pub r: i64,
    /// Per slot, the code of the signed distance `res · (min(√D_occ, r) − min(√D_free, r))`
    /// (metres), with `D_occ` (`D_free`) the squared distance in voxels to the nearest occupied
    /// (non-occupied) voxel centre, everything outside the window counting as non-occupied:
    /// `D_occ` for a non-occupied voxel (`r² + 1` for any beyond `r²`), else
    /// `r² + 2 + min(D_free, r²)` (an occupied voxel has `D_occ = 0`). `table` decodes it.
    pub code: Vec<u16>,
    /// The value (m) of each code, computed as the formula above computes it.
    table: Vec<f64>,
    /// Voxels recomputed so far (for reports and benches).
    pub recomputed_count: u64,
    /// Pass buffers in bytes (`r ≤ 15`: squared distances within reach fit `u8`) or in `u16`.
    narrow: Passes<u8>,
    wide: Passes<u16>,
    /// The occupied voxels of one row (x offsets in the source box).
    sites: Vec<u32>,
}

/// The buffers of the three passes, in an unsigned integer type `T` whose saturating sums keep
/// every squared distance within reach (`≤ r²`) exact and every other above `r²`.
#[derive(Debug, Clone, Default)]
struct Passes<T> {
    /// After the x pass (`T_x × S_y × S_z`), after the y pass (`T_x × T_y × S_z`), a plane of
    /// the z pass (`T_x × T_y`).
    pass_x: Vec<T>,
    pass_y: Vec<T>,
    row: Vec<T>,
    /// Per z plane of `pass_x` / `pass_y`: the range of rows `(lo, hi)` outside which no row
    /// holds a value within reach (`lo > hi`: none); rows outside it are not read.
    live_x: Vec<(usize, usize)>,
    live_y: Vec<(usize, usize)>,
}

/// A squared distance in voxels as an unsigned integer (`u8` or `u16`), `MAX` standing for
/// "beyond the truncation".
trait Sq: Copy + Ord + Default + std::fmt::Debug {
    const MAX: Self;
    fn of(v: i64) -> Self;
    fn sat_add(self, other: Self) -> Self;
    fn to_u16(self) -> u16;
}

/// `Sq` for an unsigned integer type: its maximum, a truncating cast, a saturating add.
macro_rules! impl_sq {
    ($t:ty) => {
        impl Sq for $t {
            const MAX: Self = <$t>::MAX;
            #[inline]
            fn of(v: i64) -> Self {
                v as $t
            }
            #[inline]
            fn sat_add(self, other: Self) -> Self {
                self.saturating_add(other)
            }
            #[inline]
            fn to_u16(self) -> u16 {
                u16::from(self)
            }
        }
    };
}

impl_sq!(u8);
impl_sq!(u16);

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

/// The slots of the `len` consecutive x coordinates from the one in slot `start` of a ring
/// axis of `n` slots: at most two contiguous runs, `(first slot, length)`.
#[inline]
pub(crate) fn runs(start: usize, len: usize, n: usize) -> [(usize, usize); 2] {
    let first = len.min(n - start);
    [(start, first), (0, len - first)]
}

impl DistanceField {
    /// A field for `slots` slots, truncated at `r` voxels (at most 64), for a window without
    /// occupied voxels (every value `r · res`).
    pub fn new(slots: usize, r: i64, res: f64) -> Self {
        let rf = r as f64;
        let root = |j: i64| (j as f64).sqrt().min(rf);
        let r2 = r * r;
        // Non-occupied (`D_free = 0`), beyond the truncation, occupied (`D_occ = 0`).
        let table = (0..=r2)
            .map(|j| res * (root(j) - 0.0))
            .chain([res * (rf - 0.0)])
            .chain((0..=r2).map(|j| res * (0.0 - root(j))))
            .collect();
        Self {
            r,
            code: vec![(r2 + 1) as u16; slots],
            table,
            recomputed_count: 0,
            narrow: Passes::default(),
            wide: Passes::default(),
            sites: Vec::new(),
        }
    }

    /// The code of "no occupied voxel within reach" (the value `r · res`).
    pub fn beyond(&self) -> u16 {
        (self.r * self.r + 1) as u16
    }

    /// The signed distance (m) of a code.
    #[inline]
    pub fn value(&self, code: u16) -> f64 {
        self.table[usize::from(code)]
    }

    /// Appends the values of `codes` to `out`.
    pub fn decode_into(&self, codes: &[u16], out: &mut Vec<f64>) {
        out.extend(codes.iter().map(|&c| self.table[usize::from(c)]));
    }

    /// Sets every value to that of a window without occupied voxels.
    pub fn reset(&mut self) {
        let beyond = self.beyond();
        self.code.fill(beyond);
    }

    /// Recomputes the exact field over `target` (clipped to the window) for the occupancy
    /// `occupied` (per slot); `rows`, if given, counts the occupied voxels of each x row of
    /// slots (slot / `dims.x`), so that rows without any are skipped unread.
    pub fn recompute(
        &mut self,
        ring: &Ring,
        occupied: &[bool],
        rows: Option<&[u32]>,
        target: &KeyBox,
    ) {
        self.recompute_in(ring, occupied, rows, target, self.r > 15);
    }

    /// [`DistanceField::recompute`] with the passes in `u16` if `wide`, else in `u8` (only for
    /// `r ≤ 15`).
    fn recompute_in(
        &mut self,
        ring: &Ring,
        occupied: &[bool],
        rows: Option<&[u32]>,
        target: &KeyBox,
        wide: bool,
    ) {
        let Some(t) = target.grown_within(0, ring) else {
            return;
        };
        let Some(s) = t.grown_within(self.r, ring) else {
            return;
        };
        let mut out = Out {
            code: &mut self.code,
            sites: &mut self.sites,
            r: self.r,
        };
        if wide {
            out.passes(&mut self.wide, ring, occupied, rows, &t, &s);
        } else {
            out.passes(&mut self.narrow, ring, occupied, rows, &t, &s);
        }
        self.recomputed_count += (t.len(0) * t.len(1) * t.len(2)) as u64;
    }
}

/// What the passes write and read besides their buffers.
struct Out<'a> {
    code: &'a mut [u16],
    sites: &'a mut Vec<u32>,
    r: i64,
}

impl Out<'_> {
    /// The three passes over the target box `t` from the sites in `s` (`t` grown by `r`).
    ///
    /// Each pass works plane by plane (a z plane of its buffer, x fastest): for an offset `j`
    /// the rows that take `j` from live source rows form one contiguous block, so the minimum
    /// runs over whole blocks. Every plane keeps the range of its rows that may hold a value
    /// within reach (the rest are not read).
    fn passes<T: Sq>(
        &mut self,
        p: &mut Passes<T>,
        ring: &Ring,
        occupied: &[bool],
        rows: Option<&[u32]>,
        t: &KeyBox,
        s: &KeyBox,
    ) {
        let r = self.r;
        let ru = r as usize;
        let ix = ring.indexer();
        let (tx, ty, tz) = (t.len(0), t.len(1), t.len(2));
        let (sx, sy, sz) = (s.len(0), s.len(1), s.len(2));
        let d = ring.dims;
        // Offsets of `T` inside `S`.
        let (ox, oy, oz) = (
            (t.lo[0] - s.lo[0]) as usize,
            (t.lo[1] - s.lo[1]) as usize,
            (t.lo[2] - s.lo[2]) as usize,
        );
        let s_runs = runs(ix.axis_slot(0, s.lo[0]), sx, d[0]);
        let t_runs = runs(ix.axis_slot(0, t.lo[0]), tx, d[0]);

        // Pass x: for x in T, every (y, z) of S, the squared distance to the nearest occupied
        // voxel of the row within `r` (`MAX` if none).
        p.pass_x.clear();
        p.pass_x.resize(tx * sy * sz, T::MAX);
        p.live_x.clear();
        p.live_x.resize(sz, EMPTY);
        for lz in 0..sz {
            let slot_z = ix.axis_slot(2, s.lo[2] + lz as i64);
            for ly in 0..sy {
                let slot_y = ix.axis_slot(1, s.lo[1] + ly as i64);
                let row_index = slot_y + d[1] * slot_z;
                let row = d[0] * row_index;
                if rows.is_some_and(|c| c[row_index] == 0) {
                    continue;
                }
                self.sites.clear();
                let mut at = 0;
                for (start, len) in s_runs {
                    push_sites(&occupied[row + start..][..len], at, self.sites);
                    at += len;
                }
                if self.sites.is_empty() {
                    continue;
                }
                let out = &mut p.pass_x[tx * (ly + sy * lz)..][..tx];
                let mut live = false;
                // Each site writes its reach up to its neighbour sites: every x of T gets the
                // nearest site on each side (if within `r`), the nearest of all among them.
                let (t0, t1) = (ox as i64, (ox + tx) as i64 - 1);
                for (i, &site) in self.sites.iter().enumerate() {
                    let site = i64::from(site);
                    let left = if i > 0 {
                        i64::from(self.sites[i - 1])
                    } else {
                        i64::MIN / 2
                    };
                    let right = self
                        .sites
                        .get(i + 1)
                        .map_or(i64::MAX / 2, |&n| i64::from(n));
                    let lo = left.max(site - r).max(t0);
                    let hi = right.min(site + r).min(t1);
                    for x in lo..=hi {
                        let g = x - site;
                        let o = &mut out[(x - t0) as usize];
                        *o = (*o).min(T::of(g * g));
                    }
                    live |= lo <= hi;
                }
                if live {
                    let range = &mut p.live_x[lz];
                    *range = (range.0.min(ly), ly);
                }
            }
        }

        // Pass y: for (x, y) in T, every z of S: min over |j| <= r of pass_x(y + j) + j².
        p.pass_y.resize(tx * ty * sz, T::MAX);
        p.live_y.clear();
        p.live_y.resize(sz, EMPTY);
        for lz in 0..sz {
            let (xlo, xhi) = p.live_x[lz];
            if xlo > xhi {
                continue;
            }
            // Rows of T within `r` of a live source row.
            let ylo = (xlo.saturating_sub(ru)).max(oy) - oy;
            let yhi = (xhi + ru).min(oy + ty - 1);
            if yhi < oy + ylo {
                continue;
            }
            let yhi = yhi - oy;
            p.live_y[lz] = (ylo, yhi);
            let plane_in = &p.pass_x[tx * sy * lz..][..tx * sy];
            let plane_out = &mut p.pass_y[tx * ty * lz..][..tx * ty];
            plane_out[tx * ylo..tx * (yhi + 1)].fill(T::MAX);
            for j in -r..=r {
                // Output rows `iy` whose source `oy + iy + j` is in `[xlo, xhi]`.
                let a = (xlo as i64 - oy as i64 - j).max(ylo as i64);
                let b = (xhi as i64 - oy as i64 - j).min(yhi as i64);
                if a > b {
                    continue;
                }
                let (a, b) = (a as usize, b as usize);
                let src = (oy as i64 + a as i64 + j) as usize;
                min_plus(
                    &mut plane_out[tx * a..tx * (b + 1)],
                    &plane_in[tx * src..tx * (src + b - a + 1)],
                    T::of(j * j),
                );
            }
        }

        // Pass z and the field: for (x, y, z) in T, min over |j| <= r of pass_y(z + j) + j².
        let r2 = (r * r) as usize;
        let (wlo, whi) = (ring.low, ring.high());
        let beyond = (r2 + 1) as u16;
        let inside_base = (r2 + 2) as u16;
        p.row.resize(tx * ty, T::MAX);
        for iz in 0..tz {
            let z = t.lo[2] + iz as i64;
            let lz = oz + iz;
            let slot_z = ix.axis_slot(2, z);
            let src_lo = lz.saturating_sub(ru);
            let src_hi = (lz + ru).min(sz - 1);
            // The rows some source plane may reach.
            let (mut ylo, mut yhi) = EMPTY;
            for &(a, b) in &p.live_y[src_lo..=src_hi] {
                if a <= b {
                    (ylo, yhi) = (ylo.min(a), yhi.max(b));
                }
            }
            if ylo <= yhi {
                p.row[tx * ylo..tx * (yhi + 1)].fill(T::MAX);
                for src in src_lo..=src_hi {
                    let (a, b) = p.live_y[src];
                    if a > b {
                        continue;
                    }
                    let j = src as i64 - lz as i64;
                    let input = &p.pass_y[tx * (ty * src + a)..tx * (ty * src + b + 1)];
                    min_plus(&mut p.row[tx * a..tx * (b + 1)], input, T::of(j * j));
                }
            }
            for iy in 0..ty {
                let y = t.lo[1] + iy as i64;
                let row_index = ix.axis_slot(1, y) + d[1] * slot_z;
                let row = d[0] * row_index;
                if !(ylo..=yhi).contains(&iy) {
                    // No site within reach: no voxel of the row is occupied either.
                    for (start, len) in t_runs {
                        self.code[row + start..][..len].fill(beyond);
                    }
                    continue;
                }
                // Rows without an occupied voxel (by the counts) are not scanned for one.
                let any_occupied = rows.is_none_or(|c| c[row_index] > 0);
                // For the inside distances: whether the row lies on a face of the window (a
                // site outside at distance 1), and the slot offsets of its four neighbour rows.
                let on_face = y == wlo[1] || y == whi[1] || z == wlo[2] || z == whi[2];
                let sy_slot = row_index % d[1];
                let neighbours = [
                    step(sy_slot, d[0], d[1], false),
                    step(sy_slot, d[0], d[1], true),
                    step(slot_z, d[0] * d[1], d[2], false),
                    step(slot_z, d[0] * d[1], d[2], true),
                ];
                let mut at = 0;
                for (start, len) in t_runs {
                    let code = &mut self.code[row + start..][..len];
                    let sq = &p.row[tx * iy + at..][..len];
                    for (c, &dsq) in code.iter_mut().zip(sq) {
                        *c = dsq.to_u16().min(beyond);
                    }
                    if any_occupied {
                        self.sites.clear();
                        push_sites(&occupied[row + start..][..len], 0, self.sites);
                        for &i in self.sites.iter() {
                            let i = i as usize;
                            // Its own site: `D_occ = 0`.
                            debug_assert_eq!(code[i], 0);
                            let x = t.lo[0] + (at + i) as i64;
                            let slot = row + start + i;
                            // A face of the window or a non-occupied face neighbour: 1, the
                            // least there is (as `inside_sq`, which searches further).
                            let sx = start + i;
                            let face = on_face
                                || x == wlo[0]
                                || x == whi[0]
                                || !occupied[slot - sx + if sx == 0 { d[0] - 1 } else { sx - 1 }]
                                || !occupied[slot - sx + if sx + 1 == d[0] { 0 } else { sx + 1 }]
                                || neighbours
                                    .iter()
                                    .any(|&n| !occupied[(slot as isize + n) as usize]);
                            let inside = if face {
                                1.0
                            } else {
                                inside_sq(&ix, occupied, &[x, y, z], r).min(r2 as f64)
                            };
                            code[i] = inside_base + inside as u16;
                        }
                    }
                    at += len;
                }
            }
        }
    }
}

/// The slot offset, along an axis of `n` slots and stride `stride`, from a voxel in slot `s`
/// to the one below it (or above it if `up`): the ring wraps.
#[inline]
fn step(s: usize, stride: usize, n: usize, up: bool) -> isize {
    let (stride, n) = (stride as isize, n as isize);
    match up {
        false if s == 0 => stride * (n - 1),
        false => -stride,
        true if s as isize + 1 == n => -stride * (n - 1),
        true => stride,
    }
}

/// An empty range of rows (`lo > hi`).
const EMPTY: (usize, usize) = (usize::MAX, 0);

/// Appends `base + i` for every `i` with `occupied[i]` to `sites`, in order (eight voxels at a
/// time past empty stretches).
#[inline]
fn push_sites(occupied: &[bool], base: usize, sites: &mut Vec<u32>) {
    let mut chunks = occupied.chunks_exact(8);
    let mut at = base;
    for chunk in &mut chunks {
        if chunk.iter().fold(false, |a, &o| a | o) {
            for (i, _) in chunk.iter().enumerate().filter(|(_, o)| **o) {
                sites.push((at + i) as u32);
            }
        }
        at += 8;
    }
    for (i, _) in chunks.remainder().iter().enumerate().filter(|(_, o)| **o) {
        sites.push((at + i) as u32);
    }
}

/// `out[i] = min(out[i], input[i] + add)` (one step of a truncated 1-D distance pass, the sum
/// saturating; written so that it vectorizes).
#[inline]
fn min_plus<T: Sq>(out: &mut [T], input: &[T], add: T) {
    for (o, &v) in out.iter_mut().zip(input) {
        let c = v.sat_add(add);
        *o = if c < *o { c } else { *o };
    }
}

/// Squared distance (voxels) from the occupied voxel `k` to the nearest non-occupied voxel
/// centre or site outside the window, exact when at most `r²` (larger values are only known to
/// exceed `r²`): the 26 neighbours first (faces, edges, corners: distance² 1, 2, 3), the six
/// voxels two along an axis (4), then shells of growing Chebyshev radius until no closer voxel
/// can remain.
fn inside_sq(ix: &Indexer, occupied: &[bool], k: &VoxelKey, r: i64) -> f64 {
    let ring = &ix.ring;
    let (lo, hi) = (ring.low, ring.high());
    let d = ring.dims;
    let strides = [1, d[0], d[0] * d[1]];
    let s = [
        ix.axis_slot(0, k[0]),
        ix.axis_slot(1, k[1]),
        ix.axis_slot(2, k[2]),
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
    // The 26 neighbours are all inside the window here (`best >= 4`): per axis the slot
    // offsets of the voxel below, at and above (the ring wraps along each axis on its own).
    let mut delta = [[0isize; 3]; 3];
    for i in 0..3 {
        delta[i][0] = step(s[i], strides[i], d[i], false);
        delta[i][2] = step(s[i], strides[i], d[i], true);
    }
    let occupied_at = |c: [usize; 3]| {
        let q = slot as isize + delta[0][c[0]] + delta[1][c[1]] + delta[2][c[2]];
        occupied[q as usize]
    };
    // Face neighbours (distance² 1, the least possible), edge neighbours (2), corners (3):
    // all below every other site's 4.
    for i in 0..3 {
        for m in [0, 2] {
            let mut c = [1, 1, 1];
            c[i] = m;
            if !occupied_at(c) {
                return 1.0;
            }
        }
    }
    for (u, v) in [(0, 1), (0, 2), (1, 2)] {
        for (m, n) in [(0, 0), (0, 2), (2, 0), (2, 2)] {
            let mut c = [1, 1, 1];
            c[u] = m;
            c[v] = n;
            if !occupied_at(c) {
                return 2.0;
            }
        }
    }
    for c in 0..8 {
        if !occupied_at([2 * (c & 1), c & 2, (c & 4) / 2]) {
            return 3.0;
        }
    }
    // The shell of radius 1 is all occupied: nothing is nearer than 4 now; a window face two
    // voxels away, or a non-occupied voxel two voxels along an axis, is at 4.
    if best <= 4.0 {
        return best;
    }
    for i in 0..3 {
        let (stride, n) = (strides[i], d[i]);
        let below = if s[i] == 0 { n - 1 } else { s[i] - 1 };
        let above = if s[i] + 1 == n { 0 } else { s[i] + 1 };
        for q in [
            slot as isize + delta[i][0] + step(below, stride, n, false),
            slot as isize + delta[i][2] + step(above, stride, n, true),
        ] {
            if !occupied[q as usize] {
                return 4.0;
            }
        }
    }
    // Search the shells from radius 2.
    for rho in 2..=r {
        if (rho * rho) as f64 >= best {
            break;
        }
        for dz in -rho..=rho {
            for dy in -rho..=rho {
                let on_shell = dz.abs() == rho || dy.abs() == rho;
                let mut dx = -rho;
                while dx <= rho {
                    let q = [k[0] + dx, k[1] + dy, k[2] + dz];
                    if ix.slot_in(&q).is_some_and(|slot| !occupied[slot]) {
                        best = best.min((dx * dx + dy * dy + dz * dz) as f64);
                    }
                    dx += if on_shell { 1 } else { 2 * rho };
                }
            }
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// The truncated signed distance of voxel `q` by brute force over the window (the field's
    /// convention: sites outside the window count as non-occupied).
    fn brute(ring: &Ring, occupied: &[bool], q: &VoxelKey, r: i64) -> f64 {
        let (lo, hi) = (ring.low, ring.high());
        let mut d_occ = f64::INFINITY;
        let mut d_free = (0..3)
            .map(|i| (q[i] - lo[i] + 1).min(hi[i] - q[i] + 1).pow(2) as f64)
            .fold(f64::INFINITY, f64::min);
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    let k = [x, y, z];
                    let d2 = (0..3).map(|i| (k[i] - q[i]).pow(2)).sum::<i64>() as f64;
                    if occupied[ring.slot(&k)] {
                        d_occ = d_occ.min(d2);
                    } else {
                        d_free = d_free.min(d2);
                    }
                }
            }
        }
        let rf = r as f64;
        ring.res * (d_occ.sqrt().min(rf) - d_free.sqrt().min(rf))
    }

    /// A window of `dims` voxels from `low`, each occupied with probability `density`, and its
    /// occupied count per x row.
    fn random_window(
        dims: (usize, usize, usize),
        low: (i64, i64, i64),
        density: f64,
        seed: u64,
    ) -> (Ring, Vec<bool>, Vec<u32>) {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let ring = Ring {
            dims: [dims.0, dims.1, dims.2],
            low: [low.0, low.1, low.2],
            res: 0.1,
        };
        let occupied: Vec<bool> = (0..ring.len()).map(|_| rng.random_bool(density)).collect();
        let rows: Vec<u32> = occupied
            .chunks(dims.0)
            .map(|row| row.iter().filter(|&&o| o).count() as u32)
            .collect();
        (ring, occupied, rows)
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// The passes in bytes and in `u16`, with and without the row counts, equal the brute
        /// force in the target box and leave every other slot alone, for truncations on both
        /// sides of the byte's reach (`r = 15`), sparse and dense (inside distances beyond the
        /// 26 neighbours).
        #[test]
        fn passes_equal_the_brute_force(
            dims in (2usize..14, 2usize..14, 2usize..10),
            low in (-20i64..20, -20i64..20, -20i64..20),
            r in 1i64..20,
            density in prop_oneof![0.0f64..0.5, 0.8f64..0.98],
            seed in any::<u64>(),
            corner in (0usize..14, 0usize..14, 0usize..10),
            size in (0i64..8, 0i64..8, 0i64..6),
        ) {
            let (ring, occupied, rows) = random_window(dims, low, density, seed);
            let c = [low.0 + corner.0 as i64, low.1 + corner.1 as i64, low.2 + corner.2 as i64];
            let target = KeyBox { lo: c, hi: [c[0] + size.0, c[1] + size.1, c[2] + size.2] };
            let inside = |k: &VoxelKey| (0..3).all(|i| k[i] >= target.lo[i] && k[i] <= target.hi[i]);
            for wide in [false, true] {
                if !wide && r > 15 {
                    continue;
                }
                for with_rows in [false, true] {
                    let mut field = DistanceField::new(ring.len(), r, ring.res);
                    field.code.fill(u16::MAX);
                    let rows = with_rows.then_some(&rows[..]);
                    field.recompute_in(&ring, &occupied, rows, &target, wide);
                    let (lo, hi) = (ring.low, ring.high());
                    for z in lo[2]..=hi[2] {
                        for y in lo[1]..=hi[1] {
                            for x in lo[0]..=hi[0] {
                                let k = [x, y, z];
                                let code = field.code[ring.slot(&k)];
                                let got = if code == u16::MAX { -7.0 } else { field.value(code) };
                                let expect = if inside(&k) { brute(&ring, &occupied, &k, r) } else { -7.0 };
                                prop_assert!((got - expect).abs() < 1e-12, "{:?} wide {} rows {}: {} vs {}", k, wide, with_rows, got, expect);
                            }
                        }
                    }
                }
            }
        }

        /// Nearly solid windows: the inside distances of occupied voxels (the 26 neighbours,
        /// the six two along an axis, the shells beyond) equal the brute force everywhere.
        #[test]
        fn inside_distances_equal_the_brute_force(
            dims in (7usize..11, 7usize..11, 7usize..11),
            low in (-20i64..20, -20i64..20, -20i64..20),
            r in 2i64..8,
            density in 0.85f64..0.995,
            seed in any::<u64>(),
        ) {
            let (ring, occupied, rows) = random_window(dims, low, density, seed);
            let mut field = DistanceField::new(ring.len(), r, ring.res);
            field.recompute(&ring, &occupied, Some(&rows), &KeyBox { lo: ring.low, hi: ring.high() });
            let (lo, hi) = (ring.low, ring.high());
            for z in lo[2]..=hi[2] {
                for y in lo[1]..=hi[1] {
                    for x in lo[0]..=hi[0] {
                        let k = [x, y, z];
                        let got = field.value(field.code[ring.slot(&k)]);
                        let expect = brute(&ring, &occupied, &k, r);
                        prop_assert!((got - expect).abs() < 1e-12, "{:?}: {} vs {}", k, got, expect);
                    }
                }
            }
        }
    }
}
