//! # trust-vehicle — what flies the plan in the closed loop
//!
//! A [`Vehicle`] advances its true state by `dt` following a plan sampled through a
//! `&dyn Fn(f64) -> Reference` (position, velocity, acceleration, jerk and yaw at an absolute
//! time). Two implementations:
//!
//! - [`ControlledQuadrotor`] — a quadrotor rigid body ([`Quadrotor`]: mass, inertia, thrust,
//!   torque and body-rate limits, RK4 on position, velocity, attitude quaternion and body rate)
//!   tracked by the geometric controller on SE(3) of Lee, Leok & McClamroch, "Geometric tracking
//!   control of a quadrotor UAV on SE(3)", CDC 2010 ([`Se3Controller`]), with the desired body
//!   rate fed forward from the reference jerk by differential flatness as in Mellinger & Kumar,
//!   "Minimum snap trajectory generation and control for quadrotors", ICRA 2011. The paper's
//!   simulated drone uses "a nonlinear controller [Mellinger & Kumar 2011]" (Sec. IV); the
//!   default vehicle is the 0.85 kg, thrust-to-weight 3.3 racing quadrotor of Foehn et al. 2021
//!   (see [`QuadrotorParams`]).
//! - [`PerfectTracking`] — the state *is* the reference, for fast studies of the planner alone.
//!
//! Use it wherever a plan must be flown: the simulator's closed loop (`trust-flight`) does, and so
//! can any other loop. The rigid body knows nothing of the plan and the controller only reads the
//! reference and the state; perfect tracking is another implementation of the trait, not a flag in
//! the dynamics. Nothing reads a clock or global state: the same inputs give bitwise the same states.
//!
//! Tracking error of the default [`ControlledQuadrotor`] at 500 Hz over three laps of each
//! [`FigureEight`] (`cargo run --release -p trust-vehicle --example figure_eight`):
//!
//! | figure-eight | peak speed / accel. | RMS / max position error | peak thrust | peak body rate |
//! |---|---|---|---|---|
//! | [`FigureEight::gentle`] (8 m × 4 m, 9 s) | 3.95 m/s / 4.14 m/s² | 0.86 mm / 1.1 mm | 9.05 N | 0.57 rad/s |
//! | [`FigureEight::aggressive`] (15 m × 7.5 m, 7 s) | 9.52 m/s / 12.8 m/s² | 5.1 mm / 7.3 mm | 13.7 N | 2.3 rad/s |
//!
//! No thrust, torque or rate limit is reached. The model is ideal — exact parameters, no rotor
//! dynamics, delay, noise or wind — so the error is the controller's own (the lag of the attitude
//! loop); a real vehicle would do worse. A step costs ≈ 0.4 µs and allocates nothing;
//! `tests/vehicle.rs` asserts RMS < 3 mm (gentle) and < 15 mm (aggressive).
//!
//! ```
//! use trust_vehicle::{
//!     ControlledQuadrotor, FigureEight, QuadrotorParams, Se3Gains, Vehicle,
//! };
//!
//! let fig = FigureEight::gentle();
//! let reference = |t: f64| fig.reference(t);
//! let mut drone = ControlledQuadrotor::starting_on(
//!     QuadrotorParams::default(),
//!     Se3Gains::default(),
//!     0.0,
//!     &reference(0.0),
//! )?;
//! for _ in 0..500 {
//!     let info = drone.step(0.002, &reference)?; // 500 Hz
//!     assert!(!info.reference_non_finite);
//! }
//! let error = (drone.state().p - reference(drone.state().t).p).norm();
//! assert!(error < 0.05);
//! # Ok::<(), trust_vehicle::VehicleError>(())
//! ```
#![warn(missing_docs)]

mod controlled;
mod error;
mod figure_eight;
mod params;
mod perfect;
mod rigid_body;
mod se3;

use nalgebra::UnitQuaternion;
use serde::{Deserialize, Serialize};
use trust_core::{PolyTraj, Vec3};

pub use controlled::ControlledQuadrotor;
pub use error::VehicleError;
pub use figure_eight::{FigureEight, TrackingReport, tracking_error};
pub use params::{QuadrotorParams, STANDARD_GRAVITY};
pub use perfect::PerfectTracking;
pub use rigid_body::{Command, Quadrotor, Saturation};
pub use se3::{Se3Controller, Se3Gains, flat_attitude};

use error::{check_finite, check_finite_vec};

/// What the controller reads from the plan at one instant: the flat outputs (position and yaw)
/// and the derivatives of position up to jerk. World frame, z up, SI units.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// Position (m).
    pub p: Vec3,
    /// Velocity (m/s).
    pub v: Vec3,
    /// Acceleration (m/s²).
    pub a: Vec3,
    /// Jerk (m/s³).
    pub j: Vec3,
    /// Heading (rad), held by the controller (its rate is taken as zero).
    pub yaw: f64,
}

impl Reference {
    /// Hover at `p` with heading 0.
    pub fn hover(p: Vec3) -> Self {
        Reference {
            p,
            v: Vec3::zeros(),
            a: Vec3::zeros(),
            j: Vec3::zeros(),
            yaw: 0.0,
        }
    }

