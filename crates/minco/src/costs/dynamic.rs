//! The moving-obstacle penalty `I_o` through the dynamic distance field (paper eqs. design-of-Io
//! and gradients-of-Io).

use trust_core::{Aabb, Forecast, ObstacleShape, Vec3};

use super::integrand::{Integrand, SampleGrad, SampleState};
use super::smooth::SmoothedL1;

/// The DDF violation `φ_o` of one forecast at `(p, t)` and its partial derivatives
/// `(φ, ∂φ/∂p, ∂φ/∂t)`.
///
/// With `d` the forecast's signed distance ([`Forecast::distance_and_gradients`]), `c` the extra
/// `clearance`, `d' = d − c` and `R = radius(t) + c`:
/// `φ = −d' (2R + d')`. For a sphere this is exactly the paper's signed squared distance
/// `R² − ‖p − p_o(t)‖²` (positive inside the inflated obstacle); for a cylinder it is the same
/// expression of the cylinder's signed distance and radius, which keeps the sphere's scale and is
/// monotone in `d` (`R + d' ≥ 0` everywhere). `∂φ/∂t` is the obstacle part (b) of eq.
/// gradients-of-Io: centre motion and radius growth, `∂φ/∂d'·∂d/∂t + ∂φ/∂R·Ṙ`.
#[inline]
pub fn ddf_violation(forecast: &Forecast, p: &Vec3, t: f64, clearance: f64) -> (f64, Vec3, f64) {
    let (d, d_p, d_t) = forecast.distance_and_gradients(p, t);
    let dd = d - clearance;
    let r = forecast.radius(t) + clearance;
    let phi = -dd * (2.0 * r + dd);
    let phi_d = -2.0 * (r + dd);
    let phi_r = -2.0 * dd;
    (
        phi,
        d_p * phi_d,
        phi_d * d_t + phi_r * forecast.radius_rate(t),
    )
}

/// Cheap exact rejection before [`ddf_violation`]: `true` only if `p` is farther than
/// `clearance` from the inflated obstacle at `t`, where `φ ≤ 0` (no penalty). Compares squared
/// distances (no square root, no `hypot`); a cylinder is tested against its bounding
/// cylinder with flat, unrounded caps, a superset of the points within `clearance`.
#[inline]
fn outside_inflated(forecast: &Forecast, p: &Vec3, t: f64, clearance: f64) -> bool {
    let q = p - forecast.center(t);
    let r = forecast.radius(t) + clearance;
    match forecast.shape {
        ObstacleShape::Sphere => q.norm_squared() >= r * r,
        ObstacleShape::Cylinder { .. } => {
            q.x * q.x + q.y * q.y >= r * r
                || q.z.abs() >= forecast.vertical_half_extent(t) + clearance
        }
    }
}

/// Axis-aligned box that contains every point within `margin` of the inflated obstacle at any
/// time of `[t_a, t_b]` (broad phase). Never fails; non-finite input gives a non-finite box that
/// intersects nothing.
#[inline]
pub fn swept_box(forecast: &Forecast, t_a: f64, t_b: f64, margin: f64) -> Aabb {
    let (ca, cb) = (forecast.center(t_a), forecast.center(t_b));
    let t_max = t_a.max(t_b);
    let r = forecast.radius(t_max) + margin;
    let half = Vec3::new(r, r, forecast.vertical_half_extent(t_max) + margin);
    Aabb {
        min: ca.inf(&cb) - half,
        max: ca.sup(&cb) + half,
    }
}

/// `I_o` for moving obstacles: `L_o = Σ_O f_max(φ_o)` (paper eq. design-of-Io) with
/// [`ddf_violation`] and [`super::smoothed_l1`].
///
/// Broad phase: per trajectory and then per piece, only forecasts whose [`swept_box`] over the
/// time window (inflated by the clearance) meets the box of the samples are evaluated; the
/// others have `φ < 0` at every sample, so the result is the same as evaluating all of them.
///
/// The per-trajectory test runs at every evaluation of an optimization, over every forecast.
/// Between evaluations the trajectory moves little, so the term keeps a *superset*: the
/// forecasts whose swept box over a wider window (1.5 s later, `SUPERSET_MARGIN_S`) meets a wider
/// region (4 m around the samples, `SUPERSET_MARGIN_M`). While later trajectories stay inside that
/// window and region, only the superset is tested — with the same result, because a forecast's
/// swept box over a sub-window lies inside its box over the window (linear motion, radius
/// non-decreasing in time).
#[derive(Debug, Clone)]
pub struct DynamicObstacleTerm<'a> {
    forecasts: &'a [Forecast],
    clearance: f64,
    smoothing: SmoothedL1,
    near_trajectory: Vec<usize>,
    near_piece: Vec<usize>,
    superset: Superset,
}

