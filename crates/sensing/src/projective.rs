//! The projective free-space rule of a pinhole depth frame (decision 0048): a voxel is decided by
//! the one pixel its centre projects into, instead of by the rays that happen to cross it.
//!
//! [`DepthFrame`] holds what the rule needs of one frame: the world-to-sensor rotation, the
//! intrinsics of [`DepthCamera`] (its pixel grid over the fields of view) and, per pixel, the
//! depth below which a voxel centre counts as free ([`DepthFrame::miss_at`]). The map iterates
//! the voxels of the frame's frustum row by row ([`DepthFrame::row_span`] bounds each x row of
//! the window) and asks the rule for each.

use trust_geometry::Vec3;

use crate::camera::DepthCamera;
use crate::error::SensingError;
use crate::pose::Pose;
use crate::scan::{ReturnKind, Scan};

/// Half a voxel's diagonal in voxels, `√3 / 2`.
const HALF_DIAGONAL: f64 = 0.866_025_403_784_438_6;

/// One frame's projective rule (module docs).
#[derive(Debug, Clone)]
pub(crate) struct DepthFrame {
    /// Rows of the world-to-sensor rotation (`Rᵀ`): sensor coordinate `j` of a world offset `d`
    /// is `rt[j][0] d.x + (rt[j][1] d.y + rt[j][2] d.z)`, in that order (the row loop keeps the
    /// bracket per row and gets the same bits).
    pub rt: [[f64; 3]; 3],
    /// The sensor origin (the scan's).
    pub origin: Vec3,
    width: usize,
    height: usize,
    /// `tan(hfov / 2)`, `tan(vfov / 2)`.
    tx: f64,
    ty: f64,
    /// Column and row coordinates: `u = w/2 − fu · y/x`, `v = h/2 − fv · z/x` (pixel `u` spans
    /// `[u, u + 1)`, its centre ray at `u + 0.5`, as [`DepthCamera`] builds its rays).
    fu: f64,
    fv: f64,
    /// A voxel centre outside the image whose voxel reaches across the frustum's side plane is
    /// decided by the nearest edge pixel: the margins below columns 0 and above `w`, below row 0
    /// and above `h`, are these over the depth `x` (the box's support along the plane's normal,
    /// `res/2 · |n|₁` in the world frame, in pixels at unit depth).
    edges: [f64; 4],
    /// Per pixel (row by row): a voxel whose centre projects into the pixel is a miss when its
    /// depth along the optical axis is below this; `-inf` for a pixel without evidence.
    clear_below: Vec<f64>,
    /// The largest finite `clear_below` (`-inf` if none): no voxel at or beyond this depth is a
    /// miss.
    pub far: f64,
    /// Pixels that brought evidence (hits, and no-returns if they clear).
    pub ray_count: usize,
    /// The x slopes of [`DepthFrame::row_span`]'s six conditions and their inverses.
    span_beta: [f64; 6],
    span_inv: [f64; 6],
}

