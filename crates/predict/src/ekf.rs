//! Constant-velocity tracker for one moving obstacle (the "dynamic obstacle estimator" of paper
//! Sec. III-D and IV: the planner sees only estimated position and velocity).
//!
//! State `x = [p; v] ∈ R⁶`, motion model `ṗ = v`, `v̇ = w` with `w` continuous white acceleration
//! of spectral density `q` per axis ("continuous white noise acceleration" model, Bar-Shalom, Li &
//! Kirubarajan, *Estimation with Applications to Tracking and Navigation*, 2001, Sec. 6.2.2):
//!
//! ```text
//! F(dt) = [I  dt·I]      Q(dt) = q·[dt³/3·I  dt²/2·I]
//!         [0     I]               [dt²/2·I     dt·I]
//! ```
//!
//! Measurements are positions `z = p + n`, `n ~ N(0, σ²I)`. Model and measurement are linear, so
//! the extended Kalman filter the paper cites reduces to the linear Kalman filter; the update uses
//! the Joseph form and re-symmetrizes, which keeps the covariance symmetric positive definite.
//!
//! [`CvEkf::forecast`] turns the estimate into a [`Forecast`] whose growth rate is
//! `mu = sigma_scale·√(tr P_vv) + mu_min`: `√(tr P_vv)` is the RMS norm of the velocity error, so
//! with the default `sigma_scale = 2` the extrapolation error `e_v·(t − t0)` stays below
//! `mu·(t − t0)` with about 99 % probability (see [`EkfParams::sigma_scale`]),
//! and `mu_min` covers manoeuvres the constant-velocity model does not describe (see
//! [`EkfParams::mu_for_manoeuvre`]). Optionally the current position uncertainty
//! `sigma_scale·√(tr P_pp)` is added to `r_safe`.

use nalgebra::{Matrix3, Matrix6, Matrix6x3, Vector6};
use serde::{Deserialize, Serialize};
use trust_geometry::Vec3;

use crate::error::{check_finite, check_non_negative, check_positive, check_vec};
use crate::walls::half_extents;
use crate::{Aabb, Forecast, MAX_REFLECTIONS_PER_AXIS, ObstacleShape, PredictError};
use trust_geometry::scale::{self, Quantity};

/// Largest accepted [`EkfParams::accel_psd`] (m²/s³).
pub const MAX_ACCEL_PSD: f64 = 1.0e6;
/// Largest accepted [`EkfParams::manoeuvre_gate`] (dimensionless).
pub const MAX_MANOEUVRE_GATE: f64 = 1.0e6;
/// The 95 % quantile of χ²(3), the suggested [`EkfParams::manoeuvre_gate`].
pub const CHI2_3_95: f64 = 7.815;
/// Largest covariance scaling of one manoeuvre update ([`EkfParams::manoeuvre_gate`]).
const MAX_FADING_FACTOR: f64 = 1.0e3;
/// Age of a track (s, from its first measurement) before its velocity changes feed the
/// acceleration estimate of the lag compensation ([`EkfParams::accel_smoothing_s`]): the
/// velocity estimate first converges from its initial guess (at rest), which looks like an
/// acceleration of the obstacle but is none; it settles within a few of the filter's lag times
/// (`τ_v` = 0.54 s with the defaults). Tracking a steady walker from rest, the forecast made
/// 2 s in erred by up to 0.46 m (position plus velocity, 40 seeds) when the estimate was fed
/// after 0.5 s, 0.50 m after 1 s, 0.31 m — as without the compensation — after 2 s.
pub const LAG_WARMUP_S: f64 = 2.0;
/// The lag compensation ([`EkfParams::accel_smoothing_s`]) uses the acceleration estimate less
/// this many times its noise (the RMS of its scatter, from the variance of the per-update
/// velocity changes; a soft threshold). Measured with this module's forecast tests (mean error
/// of the forecast centre 0.5 s and 1 s ahead, 0.1 m noise at 20 Hz, 100 seeds;
/// uncompensated: 0.453 m on a person setting off at 0.65 m/s², 0.115 m on a steady walker,
/// 0.749 m after a reversal):
///
/// | threshold | setting off | steady | reversal |
/// |---|---|---|---|
/// | 0 | 0.312 | 0.177 | 0.681 |
/// | 0.5 | 0.331 | 0.136 | 0.670 |
/// | 1 | 0.358 | 0.118 | 0.659 |
/// | 2 | 0.419 | 0.115 | 0.644 |
///
/// Flown with the manager's fallback that steps out of a person's likely path, in the holdout
/// room with a person pacing across it (`scenarios/variants/room_penetration_pacing_person.toml`,
/// seeds 25–84): 16 collisions in 60 without the compensation, 11 with the fallback alone; with
/// both, 2 at 0.5 and 3 at 1 (the velocity shift capped at `mu` then; capped at the estimate's
/// stated uncertainty, as now, 3 at 1). The six room files with people (seeds 100–119) took
/// more than 1.3 × `d/v_max` in 26 of 120 flights without the compensation (mean ratio 1.227),
/// 34 at 0.5 and 32 at 1 with the `mu` cap, 31 (1.246) as now: a noisier forecast drops more
/// plans. 1 keeps the steady walker's forecasts as they were.
pub const LAG_NOISE_THRESHOLD: f64 = 1.0;
/// Largest accepted [`EkfParams::sigma_scale`] (dimensionless).
pub const MAX_SIGMA_SCALE: f64 = 100.0;

