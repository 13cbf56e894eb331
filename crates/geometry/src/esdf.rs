//! Exact Euclidean distance transforms and the voxel signed distance field (ESDF) built from a
//! point cloud.
//!
//! The transform is the separable algorithm of Felzenszwalb & Huttenlocher ("Distance Transforms
//! of Sampled Functions", Theory of Computing 8, 2012): one pass per axis, each computing the lower
//! envelope of parabolas `(q - v)^2 + f(v)`, which yields *exact* squared Euclidean distances
//! between voxel centres in `O(n)` per voxel.

use crate::Vec3;
use crate::aabb::Aabb;
use crate::error::{GeometryError, check_positive};

/// Largest number of voxels a grid may have (200 million; about 1.6 GB of `f64`). Building the field
/// takes about 40 ns per voxel on the 2-core development machine, so grids above about 2²⁴ voxels
/// take more than the scale policy's 1 s per call ([`crate::scale`]): that work is proportional to
/// the grid the caller asked for (experiment E4's 250 × 75 × 20 m world at 0.2 m is 47 million
/// voxels, about 2 s), and the cap bounds it.
pub const MAX_VOXELS: usize = 200_000_000;

/// Reusable buffers for [`edt_1d_with_scratch`] (avoids allocating per line).
#[derive(Debug, Clone, Default)]
pub struct EdtScratch {
    /// Locations of the parabolas in the lower envelope.
    sites: Vec<usize>,
    /// Boundaries between consecutive envelope parabolas.
    bounds: Vec<f64>,
}

/// One-dimensional squared distance transform (Felzenszwalb–Huttenlocher lower envelope).
///
/// For every `q`, `out[q] = min_v ((q - v)^2 + f[v])`. `f` holds squared distances in voxel units
/// (`0` at sites, `f64::INFINITY` where there is none); entries equal to `+inf` (or NaN) are
/// skipped, so an all-infinite input gives an all-infinite output. `out` must have the length of `f` (only the
/// common prefix is written otherwise). Allocates two small buffers; see
/// [`edt_1d_with_scratch`] to reuse them.
pub fn edt_1d(f: &[f64], out: &mut [f64]) {
    edt_1d_with_scratch(f, out, &mut EdtScratch::default());
}

/// [`edt_1d`] with caller-provided scratch buffers.
pub fn edt_1d_with_scratch(f: &[f64], out: &mut [f64], scratch: &mut EdtScratch) {
    let n = f.len().min(out.len());
    let v = &mut scratch.sites;
    let z = &mut scratch.bounds;
    v.clear();
    z.clear();
    for (q, &fq) in f.iter().enumerate().take(n) {
        // Skips +inf (no site) and NaN entries.
        if fq.is_nan() || fq == f64::INFINITY {
            continue;
        }
        let qf = q as f64;
        // Pop parabolas that the new one hides entirely.
        while let Some(&top) = v.last() {
            let vf = top as f64;
            let s = ((fq + qf * qf) - (f[top] + vf * vf)) / (2.0 * (qf - vf));
            let z_top = *z.last().unwrap_or(&f64::NEG_INFINITY);
            if s <= z_top {
                v.pop();
                z.pop();
            } else {
                v.push(q);
                z.push(s);
                break;
            }
        }
        if v.is_empty() {
            v.push(q);
            z.push(f64::NEG_INFINITY);
        }
    }
    if v.is_empty() {
        out[..n].fill(f64::INFINITY);
        return;
    }
    // z[k] is the left boundary of parabola k; walk the envelope.
    let mut k = 0;
    for (q, o) in out.iter_mut().enumerate().take(n) {
        let qf = q as f64;
        while k + 1 < v.len() && z[k + 1] < qf {
            k += 1;
        }
        let d = qf - v[k] as f64;
        *o = d * d + f[v[k]];
    }
}

/// Linear index of voxel `(x, y, z)` in a grid of `dims` (x fastest).
pub fn voxel_index(dims: [usize; 3], x: usize, y: usize, z: usize) -> usize {
    x + dims[0] * (y + dims[1] * z)
}

/// Checks that `dims` has a positive number of voxels not above [`MAX_VOXELS`] and returns it.
pub fn checked_voxel_count(dims: [usize; 3]) -> Result<usize, GeometryError> {
    // Saturating: three `usize::MAX` dimensions overflow even a u128 product.
    let count = dims
        .iter()
        .fold(1u128, |acc, &d| acc.saturating_mul(d as u128));
    if count == 0 || count > MAX_VOXELS as u128 {
        return Err(GeometryError::GridTooLarge {
            nx: dims[0],
            ny: dims[1],
            nz: dims[2],
            count,
            limit: MAX_VOXELS,
        });
    }
    Ok(count as usize)
}

/// Exact 3-D squared Euclidean distance transform, in place, in voxel units.
///
/// On input `values[i]` is `0` at sites and `f64::INFINITY` elsewhere (any non-negative initial
/// values are allowed: the result is `min_v (|x - v|^2 + values[v])`). On output it holds the
/// squared distance from each voxel centre to the nearest site (`+inf` if there is none). Layout:
/// [`voxel_index`] (x fastest). Errors if `values.len()` does not match `dims` or the grid is
/// empty or larger than [`MAX_VOXELS`].
pub fn edt_3d(values: &mut [f64], dims: [usize; 3]) -> Result<(), GeometryError> {
    edt_3d_impl(values, dims, false)
}

/// Like [`edt_3d`], but with a layer of sites (value 0) just outside the grid on every side, as if
/// the grid were surrounded by one voxel of sites. Used for the inside distance of occupied
/// voxels, where everything outside the grid counts as free.
pub(crate) fn edt_3d_with_site_border(
    values: &mut [f64],
    dims: [usize; 3],
) -> Result<(), GeometryError> {
    edt_3d_impl(values, dims, true)
}

