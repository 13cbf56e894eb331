//! The figure-eight test trajectory and the tracking-error measurement.

use std::f64::consts::TAU;

use serde::{Deserialize, Serialize};
use trust_core::Vec3;

use super::error::{
    VehicleError, check_dt, check_finite, check_finite_vec, check_non_negative, check_positive,
    out_of_range,
};
use super::{Reference, Vehicle};

/// Largest number of steps [`tracking_error`] accepts.
const MAX_STEP_COUNT: f64 = 1e9;

/// A horizontal figure-eight (a 1:2 Lissajous curve) at constant height and heading:
///
/// ```text
/// p(t) = center + (A sin ωt, B sin 2ωt, 0),   ω = 2π / period
/// ```
///
/// with analytic velocity, acceleration and jerk. It starts at the crossing point, at full speed.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FigureEight {
    /// Centre (crossing point) of the figure (m).
    pub center: Vec3,
    /// Half extent along x, `A` (m).
    pub half_length_x_m: f64,
    /// Half extent along y, `B` (m).
    pub half_width_y_m: f64,
    /// Duration of one lap (s).
    pub period_s: f64,
    /// Held heading (rad).
    pub yaw: f64,
}

impl FigureEight {
    /// The gentle case: 8 m × 4 m in 9 s — peak speed 3.95 m/s, peak acceleration 4.14 m/s².
    pub fn gentle() -> Self {
        FigureEight {
            center: Vec3::new(0.0, 0.0, 5.0),
            half_length_x_m: 4.0,
            half_width_y_m: 2.0,
            period_s: 9.0,
            yaw: 0.0,
        }
    }

    /// The aggressive case, close to the planner's limits (v_max = 10 m/s, a_max = 15 m/s²,
    /// paper Sec. IV): 15 m × 7.5 m in 7 s — peak speed 9.52 m/s, peak acceleration 12.8 m/s².
    pub fn aggressive() -> Self {
        FigureEight {
            center: Vec3::new(0.0, 0.0, 5.0),
            half_length_x_m: 7.5,
            half_width_y_m: 3.75,
            period_s: 7.0,
            yaw: 0.0,
        }
    }

    /// Checks that every number is finite, the extents non-negative and the period positive.
    pub fn validate(&self) -> Result<(), VehicleError> {
        check_finite_vec("center", &self.center)?;
        check_non_negative("half_length_x_m", self.half_length_x_m)?;
        check_non_negative("half_width_y_m", self.half_width_y_m)?;
        check_positive("period_s", self.period_s)?;
        check_finite("yaw", self.yaw)?;
        Ok(())
    }

    fn omega(&self) -> f64 {
        TAU / self.period_s
    }

    /// The reference (position, velocity, acceleration, jerk, yaw) at absolute time `t` (s).
    pub fn reference(&self, t: f64) -> Reference {
        let w = self.omega();
        let (a, b) = (self.half_length_x_m, self.half_width_y_m);
        let (s1, c1) = (w * t).sin_cos();
        let (s2, c2) = (2.0 * w * t).sin_cos();
        Reference {
            p: self.center + Vec3::new(a * s1, b * s2, 0.0),
            v: Vec3::new(a * w * c1, 2.0 * b * w * c2, 0.0),
            a: Vec3::new(-a * w * w * s1, -4.0 * b * w * w * s2, 0.0),
            j: Vec3::new(-a * w.powi(3) * c1, -8.0 * b * w.powi(3) * c2, 0.0),
            yaw: self.yaw,
        }
    }

    /// Largest speed along the figure (m/s), reached at the crossing: `ω √(A² + 4B²)`.
    pub fn peak_speed(&self) -> f64 {
        let (a, b) = (self.half_length_x_m, self.half_width_y_m);
        self.omega() * (a * a + 4.0 * b * b).sqrt()
    }

    /// Largest acceleration norm along the figure (m/s²). With `s = sin² ωt`,
    /// `|a|² / ω⁴ = A² s + 64 B² s (1 − s)`, maximized in closed form over `s ∈ [0, 1]`.
    pub fn peak_acceleration(&self) -> f64 {
        let (a2, b2) = (self.half_length_x_m.powi(2), self.half_width_y_m.powi(2));
        let s = if b2 > 0.0 {
            ((a2 + 64.0 * b2) / (128.0 * b2)).min(1.0)
        } else {
            1.0
        };
        self.omega().powi(2) * (a2 * s + 64.0 * b2 * s * (1.0 - s)).sqrt()
    }
}

/// How closely a vehicle followed a reference over a flight (see [`tracking_error`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackingReport {
    /// Number of [`Vehicle::step`] calls.
    pub step_count: usize,
    /// Flight duration (s).
    pub duration_s: f64,
    /// Root mean square of the position error over the steps (m).
    pub rms_position_m: f64,
    /// Largest position error (m).
    pub max_position_m: f64,
    /// Root mean square of the velocity error (m/s).
    pub rms_velocity_m_s: f64,
    /// Largest velocity error (m/s).
    pub max_velocity_m_s: f64,
    /// Largest speed of the vehicle (m/s).
    pub max_speed_m_s: f64,
    /// Largest acceleration norm of the vehicle (m/s²).
    pub max_acceleration_m_s2: f64,
    /// Largest body-rate norm of the vehicle (rad/s).
    pub max_body_rate_rad_s: f64,
    /// Largest applied collective thrust (N), `None` for vehicles without actuators.
    pub max_thrust_n: Option<f64>,
    /// Steps during which some actuator or rate limit was active.
    pub saturated_step_count: usize,
    /// Steps that met a non-finite reference sample (excluded from the error statistics).
    pub non_finite_reference_step_count: usize,
}