/// Parameters of [`CvEkf`] and of the growth rate it reports.
///
/// The paper gives no values; the defaults describe the simulator's obstacle sensing (a position
/// sensor with 0.1 m noise at 20 Hz) and obstacles that manoeuvre gently, and each field says how to
/// derive it for other settings.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct EkfParams {
    /// Measurement noise standard deviation `σ` per axis (m), accepted in `[1e-9, 1e6]` m
    /// (`scale::MIN_POSITIVE`..`scale::MAX_LENGTH_M`). Default 0.1 m: the position
    /// noise of the simulator's obstacle sensor (`trust-sim`) and of the acceptance test in this
    /// crate.
    pub meas_std: f64,
    /// Spectral density `q` of the white acceleration (m²/s³), accepted in `[0, 1e6]` m²/s³
    /// ([`MAX_ACCEL_PSD`]: a velocity standard deviation of 1000 m/s after one second, far above
    /// any obstacle the scale policy's `1e4` m/s admits). Default 0.02: Bar-Shalom et
    /// al. (2001, Sec. 6.2.2) choose `q` so that `√(q·T)` matches the velocity change over a time
    /// `T`; 0.02 m²/s³ is a nearly-constant-velocity target (~0.14 m/s change per second), and
    /// stronger manoeuvres are left to `mu_min`. Larger `q` tracks manoeuvres faster but gives
    /// noisier velocities (and so a larger `mu`): with σ = 0.1 m at 20 Hz the RMS velocity error
    /// after 2 s on a constant-velocity target is 0.089 m/s at `q = 0.02`, 0.125 at 0.05, 0.33 at 0.5
    /// (measured over 200 seeds).
    pub accel_psd: f64,
    /// Initial velocity standard deviation per axis (m/s), accepted in `[1e-9, 1e4]` m/s
    /// (`scale::MIN_POSITIVE`..`scale::MAX_SPEED_M_S`; the filter starts at rest).
    /// Default 3 m/s: above the obstacle speeds of the paper's scenarios (Sec. IV).
    pub init_vel_std: f64,
    /// Multiplier `k` on the RMS error norms `√tr P` in `mu` and the position margin
    /// (dimensionless), accepted in `[0, 100]` ([`MAX_SIGMA_SCALE`]: 100 standard deviations is far
    /// beyond any confidence level).
    /// Default 2: for an isotropic covariance `√tr P = √3·σ`, so `2·√tr P ≈ 3.46σ`, the 99 %
    /// quantile of the norm of a 3-D Gaussian error (chi distribution with 3 degrees of freedom).
    pub sigma_scale: f64,
    /// Floor added to `mu` for unmodelled manoeuvres (m/s), accepted in `[0, 1e4]` m/s
    /// (`scale::MAX_SPEED_M_S`). Default 0.2 m/s =
    /// [`EkfParams::mu_for_manoeuvre`]`(0.2 m/s², 2 s)`: an acceleration of 0.2 m/s² sustained over
    /// a 2 s horizon.
    pub mu_min: f64,
    /// Whether [`CvEkf::forecast`] adds `sigma_scale·√(tr P_pp)` to `r_safe`. Default `true`
    /// (the estimated centre itself is uncertain at `t0`).
    pub inflate_by_position_std: bool,
    /// Manoeuvre gate on the normalized innovation squared `NIS = νᵀS⁻¹ν` (dimensionless, 3
    /// degrees of freedom), accepted in `[0, 1e6]`; 0 turns the detection off. When two updates
    /// in a row exceed it, the obstacle is taken to manoeuvre and the predicted covariance is
    /// scaled by the NIS before the update (a fading factor, as in the "strong tracking" filters
    /// of Zhou & Frank, 1996; Bar-Shalom et al. 2001, Sec. 11.2 for manoeuvre detection): the
    /// filter follows the new velocity within a few updates, and `mu` (from `P_vv`) widens the
    /// forecast meanwhile instead of forecasting the old velocity with full confidence.
    /// Default 0 (off). [`CHI2_3_95`] (7.815) is the gate to use: two consecutive false alarms
    /// on a constant-velocity target come once in 400 updates (the mean `mu` on a straight walk
    /// grows by about 1 %), and of the forecasts issued in the second after a person turns at a
    /// wall at 1.2 m/s, 31 % miss the person within 1 s instead of 92 % (this module's turn
    /// test, 100 seeds). It is off by default because the flights did not gain from it: E4
    /// (50 trials, seed 7300) 28.8 ± 0.4 s and 0.5 fallbacks per flight against 28.6 ± 0.5 s and
    /// 0.1, and the room with people faster than the vehicle 7 collisions in 60 flights either
    /// way (the vehicle is caught in a faster person's lane with either forecast).
    pub manoeuvre_gate: f64,
    /// Smoothing time (s) of the acceleration estimate that compensates the constant-velocity
    /// model's lag behind an accelerating obstacle (beyond the paper), accepted in `[0, 1e7]` s;
    /// 0 turns the compensation off (the forecast is the filter's estimate, as in the paper).
    ///
    /// On a target with constant acceleration `a` a constant-velocity Kalman filter settles
    /// behind it by `a·τ_v` in velocity and `a·τ_p` in position, where `τ_v = α/K_v − Δt/2` and
    /// `τ_p = Δt(1 − α)/K_v` follow from its position gain `α`, velocity gain `K_v` and update
    /// interval `Δt` (the steady-state α-β filter's bias; Kalata 1984, Bar-Shalom et al. 2001,
    /// Sec. 6.5): 0.54 s and 0.145 s with the defaults at 20 Hz. The filter estimates `a` from the
    /// change of its velocity estimate per update, smoothed over this time, and
    /// [`CvEkf::forecast`] starts from `p + a·τ_p` with velocity `v + a·τ_v` (the velocity shift
    /// at most `sigma_scale·√(tr P_vv)`, the estimate's own stated uncertainty) once the track is older than
    /// [`LAG_WARMUP_S`] plus this time. Default 0.5 s. Why: a person setting off from a pause
    /// (0 → 1.3 m/s in 2 s) was forecast 0.35–0.45 m/s too slow for the whole second the vehicle
    /// decided to cross in front of them; with the forecasts' growth stopped after `T_h/16` the
    /// error was not covered, and 16 of 60 flights through a room with such a pacing person
    /// collided (6 with the compensation alone, 3 with the manager's fallback to the likely
    /// path too; [`LAG_NOISE_THRESHOLD`] has the figures). The smoothing trades noise for
    /// delay (measured as in [`LAG_NOISE_THRESHOLD`], with its default: smoothed over 0.25 /
    /// 0.5 / 1 s the forecasts of a person setting off err by 0.364 / 0.358 / 0.373 m, of a
    /// steady walker by 0.126 / 0.118 / 0.116 m, after a reversal by 0.570 / 0.659 / 0.734 m),
    /// and only the part of the estimate that stands out of its noise is used.
    pub accel_smoothing_s: f64,
}

impl Default for EkfParams {
    fn default() -> Self {
        EkfParams {
            meas_std: 0.1,
            accel_psd: 0.02,
            init_vel_std: 3.0,
            sigma_scale: 2.0,
            mu_min: Self::mu_for_manoeuvre(0.2, 2.0),
            inflate_by_position_std: true,
            manoeuvre_gate: 0.0,
            accel_smoothing_s: 0.5,
        }
    }
}

impl EkfParams {
    /// Growth rate covering an unmodelled acceleration of magnitude `accel` over a horizon:
    /// the extra displacement `accel·τ²/2` stays below `(accel·horizon/2)·τ` for `τ ≤ horizon`.
    pub fn mu_for_manoeuvre(accel: f64, horizon: f64) -> f64 {
        0.5 * accel * horizon
    }

    /// Checks every field's range.
    ///
    /// # Errors
    /// The first invalid field, with its value.
    pub fn validate(&self) -> Result<(), PredictError> {
        check_positive("ekf.meas_std", self.meas_std, Quantity::PositiveLength)?;
        scale::check_range("ekf.accel_psd", self.accel_psd, 0.0, MAX_ACCEL_PSD, "m²/s³")?;
        check_positive(
            "ekf.init_vel_std",
            self.init_vel_std,
            Quantity::PositiveSpeed,
        )?;
        scale::check_range(
            "ekf.sigma_scale",
            self.sigma_scale,
            0.0,
            MAX_SIGMA_SCALE,
            "(dimensionless)",
        )?;
        check_non_negative("ekf.mu_min", self.mu_min, Quantity::Rate)?;
        scale::check_range(
            "ekf.manoeuvre_gate",
            self.manoeuvre_gate,
            0.0,
            MAX_MANOEUVRE_GATE,
            "(dimensionless; 0 turns the detection off)",
        )?;
        scale::check_range(
            "ekf.accel_smoothing_s",
            self.accel_smoothing_s,
            0.0,
            scale::MAX_TIME_S,
            "s (0 turns the lag compensation off)",
        )?;
        Ok(())
    }
}