    /// Samples a planned trajectory at absolute time `t` (clamped to its span, where it holds its
    /// end state), with heading `yaw`.
    pub fn from_traj(traj: &PolyTraj, t: f64, yaw: f64) -> Self {
        Reference {
            p: traj.position(t),
            v: traj.velocity(t),
            a: traj.acceleration(t),
            j: traj.jerk(t),
            yaw,
        }
    }

    /// Whether every number is finite.
    pub fn is_finite(&self) -> bool {
        [self.p, self.v, self.a, self.j]
            .iter()
            .all(|x| x.iter().all(|c| c.is_finite()))
            && self.yaw.is_finite()
    }
}

/// True state of a vehicle at absolute time `t`, as the run log records it. World frame z up;
/// body frame x forward, z along the thrust.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct VehicleState {
    /// Absolute time (s).
    pub t: f64,
    /// Position (m).
    pub p: Vec3,
    /// Velocity (m/s).
    pub v: Vec3,
    /// True linear acceleration (m/s²): for a quadrotor, thrust/mass along body z minus gravity
    /// (minus drag, if modelled), evaluated at the end of the step, so consistent with the
    /// integrated velocity.
    pub a: Vec3,
    /// Rotation from the body to the world frame.
    pub attitude: UnitQuaternion<f64>,
    /// Body rate (rad/s), in the body frame.
    pub body_rate: Vec3,
}

impl VehicleState {
    /// At rest and level at `p`, time `t`.
    pub fn hover(t: f64, p: Vec3) -> Self {
        VehicleState {
            t,
            p,
            v: Vec3::zeros(),
            a: Vec3::zeros(),
            attitude: UnitQuaternion::identity(),
            body_rate: Vec3::zeros(),
        }
    }

    /// Exactly on the reference at time `t`: position, velocity and acceleration copied, attitude
    /// and body rate of a quadrotor flying it ([`flat_attitude`]; level with the reference yaw
    /// and no rotation where that is undefined, e.g. in free fall). `Err` if the reference, `t`
    /// or gravity is not finite.
    pub fn on_reference(t: f64, r: &Reference, gravity_m_s2: f64) -> Result<Self, VehicleError> {
        check_finite("t", t)?;
        check_finite("gravity_m_s2", gravity_m_s2)?;
        check_finite_vec("reference.p", &r.p)?;
        check_finite_vec("reference.v", &r.v)?;
        check_finite_vec("reference.a", &r.a)?;
        check_finite_vec("reference.j", &r.j)?;
        check_finite("reference.yaw", r.yaw)?;
        let (attitude, body_rate) = flat_attitude(&r.a, &r.j, r.yaw, gravity_m_s2).unwrap_or((
            UnitQuaternion::from_euler_angles(0.0, 0.0, r.yaw),
            Vec3::zeros(),
        ));
        Ok(VehicleState {
            t,
            p: r.p,
            v: r.v,
            a: r.a,
            attitude,
            body_rate,
        })
    }

    /// Checks that every number is finite.
    pub fn validate(&self) -> Result<(), VehicleError> {
        check_finite("state.t", self.t)?;
        check_finite_vec("state.p", &self.p)?;
        check_finite_vec("state.v", &self.v)?;
        check_finite_vec("state.a", &self.a)?;
        let q = self.attitude.quaternion();
        for (name, x) in ["w", "i", "j", "k"].iter().zip([q.w, q.i, q.j, q.k]) {
            if !x.is_finite() {
                check_finite(&format!("state.attitude.{name}"), x)?;
            }
        }
        check_finite_vec("state.body_rate", &self.body_rate)?;
        Ok(())
    }

    /// The kinematic part, as the planner sees it.
    pub fn kinematic(&self) -> trust_core::State {
        trust_core::State {
            t: self.t,
            p: self.p,
            v: self.v,
            a: self.a,
        }
    }
}

/// What happened during one [`Vehicle::step`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct StepInfo {
    /// Number of physics steps taken (1 for [`PerfectTracking`]).
    pub substep_count: u32,
    /// Command applied during the last physics step, after saturation; `None` for vehicles
    /// without actuators ([`PerfectTracking`]).
    pub command: Option<Command>,
    /// Limits active during any of the physics steps.
    pub saturation: Saturation,
    /// Some reference sample was not finite and was replaced (see each implementation).
    pub reference_non_finite: bool,
}

/// Something that flies a plan: a rigid body with a controller, or a perfect tracker.
///
/// A step is `(dt, plan, &mut self) -> report`: no clock is read and no global state is touched,
/// so a step is reproducible and testable alone.
pub trait Vehicle: Send + Sync {
    /// Short name for reports (`se3-quadrotor`, `perfect-tracking`).
    fn name(&self) -> &str;

    /// The true state.
    fn state(&self) -> &VehicleState;

    /// Advances from `state().t` to `state().t + dt` following the plan; `reference(t)` samples
    /// the plan at absolute time `t`. `Err` (state unchanged) if `dt` is not finite and positive;
    /// a non-finite reference is not an error (see [`StepInfo::reference_non_finite`]).
    fn step(
        &mut self,
        dt: f64,
        reference: &dyn Fn(f64) -> Reference,
    ) -> Result<StepInfo, VehicleError>;
}