fn edt_3d_impl(values: &mut [f64], dims: [usize; 3], border: bool) -> Result<(), GeometryError> {
    let count = checked_voxel_count(dims)?;
    if values.len() != count {
        return Err(GeometryError::LengthMismatch {
            field: "values".into(),
            len: values.len(),
            expected: count,
        });
    }
    let pad = usize::from(border);
    let max_n = dims.iter().copied().max().unwrap_or(0) + 2 * pad;
    let mut line = vec![0.0; max_n];
    let mut out = vec![0.0; max_n];
    let mut scratch = EdtScratch::default();
    let strides = [1, dims[0], dims[0] * dims[1]];
    for axis in 0..3 {
        let n = dims[axis];
        let stride = strides[axis];
        let (a1, a2) = match axis {
            0 => (1, 2),
            1 => (0, 2),
            _ => (0, 1),
        };
        for j in 0..dims[a2] {
            for i in 0..dims[a1] {
                let base = i * strides[a1] + j * strides[a2];
                let len = n + 2 * pad;
                if border {
                    line[0] = 0.0;
                    line[len - 1] = 0.0;
                }
                let (mut all_zero, mut all_inf) = (true, true);
                for q in 0..n {
                    let x = values[base + q * stride];
                    all_zero &= x == 0.0;
                    all_inf &= x == f64::INFINITY;
                    line[q + pad] = x;
                }
                // Lines that the transform leaves unchanged (common in sparse maps).
                if all_zero || (all_inf && !border) {
                    continue;
                }
                edt_1d_with_scratch(&line[..len], &mut out[..len], &mut scratch);
                for q in 0..n {
                    values[base + q * stride] = out[q + pad];
                }
            }
        }
    }
    Ok(())
}

/// A voxel signed distance field with trilinear interpolation.
///
/// Voxel `(i, j, k)` has its centre at `origin + resolution * (i, j, k)`. The stored value is
/// `resolution * (sqrt(D_occ) - sqrt(D_free))`, where `D_occ` is the exact squared distance (voxel
/// units) from the voxel centre to the nearest occupied voxel centre and `D_free` the one to the
/// nearest free voxel centre, counting everything outside the grid as free. So free voxels hold the
/// positive distance to the nearest occupied voxel, occupied voxels a negative value, and the
/// interpolated zero level lies on the faces between free and occupied voxels. Relative to the
/// original points the field is accurate to about `resolution * sqrt(3) / 2`.
///
/// A grid without occupied voxels holds `+inf` everywhere; queries then return `+inf` with a zero
/// gradient.
#[derive(Debug, Clone, PartialEq)]
pub struct Esdf {
    origin: Vec3,
    resolution: f64,
    dims: [usize; 3],
    distances: Vec<f64>,
    occupied_count: usize,
    /// Minimum of the voxel values over each block of [`COARSE_BLOCK`]³ voxels plus the next
    /// voxel on the high side of every axis: a lower bound of the interpolant anywhere in the
    /// block ([`Esdf::lower_bound`]).
    coarse: Vec<f64>,
    coarse_dims: [usize; 3],
}

/// Voxels per axis of one block of the ESDF's coarse lower-bound grid.
pub const COARSE_BLOCK: usize = 8;

impl Esdf {
    /// Builds the field from an occupancy grid (`occupied[voxel_index(dims, i, j, k)]`).
    ///
    /// Errors on a non-finite `origin`, a non-positive `resolution`, an empty or too large grid, or
    /// an `occupied` slice of the wrong length.
    pub fn from_occupancy(
        origin: Vec3,
        resolution: f64,
        dims: [usize; 3],
        occupied: &[bool],
    ) -> Result<Self, GeometryError> {
        crate::error::check_vec("esdf.origin", &origin)?;
        check_positive("esdf.resolution", resolution)?;
        let count = checked_voxel_count(dims)?;
        if occupied.len() != count {
            return Err(GeometryError::LengthMismatch {
                field: "occupied".into(),
                len: occupied.len(),
                expected: count,
            });
        }
        let occupied_count = occupied.iter().filter(|&&o| o).count();
        let mut outside: Vec<f64> = occupied
            .iter()
            .map(|&o| if o { 0.0 } else { f64::INFINITY })
            .collect();
        edt_3d(&mut outside, dims)?;
        let mut distances = outside;
        if occupied_count > 0 {
            let mut inside: Vec<f64> = occupied
                .iter()
                .map(|&o| if o { f64::INFINITY } else { 0.0 })
                .collect();
            edt_3d_with_site_border(&mut inside, dims)?;
            for (d, i) in distances.iter_mut().zip(&inside) {
                *d = resolution * (d.sqrt() - i.sqrt());
            }
        }
        let (coarse, coarse_dims) = coarse_minima(&distances, dims);
        Ok(Self {
            origin,
            resolution,
            dims,
            distances,
            occupied_count,
            coarse,
            coarse_dims,
        })
    }