/// How far (m) the superset's region reaches beyond the samples that built it. It also covers
/// a braking tail (`v_max² / 2a_max`, 3.3 m at 10 m/s and 15 m/s²) from a terminal inside.
pub const SUPERSET_MARGIN_M: f64 = 4.0;

/// How far (s) the superset's window reaches beyond the end of the trajectory that built it
/// (the braking tail's window starts there).
pub const SUPERSET_MARGIN_S: f64 = 1.5;

/// The cached superset of the trajectory broad phase ([`DynamicObstacleTerm`]).
#[derive(Debug, Clone)]
struct Superset {
    /// `false` if some forecast's radius shrinks in time (`μ < 0`, which `Forecast::validate`
    /// rejects): the containment argument fails, so no superset is used.
    usable: bool,
    /// Region, window and forecast indices; `None` until the first trajectory.
    cached: Option<(Aabb, f64, f64)>,
    indices: Vec<usize>,
    /// Times the superset was rebuilt (diagnostics and tests).
    rebuilds: usize,
}

impl<'a> DynamicObstacleTerm<'a> {
    /// The penalty against `forecasts` with extra `clearance` (m) and smoothing `μ`.
    pub fn new(forecasts: &'a [Forecast], clearance: f64, smoothing: f64) -> Self {
        Self {
            forecasts,
            clearance,
            smoothing: SmoothedL1::new(smoothing),
            near_trajectory: Vec::with_capacity(forecasts.len()),
            near_piece: Vec::with_capacity(forecasts.len()),
            superset: Superset {
                usable: forecasts.iter().all(|f| f.mu >= 0.0),
                cached: None,
                indices: Vec::with_capacity(forecasts.len()),
                rebuilds: 0,
            },
        }
    }

    /// Times the per-trajectory broad phase rebuilt its superset (see the type's docs).
    pub fn superset_rebuilds(&self) -> usize {
        self.superset.rebuilds
    }

    /// Indices of the forecasts that survived the broad phase of the current piece.
    pub fn candidates(&self) -> &[usize] {
        &self.near_piece
    }

    /// `L_o` at `(p, t)` without broad phase: adds `weight · ∂L_o/∂p` into `grad_p` and
    /// `weight · ∂L_o/∂t` into `grad_t` and returns the unweighted `L_o` over the forecasts listed
    /// in `indices`.
    #[inline(always)]
    fn accumulate(
        &self,
        indices: impl Iterator<Item = usize>,
        p: &Vec3,
        t: f64,
        weight: f64,
        grad_p: &mut Vec3,
        grad_t: &mut f64,
    ) -> f64 {
        let mut total = 0.0;
        for o in indices {
            let forecast = &self.forecasts[o];
            if outside_inflated(forecast, p, t, self.clearance) {
                continue;
            }
            let (phi, phi_p, phi_t) = ddf_violation(forecast, p, t, self.clearance);
            if phi <= 0.0 {
                continue;
            }
            let (value, slope) = self.smoothing.eval(phi);
            total += value;
            let k = weight * slope;
            *grad_p += phi_p * k;
            *grad_t += phi_t * k;
        }
        total
    }