impl DepthFrame {
    /// The rule for `scan`, taken by `camera` at `pose`, in a map of voxel edge `res` that clears
    /// along no-returns if `free_on_no_return`.
    ///
    /// A hit pixel of depth `z` clears voxel centres of depth `< z − res/2`: every voxel wholly
    /// in front of the plane of depth `z` has its centre more than `res/2` in front of it (a
    /// voxel's half-extent along any unit direction is at least `res/2`), and a voxel whose
    /// centre lies within `res/2` of the surface may hold it. A no-return pixel (nothing within
    /// the maximum depth `z_max`) clears centres of depth `< z_max` if `free_on_no_return`, an
    /// invalid one nothing.
    ///
    /// Errors (a [`SensingError`]) if the pose is invalid, the scan's origin is not the pose's
    /// position (within `1e-6` m), the scan does not hold one ray per pixel, or a ray's
    /// direction is not its pixel's direction rotated by the pose (within `1e-6`) or its range
    /// not finite in `[0, 1e4]` m.
    pub fn new(
        camera: &DepthCamera,
        pose: &Pose,
        scan: &Scan,
        res: f64,
        free_on_no_return: bool,
    ) -> Result<Self, SensingError> {
        pose.validate()?;
        let p = camera.params();
        let (w, h) = (p.width, p.height);
        if scan.rays.len() != w * h {
            return Err(SensingError::Scan {
                field: "scan.rays".into(),
                problem: format!(
                    "{} rays; the camera has {w} x {h} = {} pixels",
                    scan.rays.len(),
                    w * h
                ),
            });
        }
        let offset = (scan.origin - pose.position).norm();
        if offset.is_nan() || offset > 1e-6 {
            return Err(SensingError::Scan {
                field: "scan.origin".into(),
                problem: format!("{offset} m from pose.position; expected the camera's position"),
            });
        }
        let rot = pose.attitude.to_rotation_matrix();
        let m = rot.matrix();
        let rt = [
            [m[(0, 0)], m[(1, 0)], m[(2, 0)]],
            [m[(0, 1)], m[(1, 1)], m[(2, 1)]],
            [m[(0, 2)], m[(1, 2)], m[(2, 2)]],
        ];
        let (dirs, per_unit) = camera.pixel_rays();
        let mut clear_below = Vec::with_capacity(w * h);
        let mut far = f64::NEG_INFINITY;
        let mut ray_count = 0;
        for (i, ray) in scan.rays.iter().enumerate() {
            // Squared, so that a good ray costs no square root.
            let err2 = (ray.direction - rot * dirs[i]).norm_squared();
            if err2.is_nan() || err2 > 1e-12 {
                return Err(SensingError::Scan {
                    field: format!("scan.rays[{i}].direction"),
                    problem: format!(
                        "{} from pixel ({}, {})'s direction; expected the camera's ray",
                        err2.sqrt(),
                        i % w,
                        i / w
                    ),
                });
            }
            if !(0.0..=1e4).contains(&ray.range) {
                return Err(SensingError::OutOfRange {
                    field: format!("scan.rays[{i}].range"),
                    value: ray.range,
                    expected: "in [0, 1e4] m",
                });
            }
            let depth = ray.range / per_unit[i];
            let limit = match ray.kind {
                ReturnKind::Hit => depth - 0.5 * res,
                ReturnKind::NoReturn if free_on_no_return => depth,
                _ => f64::NEG_INFINITY,
            };
            if limit > f64::NEG_INFINITY {
                ray_count += 1;
            }
            far = far.max(limit);
            clear_below.push(limit);
        }
        let tx = (0.5 * p.hfov_rad).tan();
        let ty = (0.5 * p.vfov_rad).tan();
        let a = [rt[0][0], rt[1][0], rt[2][0]];
        let span_beta = [
            a[0],
            -a[0],
            tx * a[0] - a[1],
            tx * a[0] + a[1],
            ty * a[0] - a[2],
            ty * a[0] + a[2],
        ];
        Ok(Self {
            rt,
            origin: scan.origin,
            width: w,
            height: h,
            tx,
            ty,
            fu: w as f64 / (2.0 * tx),
            fv: h as f64 / (2.0 * ty),
            edges: [
                (tx, 1.0, 0.0, w as f64 / (2.0 * tx)),
                (tx, -1.0, 0.0, w as f64 / (2.0 * tx)),
                (ty, 0.0, 1.0, h as f64 / (2.0 * ty)),
                (ty, 0.0, -1.0, h as f64 / (2.0 * ty)),
            ]
            .map(|(t, ny, nz, f)| {
                // The side plane's outward normal `(−t, ny, nz) / √(1 + t²)` in the world frame.
                let support: f64 = (0..3)
                    .map(|j| (-t * rt[0][j] + ny * rt[1][j] + nz * rt[2][j]).abs())
                    .sum::<f64>()
                    / t.hypot(1.0);
                f * 0.5 * res * support * t.hypot(1.0)
            }),
            clear_below,
            far,
            ray_count,
            span_beta,
            span_inv: span_beta.map(|b| if b != 0.0 { 1.0 / b } else { 0.0 }),
        })
    }

    /// Sensor coordinates of the world offset `d` from the origin (the order of operations the
    /// row loop reproduces).
    #[cfg(test)]
    pub fn sensor(&self, d: &Vec3) -> [f64; 3] {
        let q = self.row_part(d.y, d.z);
        [
            self.rt[0][0] * d.x + q[0],
            self.rt[1][0] * d.x + q[1],
            self.rt[2][0] * d.x + q[2],
        ]
    }

    /// The part of the sensor coordinates that is constant along an x row.
    #[inline]
    pub fn row_part(&self, dy: f64, dz: f64) -> [f64; 3] {
        [
            self.rt[0][1] * dy + self.rt[0][2] * dz,
            self.rt[1][1] * dy + self.rt[1][2] * dz,
            self.rt[2][1] * dy + self.rt[2][2] * dz,
        ]
    }