    /// A field from signed distances computed elsewhere (`distances[voxel_index(dims, i, j, k)]`,
    /// in metres, with the convention of [`Esdf`]: negative at occupied voxels, positive at free
    /// ones). An online map that keeps its own distance field incrementally (`trust-sensing`)
    /// hands it to a [`crate::StaticMap`] this way, without a second transform.
    ///
    /// Positive values may be lower bounds of the true distance (a field truncated at some
    /// distance stays conservative and keeps the slope bound the line-of-sight test relies on);
    /// `+inf` is allowed. Errors on a non-finite `origin`, a non-positive `resolution`, an empty
    /// or too large grid, a slice of the wrong length, or a NaN or `-inf` value (naming its
    /// index).
    pub fn from_signed_distances(
        origin: Vec3,
        resolution: f64,
        dims: [usize; 3],
        distances: Vec<f64>,
    ) -> Result<Self, GeometryError> {
        crate::error::check_vec("esdf.origin", &origin)?;
        check_positive("esdf.resolution", resolution)?;
        let count = checked_voxel_count(dims)?;
        if distances.len() != count {
            return Err(GeometryError::LengthMismatch {
                field: "distances".into(),
                len: distances.len(),
                expected: count,
            });
        }
        // One pass for the check and the count (the position only for the error).
        let (mut occupied_count, mut bad) = (0usize, false);
        for &d in &distances {
            occupied_count += usize::from(d < 0.0);
            bad |= d.is_nan() | (d == f64::NEG_INFINITY);
        }
        if bad {
            let i = distances
                .iter()
                .position(|d| d.is_nan() || *d == f64::NEG_INFINITY)
                .unwrap_or(0);
            return Err(GeometryError::non_finite(
                format!("distances[{i}]"),
                distances[i],
            ));
        }
        let (coarse, coarse_dims) = coarse_minima(&distances, dims);
        Ok(Self {
            origin,
            resolution,
            dims,
            distances,
            occupied_count,
            coarse,
            coarse_dims,
        })
    }

    /// A lower bound of [`Esdf::signed_distance`] at `p`, from the coarse grid of block minima:
    /// one memory access instead of eight, for rejecting points that are surely clear (the
    /// interpolant is a convex combination of its cell's corners, which all lie in `p`'s block
    /// or on its high faces; outside the grid the extrapolation only adds to the clamped value).
    /// `-inf` for a non-finite `p`.
    pub fn lower_bound(&self, p: &Vec3) -> f64 {
        if !p.iter().all(|c| c.is_finite()) {
            return f64::NEG_INFINITY;
        }
        let mut c = [0usize; 3];
        for i in 0..3 {
            c[i] = self.coarse_coord(i, p[i]);
        }
        self.coarse[voxel_index(self.coarse_dims, c[0], c[1], c[2])]
    }

    /// A lower bound of [`Esdf::signed_distance`] over the box `region` (the minimum over the
    /// coarse blocks it overlaps). `-inf` for a non-finite box.
    pub fn lower_bound_in(&self, region: &Aabb) -> f64 {
        if !region
            .min
            .iter()
            .chain(region.max.iter())
            .all(|c| c.is_finite())
        {
            return f64::NEG_INFINITY;
        }
        let mut lo = [0usize; 3];
        let mut hi = [0usize; 3];
        for i in 0..3 {
            lo[i] = self.coarse_coord(i, region.min[i]);
            hi[i] = self.coarse_coord(i, region.max[i]).max(lo[i]);
        }
        let mut m = f64::INFINITY;
        for z in lo[2]..=hi[2] {
            for y in lo[1]..=hi[1] {
                for x in lo[0]..=hi[0] {
                    m = m.min(self.coarse[voxel_index(self.coarse_dims, x, y, z)]);
                }
            }
        }
        m
    }

    /// The coarse block along axis `i` of world coordinate `x` (clamped into the grid).
    #[inline]
    fn coarse_coord(&self, i: usize, x: f64) -> usize {
        let n = self.dims[i];
        let g = ((x - self.origin[i]) / self.resolution).clamp(0.0, (n - 1) as f64);
        // The voxel whose cell holds `g` (the last cell's base is `n − 2`), then its block.
        let base = (g as usize).min(n.saturating_sub(2));
        (base / COARSE_BLOCK).min(self.coarse_dims[i] - 1)
    }

    /// Builds the field over `bounds` from occupied `points`.
    ///
    /// The grid tiles `bounds` with cubes of side `resolution` starting at `bounds.min`
    /// (`ceil(extent / resolution)` voxels per axis, at least one); each point marks the voxel
    /// containing it. Points outside `bounds` are ignored. Errors on bounds of zero volume, a
    /// non-positive resolution, a grid above [`MAX_VOXELS`], or a non-finite point (naming its
    /// index).
    pub fn from_points(
        bounds: &Aabb,
        points: &[Vec3],
        resolution: f64,
    ) -> Result<Self, GeometryError> {
        crate::aabb::check_box("bounds", &bounds.min, &bounds.max)?;
        bounds.check_volume("bounds")?;
        check_positive("resolution", resolution)?;
        let ext = bounds.extent();
        let mut dims = [0usize; 3];
        for i in 0..3 {
            // The tiny shrink keeps an exact multiple (10 / 0.1 = 100.000…01) from gaining a voxel.
            let n = (ext[i] / resolution * (1.0 - 1e-12)).ceil().max(1.0);
            // Saturating conversion; the count check below rejects anything huge.
            dims[i] = if n < 1e15 { n as usize } else { usize::MAX / 4 };
        }
        let count = checked_voxel_count(dims)?;
        let mut occupied = vec![false; count];
        for (idx, p) in points.iter().enumerate() {
            if !p.iter().all(|c| c.is_finite()) {
                // Name the field only on error: formatting a name for every point showed up in
                // profiles of the E4 world build.
                for (i, axis) in ['x', 'y', 'z'].into_iter().enumerate() {
                    crate::error::check_finite(&format!("points[{idx}].{axis}"), p[i])?;
                }
            }
            // Finite points beyond the scale policy lie outside the (validated) bounds too.
            if !bounds.contains(p) {
                continue;
            }
            let mut ijk = [0usize; 3];
            for i in 0..3 {
                let c = ((p[i] - bounds.min[i]) / resolution).floor();
                ijk[i] = (c.max(0.0) as usize).min(dims[i] - 1);
            }
            occupied[voxel_index(dims, ijk[0], ijk[1], ijk[2])] = true;
        }
        let origin = bounds.min.add_scalar(0.5 * resolution);
        Self::from_occupancy(origin, resolution, dims, &occupied)
    }