/// Constant-velocity Kalman tracker of one obstacle; see the module documentation for the model.
///
/// ```
/// use trust_predict::{CvEkf, EkfParams, ObstacleShape, Vec3};
/// let mut ekf = CvEkf::new(0.0, Vec3::new(0.0, 0.0, 1.0), EkfParams::default())?;
/// ekf.step(0.05, Some(Vec3::new(0.05, 0.0, 1.0)))?;
/// ekf.step(0.10, None)?; // dropout: predict only
/// let forecast = ekf.forecast(ObstacleShape::Sphere, 0.3, 0.1)?;
/// assert!(forecast.mu >= EkfParams::default().mu_min);
/// # Ok::<(), trust_predict::PredictError>(())
/// ```
#[derive(Debug, Clone, PartialEq)]
pub struct CvEkf {
    params: EkfParams,
    t: f64,
    x: Vector6<f64>,
    cov: Matrix6<f64>,
    /// Consecutive updates whose NIS exceeded the manoeuvre gate.
    over_gate: u32,
    /// Lag compensation ([`EkfParams::accel_smoothing_s`]).
    lag: LagCompensation,
    /// The box the estimated centre is folded into, `(lo, hi)` ([`CvEkf::with_walls`]).
    walls: Option<(Vec3, Vec3)>,
}

/// The state of the lag compensation ([`EkfParams::accel_smoothing_s`]).
#[derive(Debug, Clone, Copy, PartialEq)]
struct LagCompensation {
    /// Time of the first measurement.
    first_t: f64,
    /// Time of the last update.
    last_update_t: f64,
    /// Smoothed acceleration estimate (m/s²).
    accel: Vec3,
    /// Smoothed mean square of the per-update accelerations `|Δv/Δt|²` (m²/s⁴).
    accel_ms: f64,
    /// The estimate's noise: RMS norm of `accel`'s scatter (m/s²).
    noise: f64,
    /// Time over which the estimate has been fed (s).
    fed_s: f64,
    /// Position and velocity lag times `(τ_p, τ_v)` of the last update's gains (s).
    lag_s: (f64, f64),
}

impl LagCompensation {
    fn new(t: f64) -> Self {
        Self {
            first_t: t,
            last_update_t: t,
            accel: Vec3::zeros(),
            accel_ms: 0.0,
            noise: 0.0,
            fed_s: 0.0,
            lag_s: (0.0, 0.0),
        }
    }

    /// Feeds the velocity change `dv` of an update at `t` with position gain `alpha` and
    /// velocity gain `k_v` (1/s), smoothing over `smoothing_s`.
    fn feed(&mut self, t: f64, dv: &Vec3, alpha: f64, k_v: f64, smoothing_s: f64) {
        let dt = t - self.last_update_t;
        self.last_update_t = t;
        if !(dt > 0.0 && smoothing_s > 0.0) || t - self.first_t < LAG_WARMUP_S {
            return;
        }
        let w = (dt / smoothing_s).min(1.0);
        let raw = dv / dt;
        self.accel += (raw - self.accel) * w;
        self.accel_ms += (raw.norm_squared() - self.accel_ms) * w;
        // The per-update velocity changes of a Kalman filter are white on a target its model
        // describes (they are gains times innovations), so their smoothed mean scatters by this
        // RMS around the target's acceleration (the variance of the changes, smoothed).
        let variance = (self.accel_ms - self.accel.norm_squared()).max(0.0);
        self.noise = (variance * w / (2.0 - w)).sqrt();
        self.fed_s += dt;
        self.lag_s = if k_v.is_finite() && k_v > 0.0 && alpha.is_finite() {
            (
                (dt * (1.0 - alpha) / k_v).max(0.0),
                (alpha / k_v - 0.5 * dt).max(0.0),
            )
        } else {
            (0.0, 0.0)
        };
    }

    /// The shifts `(Δp, Δv)` of the forecast's start; none until the estimate has been fed for
    /// the smoothing time; the acceleration used is scaled down so that `Δv` is at most
    /// `max_dv` long (`Δp` with it).
    fn shifts(&self, smoothing_s: f64, max_dv: f64) -> (Vec3, Vec3) {
        if !(smoothing_s > 0.0 && self.fed_s >= smoothing_s) {
            return (Vec3::zeros(), Vec3::zeros());
        }
        // Only what stands out of the estimate's noise (a soft threshold).
        let threshold = LAG_NOISE_THRESHOLD * self.noise;
        let n = self.accel.norm();
        let mut accel = if n > threshold {
            self.accel * (1.0 - threshold / n)
        } else {
            Vec3::zeros()
        };
        let dv = accel.norm() * self.lag_s.1;
        if dv > max_dv {
            accel *= max_dv / dv;
        }
        (accel * self.lag_s.0, accel * self.lag_s.1)
    }
}

impl CvEkf {
    /// Starts a track at time `t` from a first position measurement `z0` (velocity 0 with
    /// standard deviation `params.init_vel_std`, position standard deviation `params.meas_std`).
    ///
    /// # Errors
    /// [`PredictError`] for invalid parameters or non-finite `t` / `z0`.
    pub fn new(t: f64, z0: Vec3, params: EkfParams) -> Result<Self, PredictError> {
        params.validate()?;
        check_finite("t", t, Quantity::Time)?;
        check_vec("measurement", &z0, Quantity::Position)?;
        let mut x = Vector6::zeros();
        x.fixed_rows_mut::<3>(0).copy_from(&z0);
        let sp = params.meas_std * params.meas_std;
        let sv = params.init_vel_std * params.init_vel_std;
        let cov = Matrix6::from_diagonal(&Vector6::new(sp, sp, sp, sv, sv, sv));
        Ok(CvEkf {
            params,
            t,
            x,
            cov,
            over_gate: 0,
            lag: LagCompensation::new(t),
            walls: None,
        })
    }

    /// This filter with the box its obstacle stays inside, turning at the walls (beyond the
    /// paper; the prior the forecasts' [`crate::wall_images`] take, used here by the tracker too).
    /// When a prediction carries the estimated centre past a wall's plane while it moves outward
    /// (the planes of [`crate::wall_images`]: `walls` shrunk by the shape's half extents), the
    /// estimate is mirrored back: the position reflected at the plane, that axis's velocity and
    /// acceleration estimate negated, the covariance transformed alike (the fold is a linear map
    /// per axis, `(p, v) → (2·plane − p, −v)`). Without it a constant-velocity filter keeps
    /// walking an obstacle that bounced off a wall into the wall while its velocity turns (about
    /// 0.5 s with the defaults at 20 Hz, and 1 s to settle), and the forecast puts the obstacle
    /// on the far side of the gap it is coming back into. An obstacle that stops at a wall
    /// instead is forecast coming back until the measurements say otherwise, as its wall images
    /// are. An axis on which the shape does not fit inside the box is not folded.
    ///
    /// # Errors
    /// [`PredictError`] naming the field for a non-finite wall, `r_o ≤ 0` or a cylinder's
    /// `half_height ≤ 0`.
    pub fn with_walls(
        mut self,
        walls: &Aabb,
        shape: ObstacleShape,
        r_o: f64,
    ) -> Result<Self, PredictError> {
        check_vec("walls.min", &walls.min, Quantity::Position)?;
        check_vec("walls.max", &walls.max, Quantity::Position)?;
        check_positive("r_o", r_o, Quantity::Length)?;
        if let ObstacleShape::Cylinder { half_height } = shape {
            check_positive("shape.half_height", half_height, Quantity::Length)?;
        }
        let e = Vec3::from(half_extents(shape, r_o));
        self.walls = Some((walls.min + e, walls.max - e));
        self.fold_at_walls();
        Ok(self)
    }

