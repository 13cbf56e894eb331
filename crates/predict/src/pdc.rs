//! The predictive directional cone (PDC, paper Sec. III-B, eq. PDC).
//!
//! # Geometry
//!
//! Over a window `[t_s, t_e]` (length `T`), with `τ = t − t_s`, the obstacle is the base shape at
//! `c(τ) = c_s + v·τ` inflated to size `r(τ) = r_s + mu·τ` (cylinders: radius and half-height both
//! grow by `mu·τ`, see [`ObstacleShape`]). The PDC is the union of these shapes over `τ ∈ [0, T]`.
//!
//! Because the centre and the size are affine in `τ` and the shapes are homothetic, the shape at
//! `τ = λT` is the Minkowski combination `(1 − λ)·K(0) + λ·K(T)`, so **the PDC is the convex hull of
//! its two end shapes** — a tapered capsule ("cone-frustum capsule") for a sphere, the hull of two
//! cylinders for a cylinder. Two consequences used below:
//!
//! * `(x, τ) ↦ sd(x, K(τ))` is jointly convex (the signed distance to a convex set is
//!   `sup_n (n·x − σ_K(n))`, and the support function `σ_{K(τ)}(n)` is affine in `τ`), so along a
//!   segment `x(s)` the function `(s, τ) ↦ sd(x(s), K(τ))` is convex on `[0,1] × [0,T]`.
//! * Sphere: `‖x − c(τ)‖ − r(τ)` is a norm of an affine map minus an affine function, minimized in
//!   closed form over an interval or a polygon ([`crate::convex`]).
//!
//! # Exactness
//!
//! | query | sphere | cylinder |
//! |---|---|---|
//! | [`Pdc::signed_distance`] | exact outside; inside negative, magnitude ≤ true depth | same, by golden-section search on the convex `τ ↦ sd`, to within `(‖v‖ + √2·mu)·1e-13·T` |
//! | [`Pdc::point_clear`], [`Pdc::contains`] | exact | exact for `clearance ≤ 0`; conservative for `clearance > 0` |
//! | [`Pdc::segment_clear`] | exact | exact for `clearance ≤ 0`; conservative for `clearance > 0` |
//!
//! "Conservative" for cylinders: a positive clearance is applied by inflating the cylinder's radius
//! and half-height by `clearance` (a square rim instead of the rounded offset surface), so a point
//! or segment may be reported blocked although its distance is up to `√2·clearance` — never the
//! other way round. "Exact" means up to floating-point rounding; all clearance tests additionally
//! use [`CLEAR_TOLERANCE`] so that rounding can only make them stricter.

use std::f64::consts::PI;

use trust_geometry::{Aabb, Vec3, cylinder_sdf};

use crate::convex::{
    NormMinusAffine2d, Vec2, clip_half_plane, min_norm_minus_affine, min_over_convex_polygon,
};
use crate::error::{check_finite, check_non_negative, check_vec};
use crate::{Forecast, ObstacleShape, PredictError};

/// A point or segment counts as clear of a PDC only if its distance exceeds the requested clearance
/// by more than this (m); absorbs floating-point rounding in the exact tests.
pub const CLEAR_TOLERANCE: f64 = 1e-9;

/// Iterations of the golden-section search used for cylinder signed distances
/// (`0.618^70 ≈ 2.5e-15` of the window).
const GOLDEN_ITERATIONS: usize = 70;

/// The predictive directional cone of one [`Forecast`] over a time window (paper eq. PDC).
///
/// Build with [`Pdc::new`] (the paper's `[t0, t0 + T_h]`) or [`Pdc::over_window`]. See the module
/// documentation for the geometry and the exactness of every query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pdc {
    forecast: Forecast,
    t_start: f64,
    /// Window length `T` (s).
    duration: f64,
    /// Centre at `t_start`.
    c_start: Vec3,
    /// Radius at `t_start` (sphere or cylinder radius).
    r_start: f64,
    /// Vertical half-extent at `t_start` (cylinder half-height; the radius for a sphere).
    h_start: f64,
    /// Centre of a ball containing the PDC (the midpoint of the centre path).
    ball_center: Vec3,
    /// Radius of that ball: half the path length plus the final shape's circumradius.
    ball_radius: f64,
}

impl Pdc {
    /// The PDC over `[t0, t0 + horizon]` (paper eq. PDC with `T_h = horizon`).
    ///
    /// # Errors
    /// [`PredictError`] if the forecast is invalid or `horizon` is non-finite or negative.
    pub fn new(forecast: &Forecast, horizon: f64) -> Result<Self, PredictError> {
        check_non_negative("horizon", horizon)?;
        Self::over_window(forecast, forecast.t0, forecast.t0 + horizon)
    }