    /// The pixel (row-major index) that decides a voxel centre at sensor coordinates `p`: the
    /// one it projects into, or the nearest edge pixel if it projects outside the image but its
    /// voxel reaches across the side planes it lies beyond; `None` behind the sensor or
    /// farther out.
    #[inline]
    pub fn pixel_of(&self, p: &[f64; 3]) -> Option<usize> {
        if p[0].is_nan() || p[0] <= 0.0 {
            return None;
        }
        let inv = 1.0 / p[0];
        let (w, h) = (self.width as f64, self.height as f64);
        let u = 0.5 * w - self.fu * (p[1] * inv);
        let v = 0.5 * h - self.fv * (p[2] * inv);
        let e = self.edges;
        if !(u >= -e[0] * inv && u < w + e[1] * inv && v >= -e[2] * inv && v < h + e[3] * inv) {
            return None;
        }
        // Not NaN here: truncated (`as` saturates), then clamped to the image (a value below 0
        // to 0, one beyond the far edge to it).
        let (u, v) = (
            (u as i64).clamp(0, self.width as i64 - 1) as usize,
            (v as i64).clamp(0, self.height as i64 - 1) as usize,
        );
        Some(v * self.width + u)
    }

    /// True if a voxel centre at sensor coordinates `p` is a miss: it lies in front of the
    /// measurement of the pixel that decides it ([`DepthFrame::pixel_of`], [`DepthFrame::new`]).
    #[inline]
    pub fn miss_at(&self, p: &[f64; 3]) -> bool {
        self.pixel_of(p).is_some_and(|i| p[0] < self.clear_below[i])
    }

    /// Slack (m) for [`DepthFrame::row_span`] that covers the edge margins of
    /// [`DepthFrame::pixel_of`] (at most half a voxel diagonal from the side planes,
    /// `√3/2 res · √(1 + tan²)` in `|y| − x tan`) with a voxel to spare.
    pub fn span_slack(&self, res: f64) -> f64 {
        res * (1.0 + HALF_DIAGONAL * self.tx.max(self.ty).hypot(1.0))
    }

    /// The world x offsets from the origin along the row of offsets `(·, dy, dz)` that can hold
    /// a miss, as an interval `[lo, hi]` (`lo > hi` if none), `slack` metres wider than the
    /// frustum: the sensor depth in `(0, far)` and `|y| ≤ x tan(hfov/2)`,
    /// `|z| ≤ x tan(vfov/2)`, each a linear condition on the offset.
    pub fn row_span(&self, dy: f64, dz: f64, slack: f64) -> (f64, f64) {
        let q = self.row_part(dy, dz);
        // Conditions `alpha + beta · dx ≥ 0`, the betas fixed per frame.
        let alphas = [
            q[0] + slack,
            self.far + slack - q[0],
            self.tx * q[0] - q[1] + slack,
            self.tx * q[0] + q[1] + slack,
            self.ty * q[0] - q[2] + slack,
            self.ty * q[0] + q[2] + slack,
        ];
        let (mut lo, mut hi) = (f64::NEG_INFINITY, f64::INFINITY);
        for ((alpha, beta), inv) in alphas.into_iter().zip(self.span_beta).zip(self.span_inv) {
            if beta > 0.0 {
                lo = lo.max(-alpha * inv);
            } else if beta < 0.0 {
                hi = hi.min(-alpha * inv);
            } else if alpha < 0.0 {
                return (1.0, 0.0);
            }
        }
        (lo, hi)
    }

    /// The world box of the frustum out to depth `far` (the pyramid's apex and its four far
    /// corners), as `(min, max)`; empty-free only when `far > 0`.
    pub fn frustum_box(&self) -> (Vec3, Vec3) {
        let mut lo = self.origin;
        let mut hi = self.origin;
        for (sy, sz) in [(1.0, 1.0), (1.0, -1.0), (-1.0, 1.0), (-1.0, -1.0)] {
            let s = [self.far, sy * self.tx * self.far, sz * self.ty * self.far];
            let mut c = self.origin;
            for j in 0..3 {
                c[j] += self.rt[0][j] * s[0] + self.rt[1][j] * s[1] + self.rt[2][j] * s[2];
            }
            lo = lo.inf(&c);
            hi = hi.sup(&c);
        }
        (lo, hi)
    }
}
