//! The perfect-tracking vehicle: the state is the reference, for fast studies of the planner alone.

use trust_core::Vec3;

use super::error::{VehicleError, check_dt, check_positive};
use super::params::STANDARD_GRAVITY;
use super::se3::flat_attitude;
use super::{Reference, StepInfo, Vehicle, VehicleState};

/// A vehicle that follows the plan exactly: after a step to `t + dt` its position, velocity and
/// acceleration are the reference's at `t + dt`, its attitude and body rate those of a quadrotor
/// flying that reference (differential flatness, see [`flat_attitude`]).
///
/// A non-finite reference sample leaves the vehicle hovering at its last position (velocity and
/// acceleration zero, attitude kept, body rate zero) and is reported in
/// [`StepInfo::reference_non_finite`]. Where the attitude is undefined (free fall) the previous
/// attitude is kept.
#[derive(Debug, Clone, PartialEq)]
pub struct PerfectTracking {
    state: VehicleState,
    gravity_m_s2: f64,
}

impl PerfectTracking {
    /// Starts on `reference` at time `t0`, with standard gravity ([`STANDARD_GRAVITY`]) for the
    /// attitude.
    pub fn new(t0: f64, reference: &Reference) -> Result<Self, VehicleError> {
        Self::with_gravity(t0, reference, STANDARD_GRAVITY)
    }

    /// Starts on `reference` at time `t0`, with the given gravity (m/s², > 0) for the attitude.
    pub fn with_gravity(
        t0: f64,
        reference: &Reference,
        gravity_m_s2: f64,
    ) -> Result<Self, VehicleError> {
        check_positive("gravity_m_s2", gravity_m_s2)?;
        Ok(PerfectTracking {
            state: VehicleState::on_reference(t0, reference, gravity_m_s2)?,
            gravity_m_s2,
        })
    }
}

impl Vehicle for PerfectTracking {
    fn name(&self) -> &str {
        "perfect-tracking"
    }

    fn state(&self) -> &VehicleState {
        &self.state
    }

    fn step(
        &mut self,
        dt: f64,
        reference: &dyn Fn(f64) -> Reference,
    ) -> Result<StepInfo, VehicleError> {
        check_dt(dt)?;
        let t = self.state.t + dt;
        let r = reference(t);
        let finite = r.is_finite();
        if finite {
            let (attitude, body_rate) = flat_attitude(&r.a, &r.j, r.yaw, self.gravity_m_s2)
                .unwrap_or((self.state.attitude, Vec3::zeros()));
            self.state = VehicleState {
                t,
                p: r.p,
                v: r.v,
                a: r.a,
                attitude,
                body_rate,
            };
        } else {
            self.state = VehicleState {
                t,
                p: self.state.p,
                v: Vec3::zeros(),
                a: Vec3::zeros(),
                attitude: self.state.attitude,
                body_rate: Vec3::zeros(),
            };
        }
        Ok(StepInfo {
            substep_count: 1,
            command: None,
            saturation: Default::default(),
            reference_non_finite: !finite,
        })
    }
}