    /// The PDC over an arbitrary window `[t_start, t_end]` with `t0 ≤ t_start ≤ t_end` (e.g. from
    /// the planning time, later than the observation, to the end of the horizon).
    ///
    /// # Errors
    /// [`PredictError`] if the forecast is invalid, a time is non-finite, `t_start < forecast.t0`
    /// or `t_end < t_start`.
    pub fn over_window(
        forecast: &Forecast,
        t_start: f64,
        t_end: f64,
    ) -> Result<Self, PredictError> {
        forecast.validate()?;
        check_finite("t_start", t_start)?;
        check_finite("t_end", t_end)?;
        if t_end < t_start || t_start < forecast.t0 {
            return Err(PredictError::InvalidWindow {
                t_start,
                t_end,
                hint: format!(" and t_start >= forecast.t0 = {}", forecast.t0),
            });
        }
        let (c0, c1) = (forecast.center(t_start), forecast.center(t_end));
        let (r1, h1) = (forecast.radius(t_end), forecast.vertical_half_extent(t_end));
        let circumradius = match forecast.shape {
            ObstacleShape::Sphere => r1,
            ObstacleShape::Cylinder { .. } => r1.hypot(h1),
        };
        Ok(Pdc {
            forecast: *forecast,
            t_start,
            duration: t_end - t_start,
            c_start: c0,
            r_start: forecast.radius(t_start),
            h_start: forecast.vertical_half_extent(t_start),
            ball_center: 0.5 * (c0 + c1),
            ball_radius: 0.5 * (c1 - c0).norm() + circumradius,
        })
    }

    /// The forecast this cone was built from.
    pub fn forecast(&self) -> &Forecast {
        &self.forecast
    }

    /// Start of the window (s).
    pub fn t_start(&self) -> f64 {
        self.t_start
    }

    /// End of the window (s).
    pub fn t_end(&self) -> f64 {
        self.t_start + self.duration
    }

    /// Window length (s).
    pub fn horizon(&self) -> f64 {
        self.duration
    }

    /// Radius of a ball around `ball_center` containing every point the clearance tests with
    /// inflation `c` (clearance plus tolerance) could block: a cylinder grown by `c > 0` in radius
    /// and half-height has a circumradius at most `√2·c` larger.
    fn blocking_radius(&self, c: f64) -> f64 {
        let k = match self.forecast.shape {
            ObstacleShape::Sphere => 1.0,
            ObstacleShape::Cylinder { .. } => std::f64::consts::SQRT_2,
        };
        self.ball_radius + k * c.max(0.0)
    }

    fn v(&self) -> Vec3 {
        self.forecast.v0
    }

    fn mu(&self) -> f64 {
        self.forecast.mu
    }

    fn center_at(&self, tau: f64) -> Vec3 {
        self.c_start + self.forecast.v0 * tau
    }

    fn radius_at(&self, tau: f64) -> f64 {
        self.r_start + self.forecast.mu * tau
    }

    fn half_height_at(&self, tau: f64) -> f64 {
        self.h_start + self.forecast.mu * tau
    }

    /// Axis-aligned bounding box of the PDC (exact: the box of the two end shapes).
    pub fn aabb(&self) -> Aabb {
        let t = self.duration;
        let (c0, c1) = (self.c_start, self.center_at(t));
        let h0 = Vec3::new(self.r_start, self.r_start, self.h_start);
        let h1 = Vec3::new(self.radius_at(t), self.radius_at(t), self.half_height_at(t));
        Aabb {
            min: (c0 - h0).inf(&(c1 - h1)),
            max: (c0 + h0).sup(&(c1 + h1)),
        }
    }

    /// `min_τ sd(p, K(τ))`: the signed distance from `p` to the PDC — exact outside and on the
    /// boundary; inside it is negative with magnitude at most the true depth.
    ///
    /// Sphere: closed form ([`min_norm_minus_affine`]). Cylinder: golden-section search on the
    /// convex function `τ ↦ sd(p, K(τ))`; the value returned is attained at some `τ` (never below
    /// the true minimum) and exceeds it by at most `(‖v‖ + √2·mu)·1e-13·T`.
    /// `p` is assumed finite.
    pub fn signed_distance(&self, p: &Vec3) -> f64 {
        match self.forecast.shape {
            ObstacleShape::Sphere => {
                min_norm_minus_affine(
                    &(p - self.c_start),
                    &(-self.v()),
                    self.r_start,
                    self.mu(),
                    0.0,
                    self.duration,
                )
                .value
            }
            ObstacleShape::Cylinder { .. } => {
                let f = |tau: f64| {
                    cylinder_sdf(
                        &self.center_at(tau),
                        self.radius_at(tau),
                        self.half_height_at(tau),
                        p,
                    )
                    .0
                };
                golden_section_min(f, 0.0, self.duration)
            }
        }
    }

