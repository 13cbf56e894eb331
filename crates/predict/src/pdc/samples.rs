//! Obstacle-aware samples on the surface of a PDC (paper Sec. III-B, `P_PDC` of Algorithm 2).

use trust_geometry::{Aabb, Vec3};

use super::{Pdc, frame_along};
use crate::PredictError;
use crate::error::check_non_negative;
use trust_geometry::scale::{self, Quantity};

impl Pdc {
    /// Obstacle-aware samples (paper Sec. III-B): points at signed distance `margin` outside the
    /// PDC ([`Pdc::signed_distance`]) and inside `region`, on `slices` cross-sections evenly spaced
    /// along the sweep (perpendicular to the predicted velocity; both ends included) plus, for a
    /// moving obstacle, one point beyond each end of the sweep. See
    /// [`Pdc::surface_samples_into`] for where they lie.
    ///
    /// # Errors
    /// As [`Pdc::surface_samples_into`].
    pub fn surface_samples(
        &self,
        slices: usize,
        per_slice: usize,
        margin: f64,
        region: &Aabb,
    ) -> Result<Vec<Vec3>, PredictError> {
        let mut out = Vec::new();
        self.surface_samples_into(slices, per_slice, margin, region, &mut out)?;
        Ok(out)
    }

    /// As [`Pdc::surface_samples`], appending to `out` (not cleared). At most
    /// `slices · per_slice + 2` points, deterministic:
    ///
    /// * sphere: on each slice a ring around the slice centre (perpendicular to the sweep; a
    ///   horizontal ring if the obstacle does not move, which then has one slice);
    /// * cylinder: on each slice the two vertical sides at heights spread over the part of the
    ///   slice inside `region`, and the points above and below the slice centre (a horizontal ring
    ///   at the region's mid-height if the obstacle does not move horizontally);
    /// * moving obstacle: on the first and the last slice also the point on the axis of the sweep
    ///   beyond the cap (at the region's mid-height for a cylinder): the ways around its back and
    ///   front.
    ///
    /// Each slice spreads its candidates evenly over its boundary, drops those outside `region` and
    /// keeps at most `per_slice` of the rest, evenly spread, so that the samples land where a
    /// planner samples. Each point is found along a ray from inside the shape of its slice, by
    /// Newton steps on the signed distance (bisection if they do not converge); its signed distance
    /// is `margin` up to `1e-9` — for a cylinder the square-rim distance, so its Euclidean distance
    /// lies in `[margin, √2·margin]`.
    ///
    /// # Errors
    /// [`PredictError`] if `margin` is non-finite or negative, or the number of candidates
    /// overflows `usize`.
    pub fn surface_samples_into(
        &self,
        slices: usize,
        per_slice: usize,
        margin: f64,
        region: &Aabb,
        out: &mut Vec<Vec3>,
    ) -> Result<(), PredictError> {
        check_non_negative("margin", margin, Quantity::Length)?;
        scale::check_count(
            "slices * per_slice",
            slices as u128 * per_slice as u128,
            scale::MAX_SOLVED_SAMPLE_COUNT,
        )?;
        // At most 4 · MAX_SOLVED_SAMPLE_COUNT: no overflow.
        let candidates_per_slice = per_slice * 4;
        if slices == 0 || per_slice == 0 {
            return Ok(());
        }
        let offset = margin;
        let sweep = self.b - self.a;
        let moving = sweep.norm() > 1e-9;
        let slice_count = if moving { slices } else { 1 };
        let height = if self.cylinder {
            self.aabb.max.z - self.aabb.min.z
        } else {
            0.0
        };
        let reach = self.ra.max(self.rb) + sweep.norm() + height + offset.abs() + 1.0;
        // Slack for the cheap region pre-test of a candidate direction: the exact point is within
        // this distance of its guess (the hull's cross-section radius exceeds the slice radius by
        // at most the radius change over the sweep, scaled by the cone's slope).
        let slack = 2.0 * (self.ra - self.rb).abs() + offset.abs() + 0.5;
        // Cosine of the lateral surface's slope: a ray perpendicular to the axis from the slice
        // centre (radius r) meets the offset surface at (r + offset) / cos α when it leaves
        // through the lateral surface — the Newton start, exact in that case.
        let axis_len = if self.cylinder {
            sweep.x.hypot(sweep.y)
        } else {
            sweep.norm()
        };
        let sin_a = if axis_len > (self.ra - self.rb).abs() {
            (self.ra - self.rb) / axis_len
        } else {
            0.0
        };
        let cos_a = (1.0 - sin_a * sin_a).sqrt().max(0.05);
        let region_mid_z = 0.5 * (region.min.z + region.max.z);
        let mut candidates: Vec<(Vec3, Vec3, f64)> = Vec::with_capacity(candidates_per_slice + 2);
        let mut kept = Vec::new();
        for k in 0..slice_count {
            let s = if slice_count == 1 {
                0.5 * f64::from(u8::from(moving))
            } else {
                k as f64 / (slice_count - 1) as f64
            };
            let center = self.a + sweep * s;
            let r_k = self.ra + (self.rb - self.ra) * s;
            // Vertical extent of the slice's cylinder.
            let h_k = self.ha + (self.hb - self.ha) * s;
            let (z_bottom, z_top) = (center.z - h_k, center.z + h_k);
            let z_mid = region_mid_z.clamp(z_bottom, z_top);
            let stagger = 0.5 * (k % 2) as f64;
            let lateral = (r_k + offset) / cos_a;
            candidates.clear();
            let ring = |axis: &Vec3, origin: Vec3, n: usize, out: &mut Vec<(Vec3, Vec3, f64)>| {
                let [_, w1, w2] = frame_along(axis);
                for j in 0..n {
                    let theta = std::f64::consts::TAU * (j as f64 + stagger) / n as f64;
                    out.push((origin, w1 * theta.cos() + w2 * theta.sin(), lateral));
                }
            };
            match (self.cylinder, moving) {
                (false, true) => ring(&sweep.normalize(), center, 4 * per_slice, &mut candidates),
                (false, false) => ring(&Vec3::z(), center, 4 * per_slice, &mut candidates),
                (true, _) => {
                    let flat_sweep = Vec3::new(sweep.x, sweep.y, 0.0);
                    if flat_sweep.norm() > 1e-9 {
                        let side = Vec3::new(-flat_sweep.y, flat_sweep.x, 0.0).normalize();
                        let z_lo = region.min.z.max(z_bottom);
                        let z_hi = region.max.z.min(z_top);
                        let heights = 2 * per_slice;
                        if z_lo <= z_hi {
                            for j in 0..heights {
                                let z = z_lo + (j as f64 + 0.5) / heights as f64 * (z_hi - z_lo);
                                let origin = Vec3::new(center.x, center.y, z);
                                candidates.push((origin, side, lateral));
                                candidates.push((origin, -side, lateral));
                            }
                        }
                    } else {
                        ring(
                            &Vec3::z(),
                            Vec3::new(center.x, center.y, z_mid),
                            4 * per_slice,
                            &mut candidates,
                        );
                    }
                    let top = Vec3::new(center.x, center.y, z_mid);
                    candidates.push((top, Vec3::z(), z_top - z_mid + offset));
                    candidates.push((top, -Vec3::z(), z_mid - z_bottom + offset));
                }
            }
            kept.clear();
            for (origin, dir, y0) in &candidates {
                let guess = origin + dir * (r_k + offset);
                if region.distance_to_point(&guess) > slack {
                    continue;
                }
                let p = self.point_at_distance(origin, dir, offset, *y0, reach);
                if region.contains(&p) {
                    kept.push(p);
                }
            }
            if kept.len() <= per_slice {
                out.extend_from_slice(&kept);
            } else {
                out.extend((0..per_slice).map(|i| kept[i * kept.len() / per_slice]));
            }
            // The end slices also get the point on the axis beyond the cap: the way around the
            // front or the back of the swept volume.
            if moving && (k == 0 || k + 1 == slice_count) {
                let axial = if self.cylinder {
                    let flat = Vec3::new(sweep.x, sweep.y, 0.0);
                    let n = flat.norm();
                    (n > 1e-9).then(|| flat / n)
                } else {
                    Some(sweep / sweep.norm())
                };
                if let Some(axial) = axial {
                    let dir = if k == 0 { -axial } else { axial };
                    let origin = if self.cylinder {
                        Vec3::new(center.x, center.y, z_mid)
                    } else {
                        center
                    };
                    let r_end = if k == 0 { self.ra } else { self.rb };
                    let p = self.point_at_distance(&origin, &dir, offset, r_end + offset, reach);
                    if region.contains(&p) {
                        out.push(p);
                    }
                }
            }
        }
        Ok(())
    }

    /// The point on the ray `origin + y·dir` (from a point inside the cone) whose signed distance
    /// is `offset`: Newton steps on `d(y) − offset` with the analytic gradient from `y = y0`,
    /// falling back to bisection on `y ∈ [0, reach]` (the distance grows along the ray) if they do
    /// not converge.
    fn point_at_distance(
        &self,
        origin: &Vec3,
        dir: &Vec3,
        offset: f64,
        y0: f64,
        reach: f64,
    ) -> Vec3 {
        let mut y = if y0.is_finite() { y0 } else { offset }.clamp(0.0, reach);
        for _ in 0..8 {
            let (d, g) = self.distance_and_gradient(&(origin + dir * y));
            let err = offset - d;
            if err.abs() < 1e-9 {
                return origin + dir * y;
            }
            let slope = g.dot(dir);
            if slope.is_nan() || slope <= 0.05 {
                break;
            }
            y = (y + err / slope).clamp(0.0, reach);
        }
        let (mut lo, mut hi) = (0.0, reach);
        for _ in 0..48 {
            let mid = 0.5 * (lo + hi);
            if self.signed_distance(&(origin + dir * mid)) < offset {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        origin + dir * hi
    }
}