    /// Mirrors the estimate back inside the box of [`CvEkf::with_walls`] (at most
    /// [`MAX_REFLECTIONS_PER_AXIS`] reflections per axis and call).
    fn fold_at_walls(&mut self) {
        let Some((lo, hi)) = self.walls else { return };
        for a in 0..3 {
            if lo[a] >= hi[a] {
                continue;
            }
            for _ in 0..MAX_REFLECTIONS_PER_AXIS {
                let (p, v) = (self.x[a], self.x[3 + a]);
                let plane = if p < lo[a] && v < 0.0 {
                    lo[a]
                } else if p > hi[a] && v > 0.0 {
                    hi[a]
                } else {
                    break;
                };
                self.x[a] = 2.0 * plane - p;
                self.x[3 + a] = -v;
                // P ← J P J with J = diag(±1), −1 on this axis's position and velocity: the
                // entries coupling them to the other axes change sign.
                for i in [a, 3 + a] {
                    for j in (0..6).filter(|&j| j != a && j != 3 + a) {
                        self.cov[(i, j)] = -self.cov[(i, j)];
                        self.cov[(j, i)] = -self.cov[(j, i)];
                    }
                }
                self.lag.accel[a] = -self.lag.accel[a];
            }
        }
    }

    /// The filter's parameters.
    pub fn params(&self) -> &EkfParams {
        &self.params
    }

    /// Time of the current estimate (s).
    pub fn time(&self) -> f64 {
        self.t
    }

    /// State `[p; v]`.
    pub fn state(&self) -> &Vector6<f64> {
        &self.x
    }

    /// Estimated position (m).
    pub fn position(&self) -> Vec3 {
        self.x.fixed_rows::<3>(0).into_owned()
    }

    /// Estimated velocity (m/s).
    pub fn velocity(&self) -> Vec3 {
        self.x.fixed_rows::<3>(3).into_owned()
    }

    /// State covariance (symmetric positive definite), ordered like [`CvEkf::state`].
    pub fn covariance(&self) -> &Matrix6<f64> {
        &self.cov
    }

    /// RMS norm of the position error, `√(tr P_pp)` (m).
    pub fn position_std(&self) -> f64 {
        self.cov.fixed_view::<3, 3>(0, 0).trace().max(0.0).sqrt()
    }

    /// RMS norm of the velocity error, `√(tr P_vv)` (m/s).
    pub fn velocity_std(&self) -> f64 {
        self.cov.fixed_view::<3, 3>(3, 3).trace().max(0.0).sqrt()
    }

    /// The smoothed acceleration estimate of the lag compensation (m/s²;
    /// [`EkfParams::accel_smoothing_s`]): zero until the track is [`LAG_WARMUP_S`] old, and
    /// always zero with the compensation off.
    pub fn acceleration(&self) -> Vec3 {
        self.lag.accel
    }

    /// Uncertainty growth rate `mu = sigma_scale·√(tr P_vv) + mu_min` (m/s).
    pub fn uncertainty_rate(&self) -> f64 {
        self.params.sigma_scale * self.velocity_std() + self.params.mu_min
    }

    /// Propagates the estimate `dt` seconds ahead (no measurement).
    ///
    /// # Errors
    /// [`PredictError`] if `dt` is non-finite, negative, or so large that the covariance
    /// overflows; the filter is unchanged on error.
    pub fn predict(&mut self, dt: f64) -> Result<(), PredictError> {
        check_non_negative("dt", dt, Quantity::Duration)?;
        // The filter time stays inside the scale policy, which bounds the covariance's growth.
        if !Quantity::Time.accepts(self.t + dt) {
            return Err(PredictError::Derived {
                what: "filter time + dt".into(),
                value: self.t + dt,
                limit: scale::MAX_TIME_S,
                cause: format!(
                    "dt = {} s from the filter time {} s leaves the scale policy's times; \
                     lower dt",
                    scale::Sci(dt),
                    scale::Sci(self.t)
                ),
            });
        }
        self.propagate(dt, "dt")
    }