/// Flies `vehicle` for `duration_s` seconds in steps of `dt_s` (rounded to a whole number of
/// steps) along `reference`, and compares after every step the state at time `t` with
/// `reference(t)`.
///
/// The vehicle starts wherever it is; build it with
/// [`ControlledQuadrotor::starting_on`](super::ControlledQuadrotor::starting_on) or
/// [`PerfectTracking::new`](super::PerfectTracking::new) to start on the reference. `Err` for a
/// non-finite or negative duration, an invalid `dt_s`, more than 10⁹ steps, or a vehicle error.
pub fn tracking_error(
    vehicle: &mut dyn Vehicle,
    reference: &dyn Fn(f64) -> Reference,
    duration_s: f64,
    dt_s: f64,
) -> Result<TrackingReport, VehicleError> {
    check_non_negative("duration_s", duration_s)?;
    check_dt(dt_s)?;
    let steps = (duration_s / dt_s).round();
    if steps > MAX_STEP_COUNT {
        return Err(out_of_range(
            "duration_s",
            duration_s,
            format!("at most {MAX_STEP_COUNT} steps of dt_s = {dt_s} s"),
        ));
    }
    // Non-negative and at most 1e9 here: the conversion is exact.
    let steps = steps as usize;
    let mut report = TrackingReport {
        step_count: steps,
        duration_s: steps as f64 * dt_s,
        rms_position_m: 0.0,
        max_position_m: 0.0,
        rms_velocity_m_s: 0.0,
        max_velocity_m_s: 0.0,
        max_speed_m_s: 0.0,
        max_acceleration_m_s2: 0.0,
        max_body_rate_rad_s: 0.0,
        max_thrust_n: None,
        saturated_step_count: 0,
        non_finite_reference_step_count: 0,
    };
    let (mut sum_p2, mut sum_v2, mut counted) = (0.0, 0.0, 0usize);
    for _ in 0..steps {
        let info = vehicle.step(dt_s, reference)?;
        let s = vehicle.state();
        let r = reference(s.t);
        if info.saturation.any() {
            report.saturated_step_count += 1;
        }
        if let Some(cmd) = info.command {
            let m = report
                .max_thrust_n
                .map_or(cmd.thrust, |m: f64| m.max(cmd.thrust));
            report.max_thrust_n = Some(m);
        }
        report.max_speed_m_s = report.max_speed_m_s.max(s.v.norm());
        report.max_acceleration_m_s2 = report.max_acceleration_m_s2.max(s.a.norm());
        report.max_body_rate_rad_s = report.max_body_rate_rad_s.max(s.body_rate.norm());
        if info.reference_non_finite || !r.is_finite() {
            report.non_finite_reference_step_count += 1;
            continue;
        }
        let e_p = (s.p - r.p).norm();
        let e_v = (s.v - r.v).norm();
        sum_p2 += e_p * e_p;
        sum_v2 += e_v * e_v;
        counted += 1;
        report.max_position_m = report.max_position_m.max(e_p);
        report.max_velocity_m_s = report.max_velocity_m_s.max(e_v);
    }
    if counted > 0 {
        report.rms_position_m = (sum_p2 / counted as f64).sqrt();
        report.rms_velocity_m_s = (sum_v2 / counted as f64).sqrt();
    }
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn derivatives_are_consistent_and_peaks_are_right() {
        for fig in [FigureEight::gentle(), FigureEight::aggressive()] {
            let h = 1e-5;
            let (mut v_max, mut a_max) = (0.0f64, 0.0f64);
            for i in 0..20_000 {
                let t = fig.period_s * f64::from(i) / 20_000.0;
                let r = fig.reference(t);
                let fd = |d: fn(&Reference) -> Vec3| {
                    trust_numdiff::central_difference(|s| d(&fig.reference(s)), t, h)
                };
                assert_relative_eq!(fd(|r| r.p), r.v, epsilon = 1e-7);
                assert_relative_eq!(fd(|r| r.v), r.a, epsilon = 1e-7);
                assert_relative_eq!(fd(|r| r.a), r.j, epsilon = 1e-7);
                v_max = v_max.max(r.v.norm());
                a_max = a_max.max(r.a.norm());
            }
            assert_relative_eq!(fig.peak_speed(), v_max, max_relative = 1e-6);
            assert_relative_eq!(fig.peak_acceleration(), a_max, max_relative = 1e-6);
        }
        let (g, a) = (FigureEight::gentle(), FigureEight::aggressive());
        assert_relative_eq!(g.peak_speed(), 3.95, epsilon = 0.01);
        assert_relative_eq!(g.peak_acceleration(), 4.14, epsilon = 0.01);
        assert_relative_eq!(a.peak_speed(), 9.52, epsilon = 0.01);
        assert_relative_eq!(a.peak_acceleration(), 12.84, epsilon = 0.01);
    }

    #[test]
    fn invalid_figures_are_rejected() {
        let mut f = FigureEight::gentle();
        f.period_s = 0.0;
        assert!(f.validate().unwrap_err().to_string().contains("period_s"));
        let mut f = FigureEight::gentle();
        f.center.z = f64::NAN;
        assert!(f.validate().unwrap_err().to_string().contains("center.z"));
    }
}
