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

use crate::ring::{Indexer, Ring};
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
    /// Pass buffers in bytes (`r ≤ 15`: squared distances within reach fit `u8`) or in `u16`.
    narrow: Passes<u8>,
    wide: Passes<u16>,
    /// One row of occupancy, and `min(√j, r)` for `j` in `0..=r²`.
    occ_row: Vec<bool>,
    root: Vec<f64>,
}

/// The buffers of the three passes, in an unsigned integer type `T` whose saturating sums keep
/// every squared distance within reach (`≤ r²`) exact and every other above `r²`.
#[derive(Debug, Clone, Default)]
struct Passes<T> {
    /// After the x pass (`T_x × S_y × S_z`), after the y pass (`T_x × T_y × S_z`), a row of
    /// the z pass.
    pass_x: Vec<T>,
    pass_y: Vec<T>,
    row: Vec<T>,
    /// Whether a row of `pass_x` / `pass_y` holds a value within reach (rows that do not are
    /// neither written nor read).
    live_x: Vec<bool>,
    live_y: Vec<bool>,
}

/// A squared distance in voxels as an unsigned integer (`u8` or `u16`), `MAX` standing for
/// "beyond the truncation".
trait Sq: Copy + Ord + Default + std::fmt::Debug {
    const MAX: Self;
    fn of(v: i64) -> Self;
    fn sat_add(self, other: Self) -> Self;
    fn index(self) -> usize;
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
            fn index(self) -> usize {
                usize::from(self)
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
fn runs(start: usize, len: usize, n: usize) -> [(usize, usize); 2] {
    let first = len.min(n - start);
    [(start, first), (0, len - first)]
}

impl DistanceField {
    /// A field for `slots` slots, truncated at `r` voxels, for a window without occupied voxels
    /// (every value `r · res`).
    pub fn new(slots: usize, r: i64, res: f64) -> Self {
        let rf = r as f64;
        Self {
            r,
            dist: vec![rf * res; slots],
            recomputed_count: 0,
            narrow: Passes::default(),
            wide: Passes::default(),
            occ_row: Vec::new(),
            root: (0..=r * r).map(|j| (j as f64).sqrt().min(rf)).collect(),
        }
    }

    /// Sets every value to that of a window without occupied voxels.
    pub fn reset(&mut self, res: f64) {
        self.dist.fill(self.r as f64 * res);
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
            dist: &mut self.dist,
            occ_row: &mut self.occ_row,
            root: &self.root,
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
    dist: &'a mut [f64],
    occ_row: &'a mut Vec<bool>,
    root: &'a [f64],
    r: i64,
}

impl Out<'_> {
    /// The three passes over the target box `t` from the sites in `s` (`t` grown by `r`).
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
        p.pass_x.resize(tx * sy * sz, T::MAX);
        p.live_x.clear();
        p.live_x.resize(sy * sz, false);
        self.occ_row.resize(sx, false);
        for lz in 0..sz {
            let slot_z = ix.axis_slot(2, s.lo[2] + lz as i64);
            for ly in 0..sy {
                let slot_y = ix.axis_slot(1, s.lo[1] + ly as i64);
                let row_index = slot_y + d[1] * slot_z;
                let row = d[0] * row_index;
                if rows.is_some_and(|c| c[row_index] == 0) {
                    continue;
                }
                let mut any = false;
                let mut at = 0;
                for (start, len) in s_runs {
                    let src = &occupied[row + start..][..len];
                    self.occ_row[at..at + len].copy_from_slice(src);
                    any |= src.contains(&true);
                    at += len;
                }
                if !any {
                    continue;
                }
                let out = &mut p.pass_x[tx * (ly + sy * lz)..][..tx];
                out.fill(T::MAX);
                let mut live = false;
                // Forward: the last site at or before x; backward: the next at or after.
                let mut last = i64::MIN / 2;
                for lx in 0..ox + tx {
                    if self.occ_row[lx] {
                        last = lx as i64;
                    }
                    if lx >= ox && lx as i64 - last <= r {
                        let g = lx as i64 - last;
                        out[lx - ox] = T::of(g * g);
                        live = true;
                    }
                }
                let mut next = i64::MAX / 2;
                for lx in (ox..sx).rev() {
                    if self.occ_row[lx] {
                        next = lx as i64;
                    }
                    if lx < ox + tx && next - lx as i64 <= r {
                        let g = next - lx as i64;
                        let o = &mut out[lx - ox];
                        *o = (*o).min(T::of(g * g));
                        live = true;
                    }
                }
                p.live_x[ly + sy * lz] = live;
            }
        }

        // Pass y: for (x, y) in T, every z of S: min over |j| <= r of pass_x(y + j) + j².
        p.pass_y.resize(tx * ty * sz, T::MAX);
        p.live_y.clear();
        p.live_y.resize(ty * sz, false);
        for lz in 0..sz {
            for iy in 0..ty {
                let ly = oy + iy;
                let lo = ly.saturating_sub(r as usize);
                let hi = (ly + r as usize).min(sy - 1);
                let live_rows = &p.live_x[lo + sy * lz..=hi + sy * lz];
                if !live_rows.contains(&true) {
                    continue;
                }
                let out = &mut p.pass_y[tx * (iy + ty * lz)..][..tx];
                out.fill(T::MAX);
                for (src, _) in (lo..=hi).zip(live_rows).filter(|(_, l)| **l) {
                    let j = src as i64 - ly as i64;
                    let input = &p.pass_x[tx * (src + sy * lz)..][..tx];
                    min_plus(out, input, T::of(j * j));
                }
                p.live_y[iy + ty * lz] = true;
            }
        }

        // Pass z and the field: for (x, y, z) in T, min over |j| <= r of pass_y(z + j) + j².
        let rf = r as f64;
        let res = ring.res;
        let far = res * rf;
        p.row.resize(tx, T::MAX);
        for iz in 0..tz {
            let z = t.lo[2] + iz as i64;
            let lz = oz + iz;
            let slot_z = ix.axis_slot(2, z);
            let lo = lz.saturating_sub(r as usize);
            let hi = (lz + r as usize).min(sz - 1);
            for iy in 0..ty {
                let y = t.lo[1] + iy as i64;
                let row = d[0] * (ix.axis_slot(1, y) + d[1] * slot_z);
                let mut live = false;
                for src in lo..=hi {
                    if !p.live_y[iy + ty * src] {
                        continue;
                    }
                    let input = &p.pass_y[tx * (iy + ty * src)..][..tx];
                    let j = src as i64 - lz as i64;
                    if live {
                        min_plus(&mut p.row, input, T::of(j * j));
                    } else {
                        plus(&mut p.row, input, T::of(j * j));
                        live = true;
                    }
                }
                if !live {
                    // No site within reach: no voxel of the row is occupied either.
                    for (start, len) in t_runs {
                        self.dist[row + start..][..len].fill(far);
                    }
                    continue;
                }
                let mut at = 0;
                for (start, len) in t_runs {
                    let dist = &mut self.dist[row + start..][..len];
                    let occ = &occupied[row + start..][..len];
                    let sq = &p.row[at..at + len];
                    for (i, ((o, &dsq), &is_occ)) in dist.iter_mut().zip(sq).zip(occ).enumerate() {
                        let dsq = dsq.index();
                        let d_occ = if dsq < self.root.len() {
                            self.root[dsq]
                        } else {
                            rf
                        };
                        let d_free = if is_occ {
                            let k = [t.lo[0] + (at + i) as i64, y, z];
                            inside_sq(&ix, occupied, &k, r).sqrt().min(rf)
                        } else {
                            0.0
                        };
                        *o = res * (d_occ - d_free);
                    }
                    at += len;
                }
            }
        }
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

/// `out[i] = input[i] + add` (saturating): the first step of a pass.
#[inline]
fn plus<T: Sq>(out: &mut [T], input: &[T], add: T) {
    for (o, &v) in out.iter_mut().zip(input) {
        *o = v.sat_add(add);
    }
}

/// Squared distance (voxels) from the occupied voxel `k` to the nearest non-occupied voxel
/// centre or site outside the window, exact when at most `r²` (larger values are only known to
/// exceed `r²`): a face neighbour first, then shells of growing Chebyshev radius until no
/// closer voxel can remain.
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

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// The passes in bytes and in `u16`, with and without the row counts, equal the brute
        /// force in the target box and leave every other slot alone, for truncations on both
        /// sides of the byte's reach (`r = 15`).
        #[test]
        fn passes_equal_the_brute_force(
            dims in (2usize..14, 2usize..14, 2usize..10),
            low in (-20i64..20, -20i64..20, -20i64..20),
            r in 1i64..20,
            density in 0.0f64..0.5,
            seed in any::<u64>(),
            corner in (0usize..14, 0usize..14, 0usize..10),
            size in (0i64..8, 0i64..8, 0i64..6),
        ) {
            use rand::{Rng, SeedableRng};
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
            let ring = Ring { dims: [dims.0, dims.1, dims.2], low: [low.0, low.1, low.2], res: 0.1 };
            let occupied: Vec<bool> = (0..ring.len()).map(|_| rng.random_bool(density)).collect();
            let rows: Vec<u32> = occupied
                .chunks(dims.0)
                .map(|row| row.iter().filter(|&&o| o).count() as u32)
                .collect();
            let c = [low.0 + corner.0 as i64, low.1 + corner.1 as i64, low.2 + corner.2 as i64];
            let target = KeyBox { lo: c, hi: [c[0] + size.0, c[1] + size.1, c[2] + size.2] };
            let inside = |k: &VoxelKey| (0..3).all(|i| k[i] >= target.lo[i] && k[i] <= target.hi[i]);
            for wide in [false, true] {
                if !wide && r > 15 {
                    continue;
                }
                for with_rows in [false, true] {
                    let mut field = DistanceField::new(ring.len(), r, ring.res);
                    field.dist.fill(-7.0);
                    let rows = with_rows.then_some(&rows[..]);
                    field.recompute_in(&ring, &occupied, rows, &target, wide);
                    let (lo, hi) = (ring.low, ring.high());
                    for z in lo[2]..=hi[2] {
                        for y in lo[1]..=hi[1] {
                            for x in lo[0]..=hi[0] {
                                let k = [x, y, z];
                                let got = field.dist[ring.slot(&k)];
                                let expect = if inside(&k) { brute(&ring, &occupied, &k, r) } else { -7.0 };
                                prop_assert!((got - expect).abs() < 1e-12, "{:?} wide {} rows {}: {} vs {}", k, wide, with_rows, got, expect);
                            }
                        }
                    }
                }
            }
        }
    }
}
