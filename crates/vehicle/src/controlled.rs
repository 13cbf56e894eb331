//! A quadrotor rigid body flown by the SE(3) controller: the simulator's default vehicle.

use trust_core::Vec3;

use super::error::{VehicleError, check_dt, check_positive, out_of_range};
use super::params::QuadrotorParams;
use super::rigid_body::{Command, Quadrotor, Saturation};
use super::se3::{Se3Controller, Se3Gains};
use super::{Reference, StepInfo, Vehicle, VehicleState};

/// Largest number of physics sub-steps one [`Vehicle::step`] may take (guards against a huge `dt`
/// that would make the call run for minutes).
const MAX_SUBSTEP_COUNT: f64 = 1e7;

/// A [`Quadrotor`] rigid body tracked by an [`Se3Controller`].
///
/// Each [`Vehicle::step`] of length `dt` is split into `⌈dt / max_substep_s⌉` equal physics steps
/// (one step when `dt ≤ max_substep_s`, e.g. the validated 500 Hz, `dt = 0.002 s`). Per physics
/// step the plan is sampled at the step's start time, the controller computes a command from the
/// sample and the true state, and the body integrates that command held over the step (zero-order
/// hold; controller and physics run at the same rate).
///
/// A non-finite reference sample is replaced by a hover at the last finite reference position and
/// heading (before any finite sample, the initial position and heading), and a non-finite command
/// (only possible with absurd finite references, e.g. a jerk of 1e308 m/s³) by the last finite
/// one; both are reported in [`StepInfo::reference_non_finite`]. The state therefore never
/// contains NaN.
#[derive(Debug, Clone, PartialEq)]
pub struct ControlledQuadrotor {
    /// The rigid body (parameters and true state).
    pub body: Quadrotor,
    /// The tracking controller.
    pub controller: Se3Controller,
    max_substep_s: f64,
    last_reference: Reference,
    last_command: Command,
}

impl ControlledQuadrotor {
    /// Default longest physics step (s): 500 Hz, the rate the vehicle was validated at.
    pub const DEFAULT_MAX_SUBSTEP_S: f64 = 0.002;

    /// Flies `body` with `controller`, with physics steps of at most
    /// [`DEFAULT_MAX_SUBSTEP_S`](Self::DEFAULT_MAX_SUBSTEP_S).
    pub fn new(body: Quadrotor, controller: Se3Controller) -> Self {
        let mut last_reference = Reference::hover(body.state().p);
        last_reference.yaw = body.state().attitude.euler_angles().2;
        let last_command = Command::hover(body.params());
        ControlledQuadrotor {
            body,
            controller,
            max_substep_s: Self::DEFAULT_MAX_SUBSTEP_S,
            last_reference,
            last_command,
        }
    }

    /// A vehicle with the given parameters and gains (controller model = body parameters) that
    /// starts exactly on `reference` at time `t0` (see [`VehicleState::on_reference`]).
    pub fn starting_on(
        params: QuadrotorParams,
        gains: Se3Gains,
        t0: f64,
        reference: &Reference,
    ) -> Result<Self, VehicleError> {
        let state = VehicleState::on_reference(t0, reference, params.gravity_m_s2)?;
        let body = Quadrotor::new(params, state)?;
        let controller = Se3Controller::new(gains, &params)?;
        Ok(Self::new(body, controller))
    }

    /// Sets the longest physics step (s); must be finite and positive.
    pub fn with_max_substep(mut self, max_substep_s: f64) -> Result<Self, VehicleError> {
        check_positive("max_substep_s", max_substep_s)?;
        self.max_substep_s = max_substep_s;
        Ok(self)
    }

    /// The longest physics step (s).
    pub fn max_substep_s(&self) -> f64 {
        self.max_substep_s
    }

    /// The last command the controller produced, before saturation (hover before the first step).
    pub fn last_command(&self) -> &Command {
        &self.last_command
    }

    /// Number of physics steps for a call of length `dt` (already validated).
    fn substep_count(&self, dt: f64) -> Result<u32, VehicleError> {
        // The tiny relative slack keeps dt = k · max_substep_s (up to rounding) at k steps.
        let n = (dt / self.max_substep_s * (1.0 - 1e-12)).ceil().max(1.0);
        if n > MAX_SUBSTEP_COUNT {
            return Err(out_of_range(
                "dt",
                dt,
                format!(
                    "at most {MAX_SUBSTEP_COUNT} physics steps of {} s",
                    self.max_substep_s
                ),
            ));
        }
        // In 1..=1e7 here, so the conversion is exact.
        Ok(n as u32)
    }
}

impl Vehicle for ControlledQuadrotor {
    fn name(&self) -> &str {
        "se3-quadrotor"
    }

    fn state(&self) -> &VehicleState {
        self.body.state()
    }

    fn step(
        &mut self,
        dt: f64,
        reference: &dyn Fn(f64) -> Reference,
    ) -> Result<StepInfo, VehicleError> {
        check_dt(dt)?;
        let n = self.substep_count(dt)?;
        let h = dt / f64::from(n);
        let mut saturation = Saturation::default();
        let mut reference_non_finite = false;
        for _ in 0..n {
            let mut r = reference(self.body.state().t);
            if r.is_finite() {
                self.last_reference = r;
            } else {
                reference_non_finite = true;
                r = Reference {
                    p: self.last_reference.p,
                    v: Vec3::zeros(),
                    a: Vec3::zeros(),
                    j: Vec3::zeros(),
                    yaw: self.last_reference.yaw,
                };
            }
            let cmd = self.controller.command(self.body.state(), &r);
            if cmd.is_finite() {
                self.last_command = cmd;
            } else {
                reference_non_finite = true;
            }
            saturation = saturation.merge(self.body.step(&self.last_command, h)?);
        }
        Ok(StepInfo {
            substep_count: n,
            command: Some(*self.body.applied_command()),
            saturation,
            reference_non_finite,
        })
    }
}