    /// The prediction step over `dt ≥ 0` (the filter time and `self.t + dt` inside the scale
    /// policy); `culprit` names the caller's input that set `dt`, for the error.
    fn propagate(&mut self, dt: f64, culprit: &str) -> Result<(), PredictError> {
        let mut f = Matrix6::identity();
        f.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(Matrix3::identity() * dt));
        let q = self.params.accel_psd;
        let i3 = Matrix3::<f64>::identity();
        let mut qm = Matrix6::zeros();
        qm.fixed_view_mut::<3, 3>(0, 0)
            .copy_from(&(i3 * (q * dt * dt * dt / 3.0)));
        qm.fixed_view_mut::<3, 3>(0, 3)
            .copy_from(&(i3 * (q * dt * dt / 2.0)));
        qm.fixed_view_mut::<3, 3>(3, 0)
            .copy_from(&(i3 * (q * dt * dt / 2.0)));
        qm.fixed_view_mut::<3, 3>(3, 3).copy_from(&(i3 * (q * dt)));
        let x = f * self.x;
        let cov = symmetrized(&(f * self.cov * f.transpose() + qm));
        if !(x.iter().all(|e| e.is_finite()) && cov.iter().all(|e| e.is_finite())) {
            return Err(PredictError::Derived {
                what: "predicted state or covariance".into(),
                value: f64::INFINITY,
                limit: f64::MAX,
                cause: format!(
                    "the estimate (velocity std {} m/s from ekf.init_vel_std, ekf.accel_psd = {} \
                     m²/s³) cannot be propagated over {} s ({culprit})",
                    scale::Sci(self.velocity_std()),
                    scale::Sci(self.params.accel_psd),
                    scale::Sci(dt)
                ),
            });
        }
        self.x = x;
        self.cov = cov;
        self.t += dt;
        self.fold_at_walls();
        Ok(())
    }

    /// Corrects the estimate with a position measurement `z` taken at the current filter time.
    ///
    /// # Errors
    /// [`PredictError`] naming the component if `z` is non-finite; the filter is unchanged on
    /// error.
    pub fn update(&mut self, z: &Vec3) -> Result<(), PredictError> {
        check_vec("measurement", z, Quantity::Position)?;
        let r = Matrix3::identity() * (self.params.meas_std * self.params.meas_std);
        let innovation = z - self.position();
        let s_inv = self.innovation_precision(&self.cov, &r)?;
        let nis = innovation.dot(&(s_inv * innovation));
        let gate = self.params.manoeuvre_gate;
        let over_gate = if gate > 0.0 && nis > gate {
            self.over_gate + 1
        } else {
            0
        };
        // A manoeuvre (two updates in a row beyond the gate): the prediction was too confident;
        // scale it by the NIS (a fading factor; NIS/3 would make the innovation about as large as
        // expected, NIS follows the new velocity sooner: in the turn test 31 % of the forecasts
        // after the turn miss the obstacle instead of 40 %, at the same false-alarm cost).
        let (cov, s_inv) = if over_gate >= 2 {
            let inflated = self.cov * nis.clamp(1.0, MAX_FADING_FACTOR);
            let s_inv = self.innovation_precision(&inflated, &r)?;
            (inflated, s_inv)
        } else {
            (self.cov, s_inv)
        };
        let pht: Matrix6x3<f64> = cov.fixed_view::<6, 3>(0, 0).into_owned();
        let k = pht * s_inv;
        let x = self.x + k * innovation;
        // Joseph form: (I − KH) P (I − KH)ᵀ + K R Kᵀ.
        let mut i_kh = Matrix6::identity();
        {
            let mut block = i_kh.fixed_view_mut::<6, 3>(0, 0);
            block -= &k;
        }
        let cov = symmetrized(&(i_kh * cov * i_kh.transpose() + k * r * k.transpose()));
        if !(x.iter().all(|e| e.is_finite()) && cov.iter().all(|e| e.is_finite())) {
            return Err(PredictError::Numerical {
                what: "measurement update produced a non-finite estimate".into(),
            });
        }
        let dv: Vec3 = (x - self.x).fixed_rows::<3>(3).into_owned();
        let alpha = (k[(0, 0)] + k[(1, 1)] + k[(2, 2)]) / 3.0;
        let k_v = (k[(3, 0)] + k[(4, 1)] + k[(5, 2)]) / 3.0;
        self.lag
            .feed(self.t, &dv, alpha, k_v, self.params.accel_smoothing_s);
        self.x = x;
        self.cov = cov;
        self.over_gate = over_gate;
        Ok(())
    }

    /// `S⁻¹ = (P_pp + r)⁻¹` for the state covariance `cov` and measurement noise covariance `r`.
    fn innovation_precision(
        &self,
        cov: &Matrix6<f64>,
        r: &Matrix3<f64>,
    ) -> Result<Matrix3<f64>, PredictError> {
        let s = cov.fixed_view::<3, 3>(0, 0) + r;
        s.cholesky()
            .map(|c| c.inverse())
            .ok_or_else(|| PredictError::Numerical {
                what: format!(
                    "innovation covariance is not positive definite (position std {} m against \
                     ekf.meas_std = {} m; ekf.init_vel_std, ekf.accel_psd and the time since the \
                     last measurement drive the former)",
                    scale::Sci(self.position_std()),
                    scale::Sci(self.params.meas_std)
                ),
            })
    }

    /// Advances to time `t` and, if `z` is `Some`, applies the measurement taken at `t`; `None` is a
    /// dropout (predict only).
    ///
    /// # Errors
    /// [`PredictError::TimeWentBackwards`] if `t` is before the filter time, or the errors of
    /// [`CvEkf::predict`] / [`CvEkf::update`]. A non-finite measurement is rejected before the
    /// filter changes.
    pub fn step(&mut self, t: f64, z: Option<Vec3>) -> Result<(), PredictError> {
        check_finite("t", t, Quantity::Time)?;
        if t < self.t {
            return Err(PredictError::TimeWentBackwards {
                t,
                filter_t: self.t,
            });
        }
        if let Some(z) = &z {
            check_vec("measurement", z, Quantity::Position)?;
        }
        let saved = self.clone();
        // `t` and the filter time are both inside the scale policy, so `t − filter time ≤ 2e7` s
        // keeps the covariance finite; errors name `t`, the input (step takes no `dt`).
        self.propagate(t - self.t, "t − filter time")?;
        if let Some(z) = &z
            && let Err(e) = self.update(z)
        {
            *self = saved;
            return Err(e);
        }
        Ok(())
    }

    /// The forecast at time `t`: the filter predicted to `t` on a copy, then [`CvEkf::forecast`];
    /// at or before the filter time, the forecast made at the filter time. This is what a
    /// tracker hands the planner each cycle (the simulator's `trust_world::Sensing::forecasts`,
    /// the ROS 2 node's obstacle tracks).
    ///
    /// # Errors
    /// As [`CvEkf::predict`] (a non-finite or absurd `t`) and [`CvEkf::forecast`].
    pub fn forecast_at(
        &self,
        t: f64,
        shape: ObstacleShape,
        r_o: f64,
        r_safe: f64,
    ) -> Result<Forecast, PredictError> {
        // A NaN `t` goes to `predict`, which names it.
        if t.is_nan() || t > self.time() {
            let mut g = self.clone();
            g.predict(t - self.time())?;
            g.forecast(shape, r_o, r_safe)
        } else {
            self.forecast(shape, r_o, r_safe)
        }
    }

    /// A forecast made at the filter time from the current estimate: `p0`, `v0` are the estimate
    /// shifted by the lag compensation ([`EkfParams::accel_smoothing_s`],
    /// [`CvEkf::acceleration`]), `mu` is [`CvEkf::uncertainty_rate`], and `r_safe` is increased
    /// by `sigma_scale·√(tr P_pp)` when `params.inflate_by_position_std` is set.
    ///
    /// # Errors
    /// As [`Forecast::new`] (invalid `shape`, `r_o` or `r_safe`).
    pub fn forecast(
        &self,
        shape: ObstacleShape,
        r_o: f64,
        r_safe: f64,
    ) -> Result<Forecast, PredictError> {
        check_non_negative("forecast.r_safe", r_safe, Quantity::Length)?;
        let extra = if self.params.inflate_by_position_std {
            self.params.sigma_scale * self.position_std()
        } else {
            0.0
        };
        // Name the filter's estimate, not the forecast's fields, when the estimate is what left
        // the scale policy.
        let (dp, dv) = self.lag.shifts(
            self.params.accel_smoothing_s,
            self.params.sigma_scale * self.velocity_std(),
        );
        let p = self.position() + dp;
        let v = self.velocity() + dv;
        let derived = |what: &str, value: f64, limit: f64, cause: String| {
            Err(PredictError::Derived {
                what: what.into(),
                value,
                limit,
                cause,
            })
        };
        if !scale::position_in_scale(&p) {
            return derived(
                "estimated position (max |component|)",
                p.amax(),
                scale::MAX_COORD_M,
                "the measurements fed to the filter (and its velocity times the elapsed time) \
                 left the map scale"
                    .into(),
            );
        }
        if !v.iter().all(|c| Quantity::Velocity.accepts(*c)) {
            return derived(
                "estimated velocity (max |component|)",
                v.amax(),
                scale::MAX_SPEED_M_S,
                "consecutive measurements imply an obstacle speed beyond the scale policy; \
                 check the measurements and their times"
                    .into(),
            );
        }
        let mu = self.uncertainty_rate();
        if !Quantity::Rate.accepts(mu) {
            return derived(
                "uncertainty rate mu = sigma_scale·velocity_std + mu_min",
                mu,
                scale::MAX_SPEED_M_S,
                format!(
                    "ekf.sigma_scale = {}, velocity std = {} m/s (it grows from \
                     ekf.init_vel_std = {} m/s with ekf.accel_psd = {} m²/s³ over the time \
                     since the last measurement), ekf.mu_min = {} m/s",
                    scale::Sci(self.params.sigma_scale),
                    scale::Sci(self.velocity_std()),
                    scale::Sci(self.params.init_vel_std),
                    scale::Sci(self.params.accel_psd),
                    scale::Sci(self.params.mu_min)
                ),
            );
        }
        if !Quantity::Length.accepts(r_safe + extra) {
            return derived(
                "r_safe + sigma_scale·position_std",
                r_safe + extra,
                scale::MAX_LENGTH_M,
                format!(
                    "r_safe = {}, ekf.sigma_scale = {}, position std = {} m (ekf.meas_std, \
                     ekf.init_vel_std, ekf.accel_psd and the time since the last measurement \
                     drive it)",
                    scale::Sci(r_safe),
                    scale::Sci(self.params.sigma_scale),
                    scale::Sci(self.position_std())
                ),
            );
        }
        Forecast::new(
            shape,
            p,
            v,
            self.t,
            r_o,
            r_safe + extra,
            self.uncertainty_rate(),
        )
    }
}