    /// Centre of voxel `(0, 0, 0)`.
    pub fn origin(&self) -> Vec3 {
        self.origin
    }

    /// Voxel edge length.
    pub fn resolution(&self) -> f64 {
        self.resolution
    }

    /// Voxels along x, y and z.
    pub fn dims(&self) -> [usize; 3] {
        self.dims
    }

    /// Number of occupied voxels.
    pub fn occupied_count(&self) -> usize {
        self.occupied_count
    }

    /// Signed distances at the voxel centres, indexed by [`voxel_index`].
    pub fn distances(&self) -> &[f64] {
        &self.distances
    }

    /// Signed distance stored at voxel `(x, y, z)`, or `None` outside the grid.
    pub fn voxel_distance(&self, x: usize, y: usize, z: usize) -> Option<f64> {
        (x < self.dims[0] && y < self.dims[1] && z < self.dims[2])
            .then(|| self.distances[voxel_index(self.dims, x, y, z)])
    }

    /// Centre of voxel `(x, y, z)`.
    pub fn voxel_center(&self, x: usize, y: usize, z: usize) -> Vec3 {
        self.origin + self.resolution * Vec3::new(x as f64, y as f64, z as f64)
    }

    /// The region covered by the voxel cubes.
    pub fn bounds(&self) -> Aabb {
        let half = 0.5 * self.resolution;
        let n = Vec3::new(
            self.dims[0] as f64,
            self.dims[1] as f64,
            self.dims[2] as f64,
        );
        Aabb {
            min: self.origin.add_scalar(-half),
            max: self.origin + (n * self.resolution).add_scalar(-half),
        }
    }

    /// The box spanned by the voxel centres (where trilinear interpolation applies).
    pub fn center_box(&self) -> Aabb {
        let n = Vec3::new(
            self.dims[0] as f64 - 1.0,
            self.dims[1] as f64 - 1.0,
            self.dims[2] as f64 - 1.0,
        );
        Aabb {
            min: self.origin,
            max: self.origin + n * self.resolution,
        }
    }

    /// Interpolated signed distance at `p`; see [`Esdf::distance_and_gradient`]. The same value,
    /// without computing the gradient (line-of-sight tests call this in their inner loop).
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        self.interpolate::<false>(p).0
    }

    /// Trilinearly interpolated signed distance at `p` and the exact gradient of the interpolant.
    ///
    /// Inside the box of voxel centres ([`Esdf::center_box`]) this is plain trilinear
    /// interpolation in the cell containing `p` (on a cell face, the cell on the `+` side, except
    /// at the last face; the interpolant is continuous, its gradient jumps across faces).
    ///
    /// Outside that box, `p` is clamped to its nearest point `c` in the box, at distance `o`. With
    /// `d_c` the interpolated value at `c` (and its gradient along the unclamped axes):
    /// `sqrt(o^2 + d_c^2)` if `d_c >= 0` (a lower bound on the distance to the occupied voxels,
    /// which all lie in the box, exact when the nearest one is straight behind `c`), and
    /// `d_c + o` if `d_c < 0`. Both are continuous at the box and never NaN.
    ///
    /// A non-finite `p` gives `(-inf, 0)` (treated as in collision); a point so far away that its
    /// offset overflows gives `(+inf, 0)` when outside the obstacles.
    pub fn distance_and_gradient(&self, p: &Vec3) -> (f64, Vec3) {
        self.interpolate::<true>(p)
    }

    /// [`Esdf::distance_and_gradient`]; with `GRAD = false` the gradient is not computed (zero).
    #[inline(always)]
    fn interpolate<const GRAD: bool>(&self, p: &Vec3) -> (f64, Vec3) {
        if !p.iter().all(|c| c.is_finite()) {
            return (f64::NEG_INFINITY, Vec3::zeros());
        }
        let g = (p - self.origin) / self.resolution;
        let mut base = [0usize; 3];
        let mut t = [0.0f64; 3];
        let mut step = [0usize; 3];
        let mut clamped = Vec3::zeros();
        let mut offset = Vec3::zeros();
        for i in 0..3 {
            let n = self.dims[i];
            let hi = (n - 1) as f64;
            let c = g[i].clamp(0.0, hi);
            clamped[i] = c;
            offset[i] = (g[i] - c) * self.resolution;
            if n == 1 {
                continue;
            }
            // `c >= 0`, so truncation is the floor (without a libm call on baseline x86-64).
            let b = (c as usize).min(n - 2);
            base[i] = b;
            t[i] = c - b as f64;
            step[i] = 1;
        }
        let idx = |x: usize, y: usize, z: usize| self.distances[voxel_index(self.dims, x, y, z)];
        let (bx, by, bz) = (base[0], base[1], base[2]);
        let (sx, sy, sz) = (step[0], step[1], step[2]);
        let c000 = idx(bx, by, bz);
        let c100 = idx(bx + sx, by, bz);
        let c010 = idx(bx, by + sy, bz);
        let c110 = idx(bx + sx, by + sy, bz);
        let c001 = idx(bx, by, bz + sz);
        let c101 = idx(bx + sx, by, bz + sz);
        let c011 = idx(bx, by + sy, bz + sz);
        let c111 = idx(bx + sx, by + sy, bz + sz);
        let corners = [c000, c100, c010, c110, c001, c101, c011, c111];
        if let Some(&bad) = corners.iter().find(|c| !c.is_finite()) {
            return (bad, Vec3::zeros());
        }
        let [tx, ty, tz] = t;
        // Interpolate along x, then y, then z.
        let c00 = c000 + tx * (c100 - c000);
        let c10 = c010 + tx * (c110 - c010);
        let c01 = c001 + tx * (c101 - c001);
        let c11 = c011 + tx * (c111 - c011);
        let c0 = c00 + ty * (c10 - c00);
        let c1 = c01 + ty * (c11 - c01);
        let value = c0 + tz * (c1 - c0);
        if !GRAD {
            let o = offset.norm();
            return if o == 0.0 {
                (value, Vec3::zeros())
            } else if !o.is_finite() {
                (f64::INFINITY, Vec3::zeros())
            } else if value >= 0.0 {
                (o.hypot(value), Vec3::zeros())
            } else {
                (value + o, Vec3::zeros())
            };
        }
        let dx = (1.0 - ty) * (1.0 - tz) * (c100 - c000)
            + ty * (1.0 - tz) * (c110 - c010)
            + (1.0 - ty) * tz * (c101 - c001)
            + ty * tz * (c111 - c011);
        let dy = (1.0 - tz) * (c10 - c00) + tz * (c11 - c01);
        let dz = c1 - c0;
        let mut grad = Vec3::new(dx, dy, dz) / self.resolution;
        for i in 0..3 {
            if step[i] == 0 || offset[i] != 0.0 {
                grad[i] = 0.0;
            }
        }
        let o = offset.norm();
        if o == 0.0 {
            return (value, grad);
        }
        if !o.is_finite() {
            return (f64::INFINITY, Vec3::zeros());
        }
        let dir = offset / o;
        if value >= 0.0 {
            let d = o.hypot(value);
            (d, (dir * o + grad * value) / d)
        } else {
            (value + o, grad + dir)
        }
    }
}