    /// Broad phase for the whole trajectory.
    pub(crate) fn begin_trajectory_impl(&mut self, t_begin: f64, t_end: f64, samples_box: &Aabb) {
        self.near_trajectory.clear();
        let clearance = self.clearance;
        let superset = &mut self.superset;
        if !superset.usable {
            for (o, f) in self.forecasts.iter().enumerate() {
                if swept_box(f, t_begin, t_end, clearance).intersects(samples_box) {
                    self.near_trajectory.push(o);
                }
            }
            return;
        }
        let inside = superset.cached.is_some_and(|(region, w0, w1)| {
            t_begin >= w0 && t_end <= w1 && t_begin <= t_end && region.contains_box(samples_box)
        });
        if !inside {
            let region = samples_box.inflated(SUPERSET_MARGIN_M);
            let (w0, w1) = (t_begin, t_end.max(t_begin) + SUPERSET_MARGIN_S);
            superset.indices.clear();
            for (o, f) in self.forecasts.iter().enumerate() {
                if swept_box(f, w0, w1, clearance).intersects(&region) {
                    superset.indices.push(o);
                }
            }
            superset.cached = Some((region, w0, w1));
            superset.rebuilds += 1;
        }
        for &o in &superset.indices {
            let f = &self.forecasts[o];
            if swept_box(f, t_begin, t_end, clearance).intersects(samples_box) {
                self.near_trajectory.push(o);
            }
        }
    }

    /// Broad phase for one piece; `true` if any forecast survived: the forecasts of the
    /// trajectory's broad phase whose [`swept_box`] over `[t_begin, t_end]` (inflated by the
    /// clearance) meets `samples_box` (computed inline, without building the box).
    pub(crate) fn begin_piece_impl(
        &mut self,
        t_begin: f64,
        t_end: f64,
        samples_box: &Aabb,
    ) -> bool {
        self.near_piece.clear();
        let (b_min, b_max) = (samples_box.min, samples_box.max);
        let t_max = t_begin.max(t_end);
        for &o in &self.near_trajectory {
            let f = &self.forecasts[o];
            let (da, db) = (t_begin - f.t0, t_end - f.t0);
            let r = f.radius(t_max) + self.clearance;
            let rz = f.vertical_half_extent(t_max) + self.clearance;
            // Per axis: the centre's range over the window, grown by the half-extent, must meet
            // the box.
            let meets = |p0: f64, v0: f64, half: f64, lo: f64, hi: f64| {
                let (a, b) = (p0 + v0 * da, p0 + v0 * db);
                let (c_lo, c_hi) = if a <= b { (a, b) } else { (b, a) };
                c_lo - half <= hi && lo <= c_hi + half
            };
            if meets(f.p0.x, f.v0.x, r, b_min.x, b_max.x)
                && meets(f.p0.y, f.v0.y, r, b_min.y, b_max.y)
                && meets(f.p0.z, f.v0.z, rz, b_min.z, b_max.z)
            {
                self.near_piece.push(o);
            }
        }
        !self.near_piece.is_empty()
    }

    /// `L_o` at `(p, t)` over the current piece's candidates; adds the gradient scaled by
    /// `weight` into `grad_p` and `grad_t`.
    #[inline(always)]
    pub(crate) fn at(
        &self,
        p: &Vec3,
        t: f64,
        weight: f64,
        grad_p: &mut Vec3,
        grad_t: &mut f64,
    ) -> f64 {
        self.accumulate(
            self.near_piece.iter().copied(),
            p,
            t,
            weight,
            grad_p,
            grad_t,
        )
    }

    /// Sets `flags[k]` for every node `k` (position `(x[k], y[k], z[k])`, time `t[k]`) that is
    /// not provably farther than the clearance plus
    /// [`FILTER_MARGIN_M`](crate::costs::integrand::FILTER_MARGIN_M) from a forecast kept by
    /// the piece's broad phase (the rejection of [`outside_inflated`], column by column).
    #[expect(
        clippy::neg_cmp_op_on_partial_ord,
        reason = "a NaN must count as possibly active"
    )]
    pub(crate) fn flag_nodes(
        &self,
        x: &[f64],
        y: &[f64],
        z: &[f64],
        t: &[f64],
        flags: &mut [bool],
    ) {
        let m = flags.len();
        let (x, y, z, t) = (&x[..m], &y[..m], &z[..m], &t[..m]);
        let grow = self.clearance + crate::costs::integrand::FILTER_MARGIN_M;
        for &o in &self.near_piece {
            let f = &self.forecasts[o];
            let (p0, v0, t0) = (f.p0, f.v0, f.t0);
            match f.shape {
                ObstacleShape::Sphere => {
                    for (k, flag) in flags.iter_mut().enumerate() {
                        let dt = t[k] - t0;
                        let (qx, qy, qz) = (
                            x[k] - (p0.x + v0.x * dt),
                            y[k] - (p0.y + v0.y * dt),
                            z[k] - (p0.z + v0.z * dt),
                        );
                        let r = f.radius(t[k]) + grow;
                        *flag |= !(qx * qx + qy * qy + qz * qz >= r * r);
                    }
                }
                ObstacleShape::Cylinder { .. } => {
                    for (k, flag) in flags.iter_mut().enumerate() {
                        let dt = t[k] - t0;
                        let (qx, qy, qz) = (
                            x[k] - (p0.x + v0.x * dt),
                            y[k] - (p0.y + v0.y * dt),
                            z[k] - (p0.z + v0.z * dt),
                        );
                        let r = f.radius(t[k]) + grow;
                        let h = f.vertical_half_extent(t[k]) + grow;
                        *flag |= !(qx * qx + qy * qy >= r * r || qz.abs() >= h);
                    }
                }
            }
        }
    }

    /// `L_o` at one node over **all** forecasts (no broad phase), gradient added into `grad`.
    /// Used to check the broad phase; prefer integrating the term.
    pub fn sample_all(&self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        self.accumulate(
            0..self.forecasts.len(),
            &s.p,
            s.t,
            1.0,
            &mut grad.p,
            &mut grad.t,
        )
    }
}

