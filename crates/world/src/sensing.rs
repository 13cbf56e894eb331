//! Obstacle sensing: noisy positions at a fixed rate, with dropouts, tracked by one
//! constant-velocity Kalman filter per obstacle ([`trust_predict::CvEkf`]); the filters'
//! estimates are the forecasts the planner gets (paper Sec. IV: "only the current position and
//! velocity to estimate by utilizing the Extended Kalman Filter").
//!
//! The planner never reads true obstacle state: the closed loop passes the true positions to
//! [`Sensing::update`] and hands the planner only [`Sensing::forecasts`].
//!
//! * **Measurements.** At `t_k = k / rate_hz` (`k = 0, 1, …`) every obstacle is measured
//!   independently: with probability `dropout_probability` the measurement is lost, otherwise it
//!   is the true centre plus Gaussian noise of standard deviation `position_noise_m` per axis.
//!   The sensor sees every obstacle wherever it is (no range limit, no occlusion).
//! * **Tracks.** An obstacle's filter is created at its first measurement; a lost measurement is
//!   a predict-only step. An obstacle never measured yet is **absent** from the forecasts (there
//!   is nothing to forecast from).
//! * **Warm-up.** A filter's first estimate has zero velocity with a 3 m/s standard deviation
//!   (`EkfParams::init_vel_std`), so its growth rate `mu` starts above 10 m/s and the obstacle's
//!   forecast swallows everything within a second — a planner started then sees a blocked world.
//!   A real vehicle has been watching before it takes off: [`Sensing::warm_up`] (called by
//!   [`crate::World::sensing`]) takes the rounds of the `warmup_s` seconds before `t = 0`
//!   (at `t = −warmup_s + k / rate_hz < 0`) from a pre-history in which every obstacle moved at
//!   its initial velocity (`p(t) = p(0) + v(0)·t`, no reflections), with the same noise and
//!   dropouts. After the default 2 s the tracks have converged (trust-predict measures an RMS
//!   velocity error of 0.09 m/s after 2 s at 20 Hz) and `mu` is back near `mu_min`.
//! * **Forecasts.** [`Sensing::forecasts`]`(t)` predicts each filter to `t` (on a copy) and calls
//!   [`trust_predict::CvEkf::forecast`] with the obstacle's true shape and size as `r_o` (the
//!   sensor is assumed to know sizes) and `r_safe = vehicle radius + r_safe_margin_m`; the filter
//!   adds its position uncertainty (`EkfParams::inflate_by_position_std`) and sets the growth
//!   rate `mu`. So a vehicle centre outside the forecast shape is clear of the estimated obstacle
//!   by the margin.
//! * **Randomness** comes from its own seeded stream (see [`crate::Seeds`]), separate from
//!   the traffic's, so noise and dropouts do not depend on the planner either. Each round draws
//!   the same numbers per obstacle (one dropout draw, three noise draws) whatever is dropped.

use rand::{Rng as _, SeedableRng};
use rand_distr::{Distribution, Normal};
use serde::{Deserialize, Serialize};
use trust_core::{Aabb, Forecast, Rng, Vec3};
use trust_predict::{CvEkf, EkfParams, PredictError};

use crate::error::WorldError;
use crate::map_sensing::StaticSensing;
use crate::problem::Problems;
use crate::traffic::MovingShape;

/// Scenario section `[sensing]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct SensingParams {
    /// Measurement rate (Hz), `> 0`; its period must be a multiple of the physics step.
    /// Default 20 Hz: the sensor `trust_predict::EkfParams`' defaults are tuned for.
    pub rate_hz: f64,
    /// Standard deviation of the position noise per axis (m), `≥ 0`. Default 0.1 m: the
    /// `EkfParams::meas_std` default (a mismatch between the two is allowed: a mistuned filter).
    pub position_noise_m: f64,
    /// Probability that one obstacle's measurement in one round is lost, in `[0, 1)`. Default 0.
    pub dropout_probability: f64,
    /// Margin (m) added to the vehicle radius in every forecast's `r_safe`, `≥ 0`. Default 0.1 m
    /// (ours: the backends' default clearance from moving obstacles).
    pub r_safe_margin_m: f64,
    /// Observation before take-off (s), `≥ 0` ([`Sensing::warm_up`]). Default 2 s: the time the
    /// default EKF needs to converge at 20 Hz (trust-predict's measured RMS velocity error
    /// 0.09 m/s after 2 s).
    pub warmup_s: f64,
    /// The tracking filter's parameters (`trust_predict::EkfParams`).
    pub ekf: EkfParams,
    /// Whether each filter folds its estimate at the walls of the box its obstacle stays inside
    /// (its region; `trust_predict::CvEkf::with_walls`). Default `true`: the traffic turns
    /// obstacles back at those walls, and a filter that does not know it walks a bounced
    /// obstacle into the wall while its velocity turns (the forecasts' wall images assume the
    /// same box). `false` is the paper's constant-velocity filter.
    pub fold_at_walls: bool,
    /// `[sensing.static]`: whether the planner is given the static map (`"known"`, the
    /// default) or senses it with a depth camera or a LiDAR ([`crate::map_sensing`]).
    #[serde(rename = "static", skip_serializing_if = "StaticSensing::is_known")]
    pub static_map: StaticSensing,
}