    /// Whether `p` lies in the PDC (within [`CLEAR_TOLERANCE`]). Exact for both shapes.
    /// Non-finite `p` counts as contained.
    pub fn contains(&self, p: &Vec3) -> bool {
        !self.point_clear(p, 0.0)
    }

    /// Whether `p` is farther than `clearance` (m, may be negative) from the PDC: exact for spheres
    /// and for `clearance ≤ 0`; conservative (may say "not clear" up to `√2·clearance`) for
    /// cylinders with `clearance > 0`. Non-finite input counts as not clear.
    pub fn point_clear(&self, p: &Vec3, clearance: f64) -> bool {
        if check_vec("p", p).is_err() || !clearance.is_finite() {
            return false;
        }
        let c = clearance + CLEAR_TOLERANCE;
        if (p - self.ball_center).norm() > self.blocking_radius(c) {
            return true; // broad phase: outside a ball containing the (inflated) cone
        }
        let w = p - self.c_start;
        let v = self.v();
        let mu = self.mu();
        match self.forecast.shape {
            ObstacleShape::Sphere => {
                min_norm_minus_affine(&w, &(-v), self.r_start + c, mu, 0.0, self.duration).value
                    > 0.0
            }
            ObstacleShape::Cylinder { .. } => {
                // Vertical overlap |w_z − v_z τ| ≤ h + c + mu τ is an interval of τ.
                let h = self.h_start + c;
                let mut lo = 0.0_f64;
                let mut hi = self.duration;
                for (a, b) in [(-v.z - mu, h - w.z), (v.z - mu, h + w.z)] {
                    if !restrict_interval(a, b, &mut lo, &mut hi) {
                        return true;
                    }
                }
                let wh = Vec3::new(w.x, w.y, 0.0);
                let vh = Vec3::new(-v.x, -v.y, 0.0);
                min_norm_minus_affine(&wh, &vh, self.r_start + c, mu, lo, hi).value > 0.0
            }
        }
    }