fn symmetrized(m: &Matrix6<f64>) -> Matrix6<f64> {
    (m + m.transpose()) * 0.5
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, Normal};

    fn assert_spd(p: &Matrix6<f64>) {
        assert!(
            (p - p.transpose()).abs().max() <= 1e-12 * p.abs().max(),
            "not symmetric: {p}"
        );
        assert!(p.cholesky().is_some(), "not positive definite: {p}");
    }

    /// Tracks a constant-velocity target (σ = 0.1 m noise) for `duration` s at `rate_hz`, dropping
    /// each measurement with probability `dropout`; returns the final position and velocity error
    /// norms and the filter.
    fn track(seed: u64, duration: f64, rate_hz: f64, dropout: f64) -> (f64, f64, CvEkf) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.1).unwrap();
        let (p0, v) = (Vec3::new(1.0, -2.0, 1.5), Vec3::new(1.2, 0.8, -0.3));
        let z = |t: f64, rng: &mut ChaCha8Rng| {
            p0 + v * t + Vec3::new(noise.sample(rng), noise.sample(rng), noise.sample(rng))
        };
        let mut ekf = CvEkf::new(0.0, z(0.0, &mut rng), EkfParams::default()).unwrap();
        let steps = (duration * rate_hz).round() as usize;
        for k in 1..=steps {
            let t = k as f64 / rate_hz;
            let meas = z(t, &mut rng);
            let keep = rand::Rng::random_range(&mut rng, 0.0..1.0) >= dropout;
            ekf.step(t, keep.then_some(meas)).unwrap();
            assert_spd(ekf.covariance());
        }
        let t = ekf.time();
        (
            (ekf.position() - (p0 + v * t)).norm(),
            (ekf.velocity() - v).norm(),
            ekf,
        )
    }

    /// RMS and worst error norms over 100 seeds (2 s at 20 Hz).
    fn error_statistics(dropout: f64) -> (f64, f64, f64, f64) {
        let (mut sp, mut sv, mut wp, mut wv) = (0.0, 0.0, 0.0_f64, 0.0_f64);
        let n = 100;
        for seed in 0..n {
            let (ep, ev, _) = track(seed, 2.0, 20.0, dropout);
            sp += ep * ep;
            sv += ev * ev;
            wp = wp.max(ep);
            wv = wv.max(ev);
        }
        ((sp / n as f64).sqrt(), (sv / n as f64).sqrt(), wp, wv)
    }

    #[test]
    fn converges_on_constant_velocity_target() {
        // Measured (defaults, seeds 0..100): RMS 0.060 m / 0.087 m/s, worst 0.11 m / 0.16 m/s.
        let (rp, rv, wp, wv) = error_statistics(0.0);
        println!("no dropouts: RMS {rp:.3} m, {rv:.3} m/s; worst {wp:.3} m, {wv:.3} m/s");
        assert!(rp < 0.1 && rv < 0.15, "RMS errors {rp} m, {rv} m/s");
        assert!(wp < 0.2 && wv < 0.25, "worst errors {wp} m, {wv} m/s");
    }

    #[test]
    fn converges_with_thirty_percent_dropouts() {
        // Measured (defaults, seeds 0..100): RMS 0.070 m / 0.091 m/s, worst 0.15 m / 0.17 m/s.
        let (rp, rv, wp, wv) = error_statistics(0.3);
        println!("30 % dropouts: RMS {rp:.3} m, {rv:.3} m/s; worst {wp:.3} m, {wv:.3} m/s");
        assert!(rp < 0.1 && rv < 0.15, "RMS errors {rp} m, {rv} m/s");
        assert!(wp < 0.2 && wv < 0.25, "worst errors {wp} m, {wv} m/s");
    }

    #[test]
    fn mu_grows_when_measurements_stop() {
        let (_, _, mut ekf) = track(7, 2.0, 20.0, 0.0);
        let mut last = ekf.uncertainty_rate();
        let mut last_pos = ekf.position_std();
        for k in 1..=20 {
            ekf.step(2.0 + 0.05 * k as f64, None).unwrap();
            let mu = ekf.uncertainty_rate();
            assert!(mu > last, "mu did not grow: {mu} <= {last}");
            assert!(ekf.position_std() > last_pos);
            last = mu;
            last_pos = ekf.position_std();
            assert_spd(ekf.covariance());
        }
        let f = ekf.forecast(ObstacleShape::Sphere, 0.4, 0.1).unwrap();
        assert_relative_eq!(f.mu, ekf.uncertainty_rate());
        assert_relative_eq!(
            f.r_safe,
            0.1 + ekf.params().sigma_scale * ekf.position_std()
        );
        assert_relative_eq!(f.t0, ekf.time());
        // The estimate, up to the lag compensation's shift (what stands out of the noise of the
        // acceleration estimate: little on a constant-velocity target).
        assert!(
            (f.p0 - ekf.position()).norm() < 0.02,
            "{} vs {}",
            f.p0,
            ekf.position()
        );
    }

    #[test]
    fn forecast_without_position_inflation_and_floor() {
        let params = EkfParams {
            inflate_by_position_std: false,
            sigma_scale: 0.0,
            mu_min: 0.25,
            ..EkfParams::default()
        };
        let ekf = CvEkf::new(1.0, Vec3::zeros(), params).unwrap();
        let f = ekf
            .forecast(ObstacleShape::Cylinder { half_height: 1.0 }, 0.3, 0.2)
            .unwrap();
        assert_eq!(f.r_safe, 0.2);
        assert_eq!(f.mu, 0.25);
        assert!(ekf.forecast(ObstacleShape::Sphere, 0.0, 0.2).is_err());
        assert!(ekf.forecast(ObstacleShape::Sphere, 0.3, -0.2).is_err());
    }

    #[test]
    fn invalid_input_is_rejected_and_leaves_the_filter_unchanged() {
        let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
        ekf.step(0.1, Some(Vec3::new(0.1, 0.0, 0.0))).unwrap();
        let before = ekf.clone();
        let err = ekf
            .step(0.2, Some(Vec3::new(0.0, 0.0, f64::NAN)))
            .unwrap_err();
        assert!(
            matches!(err, PredictError::NonFinite { ref field, .. } if field == "measurement.z"),
            "{err}"
        );
        assert_eq!(ekf, before);
        assert!(matches!(
            ekf.step(0.05, None),
            Err(PredictError::TimeWentBackwards { .. })
        ));
        assert!(
            matches!(ekf.predict(-0.1), Err(PredictError::OutOfRange { ref field, .. }) if field == "dt")
        );
        assert!(ekf.predict(f64::INFINITY).is_err());
        assert!(ekf.predict(1e300).is_err());
        assert!(ekf.update(&Vec3::new(f64::INFINITY, 0.0, 0.0)).is_err());
        assert!(ekf.step(f64::NAN, None).is_err());
        assert_eq!(ekf, before);
        assert!(CvEkf::new(f64::NAN, Vec3::zeros(), EkfParams::default()).is_err());
        assert!(
            CvEkf::new(
                0.0,
                Vec3::zeros(),
                EkfParams {
                    meas_std: 0.0,
                    ..EkfParams::default()
                }
            )
            .is_err()
        );
        assert!(
            CvEkf::new(
                0.0,
                Vec3::zeros(),
                EkfParams {
                    accel_psd: -1.0,
                    ..EkfParams::default()
                }
            )
            .is_err()
        );
        // A zero step is a no-op prediction.
        ekf.predict(0.0).unwrap();
        assert_relative_eq!(ekf.state(), before.state());
    }

    /// A target walking at 1.2 m/s along y that turns round at `t_turn` (a person at a wall),
    /// tracked at 20 Hz with σ = 0.1 m. Returns the share of forecasts issued in the second
    /// after the turn whose cone (`2√tr P_pp + mu·τ` around `p̂ + v̂·τ`) misses the true
    /// position τ = 0.25, 0.5 or 1 s later, and the mean `mu` over the 3 s before the turn.
    fn turn_statistics(gate: f64) -> (f64, f64) {
        let params = EkfParams {
            manoeuvre_gate: gate,
            ..EkfParams::default()
        };
        let (speed, t_turn, rate) = (1.2, 3.0, 20.0);
        let truth = |t: f64| {
            let y = if t <= t_turn {
                speed * t
            } else {
                speed * (2.0 * t_turn - t)
            };
            Vec3::new(0.0, y, 1.0)
        };
        let (mut missed, mut issued, mut mu_sum, mut mu_count) = (0, 0, 0.0, 0);
        for seed in 0..100 {
            track_noisy(seed, &params, &truth, t_turn + 1.0, rate, |t, ekf| {
                if (0.0..t_turn).contains(&t) {
                    mu_sum += ekf.uncertainty_rate();
                    mu_count += 1;
                }
                if t > t_turn {
                    for tau in [0.25, 0.5, 1.0] {
                        let centre = ekf.position() + ekf.velocity() * tau;
                        let reach =
                            params.sigma_scale * ekf.position_std() + ekf.uncertainty_rate() * tau;
                        issued += 1;
                        if (truth(t + tau) - centre).norm() > reach {
                            missed += 1;
                        }
                    }
                }
            });
        }
        (missed as f64 / issued as f64, mu_sum / mu_count as f64)
    }

    /// The manoeuvre gate: after a turn the forecasts contain the obstacle far more often, and on
    /// a straight walk its false alarms cost little growth.
    #[test]
    fn a_turn_is_followed_quickly_and_widens_the_forecast_meanwhile() {
        let (missed_off, mu_off) = turn_statistics(0.0);
        let (missed_on, mu_on) = turn_statistics(CHI2_3_95);
        println!(
            "missed after the turn: {missed_off:.3} without the gate, {missed_on:.3} with it; \
             mean mu before it: {mu_off:.3} / {mu_on:.3} m/s"
        );
        assert!(missed_on < 0.5 * missed_off, "{missed_on} vs {missed_off}");
        assert!(mu_on < 1.1 * mu_off, "{mu_on} vs {mu_off}");
    }

    /// A 0.5 m cylinder crossing a corridor at 1.9 m/s toward the wall y = 0, bouncing off it
    /// (centre plane y = 0.5) at t = 0.5 s, tracked at 20 Hz with σ = 0.1 m, with the walls or
    /// without (100 seeds). Returns the mean velocity error over the second after the bounce and
    /// the share of forecasts issued then whose cone misses the true centre 0.25 / 0.5 s later.
    fn bounce_statistics(walls: bool) -> (f64, f64) {
        let corridor = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(100.0, 20.0, 8.0),
        };
        let shape = ObstacleShape::Cylinder { half_height: 4.0 };
        let (speed, t_bounce) = (1.9, 0.5);
        let y = |t: f64| 0.5 + speed * (t - t_bounce).abs();
        let truth = |t: f64| Vec3::new(50.0 - 0.6 * t, y(t), 4.0);
        let velocity = |t: f64| Vec3::new(-0.6, speed * (t - t_bounce).signum(), 0.0);
        let params = EkfParams::default();
        let (mut v_err, mut v_count, mut missed, mut issued) = (0.0, 0, 0, 0);
        for seed in 0..100 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let noise = Normal::new(0.0, 0.1).unwrap();
            let mut z = |t: f64| {
                let n = Vec3::from_fn(|_, _| noise.sample(&mut rng));
                truth(t) + n
            };
            let mut ekf = CvEkf::new(-2.0, z(-2.0), params.clone()).unwrap();
            if walls {
                ekf = ekf.with_walls(&corridor, shape, 0.5).unwrap();
            }
            for k in 1..=50 + (t_bounce + 1.0) as usize * 20 {
                let t = -2.0 + k as f64 / 20.0;
                ekf.step(t, Some(z(t))).unwrap();
                assert_spd(ekf.covariance());
                if t > t_bounce && t <= t_bounce + 1.0 {
                    v_err += (ekf.velocity() - velocity(t)).norm();
                    v_count += 1;
                    let f = ekf.forecast(shape, 0.5, 0.0).unwrap();
                    for tau in [0.25, 0.5] {
                        let reach = f.r_safe + f.mu * tau;
                        issued += 1;
                        if (truth(t + tau) - f.center(t + tau)).norm() > reach {
                            missed += 1;
                        }
                    }
                }
            }
        }
        (v_err / v_count as f64, missed as f64 / issued as f64)
    }

    /// A filter that knows the walls follows an obstacle that bounces off one at once: its
    /// velocity turns with the obstacle's instead of half a second later, and its forecasts
    /// contain the obstacle far more often in the second after the bounce.
    #[test]
    fn a_bounce_off_a_known_wall_is_followed_at_once() {
        let (v_without, missed_without) = bounce_statistics(false);
        let (v_with, missed_with) = bounce_statistics(true);
        println!(
            "after the bounce: velocity error {v_without:.3} → {v_with:.3} m/s, forecasts \
             missing the obstacle {missed_without:.3} → {missed_with:.3}"
        );
        assert!(v_with < 0.3 * v_without, "{v_with} vs {v_without}");
        assert!(
            missed_with < 0.3 * missed_without,
            "{missed_with} vs {missed_without}"
        );
    }

    /// Folding is exact on a noiseless estimate: the state crosses the plane, comes back
    /// mirrored, and a filter already inside the box is left alone.
    #[test]
    fn the_fold_mirrors_position_velocity_and_covariance_couplings() {
        let room = Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(4.0, 4.0, 3.0),
        };
        let mut ekf = CvEkf::new(0.0, Vec3::new(3.5, 2.0, 1.0), EkfParams::default()).unwrap();
        ekf.x[3] = 1.0;
        ekf.cov[(0, 1)] = 0.001;
        ekf.cov[(1, 0)] = 0.001;
        let inside = ekf
            .clone()
            .with_walls(&room, ObstacleShape::Sphere, 0.25)
            .unwrap();
        assert_eq!(inside.state(), ekf.state());
        let mut folded = inside.clone();
        folded.predict(0.5).unwrap();
        let mut free = ekf.clone();
        free.predict(0.5).unwrap();
        // Unfolded: x = 4.0, past the plane 3.75; folded: 3.5 walking back.
        assert_relative_eq!(free.position().x, 4.0, epsilon = 1e-12);
        assert_relative_eq!(folded.position().x, 3.5, epsilon = 1e-12);
        assert_relative_eq!(folded.velocity().x, -1.0, epsilon = 1e-12);
        assert_relative_eq!(folded.covariance()[(0, 1)], -free.covariance()[(0, 1)]);
        assert_relative_eq!(folded.covariance()[(0, 3)], free.covariance()[(0, 3)]);
        assert_spd(folded.covariance());
        // Bad walls are named.
        let bad = Aabb {
            min: Vec3::new(f64::NAN, 0.0, 0.0),
            max: Vec3::repeat(1.0),
        };
        let e = ekf
            .clone()
            .with_walls(&bad, ObstacleShape::Sphere, 0.25)
            .unwrap_err();
        assert!(e.to_string().contains("walls.min"), "{e}");
        let e = ekf
            .with_walls(&room, ObstacleShape::Sphere, 0.0)
            .unwrap_err();
        assert!(e.to_string().contains("r_o"), "{e}");
    }

    /// Tracks `truth` from `t = -2` s to `until` with 0.1 m of noise at `rate` Hz (stream
    /// `seed`), calling `visit` after each update.
    fn track_noisy(
        seed: u64,
        params: &EkfParams,
        truth: &impl Fn(f64) -> Vec3,
        until: f64,
        rate: f64,
        mut visit: impl FnMut(f64, &CvEkf),
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let noise = Normal::new(0.0, 0.1).unwrap();
        let mut z = |t: f64| {
            truth(t)
                + Vec3::new(
                    noise.sample(&mut rng),
                    noise.sample(&mut rng),
                    noise.sample(&mut rng),
                )
        };
        let mut ekf = CvEkf::new(-2.0, z(-2.0), params.clone()).unwrap();
        for k in 1..=((2.0 + until) * rate).round() as usize {
            let t = -2.0 + k as f64 / rate;
            ekf.step(t, Some(z(t))).unwrap();
            visit(t, &ekf);
        }
    }

    /// Mean distance between the forecast centre and the truth `tau` seconds ahead, over the
    /// forecasts issued at 20 Hz (0.1 m noise) while `t ∈ window`, 100 seeds; the track starts
    /// at `t = -2`.
    fn forecast_error(params: &EkfParams, truth: impl Fn(f64) -> Vec3, window: (f64, f64)) -> f64 {
        let (mut sum, mut count) = (0.0, 0);
        for seed in 0..100 {
            track_noisy(seed, params, &truth, window.1, 20.0, |t, ekf| {
                if t >= window.0 {
                    let f = ekf.forecast(ObstacleShape::Sphere, 0.25, 0.0).unwrap();
                    for tau in [0.5, 1.0] {
                        sum += (f.center(t + tau) - truth(t + tau)).norm();
                        count += 1;
                    }
                }
            });
        }
        sum / count as f64
    }

    fn without_lag_compensation() -> EkfParams {
        EkfParams {
            accel_smoothing_s: 0.0,
            ..EkfParams::default()
        }
    }

    /// Issue 19 (a holdout room: a person pacing with pauses, 6 collisions in 25 flights): a
    /// person setting off from a pause, 0 → 1.3 m/s in 2 s, is forecast where they will be,
    /// not where a constant-velocity filter lagging behind them expects them.
    #[test]
    fn a_person_setting_off_is_forecast_without_the_filters_lag() {
        // At rest until t = 0, then 0.65 m/s² for 2 s, then 1.3 m/s.
        let truth = |t: f64| {
            let y = if t <= 0.0 {
                0.0
            } else if t <= 2.0 {
                0.325 * t * t
            } else {
                1.3 + 1.3 * (t - 2.0)
            };
            Vec3::new(0.0, y, 1.0)
        };
        let on = forecast_error(&EkfParams::default(), truth, (0.5, 2.5));
        let off = forecast_error(&without_lag_compensation(), truth, (0.5, 2.5));
        println!("mean forecast error 0.5 / 1 s ahead: {on:.3} m compensated, {off:.3} m not");
        assert!(on < 0.85 * off, "{on} vs {off}");
    }

    /// The compensation does not make the forecasts of a steady walker noticeably worse.
    #[test]
    fn the_lag_compensation_costs_a_steady_walker_little() {
        let truth = |t: f64| Vec3::new(1.0 + 1.2 * t, -2.0 + 0.8 * t, 1.0);
        let on = forecast_error(&EkfParams::default(), truth, (0.0, 3.0));
        let off = forecast_error(&without_lag_compensation(), truth, (0.0, 3.0));
        println!("mean forecast error 0.5 / 1 s ahead: {on:.3} m compensated, {off:.3} m not");
        assert!(on < 1.1 * off, "{on} vs {off}");
    }

    /// Noise-free, constant acceleration: once settled, the compensated forecast starts at the
    /// target's true position and velocity (the α-β filter's bias formulas), the plain one
    /// behind them by `0.145 a` and `0.54 a`.
    #[test]
    fn on_a_constant_acceleration_the_compensated_start_has_no_bias() {
        let a = 0.5;
        let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
        let mut t = 0.0;
        for k in 1..=400 {
            t = k as f64 / 20.0;
            ekf.step(t, Some(Vec3::new(0.5 * a * t * t, 0.0, 0.0)))
                .unwrap();
        }
        assert_relative_eq!(ekf.acceleration().x, a, epsilon = 1e-3);
        let f = ekf.forecast(ObstacleShape::Sphere, 0.25, 0.0).unwrap();
        assert_relative_eq!(f.p0.x, 0.5 * a * t * t, epsilon = 1e-3);
        assert_relative_eq!(f.v0.x, a * t, epsilon = 1e-3);
        assert!((a * t - ekf.velocity().x - 0.54 * a).abs() < 0.01 * a);
        // Off, the forecast is the estimate.
        let mut plain = CvEkf::new(0.0, Vec3::zeros(), without_lag_compensation()).unwrap();
        for k in 1..=400 {
            let t = k as f64 / 20.0;
            plain
                .step(t, Some(Vec3::new(0.5 * a * t * t, 0.0, 0.0)))
                .unwrap();
        }
        let f = plain.forecast(ObstacleShape::Sphere, 0.25, 0.0).unwrap();
        assert_eq!(plain.acceleration(), Vec3::zeros());
        assert_eq!((f.p0, f.v0), (plain.position(), plain.velocity()));
    }

    /// A measurement that jumps (a 3 m step, as after a swap of two tracks) makes a huge
    /// acceleration estimate; the compensation shifts the forecast's velocity by at most the
    /// estimate's stated uncertainty `sigma_scale·√(tr P_vv)`, and its position in proportion.
    #[test]
    fn a_jump_shifts_the_forecast_by_at_most_its_velocity_uncertainty() {
        let mut ekf = CvEkf::new(0.0, Vec3::zeros(), EkfParams::default()).unwrap();
        for k in 1..=100 {
            let t = k as f64 / 20.0;
            let y = if k >= 90 { 3.0 } else { 0.0 };
            ekf.step(t, Some(Vec3::new(0.0, y, 0.0))).unwrap();
        }
        let f = ekf.forecast(ObstacleShape::Sphere, 0.25, 0.0).unwrap();
        assert!(ekf.acceleration().norm() > 2.0, "{}", ekf.acceleration());
        // Held at the bound.
        let dv = (f.v0 - ekf.velocity()).norm();
        assert_relative_eq!(
            dv,
            ekf.params().sigma_scale * ekf.velocity_std(),
            max_relative = 1e-9
        );
        // Δp / Δv = τ_p / τ_v (about 0.27 with the defaults).
        let dp = (f.p0 - ekf.position()).norm();
        assert!(dp > 0.0 && dp < 0.5 * dv, "{dp} vs {dv}");
    }

    #[test]
    fn params_serde_defaults_and_unknown_fields() {
        let p: EkfParams = serde_json::from_str(r#"{"meas_std": 0.2}"#).unwrap();
        assert_eq!(
            p,
            EkfParams {
                meas_std: 0.2,
                ..EkfParams::default()
            }
        );
        assert!(serde_json::from_str::<EkfParams>(r#"{"meas_sd": 0.2}"#).is_err());
        let json = serde_json::to_string(&EkfParams::default()).unwrap();
        assert_eq!(
            serde_json::from_str::<EkfParams>(&json).unwrap(),
            EkfParams::default()
        );
        assert_relative_eq!(EkfParams::mu_for_manoeuvre(1.0, 2.0), 1.0);
    }
}