impl Default for SensingParams {
    fn default() -> Self {
        SensingParams {
            rate_hz: 20.0,
            position_noise_m: 0.1,
            dropout_probability: 0.0,
            r_safe_margin_m: 0.1,
            warmup_s: 2.0,
            ekf: EkfParams::default(),
            fold_at_walls: true,
            static_map: StaticSensing::Known,
        }
    }
}

impl SensingParams {
    /// Every problem with these parameters; field paths start with `field` (e.g. `sensing`).
    pub fn problems(&self, field: &str) -> Vec<crate::problem::Problem> {
        let mut p = Problems::default();
        self.check(field, &mut p);
        p.list
    }

    pub(crate) fn check(&self, field: &str, p: &mut Problems) {
        p.positive(&format!("{field}.rate_hz"), self.rate_hz);
        p.non_negative(&format!("{field}.position_noise_m"), self.position_noise_m);
        if !(0.0..1.0).contains(&self.dropout_probability) {
            p.push(
                format!("{field}.dropout_probability"),
                crate::problem::fmt_num(self.dropout_probability),
                "a probability in [0, 1)",
            );
        }
        p.non_negative(&format!("{field}.r_safe_margin_m"), self.r_safe_margin_m);
        p.non_negative(&format!("{field}.warmup_s"), self.warmup_s);
        if let Err(e) = self.ekf.validate() {
            p.list.push(predict_problem(e, field));
        }
        self.static_map.check(&format!("{field}.static"), p);
    }
}

/// `filter` folding at `wall` when the parameters ask for it ([`SensingParams::fold_at_walls`]).
fn fold_filter(
    filter: CvEkf,
    shape: &MovingShape,
    wall: Option<&Aabb>,
    params: &SensingParams,
) -> Result<CvEkf, WorldError> {
    match wall {
        Some(w) if params.fold_at_walls => {
            Ok(filter.with_walls(w, shape.forecast_shape(), shape.radius())?)
        }
        _ => Ok(filter),
    }
}

/// A parameter error of `trust-predict` (fields `ekf.…`) as a problem under `prefix`.
fn predict_problem(e: PredictError, prefix: &str) -> crate::problem::Problem {
    use crate::problem::Problem;
    match e {
        PredictError::NonFinite { field, value } => Problem::new(
            format!("{prefix}.{field}"),
            crate::problem::fmt_num(value),
            "a finite number",
        ),
        PredictError::OutOfRange {
            field,
            value,
            expected,
        } => Problem::new(
            format!("{prefix}.{field}"),
            crate::problem::fmt_num(value),
            expected,
        ),
        other => Problem::new(format!("{prefix}.ekf"), other, "valid EKF parameters"),
    }
}

/// Counters of a [`Sensing`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct SensingStats {
    /// Measurement rounds taken.
    pub round_count: usize,
    /// Obstacle measurements delivered to the filters.
    pub measurement_count: usize,
    /// Obstacle measurements lost.
    pub dropout_count: usize,
}

/// The obstacle sensor and trackers of one flight (see the module docs).
#[derive(Debug, Clone)]
pub struct Sensing {
    params: SensingParams,
    shapes: Vec<MovingShape>,
    filters: Vec<Option<CvEkf>>,
    /// The box each obstacle stays inside, when known ([`Sensing::with_walls`]).
    walls: Vec<Option<Aabb>>,
    rng: Rng,
    noise: Normal<f64>,
    period_s: f64,
    next_round: u64,
    r_safe: f64,
    stats: SensingStats,
}