    /// Whether the segment `a → b` stays farther than `clearance` (m, may be negative) from the
    /// obstacle at **every** time of the window — the roadmap visibility test of DEV-PRM.
    ///
    /// Sphere: exact; minimizes `‖x(s) − c(τ)‖ − r(τ)` over `(s, τ) ∈ [0,1] × [0,T]` in closed form
    /// (a convex function: norm of an affine map minus an affine function). Cylinder: exact for
    /// `clearance ≤ 0`, conservative for `clearance > 0` (the cylinder is inflated by `clearance` in
    /// radius and half-height): the `(s, τ)` where the vertical extents overlap form a convex
    /// polygon, over which the horizontal distance is minimized in closed form. Non-finite input
    /// counts as not clear.
    pub fn segment_clear(&self, a: &Vec3, b: &Vec3, clearance: f64) -> bool {
        if check_vec("a", a).is_err() || check_vec("b", b).is_err() || !clearance.is_finite() {
            return false;
        }
        let c = clearance + CLEAR_TOLERANCE;
        if point_segment_distance(&self.ball_center, a, b) > self.blocking_radius(c) {
            return true; // broad phase: the segment misses a ball containing the (inflated) cone
        }
        let t = self.duration;
        let rect = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, t),
            Vec2::new(0.0, t),
        ];
        let m = a - self.c_start;
        let d = b - a;
        let v = self.v();
        let mu = self.mu();
        match self.forecast.shape {
            ObstacleShape::Sphere => {
                let f = NormMinusAffine2d {
                    m,
                    mx: d,
                    my: -v,
                    k0: self.r_start + c,
                    k: Vec2::new(0.0, mu),
                };
                min_over_convex_polygon(&f, &rect) > 0.0
            }
            ObstacleShape::Cylinder { .. } => {
                // e(s, τ) = m_z + d_z s − v_z τ; need |e| ≤ h + c + mu τ.
                let h = self.h_start + c;
                let poly = clip_half_plane(&rect, &Vec2::new(d.z, -v.z - mu), h - m.z);
                let poly = clip_half_plane(&poly, &Vec2::new(-d.z, v.z - mu), h + m.z);
                let flat = |x: Vec3| Vec3::new(x.x, x.y, 0.0);
                let f = NormMinusAffine2d {
                    m: flat(m),
                    mx: flat(d),
                    my: flat(-v),
                    k0: self.r_start + c,
                    k: Vec2::new(0.0, mu),
                };
                min_over_convex_polygon(&f, &poly) > 0.0
            }
        }
    }

    /// Points on the surface of the PDC inflated by `margin` (paper Sec. III-B, obstacle-aware
    /// samples), on `slices` cross-sections perpendicular to `v0` at evenly spaced times of the
    /// window (both ends included; one slice is at the middle), `per_slice` points per ring, rings
    /// of odd slices rotated by half a step. Deterministic.
    ///
    /// * Sphere with `‖v‖ > mu`: ring `k` is the circle along which the sphere at `τ_k` touches the
    ///   cone's surface (its normal makes `asin(mu/‖v‖)` with the cross-section); each point's
    ///   signed distance to the PDC is exactly `margin`.
    /// * Sphere with `‖v‖ ≤ mu` (or `v = 0`): the PDC is the final sphere; rings are its latitudes
    ///   about `v` (`z` if `v = 0`), signed distance exactly `margin`.
    /// * Cylinder: rays from the axis point `c(τ_k)` in the cross-section plane are cut where they
    ///   leave the PDC of the cylinder inflated by `margin` (bisection on the exact membership
    ///   test); signed distance in `[margin, √2·margin]` (up to `1e-8`). If the final cylinder
    ///   contains the whole PDC, horizontal rings on its side wall at evenly spaced heights
    ///   (signed distance exactly `margin`).
    ///
    /// Frames perpendicular to `v` are built from the coordinate axis least aligned with `v`, so a
    /// vertical `v` works.
    ///
    /// # Errors
    /// [`PredictError`] if `margin` is non-finite or negative, or `slices·per_slice` overflows.
    pub fn surface_samples(
        &self,
        slices: usize,
        per_slice: usize,
        margin: f64,
    ) -> Result<Vec<Vec3>, PredictError> {
        let mut out = Vec::new();
        self.surface_samples_into(slices, per_slice, margin, &mut out)?;
        Ok(out)
    }

    /// As [`Pdc::surface_samples`], appending to `out` (not cleared).
    ///
    /// # Errors
    /// As [`Pdc::surface_samples`].
    pub fn surface_samples_into(
        &self,
        slices: usize,
        per_slice: usize,
        margin: f64,
        out: &mut Vec<Vec3>,
    ) -> Result<(), PredictError> {
        check_non_negative("margin", margin)?;
        let count = slices
            .checked_mul(per_slice)
            .ok_or(PredictError::OutOfRange {
                field: "slices * per_slice".into(),
                value: slices as f64 * per_slice as f64,
                expected: "a product that fits in usize",
            })?;
        out.reserve(count);
        if count == 0 {
            return Ok(());
        }
        let t = self.duration;
        let v = self.v();
        let mu = self.mu();
        let speed = v.norm();
        let ring_angle =
            |k: usize, j: usize| 2.0 * PI * (j as f64 + 0.5 * (k % 2) as f64) / per_slice as f64;
        let slice_tau = |k: usize| {
            if slices == 1 {
                0.5 * t
            } else {
                t * k as f64 / (slices - 1) as f64
            }
        };
        match self.forecast.shape {
            ObstacleShape::Sphere => {
                if speed > mu && speed * t > 0.0 {
                    let axis = v / speed;
                    let (e1, e2) = perpendicular_frame(&axis);
                    let sin_a = mu / speed;
                    let cos_a = ((1.0 - sin_a) * (1.0 + sin_a)).sqrt();
                    for k in 0..slices {
                        let tau = slice_tau(k);
                        let (c, r) = (self.center_at(tau), self.radius_at(tau) + margin);
                        for j in 0..per_slice {
                            let th = ring_angle(k, j);
                            let n = axis * (-sin_a) + (e1 * th.cos() + e2 * th.sin()) * cos_a;
                            out.push(c + n * r);
                        }
                    }
                } else {
                    let axis = if speed > 0.0 { v / speed } else { Vec3::z() };
                    let (e1, e2) = perpendicular_frame(&axis);
                    let (c, r) = (self.center_at(t), self.radius_at(t) + margin);
                    for k in 0..slices {
                        let phi = PI * (k as f64 + 0.5) / slices as f64;
                        for j in 0..per_slice {
                            let th = ring_angle(k, j);
                            let n = axis * phi.cos() + (e1 * th.cos() + e2 * th.sin()) * phi.sin();
                            out.push(c + n * r);
                        }
                    }
                }
            }
            ObstacleShape::Cylinder { .. } => {
                let vh = v.xy().norm();
                if vh <= mu && v.z.abs() <= mu {
                    // The final cylinder contains every earlier one.
                    let (c, r, h) = (
                        self.center_at(t),
                        self.radius_at(t) + margin,
                        self.half_height_at(t) + margin,
                    );
                    for k in 0..slices {
                        let z = h * (2.0 * (k as f64 + 0.5) / slices as f64 - 1.0);
                        for j in 0..per_slice {
                            let th = ring_angle(k, j);
                            out.push(c + Vec3::new(r * th.cos(), r * th.sin(), z));
                        }
                    }
                } else {
                    let axis = v / speed;
                    let (e1, e2) = perpendicular_frame(&axis);
                    for k in 0..slices {
                        let tau = slice_tau(k);
                        for j in 0..per_slice {
                            let th = ring_angle(k, j);
                            let dir = e1 * th.cos() + e2 * th.sin();
                            out.push(self.ray_exit(tau, &dir, margin));
                        }
                    }
                }
            }
        }
        Ok(())
    }

    /// The first point outside the `margin`-inflated PDC along the ray `c(τ) + λ·dir` (`dir` a unit
    /// vector), by bisection on the exact membership test (the inflated PDC is convex and contains
    /// `c(τ)`). The bracket starts at the ray's exit from the shape at `τ` (inside the PDC) and its
    /// exit from the bounding ball (outside).
    fn ray_exit(&self, tau: f64, dir: &Vec3, margin: f64) -> Vec3 {
        let origin = self.center_at(tau);
        let exit_along = |extent: f64, component: f64| {
            if component == 0.0 {
                f64::INFINITY
            } else {
                extent / component.abs()
            }
        };
        let radial = exit_along(self.radius_at(tau) + margin, dir.xy().norm());
        let vertical = exit_along(self.half_height_at(tau) + margin, dir.z);
        let mut lo = radial.min(vertical);
        let w = origin - self.ball_center;
        let rho = self.blocking_radius(margin + CLEAR_TOLERANCE) + 1e-9;
        let along = dir.dot(&w);
        let mut hi = -along
            + (along * along - (w.norm_squared() - rho * rho))
                .max(0.0)
                .sqrt();
        if lo.partial_cmp(&hi) != Some(std::cmp::Ordering::Less) {
            lo = 0.0;
        }
        while hi - lo > 1e-10 * (1.0 + hi) {
            let mid = 0.5 * (lo + hi);
            if self.point_clear(&(origin + dir * mid), margin) {
                hi = mid;
            } else {
                lo = mid;
            }
        }
        origin + dir * hi
    }
}