/// Minima of `distances` over blocks of [`COARSE_BLOCK`]³ voxels extended by one voxel on the
/// high side of each axis, and the block counts per axis.
fn coarse_minima(distances: &[f64], dims: [usize; 3]) -> (Vec<f64>, [usize; 3]) {
    let cd = [
        dims[0].div_ceil(COARSE_BLOCK).max(1),
        dims[1].div_ceil(COARSE_BLOCK).max(1),
        dims[2].div_ceil(COARSE_BLOCK).max(1),
    ];
    let mut coarse = vec![f64::INFINITY; cd[0] * cd[1] * cd[2]];
    // Each voxel contributes to its own block and, on a block's low face, to the block below.
    let blocks = |v: usize, n_blocks: usize| {
        let b = v / COARSE_BLOCK;
        let own = b.min(n_blocks - 1);
        let below = (v.is_multiple_of(COARSE_BLOCK) && b > 0).then(|| b - 1);
        (own, below)
    };
    // Per row, the minimum over each block's extended x-range first (one comparison per voxel),
    // then into the (at most four) blocks of the row's y and z.
    let mut row_min = vec![f64::INFINITY; cd[0]];
    for z in 0..dims[2] {
        let (bz, bz2) = blocks(z, cd[2]);
        for y in 0..dims[1] {
            let (by, by2) = blocks(y, cd[1]);
            let row = &distances[voxel_index(dims, 0, y, z)..][..dims[0]];
            for (cx, m) in row_min.iter_mut().enumerate() {
                let lo = cx * COARSE_BLOCK;
                let hi = (lo + COARSE_BLOCK + 1).min(dims[0]);
                *m = row[lo..hi]
                    .iter()
                    .fold(f64::INFINITY, |a, &d| if d < a { d } else { a });
            }
            for &cz in [Some(bz), bz2].iter().flatten() {
                for &cy in [Some(by), by2].iter().flatten() {
                    let k = voxel_index(cd, 0, cy, cz);
                    for (c, &m) in coarse[k..k + cd[0]].iter_mut().zip(&row_min) {
                        if m < *c {
                            *c = m;
                        }
                    }
                }
            }
        }
    }
    (coarse, cd)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn random_occupancy(dims: [usize; 3], density: f64, seed: u64) -> Vec<bool> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        (0..dims[0] * dims[1] * dims[2])
            .map(|_| rng.random_bool(density))
            .collect()
    }

    fn coords(dims: [usize; 3], i: usize) -> [i64; 3] {
        let x = i % dims[0];
        let y = (i / dims[0]) % dims[1];
        let z = i / (dims[0] * dims[1]);
        [x as i64, y as i64, z as i64]
    }

    fn sq(a: [i64; 3], b: [i64; 3]) -> f64 {
        (0..3).map(|k| ((a[k] - b[k]) * (a[k] - b[k])) as f64).sum()
    }

    /// Brute-force squared EDT: distance to the nearest voxel with `site[v]`.
    fn brute_edt(dims: [usize; 3], site: &[bool]) -> Vec<f64> {
        (0..site.len())
            .map(|i| {
                let a = coords(dims, i);
                (0..site.len())
                    .filter(|&j| site[j])
                    .map(|j| sq(a, coords(dims, j)))
                    .fold(f64::INFINITY, f64::min)
            })
            .collect()
    }

    /// Brute-force squared distance to the nearest voxel outside the grid (the border layer).
    fn brute_border(dims: [usize; 3], i: usize) -> f64 {
        let a = coords(dims, i);
        (0..3)
            .map(|k| (a[k] + 1).min(dims[k] as i64 - a[k]))
            .map(|d| (d * d) as f64)
            .fold(f64::INFINITY, f64::min)
    }

    fn dims_strategy() -> impl Strategy<Value = [usize; 3]> {
        (1usize..=12, 1usize..=12, 1usize..=12).prop_map(|(a, b, c)| [a, b, c])
    }

    proptest! {
        #[test]
        fn edt_1d_matches_brute_force(f in prop::collection::vec(prop_oneof![Just(f64::INFINITY), 0.0f64..50.0], 0..40)) {
            let mut out = vec![0.0; f.len()];
            edt_1d(&f, &mut out);
            for (q, &o) in out.iter().enumerate() {
                let brute = f.iter().enumerate()
                    .map(|(v, &fv)| (q as f64 - v as f64).powi(2) + fv)
                    .fold(f64::INFINITY, f64::min);
                prop_assert!(o == brute || (o - brute).abs() <= 1e-9 * brute.max(1.0), "q={q}: {o} vs {brute}");
            }
        }

        #[test]
        fn edt_3d_matches_brute_force(dims in dims_strategy(), density in 0.0f64..0.4, seed in any::<u64>()) {
            let occ = random_occupancy(dims, density, seed);
            let mut values: Vec<f64> = occ.iter().map(|&o| if o { 0.0 } else { f64::INFINITY }).collect();
            edt_3d(&mut values, dims).unwrap();
            prop_assert_eq!(values, brute_edt(dims, &occ));
        }

        #[test]
        fn edt_3d_with_border_matches_brute_force(dims in dims_strategy(), density in 0.0f64..0.3, seed in any::<u64>()) {
            let free = random_occupancy(dims, density, seed);
            let mut values: Vec<f64> = free.iter().map(|&s| if s { 0.0 } else { f64::INFINITY }).collect();
            edt_3d_with_site_border(&mut values, dims).unwrap();
            let inner = brute_edt(dims, &free);
            for (i, v) in values.iter().enumerate() {
                prop_assert_eq!(*v, inner[i].min(brute_border(dims, i)), "voxel {:?}", coords(dims, i));
            }
        }

        /// The stored signed distances are the documented exact values.
        #[test]
        fn esdf_values_match_definition(dims in dims_strategy(), density in 0.05f64..0.6, seed in any::<u64>()) {
            let occ = random_occupancy(dims, density, seed);
            prop_assume!(occ.iter().any(|&o| o));
            let res = 0.25;
            let esdf = Esdf::from_occupancy(Vec3::new(1.0, -2.0, 0.5), res, dims, &occ).unwrap();
            let out = brute_edt(dims, &occ);
            let free: Vec<bool> = occ.iter().map(|o| !o).collect();
            let inn = brute_edt(dims, &free);
            for i in 0..occ.len() {
                let expect = res * (out[i].sqrt() - inn[i].min(brute_border(dims, i)).sqrt());
                prop_assert!((esdf.distances()[i] - expect).abs() < 1e-12);
                prop_assert_eq!(esdf.distances()[i] < 0.0, occ[i]);
            }
        }

        /// The row-wise coarse minima equal the per-voxel definition (each voxel into its own
        /// block and, on a block's low face, the block below).
        #[test]
        fn coarse_minima_match_the_definition(dims in dims_strategy(), density in 0.0f64..0.6, seed in any::<u64>()) {
            let occ = random_occupancy(dims, density, seed);
            let esdf = Esdf::from_occupancy(Vec3::zeros(), 0.5, dims, &occ).unwrap();
            let (coarse, cd) = coarse_minima(esdf.distances(), dims);
            let mut expect = vec![f64::INFINITY; cd[0] * cd[1] * cd[2]];
            for z in 0..dims[2] {
                for y in 0..dims[1] {
                    for x in 0..dims[0] {
                        let d = esdf.distances()[voxel_index(dims, x, y, z)];
                        let own = |v: usize| v / COARSE_BLOCK;
                        let below = |v: usize| (v.is_multiple_of(COARSE_BLOCK) && v > 0).then(|| v / COARSE_BLOCK - 1);
                        for cz in [Some(own(z)), below(z)].into_iter().flatten() {
                            for cy in [Some(own(y)), below(y)].into_iter().flatten() {
                                for cx in [Some(own(x)), below(x)].into_iter().flatten() {
                                    let k = voxel_index(cd, cx, cy, cz);
                                    expect[k] = expect[k].min(d);
                                }
                            }
                        }
                    }
                }
            }
            prop_assert_eq!(coarse, expect);
        }

        /// The coarse grid bounds the interpolant from below, at points and over boxes, inside
        /// and outside the grid, and is tight somewhere in every block (it is a voxel value).
        #[test]
        fn coarse_lower_bounds_hold(
            dims in (1usize..21, 1usize..21, 1usize..13).prop_map(|(a, b, c)| [a, b, c]),
            density in 0.0f64..0.2,
            seed in any::<u64>(),
        ) {
            let occ = random_occupancy(dims, density, seed);
            let res = 0.3;
            let origin = Vec3::new(-1.0, 2.0, 0.0);
            let esdf = Esdf::from_occupancy(origin, res, dims, &occ).unwrap();
            let mut rng = ChaCha8Rng::seed_from_u64(seed ^ 0x5eed);
            let span = Vec3::new(dims[0] as f64, dims[1] as f64, dims[2] as f64) * res;
            for _ in 0..200 {
                let u = Vec3::new(rng.random_range(-0.3..1.3), rng.random_range(-0.3..1.3), rng.random_range(-0.3..1.3));
                let p = origin + span.component_mul(&u);
                let d = esdf.signed_distance(&p);
                prop_assert!(esdf.lower_bound(&p) <= d, "{} > {d} at {p:?}", esdf.lower_bound(&p));
                let half = Vec3::new(rng.random_range(0.0..2.0), rng.random_range(0.0..2.0), rng.random_range(0.0..2.0));
                let region = Aabb { min: p - half, max: p + half };
                let lb = esdf.lower_bound_in(&region);
                for _ in 0..10 {
                    let q = p + half.component_mul(&Vec3::new(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0)));
                    prop_assert!(lb <= esdf.signed_distance(&q));
                }
                prop_assert!(lb <= esdf.lower_bound(&p));
            }
            prop_assert_eq!(esdf.lower_bound(&Vec3::new(f64::NAN, 0.0, 0.0)), f64::NEG_INFINITY);
        }

        /// `signed_distance` (no gradient) gives exactly the value of `distance_and_gradient`,
        /// inside the grid, outside it and for non-finite points.
        #[test]
        fn signed_distance_is_the_value_of_distance_and_gradient(
            seed in any::<u64>(),
            u in (-0.5f64..1.5, -0.5f64..1.5, -0.5f64..1.5),
            fill in 0.0f64..1.0,
        ) {
            let dims = [6, 5, 7];
            let occ = random_occupancy(dims, fill, seed);
            let esdf = Esdf::from_occupancy(Vec3::new(-1.0, 0.5, 2.0), 0.3, dims, &occ).unwrap();
            let p = Vec3::new(-1.0 + u.0 * 1.8, 0.5 + u.1 * 1.5, 2.0 + u.2 * 2.1);
            for q in [p, Vec3::new(f64::NAN, 0.0, 0.0), p * 1e300] {
                let a = esdf.signed_distance(&q);
                let b = esdf.distance_and_gradient(&q).0;
                prop_assert!(a == b || (a.is_nan() && b.is_nan()), "{a} vs {b} at {q:?}");
            }
        }

        /// Gradient of the trilinear interpolant against central differences, away from cell faces.
        #[test]
        fn esdf_gradient_matches_fd(seed in any::<u64>(), u in (0.0f64..1.0, 0.0f64..1.0, 0.0f64..1.0)) {
            let dims = [6, 5, 7];
            let occ = random_occupancy(dims, 0.15, seed);
            prop_assume!(occ.iter().any(|&o| o));
            let res = 0.3;
            let origin = Vec3::new(-1.0, 0.5, 2.0);
            let esdf = Esdf::from_occupancy(origin, res, dims, &occ).unwrap();
            let g = Vec3::new(u.0 * 5.0, u.1 * 4.0, u.2 * 6.0);
            for i in 0..3 {
                let frac = g[i] - g[i].floor();
                prop_assume!(frac > 1e-3 && frac < 1.0 - 1e-3);
            }
            let p = origin + g * res;
            let (_, grad) = esdf.distance_and_gradient(&p);
            let fd = trust_numdiff::gradient_array(|q| esdf.signed_distance(&Vec3::from(q)), p.into(), 1e-6);
            for i in 0..3 {
                prop_assert!((fd[i] - grad[i]).abs() < 1e-6, "axis {i}: {} vs {}", grad[i], fd[i]);
            }
        }

        /// Outside the box of voxel centres: the documented extension and its gradient.
        #[test]
        fn esdf_outside_gradient_matches_fd(
            seed in any::<u64>(),
            p in (-2.0f64..4.0, -2.0f64..4.0, -2.0f64..4.0).prop_map(|(x, y, z)| Vec3::new(x, y, z)),
        ) {
            let dims = [5, 6, 4];
            let occ = random_occupancy(dims, 0.2, seed);
            prop_assume!(occ.iter().any(|&o| o));
            let res = 0.5;
            let esdf = Esdf::from_occupancy(Vec3::zeros(), res, dims, &occ).unwrap();
            let cbox = esdf.center_box();
            prop_assume!(!cbox.contains(&p));
            for i in 0..3 {
                // Away from the box faces (kinks of the clamp) and from cell faces.
                prop_assume!((p[i] - cbox.min[i]).abs() > 1e-3 && (p[i] - cbox.max[i]).abs() > 1e-3);
                let g = p[i] / res;
                let frac = g - g.floor();
                prop_assume!(frac > 1e-3 && frac < 1.0 - 1e-3);
            }
            let (d, grad) = esdf.distance_and_gradient(&p);
            let c = cbox.clamp(&p);
            let dc = esdf.signed_distance(&c);
            prop_assert!(d >= dc.min(0.0) && d.is_finite());
            // The extension switches from `sqrt(o² + d_c²)` to `d_c + o` where `d_c` crosses 0: a
            // kink like the box faces, where central differences straddle two branches
            // (PROPTEST_RNG_SEED=3174492301114349736 drew a point 6e-7 from it).
            prop_assume!(dc.abs() > 1e-3);
            let fd = trust_numdiff::gradient_array(|q| esdf.signed_distance(&Vec3::from(q)), p.into(), 1e-6);
            for i in 0..3 {
                prop_assert!((fd[i] - grad[i]).abs() < 1e-5, "axis {i}: {} vs {}", grad[i], fd[i]);
            }
        }
    }

    #[test]
    fn interpolation_reproduces_voxel_values_and_is_continuous() {
        let dims = [4, 3, 5];
        let occ = random_occupancy(dims, 0.3, 7);
        let esdf = Esdf::from_occupancy(Vec3::new(0.1, 0.2, 0.3), 0.5, dims, &occ).unwrap();
        for z in 0..5 {
            for y in 0..3 {
                for x in 0..4 {
                    let c = esdf.voxel_center(x, y, z);
                    let d = esdf.signed_distance(&c);
                    assert!((d - esdf.voxel_distance(x, y, z).unwrap()).abs() < 1e-12);
                }
            }
        }
        assert_eq!(esdf.voxel_distance(4, 0, 0), None);
        // Continuity across the boundary of the centre box.
        let c = esdf.voxel_center(3, 1, 2);
        let inside = esdf.signed_distance(&(c - Vec3::new(1e-9, 0.0, 0.0)));
        let outside = esdf.signed_distance(&(c + Vec3::new(1e-9, 0.0, 0.0)));
        assert!((inside - outside).abs() < 1e-8);
    }

    #[test]
    fn from_points_marks_voxels_and_ignores_outside_points() {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::new(2.0, 1.0, 1.0)).unwrap();
        let pts = [
            Vec3::new(1.05, 0.55, 0.55),
            Vec3::new(5.0, 0.5, 0.5),
            Vec3::new(2.0, 1.0, 1.0),
        ];
        let esdf = Esdf::from_points(&bounds, &pts, 0.1).unwrap();
        assert_eq!(esdf.dims(), [20, 10, 10]);
        assert_eq!(esdf.occupied_count(), 2);
        assert!(esdf.voxel_distance(10, 5, 5).unwrap() < 0.0);
        assert!(esdf.voxel_distance(19, 9, 9).unwrap() < 0.0);
        // A free voxel two voxels away along x holds 2 * resolution.
        assert!((esdf.voxel_distance(12, 5, 5).unwrap() - 0.2).abs() < 1e-12);
        // Zero level on the voxel face.
        assert!(esdf.signed_distance(&Vec3::new(1.1, 0.55, 0.55)).abs() < 1e-12);
        assert!((esdf.bounds().max - bounds.max).norm() < 1e-12);
        let e = Esdf::from_points(&bounds, &[Vec3::new(0.0, f64::NAN, 0.0)], 0.1).unwrap_err();
        assert_eq!(e.to_string(), "points[0].y must be finite, got NaN");
    }

    #[test]
    fn empty_and_full_grids() {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0)).unwrap();
        let empty = Esdf::from_points(&bounds, &[], 0.25).unwrap();
        let (d, g) = empty.distance_and_gradient(&Vec3::new(0.5, 0.5, 0.5));
        assert_eq!((d, g), (f64::INFINITY, Vec3::zeros()));
        assert_eq!(
            empty.distance_and_gradient(&Vec3::new(9.0, 0.5, 0.5)).0,
            f64::INFINITY
        );
        let full = Esdf::from_occupancy(Vec3::zeros(), 1.0, [3, 3, 3], &[true; 27]).unwrap();
        // Everything outside the grid is free: the centre voxel is two voxels from the outside.
        assert_eq!(full.voxel_distance(1, 1, 1), Some(-2.0));
        assert_eq!(full.voxel_distance(0, 1, 1), Some(-1.0));
        let (d, g) = full.distance_and_gradient(&Vec3::new(f64::NAN, 0.0, 0.0));
        assert_eq!((d, g), (f64::NEG_INFINITY, Vec3::zeros()));
        let (d, g) = full.distance_and_gradient(&Vec3::new(1e300, 0.0, 0.0));
        assert!(!d.is_nan() && g.iter().all(|c| c.is_finite()));
        // A single-voxel grid.
        let one = Esdf::from_occupancy(Vec3::zeros(), 1.0, [1, 1, 1], &[true]).unwrap();
        let (d, g) = one.distance_and_gradient(&Vec3::new(0.0, 0.0, 0.0));
        assert_eq!((d, g), (-1.0, Vec3::zeros()));
        assert!((one.signed_distance(&Vec3::new(3.0, 0.0, 0.0)) - 2.0).abs() < 1e-12);
    }

    #[test]
    fn invalid_grids_are_rejected() {
        let bounds = Aabb::new(Vec3::zeros(), Vec3::new(1.0, 1.0, 1.0)).unwrap();
        let e = Esdf::from_points(&bounds, &[], 0.0).unwrap_err();
        assert_eq!(e.to_string(), "resolution must be > 0, got 0");
        assert!(matches!(
            Esdf::from_points(&bounds, &[], f64::NAN),
            Err(GeometryError::NonFinite { .. })
        ));
        let e = Esdf::from_points(&bounds, &[], 1e-4).unwrap_err();
        assert!(e.to_string().contains("10000 x 10000 x 10000"), "{e}");
        let flat = Aabb::new(Vec3::zeros(), Vec3::new(1.0, 0.0, 1.0)).unwrap();
        assert!(matches!(
            Esdf::from_points(&flat, &[], 0.1),
            Err(GeometryError::EmptyBounds { axis: 'y', .. })
        ));
        let e = Esdf::from_occupancy(Vec3::zeros(), 1.0, [2, 2, 2], &[true; 7]).unwrap_err();
        assert!(
            matches!(
                e,
                GeometryError::LengthMismatch {
                    len: 7,
                    expected: 8,
                    ..
                }
            ),
            "{e}"
        );
        assert!(Esdf::from_occupancy(Vec3::zeros(), 1.0, [0, 2, 2], &[]).is_err());
        let mut v = vec![0.0; 3];
        assert!(edt_3d(&mut v, [2, 2, 1]).is_err());
        assert!(checked_voxel_count([usize::MAX, 2, 2]).is_err());
        // A product beyond u128 (the file fuzzer found it through a world placeholder).
        assert!(checked_voxel_count([usize::MAX; 3]).is_err());
    }

    #[test]
    fn from_signed_distances_round_trips_and_validates() {
        let mut occupied = vec![false; 5 * 4 * 3];
        occupied[voxel_index([5, 4, 3], 2, 1, 1)] = true;
        let a = Esdf::from_occupancy(Vec3::new(0.5, 0.5, 0.5), 0.5, [5, 4, 3], &occupied).unwrap();
        let b = Esdf::from_signed_distances(a.origin(), 0.5, [5, 4, 3], a.distances().to_vec())
            .unwrap();
        assert_eq!(a, b);
        assert_eq!(b.occupied_count(), 1);
        let mut bad = a.distances().to_vec();
        bad[7] = f64::NAN;
        let e = Esdf::from_signed_distances(a.origin(), 0.5, [5, 4, 3], bad).unwrap_err();
        assert_eq!(e.to_string(), "distances[7] must be finite, got NaN");
        let e = Esdf::from_signed_distances(a.origin(), 0.5, [5, 4, 3], vec![1.0; 3]).unwrap_err();
        assert!(
            matches!(e, GeometryError::LengthMismatch { len: 3, .. }),
            "{e}"
        );
        // +inf everywhere is an empty field.
        let empty =
            Esdf::from_signed_distances(Vec3::zeros(), 1.0, [2, 2, 2], vec![f64::INFINITY; 8])
                .unwrap();
        assert_eq!(empty.occupied_count(), 0);
        assert_eq!(empty.signed_distance(&Vec3::zeros()), f64::INFINITY);
    }
}