impl Integrand for DynamicObstacleTerm<'_> {
    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, samples_box: &Aabb) {
        self.begin_trajectory_impl(t_begin, t_end, samples_box);
    }

    fn begin_piece(&mut self, _piece: usize, t_begin: f64, t_end: f64, samples_box: &Aabb) -> bool {
        self.begin_piece_impl(t_begin, t_end, samples_box)
    }

    #[inline]
    fn sample(&mut self, s: &SampleState, grad: &mut SampleGrad) -> f64 {
        self.at(&s.p, s.t, 1.0, &mut grad.p, &mut grad.t)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;
    use trust_core::ObstacleShape;
    use trust_numdiff::central_difference;

    fn forecast(cylinder: bool) -> Forecast {
        let shape = if cylinder {
            ObstacleShape::Cylinder { half_height: 1.5 }
        } else {
            ObstacleShape::Sphere
        };
        Forecast::new(
            shape,
            Vec3::new(1.0, 2.0, 3.0),
            Vec3::new(0.5, -1.0, 0.2),
            0.5,
            0.8,
            0.2,
            0.3,
        )
        .unwrap()
    }

    #[test]
    fn the_superset_is_reused_while_the_trajectory_stays_inside_it() {
        let forecasts = vec![forecast(false), forecast(true)];
        let mut term = DynamicObstacleTerm::new(&forecasts, 0.3, 0.1);
        let b = Aabb::new(Vec3::new(0.0, 0.0, 0.0), Vec3::new(5.0, 3.0, 3.0)).unwrap();
        term.begin_trajectory_impl(0.5, 3.0, &b);
        term.begin_trajectory_impl(0.5, 3.5, &b.inflated(1.0));
        assert_eq!(term.superset_rebuilds(), 1);
        term.begin_trajectory_impl(0.5, 3.0, &b.inflated(SUPERSET_MARGIN_M + 0.1));
        term.begin_trajectory_impl(0.5, 3.0 + SUPERSET_MARGIN_S + 0.1, &b);
        assert_eq!(term.superset_rebuilds(), 3);
        let nan = Aabb {
            min: Vec3::repeat(f64::NAN),
            max: Vec3::repeat(f64::NAN),
        };
        term.begin_trajectory_impl(0.5, 3.0, &nan);
        assert!(term.near_trajectory.is_empty());
    }

    #[test]
    fn sphere_violation_is_the_signed_squared_distance() {
        let f = forecast(false);
        let (p, t, c) = (Vec3::new(1.3, 1.9, 3.4), 1.0, 0.1);
        let r = f.radius(t) + c;
        let (phi, _, _) = ddf_violation(&f, &p, t, c);
        assert_relative_eq!(
            phi,
            r * r - (p - f.center(t)).norm_squared(),
            epsilon = 1e-12
        );
    }

    proptest! {
        #[test]
        fn violation_gradients_match_finite_differences(
            px in -1.0..3.0f64, py in 0.0..4.0f64, pz in 1.0..5.0f64,
            t in 0.6..2.0f64, cylinder in any::<bool>(),
        ) {
            let f = forecast(cylinder);
            let p = Vec3::new(px, py, pz);
            let c = 0.1;
            let (_, gp, gt) = ddf_violation(&f, &p, t, c);
            let h = 1e-6;
            for d in 0..3 {
                let fd = central_difference(|s| ddf_violation(&f, &(p + Vec3::ith(d, s)), t, c).0, 0.0, h);
                prop_assert!((fd - gp[d]).abs() < 1e-4 * (1.0 + fd.abs()), "p[{d}]: {fd} vs {}", gp[d]);
            }
            let fd = central_difference(|s| ddf_violation(&f, &p, s, c).0, t, h);
            prop_assert!((fd - gt).abs() < 1e-4 * (1.0 + fd.abs()), "t: {fd} vs {gt}");
        }

        /// The cheap rejection never skips a sample with a positive violation.
        #[test]
        fn rejection_is_exact(
            px in -2.0..4.0f64, py in -1.0..5.0f64, pz in 0.0..6.0f64,
            t in 0.0..3.0f64, clearance in 0.0..0.5f64, cylinder in any::<bool>(),
        ) {
            let f = forecast(cylinder);
            let p = Vec3::new(px, py, pz);
            if outside_inflated(&f, &p, t, clearance) {
                prop_assert!(ddf_violation(&f, &p, t, clearance).0 <= 0.0);
            }
        }

        /// The per-trajectory broad phase through the cached superset keeps exactly the
        /// forecasts the brute-force test keeps, along a drifting sequence of trajectories (as
        /// in one optimization), and reuses the superset while the drift is small.
        #[test]
        fn the_cached_superset_keeps_exactly_the_brute_force_candidates(
            obstacles in proptest::collection::vec(
                (-20.0..20.0f64, -20.0..20.0f64, 0.0..6.0f64, -3.0..3.0f64, -3.0..3.0f64,
                 0.0..0.6f64, any::<bool>()),
                1..40),
            steps in proptest::collection::vec(
                (-1.5..1.5f64, -1.5..1.5f64, -0.3..0.3f64, -0.4..0.6f64), 1..30),
        ) {
            let forecasts: Vec<Forecast> = obstacles
                .iter()
                .map(|&(x, y, z, vx, vy, mu, cylinder)| {
                    let shape = if cylinder {
                        ObstacleShape::Cylinder { half_height: 1.0 }
                    } else {
                        ObstacleShape::Sphere
                    };
                    Forecast::new(shape, Vec3::new(x, y, z), Vec3::new(vx, vy, 0.0), 0.0, 0.5, 0.2, mu)
                        .unwrap()
                })
                .collect();
            let mut term = DynamicObstacleTerm::new(&forecasts, 0.3, 0.1);
            let (mut lo, mut hi) = (Vec3::new(-8.0, -2.0, 1.0), Vec3::new(2.0, 3.0, 4.0));
            let (t_begin, mut t_end) = (0.5, 3.0);
            for &(dx, dy, dz, dt) in &steps {
                lo += Vec3::new(dx, dy, dz);
                hi += Vec3::new(dx, dy, dz) * 0.5;
                t_end = (t_end + dt).max(t_begin + 0.1);
                let samples = Aabb { min: lo.inf(&hi), max: lo.sup(&hi) };
                term.begin_trajectory_impl(t_begin, t_end, &samples);
                let brute: Vec<usize> = (0..forecasts.len())
                    .filter(|&o| swept_box(&forecasts[o], t_begin, t_end, 0.3).intersects(&samples))
                    .collect();
                prop_assert_eq!(&term.near_trajectory, &brute);
            }
            prop_assert!(term.superset_rebuilds() <= steps.len());
        }

        #[test]
        fn swept_box_contains_the_obstacle(t_a in 0.0..3.0f64, dt in 0.0..2.0f64, u in 0.0..1.0f64, cylinder in any::<bool>()) {
            let f = forecast(cylinder);
            let t = t_a + u * dt;
            let b = swept_box(&f, t_a, t_a + dt, 0.1);
            let c = f.center(t);
            let r = f.radius(t) + 0.1;
            for corner in [Vec3::new(r, r, f.vertical_half_extent(t) + 0.1), Vec3::new(-r, -r, -f.vertical_half_extent(t) - 0.1)] {
                prop_assert!(b.inflated(1e-9).contains(&(c + corner)));
            }
        }
    }
}