/// Distance from `p` to the segment `a → b`.
fn point_segment_distance(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let d = b - a;
    let len2 = d.norm_squared();
    let s = if len2 > 0.0 {
        ((p - a).dot(&d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + d * s - p).norm()
}

/// Restricts `[lo, hi]` to `{τ : a·τ ≤ b}`; returns `false` if the result is empty.
fn restrict_interval(a: f64, b: f64, lo: &mut f64, hi: &mut f64) -> bool {
    if a > 0.0 {
        *hi = hi.min(b / a);
    } else if a < 0.0 {
        *lo = lo.max(b / a);
    } else if b < 0.0 {
        return false;
    }
    *lo <= *hi
}

/// Minimum of a convex (unimodal) function on `[lo, hi]` by golden-section search; returns the
/// smallest value evaluated (so never below the true minimum).
fn golden_section_min(f: impl Fn(f64) -> f64, lo: f64, hi: f64) -> f64 {
    const INV_PHI: f64 = 0.618_033_988_749_894_9;
    let (mut a, mut b) = (lo, hi);
    let mut best = f(a).min(f(b));
    if b <= a {
        return best;
    }
    let mut x1 = b - INV_PHI * (b - a);
    let mut x2 = a + INV_PHI * (b - a);
    let (mut f1, mut f2) = (f(x1), f(x2));
    for _ in 0..GOLDEN_ITERATIONS {
        if f1 <= f2 {
            b = x2;
            x2 = x1;
            f2 = f1;
            x1 = b - INV_PHI * (b - a);
            f1 = f(x1);
        } else {
            a = x1;
            x1 = x2;
            f1 = f2;
            x2 = a + INV_PHI * (b - a);
            f2 = f(x2);
        }
        best = best.min(f1).min(f2);
    }
    best
}

/// Two unit vectors completing the unit vector `axis` to a right-handed orthonormal frame
/// `(e1, e2, axis)`. The helper axis is the coordinate axis least aligned with `axis`, so every
/// direction (including vertical ones) gets a well-conditioned frame.
pub fn perpendicular_frame(axis: &Vec3) -> (Vec3, Vec3) {
    let a = axis.abs();
    let helper = if a.x <= a.y && a.x <= a.z {
        Vec3::x()
    } else if a.y <= a.z {
        Vec3::y()
    } else {
        Vec3::z()
    };
    let e1 = (helper - axis * helper.dot(axis)).normalize();
    let e2 = axis.cross(&e1);
    (e1, e2)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    fn v3(r: f64) -> impl Strategy<Value = Vec3> {
        (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    fn shape() -> impl Strategy<Value = ObstacleShape> {
        prop_oneof![
            Just(ObstacleShape::Sphere),
            (0.2..1.5f64).prop_map(|half_height| ObstacleShape::Cylinder { half_height }),
        ]
    }

    /// A forecast made at t0 = 0.5 and a PDC over `[t0 + lag, t0 + lag + horizon]`.
    fn pdc_strategy() -> impl Strategy<Value = Pdc> {
        (
            shape(),
            v3(1.0),
            v3(2.0),
            0.2..1.0f64,
            0.0..0.3f64,
            0.0..0.6f64,
            0.0..0.5f64,
            0.0..3.0f64,
        )
            .prop_map(|(shape, p0, v0, r_o, r_safe, mu, lag, horizon)| {
                let f = Forecast::new(shape, p0, v0, 0.5, r_o, r_safe, mu).unwrap();
                Pdc::over_window(&f, 0.5 + lag, 0.5 + lag + horizon).unwrap()
            })
    }

    /// The "square-rim" distance `max(q_r, q_z)` that the cylinder clearance tests use; equals the
    /// signed distance except outside near the rim, where it is smaller.
    fn square_rim(pdc: &Pdc, x: &Vec3, t: f64) -> f64 {
        let f = pdc.forecast();
        let q = x - f.center(t);
        (q.x.hypot(q.y) - f.radius(t)).max(q.z.abs() - f.vertical_half_extent(t))
    }

    /// Dense minimum over (s, t) of a function, with the grid's Lipschitz slack.
    fn dense_min(
        pdc: &Pdc,
        a: &Vec3,
        b: &Vec3,
        n: usize,
        g: impl Fn(&Vec3, f64) -> f64,
    ) -> (f64, f64) {
        let mut best = f64::INFINITY;
        for i in 0..=n {
            let x = a + (b - a) * (i as f64 / n as f64);
            for j in 0..=n {
                let t = pdc.t_start() + pdc.horizon() * j as f64 / n as f64;
                best = best.min(g(&x, t));
            }
        }
        let f = pdc.forecast();
        let lip_s = (b - a).norm();
        let lip_t = f.v0.norm() + std::f64::consts::SQRT_2 * f.mu;
        (best, (lip_s + lip_t * pdc.horizon()) / n as f64)
    }

    #[test]
    fn window_validation() {
        let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 1.0, 0.5, 0.0, 0.1).unwrap();
        assert!(
            matches!(Pdc::new(&f, -1.0), Err(PredictError::OutOfRange { ref field, .. }) if field == "horizon")
        );
        assert!(Pdc::new(&f, f64::NAN).is_err());
        assert!(matches!(
            Pdc::over_window(&f, 0.5, 2.0),
            Err(PredictError::InvalidWindow { .. })
        ));
        assert!(Pdc::over_window(&f, 2.0, 1.5).is_err());
        let mut bad = f;
        bad.r_o = -1.0;
        assert!(Pdc::new(&bad, 1.0).is_err());
        let p = Pdc::over_window(&f, 1.5, 3.0).unwrap();
        assert_relative_eq!(p.t_end(), 3.0);
        assert_relative_eq!(p.horizon(), 1.5);
        assert_eq!(p.forecast(), &f);
    }

    #[test]
    fn sphere_cone_closed_form_on_axis_and_side() {
        // r(τ) = 1 + 0.5τ, c(τ) = (2τ, 0, 0), T = 2: end ball at x = 4 with r = 2.
        let f =
            Forecast::sphere(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), 0.0, 1.0, 0.0, 0.5).unwrap();
        let pdc = f.pdc(2.0).unwrap();
        assert_relative_eq!(
            pdc.signed_distance(&Vec3::new(7.0, 0.0, 0.0)),
            1.0,
            epsilon = 1e-12
        );
        assert_relative_eq!(
            pdc.signed_distance(&Vec3::new(-3.0, 0.0, 0.0)),
            2.0,
            epsilon = 1e-12
        );
        // Beside the cone: the tangent line has slope sin α = 0.25.
        let p = Vec3::new(2.0, 5.0, 0.0);
        let brute = (0..=20000)
            .map(|i| f.signed_distance(&p, 2.0 * i as f64 / 20000.0))
            .fold(f64::INFINITY, f64::min);
        assert_relative_eq!(pdc.signed_distance(&p), brute, epsilon = 1e-6);
        assert!(pdc.contains(&Vec3::new(3.9, 1.9, 0.0)));
        assert!(!pdc.contains(&Vec3::new(0.0, 1.1, 0.0)));
    }

    #[test]
    fn slow_sphere_cone_is_the_final_ball() {
        let f =
            Forecast::sphere(Vec3::zeros(), Vec3::new(0.0, 0.0, 0.3), 0.0, 1.0, 0.0, 0.5).unwrap();
        let pdc = f.pdc(2.0).unwrap();
        for p in [
            Vec3::new(0.0, 0.0, -3.0),
            Vec3::new(2.5, 0.0, 0.6),
            Vec3::new(0.1, 0.2, 0.3),
        ] {
            assert_relative_eq!(
                pdc.signed_distance(&p),
                f.signed_distance(&p, 2.0),
                epsilon = 1e-12
            );
        }
        let samples = pdc.surface_samples(5, 7, 0.2).unwrap();
        assert_eq!(samples.len(), 35);
        for s in &samples {
            assert_relative_eq!(pdc.signed_distance(s), 0.2, epsilon = 1e-9);
        }
    }

    #[test]
    fn zero_velocity_and_zero_horizon_are_fine() {
        for shape in [
            ObstacleShape::Sphere,
            ObstacleShape::Cylinder { half_height: 1.0 },
        ] {
            let f = Forecast::new(
                shape,
                Vec3::new(1.0, 1.0, 1.0),
                Vec3::zeros(),
                0.0,
                0.5,
                0.1,
                0.0,
            )
            .unwrap();
            for horizon in [0.0, 2.0] {
                let pdc = f.pdc(horizon).unwrap();
                let samples = pdc.surface_samples(3, 6, 0.1).unwrap();
                assert_eq!(samples.len(), 18);
                for s in &samples {
                    let d = pdc.signed_distance(s);
                    assert!(
                        d > 0.1 - 1e-9 && d < 0.1 * std::f64::consts::SQRT_2 + 1e-9,
                        "{shape:?}: {d}"
                    );
                }
                assert!(pdc.contains(&f.p0));
                assert!(!pdc.segment_clear(
                    &Vec3::new(-5.0, 1.0, 1.0),
                    &Vec3::new(5.0, 1.0, 1.0),
                    0.0
                ));
                assert!(pdc.segment_clear(
                    &Vec3::new(-5.0, 3.0, 1.0),
                    &Vec3::new(5.0, 3.0, 1.0),
                    0.5
                ));
                // A degenerate segment behaves like a point.
                let p = Vec3::new(1.0, 1.75, 1.0);
                assert_eq!(pdc.segment_clear(&p, &p, 0.1), pdc.point_clear(&p, 0.1));
            }
        }
    }

    #[test]
    fn vertical_velocity_frames_work() {
        for shape in [
            ObstacleShape::Sphere,
            ObstacleShape::Cylinder { half_height: 0.5 },
        ] {
            let f = Forecast::new(
                shape,
                Vec3::zeros(),
                Vec3::new(0.0, 0.0, -2.0),
                0.0,
                0.5,
                0.0,
                0.2,
            )
            .unwrap();
            let pdc = f.pdc(1.5).unwrap();
            let samples = pdc.surface_samples(4, 6, 0.05).unwrap();
            assert_eq!(samples.len(), 24);
            for s in &samples {
                assert!(s.iter().all(|x| x.is_finite()));
                let d = pdc.signed_distance(s);
                assert!(
                    d > 0.05 - 1e-9 && d < 0.05 * std::f64::consts::SQRT_2 + 1e-9,
                    "{shape:?}: {d}"
                );
            }
        }
        let (e1, e2) = perpendicular_frame(&Vec3::z());
        assert_relative_eq!(e1.dot(&e2), 0.0);
        assert_relative_eq!(e1.cross(&e2), Vec3::z());
    }

    #[test]
    fn non_finite_queries_are_blocked_and_bad_margin_is_an_error() {
        let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 0.0, 0.5, 0.0, 0.1).unwrap();
        let pdc = f.pdc(1.0).unwrap();
        let nan = Vec3::new(f64::NAN, 0.0, 0.0);
        assert!(pdc.contains(&nan));
        assert!(!pdc.point_clear(&Vec3::new(9.0, 9.0, 9.0), f64::NAN));
        assert!(!pdc.segment_clear(&nan, &Vec3::zeros(), 0.1));
        assert!(!pdc.segment_clear(
            &Vec3::new(9.0, 9.0, 9.0),
            &Vec3::new(9.0, 9.0, 8.0),
            f64::INFINITY
        ));
        assert!(pdc.surface_samples(2, 2, -0.1).is_err());
        assert!(pdc.surface_samples(2, 2, f64::NAN).is_err());
        assert!(pdc.surface_samples(usize::MAX, 2, 0.1).is_err());
        assert!(pdc.surface_samples(0, 5, 0.1).unwrap().is_empty());
    }

    #[test]
    fn tall_cylinder_crossing_a_horizontal_segment() {
        // A pillar (r = 0.3, h = 2) walking along +y at 1 m/s crosses the segment x ∈ [-3, 3], y = 2.
        let f = Forecast::new(
            ObstacleShape::Cylinder { half_height: 2.0 },
            Vec3::new(0.0, 0.0, 1.0),
            Vec3::new(0.0, 1.0, 0.0),
            0.0,
            0.3,
            0.0,
            0.0,
        )
        .unwrap();
        let (a, b) = (Vec3::new(-3.0, 2.0, 1.0), Vec3::new(3.0, 2.0, 1.0));
        assert!(!f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.1));
        assert!(f.pdc(1.5).unwrap().segment_clear(&a, &b, 0.1)); // it has not arrived yet
        // Flying above it is clear; a clearance reaching down to the top is not.
        let (a, b) = (Vec3::new(-3.0, 2.0, 3.5), Vec3::new(3.0, 2.0, 3.5));
        assert!(f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.4));
        assert!(!f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.6));
    }

    proptest! {
        #[test]
        fn signed_distance_matches_dense_time_sampling(pdc in pdc_strategy(), p in v3(4.0)) {
            let n = 4000;
            let f = pdc.forecast();
            let dense = (0..=n)
                .map(|j| f.signed_distance(&p, pdc.t_start() + pdc.horizon() * j as f64 / n as f64))
                .fold(f64::INFINITY, f64::min);
            let slack = (f.v0.norm() + 1.5 * f.mu) * pdc.horizon() / n as f64 + 1e-9;
            let d = pdc.signed_distance(&p);
            prop_assert!(d <= dense + 1e-9, "{d} above dense {dense}");
            prop_assert!(d >= dense - slack, "{d} below dense {dense}");
        }

        #[test]
        fn point_clear_agrees_with_signed_distance(pdc in pdc_strategy(), p in v3(4.0), clearance in -0.2..0.5f64) {
            let d = pdc.signed_distance(&p);
            let clear = pdc.point_clear(&p, clearance);
            if d < clearance - 1e-7 {
                prop_assert!(!clear, "d = {d} < clearance {clearance} but clear");
            }
            if !clear {
                let bound = match pdc.forecast().shape {
                    ObstacleShape::Sphere => clearance,
                    ObstacleShape::Cylinder { .. } => clearance.max(std::f64::consts::SQRT_2 * clearance),
                };
                prop_assert!(d <= bound + 1e-7, "blocked but d = {d} > {bound}");
            }
            prop_assert_eq!(pdc.contains(&p), !pdc.point_clear(&p, 0.0));
        }

        #[test]
        fn segment_clear_agrees_with_dense_sampling(
            pdc in pdc_strategy(), a in v3(4.0), b in v3(4.0), clearance in -0.2..0.5f64,
        ) {
            let f = *pdc.forecast();
            let clear = pdc.segment_clear(&a, &b, clearance);
            let (dense_sd, slack) = dense_min(&pdc, &a, &b, 120, |x, t| f.signed_distance(x, t));
            // A sampled hit must be reported.
            if dense_sd < clearance - 1e-9 {
                prop_assert!(!clear, "dense min {dense_sd} < clearance {clearance} but reported clear");
            }
            // A reported block must be (nearly) real: exact for spheres, the square-rim superset for
            // cylinders.
            if !clear {
                let dense_exact = match f.shape {
                    ObstacleShape::Sphere => dense_sd,
                    ObstacleShape::Cylinder { .. } => dense_min(&pdc, &a, &b, 120, |x, t| square_rim(&pdc, x, t)).0,
                };
                prop_assert!(dense_exact <= clearance + slack + 1e-9,
                    "blocked but dense min {dense_exact} > clearance {clearance} + slack {slack}");
            }
        }

        #[test]
        fn surface_samples_lie_on_the_inflated_surface(
            pdc in pdc_strategy(), slices in 1usize..6, per_slice in 1usize..9, margin in 0.0..0.3f64,
        ) {
            let samples = pdc.surface_samples(slices, per_slice, margin).unwrap();
            prop_assert_eq!(samples.len(), slices * per_slice);
            for s in &samples {
                let d = pdc.signed_distance(s);
                match pdc.forecast().shape {
                    ObstacleShape::Sphere => prop_assert!((d - margin).abs() < 1e-9, "d = {d}, margin {margin}"),
                    ObstacleShape::Cylinder { .. } => prop_assert!(
                        d > margin - 1e-8 && d < std::f64::consts::SQRT_2 * margin + 1e-8,
                        "d = {d}, margin {margin}"
                    ),
                }
            }
        }

        #[test]
        fn aabb_contains_the_cone(pdc in pdc_strategy(), dirs in proptest::collection::vec(v3(1.0), 8)) {
            let b = pdc.aabb();
            let f = pdc.forecast();
            for (j, dir) in dirs.iter().enumerate() {
                prop_assume!(dir.norm() > 1e-3);
                let t = pdc.t_start() + pdc.horizon() * j as f64 / 7.0;
                let c = f.center(t);
                let ext = Vec3::new(f.radius(t), f.radius(t), f.vertical_half_extent(t));
                let corner = c + ext.component_mul(&dir.map(f64::signum));
                prop_assert!(b.inflated(1e-9).contains(&corner));
            }
        }
    }
}