impl Sensing {
    /// A sensor for obstacles of the given true `shapes` (in obstacle order), a vehicle of radius
    /// `vehicle_radius_m`, and noise/dropouts from `seed`.
    ///
    /// # Errors
    /// [`WorldError::Input`] naming the first invalid parameter (`sensing. …`) or a negative or
    /// non-finite vehicle radius.
    pub fn new(
        params: &SensingParams,
        shapes: &[MovingShape],
        vehicle_radius_m: f64,
        seed: u64,
    ) -> Result<Self, WorldError> {
        if let Some(first) = params.problems("sensing").into_iter().next() {
            return Err(WorldError::Input(first));
        }
        if !(vehicle_radius_m.is_finite() && vehicle_radius_m >= 0.0) {
            return Err(WorldError::input(
                "vehicle.radius_m",
                vehicle_radius_m,
                "a finite number >= 0",
            ));
        }
        let noise = Normal::new(0.0, params.position_noise_m).map_err(|_| {
            WorldError::input(
                "sensing.position_noise_m",
                params.position_noise_m,
                "a finite number >= 0",
            )
        })?;
        Ok(Sensing {
            params: params.clone(),
            shapes: shapes.to_vec(),
            filters: vec![None; shapes.len()],
            walls: vec![None; shapes.len()],
            rng: Rng::seed_from_u64(seed),
            noise,
            period_s: 1.0 / params.rate_hz,
            next_round: 0,
            r_safe: vehicle_radius_m + params.r_safe_margin_m,
            stats: SensingStats::default(),
        })
    }

    /// This sensor with the box each obstacle stays inside (in obstacle order; `None` for an
    /// obstacle with no known box): with `fold_at_walls` set, each obstacle's filter folds its
    /// estimate at those walls ([`trust_predict::CvEkf::with_walls`]).
    ///
    /// # Errors
    /// [`WorldError::Input`] if `walls` does not have one entry per obstacle or a box is not
    /// finite.
    pub fn with_walls(mut self, walls: Vec<Option<Aabb>>) -> Result<Self, WorldError> {
        if walls.len() != self.shapes.len() {
            return Err(WorldError::input(
                "walls",
                format!("{} boxes", walls.len()),
                format!("one per obstacle ({})", self.shapes.len()),
            ));
        }
        self.walls = walls;
        for ((filter, shape), wall) in self.filters.iter_mut().zip(&self.shapes).zip(&self.walls) {
            if let Some(f) = filter.take() {
                *filter = Some(fold_filter(f, shape, wall.as_ref(), &self.params)?);
            }
        }
        Ok(self)
    }

    /// The parameters.
    pub fn params(&self) -> &SensingParams {
        &self.params
    }

    /// Time between measurement rounds (s).
    pub fn period_s(&self) -> f64 {
        self.period_s
    }

    /// Time of the next scheduled round (s).
    pub fn next_time(&self) -> f64 {
        self.next_round as f64 * self.period_s
    }

    /// Whether a round is due at `t` (within a relative tolerance of 1e-9 of the period, so that
    /// a physics clock that accumulates rounding still hits every round).
    pub fn is_due(&self, t: f64) -> bool {
        t + 1e-9 * self.period_s >= self.next_time()
    }

    /// `r_safe` of every forecast: vehicle radius plus `r_safe_margin_m` (the filter adds its
    /// position uncertainty on top).
    pub fn r_safe(&self) -> f64 {
        self.r_safe
    }

    /// Counters so far.
    pub fn stats(&self) -> SensingStats {
        self.stats
    }

    /// Takes a measurement round at `t` if one is due ([`Sensing::is_due`]); returns whether it
    /// did. Rounds missed by a coarse caller are skipped, not replayed. `truth` holds the true
    /// centres in obstacle order.
    ///
    /// # Errors
    /// As [`Sensing::measure`].
    pub fn update(&mut self, t: f64, truth: &[Vec3]) -> Result<bool, WorldError> {
        if !self.is_due(t) {
            return Ok(false);
        }
        self.measure(t, truth)?;
        while self.is_due(t) {
            self.next_round += 1;
        }
        Ok(true)
    }

    /// Takes the rounds of the `warmup_s` seconds before `t = 0` (module docs) from a
    /// constant-velocity pre-history of the obstacles whose centres and velocities at `t = 0`
    /// are `positions` and `velocities`. Call it once, before the first [`Sensing::update`].
    ///
    /// # Errors
    /// [`WorldError::Input`] if a round was already taken or the slices do not have one entry per
    /// obstacle; as [`Sensing::measure`] otherwise.
    pub fn warm_up(&mut self, positions: &[Vec3], velocities: &[Vec3]) -> Result<(), WorldError> {
        if self.stats.round_count > 0 {
            return Err(WorldError::input(
                "sensing",
                format!("{} rounds taken", self.stats.round_count),
                "a warm-up before the first measurement round",
            ));
        }
        if velocities.len() != positions.len() {
            return Err(WorldError::input(
                "velocities",
                format!("{} velocities", velocities.len()),
                format!("one per position ({})", positions.len()),
            ));
        }
        let rounds = (self.params.warmup_s / self.period_s - 1e-9)
            .ceil()
            .max(0.0) as u64;
        let mut past = vec![Vec3::zeros(); positions.len()];
        for k in (1..=rounds).rev() {
            let t = -(k as f64) * self.period_s;
            for ((q, p), v) in past.iter_mut().zip(positions).zip(velocities) {
                *q = p + v * t;
            }
            self.measure(t, &past)?;
        }
        Ok(())
    }

    /// Takes one measurement round at `t` now, whatever the schedule.
    ///
    /// # Errors
    /// [`WorldError::Input`] if `truth` does not have one position per obstacle or `t` is not
    /// finite; [`WorldError::Predict`] if `t` is before a previous round or a true position is not
    /// finite.
    pub fn measure(&mut self, t: f64, truth: &[Vec3]) -> Result<(), WorldError> {
        if truth.len() != self.shapes.len() {
            return Err(WorldError::input(
                "truth",
                format!("{} positions", truth.len()),
                format!("one position per obstacle ({})", self.shapes.len()),
            ));
        }
        if !t.is_finite() {
            return Err(WorldError::input("t", t, "a finite time"));
        }
        self.stats.round_count += 1;
        let boxes = self.shapes.iter().zip(&self.walls);
        for ((filter, p), (shape, wall)) in self.filters.iter_mut().zip(truth).zip(boxes) {
            let lost = self.rng.random_bool(self.params.dropout_probability);
            let n = Vec3::new(
                self.noise.sample(&mut self.rng),
                self.noise.sample(&mut self.rng),
                self.noise.sample(&mut self.rng),
            );
            let z = (!lost).then_some(p + n);
            if lost {
                self.stats.dropout_count += 1;
            } else {
                self.stats.measurement_count += 1;
            }
            match (filter.as_mut(), z) {
                (Some(f), z) => f.step(t, z)?,
                (None, Some(z)) => {
                    let f = CvEkf::new(t, z, self.params.ekf.clone())?;
                    *filter = Some(fold_filter(f, shape, wall.as_ref(), &self.params)?);
                }
                (None, None) => {}
            }
        }
        Ok(())
    }

    /// Indices of the obstacles that have a track, ascending: the obstacle of each entry of
    /// [`Sensing::forecasts`].
    pub fn tracked_ids(&self) -> Vec<usize> {
        self.filters
            .iter()
            .enumerate()
            .filter_map(|(i, f)| f.as_ref().map(|_| i))
            .collect()
    }

    /// The filter of obstacle `i`, if it has been measured.
    pub fn filter(&self, i: usize) -> Option<&CvEkf> {
        self.filters.get(i).and_then(Option::as_ref)
    }

    /// The forecasts the planner gets at time `t`, one per tracked obstacle in the order of
    /// [`Sensing::tracked_ids`], each made at `t0 = max(t, filter time)`
    /// ([`trust_predict::CvEkf::forecast_at`]).
    ///
    /// # Errors
    /// [`WorldError::Input`] for a non-finite `t`; [`WorldError::Predict`] if a prediction overflows
    /// (only for absurd times).
    pub fn forecasts(&self, t: f64) -> Result<Vec<Forecast>, WorldError> {
        if !t.is_finite() {
            return Err(WorldError::input("t", t, "a finite time"));
        }
        let mut out = Vec::with_capacity(self.filters.len());
        for (filter, shape) in self.filters.iter().zip(&self.shapes) {
            let Some(f) = filter else { continue };
            out.push(f.forecast_at(t, shape.forecast_shape(), shape.radius(), self.r_safe)?);
        }
        Ok(out)
    }
}
