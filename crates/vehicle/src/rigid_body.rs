//! The quadrotor rigid body: Newton–Euler equations integrated with classical Runge–Kutta (RK4).
//!
//! The body knows nothing of plans or controllers: it takes a [`Command`] (collective thrust and
//! body torques), saturates it, holds it over the step and integrates
//!
//! ```text
//! ṗ = v
//! v̇ = (f/m) R e₃ − g e₃ − (c_d/m) v
//! q̇ = ½ q ⊗ (0, ω)                      (ω in the body frame)
//! ω̇ = J⁻¹ (M − ω × J ω)                 (Euler's equations)
//! ```
//!
//! on the full state (position, velocity, attitude quaternion, body rate). The quaternion is
//! renormalized after each step and the body rate is projected onto the rate limits.

use nalgebra::{Quaternion, UnitQuaternion};
use serde::{Deserialize, Serialize};
use trust_core::Vec3;

use super::VehicleState;
use super::error::{VehicleError, check_dt, check_finite, check_finite_vec};
use super::params::QuadrotorParams;

/// What the rigid body is asked to produce over one step: collective thrust along the body z
/// axis and torques about the body axes. Held constant (zero-order hold) over the step.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Command {
    /// Collective thrust (N), along body +z.
    pub thrust: f64,
    /// Body torques (N·m) about body x, y, z.
    pub torque: Vec3,
}

impl Command {
    /// The command that holds a level vehicle of the given parameters in hover: thrust = weight,
    /// no torque.
    pub fn hover(params: &QuadrotorParams) -> Self {
        Command {
            thrust: params.hover_thrust_n(),
            torque: Vec3::zeros(),
        }
    }

    /// Whether thrust and torques are all finite.
    pub fn is_finite(&self) -> bool {
        self.thrust.is_finite() && self.torque.iter().all(|x| x.is_finite())
    }
}

/// Which limits were active during a step (or, merged, during any of several steps).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Saturation {
    /// The commanded thrust was outside `[min_thrust_n, max_thrust_n]` and was clamped.
    pub thrust: bool,
    /// A commanded torque exceeded `max_torque_n_m` and was clamped.
    pub torque: bool,
    /// The body rate reached `max_body_rate_rad_s` and was projected back onto the limit.
    pub body_rate: bool,
}

impl Saturation {
    /// Whether any limit was active.
    pub fn any(&self) -> bool {
        self.thrust || self.torque || self.body_rate
    }

    /// The union of two saturation reports.
    pub fn merge(self, other: Saturation) -> Saturation {
        Saturation {
            thrust: self.thrust || other.thrust,
            torque: self.torque || other.torque,
            body_rate: self.body_rate || other.body_rate,
        }
    }
}

/// A quadrotor rigid body: parameters and true state. Step it with [`Quadrotor::step`].
///
/// Validated with the default parameters at dt = 2 ms (500 Hz); RK4's error at that step is far
/// below the controller's tracking error (the unit tests check conservation of angular momentum
/// and energy of a torque-free tumbling body and the analytic free-fall solution).
#[derive(Debug, Clone, PartialEq)]
pub struct Quadrotor {
    params: QuadrotorParams,
    state: VehicleState,
    applied: Command,
}

/// The integrated part of the state. The quaternion is not kept at unit norm inside a step.
#[derive(Debug, Clone, Copy)]
struct Rb {
    p: Vec3,
    v: Vec3,
    q: Quaternion<f64>,
    w: Vec3,
}

impl Rb {
    /// `self + h · k`, where `k` is a derivative.
    fn plus(&self, k: &Rb, h: f64) -> Rb {
        Rb {
            p: self.p + k.p * h,
            v: self.v + k.v * h,
            q: self.q + k.q * h,
            w: self.w + k.w * h,
        }
    }
}

impl Quadrotor {
    /// A rigid body with validated parameters, starting at `state` (which must be finite). The
    /// initial applied command is hover.
    pub fn new(params: QuadrotorParams, state: VehicleState) -> Result<Self, VehicleError> {
        params.validate()?;
        state.validate()?;
        Ok(Quadrotor {
            applied: Command::hover(&params),
            params,
            state,
        })
    }

    /// The parameters.
    pub fn params(&self) -> &QuadrotorParams {
        &self.params
    }

    /// The true state.
    pub fn state(&self) -> &VehicleState {
        &self.state
    }

    /// The command applied during the last step, after saturation (hover before the first step).
    pub fn applied_command(&self) -> &Command {
        &self.applied
    }

    /// Clamps a command to the thrust and torque limits.
    pub fn saturate(&self, cmd: &Command) -> (Command, Saturation) {
        let pr = &self.params;
        let thrust = cmd.thrust.clamp(pr.min_thrust_n, pr.max_thrust_n);
        let torque = cmd
            .torque
            .zip_map(&pr.max_torque_n_m, |m, limit| m.clamp(-limit, limit));
        let sat = Saturation {
            thrust: thrust != cmd.thrust,
            torque: torque != cmd.torque,
            body_rate: false,
        };
        (Command { thrust, torque }, sat)
    }

    /// Advances the body by `dt` seconds under `cmd`, held constant over the step.
    ///
    /// The command is first clamped to the thrust and torque limits; after the RK4 step the
    /// quaternion is renormalized and each body-rate component is clamped to
    /// `max_body_rate_rad_s`. The reported acceleration is computed from the forces at the end of
    /// the step (thrust along the new body z axis, gravity, drag at the new velocity).
    ///
    /// `Err` if `dt` is not finite and positive or the command is not finite; the state is then
    /// unchanged.
    pub fn step(&mut self, cmd: &Command, dt: f64) -> Result<Saturation, VehicleError> {
        check_dt(dt)?;
        check_finite("command.thrust", cmd.thrust)?;
        check_finite_vec("command.torque", &cmd.torque)?;
        let (applied, mut sat) = self.saturate(cmd);

        let x0 = Rb {
            p: self.state.p,
            v: self.state.v,
            q: *self.state.attitude.quaternion(),
            w: self.state.body_rate,
        };
        let f = |x: &Rb| self.derivative(x, &applied);
        let k1 = f(&x0);
        let k2 = f(&x0.plus(&k1, 0.5 * dt));
        let k3 = f(&x0.plus(&k2, 0.5 * dt));
        let k4 = f(&x0.plus(&k3, dt));
        let mut x1 = x0;
        x1.p += (k1.p + (k2.p + k3.p) * 2.0 + k4.p) * (dt / 6.0);
        x1.v += (k1.v + (k2.v + k3.v) * 2.0 + k4.v) * (dt / 6.0);
        x1.q += (k1.q + (k2.q + k3.q) * 2.0 + k4.q) * (dt / 6.0);
        x1.w += (k1.w + (k2.w + k3.w) * 2.0 + k4.w) * (dt / 6.0);

        let limit = &self.params.max_body_rate_rad_s;
        let clamped = x1.w.zip_map(limit, |w, l| w.clamp(-l, l));
        sat.body_rate = clamped != x1.w;

        let attitude = UnitQuaternion::new_normalize(x1.q);
        self.state = VehicleState {
            t: self.state.t + dt,
            p: x1.p,
            v: x1.v,
            a: self.linear_acceleration(&body_z(attitude.quaternion()), &x1.v, applied.thrust),
            attitude,
            body_rate: clamped,
        };
        self.applied = applied;
        Ok(sat)
    }

    /// Linear acceleration (m/s²) of a body with thrust axis `body_z` (unit) and velocity `v`
    /// under this thrust.
    fn linear_acceleration(&self, body_z: &Vec3, v: &Vec3, thrust: f64) -> Vec3 {
        let pr = &self.params;
        body_z * (thrust / pr.mass_kg)
            - Vec3::z() * pr.gravity_m_s2
            - v * (pr.drag_coefficient_kg_s / pr.mass_kg)
    }

    /// Time derivative of the integrated state under a (saturated) command.
    fn derivative(&self, x: &Rb, cmd: &Command) -> Rb {
        let j = &self.params.inertia_kg_m2;
        let jw = j.component_mul(&x.w);
        Rb {
            p: x.v,
            v: self.linear_acceleration(&body_z(&x.q), &x.v, cmd.thrust),
            q: x.q * Quaternion::from_imag(x.w) * 0.5,
            w: (cmd.torque - x.w.cross(&jw)).component_div(j),
        }
    }
}

/// Third column of the rotation matrix of `q / |q|` (the body z axis in the world frame), from the
/// homogeneous form of the quaternion rotation: no square root for the unnormalized intermediate
/// quaternions of a Runge–Kutta step.
fn body_z(q: &Quaternion<f64>) -> Vec3 {
    let (w, x, y, z) = (q.w, q.i, q.j, q.k);
    Vec3::new(
        2.0 * (x * z + w * y),
        2.0 * (y * z - w * x),
        w * w - x * x - y * y + z * z,
    ) / q.norm_squared()
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    fn body_at_rest() -> Quadrotor {
        Quadrotor::new(
            QuadrotorParams::default(),
            VehicleState::hover(0.0, Vec3::new(0.0, 0.0, 5.0)),
        )
        .unwrap()
    }

    #[test]
    fn body_z_is_the_rotated_z_axis_for_any_scale() {
        let q = Quaternion::new(0.3, -0.5, 0.8, 0.1);
        let unit = UnitQuaternion::new_normalize(q);
        for scale in [1.0, 0.7, 3.0] {
            assert_relative_eq!(body_z(&(q * scale)), unit * Vec3::z(), epsilon = 1e-15);
        }
    }

    #[test]
    fn hover_command_keeps_the_body_still() {
        let mut body = body_at_rest();
        let cmd = Command::hover(body.params());
        for _ in 0..5000 {
            let sat = body.step(&cmd, 0.002).unwrap();
            assert!(!sat.any());
        }
        assert_relative_eq!(body.state().t, 10.0, epsilon = 1e-9);
        assert_relative_eq!(body.state().p, Vec3::new(0.0, 0.0, 5.0), epsilon = 1e-9);
        assert_relative_eq!(body.state().a, Vec3::zeros(), epsilon = 1e-9);
    }

    #[test]
    fn free_fall_matches_the_analytic_solution() {
        let params = QuadrotorParams::default();
        assert_eq!(params.min_thrust_n, 0.0);
        let mut body = Quadrotor::new(params, VehicleState::hover(0.0, Vec3::zeros())).unwrap();
        let cmd = Command {
            thrust: 0.0,
            torque: Vec3::zeros(),
        };
        for _ in 0..500 {
            body.step(&cmd, 0.002).unwrap();
        }
        let g = params.gravity_m_s2;
        // RK4 is exact for a quadratic in time, up to rounding.
        assert_relative_eq!(body.state().p.z, -0.5 * g, epsilon = 1e-10);
        assert_relative_eq!(body.state().v.z, -g, epsilon = 1e-10);
        assert_relative_eq!(body.state().a.z, -g, epsilon = 1e-12);
    }

    #[test]
    fn torque_free_tumbling_conserves_momentum_and_energy() {
        // An asymmetric body spinning about an axis near the intermediate one (the most sensitive
        // case): angular momentum in the world frame and rotational energy are invariants.
        let params = QuadrotorParams {
            inertia_kg_m2: Vec3::new(0.001, 0.0014, 0.0017),
            max_body_rate_rad_s: Vec3::repeat(1e3),
            ..Default::default()
        };
        let mut state = VehicleState::hover(0.0, Vec3::zeros());
        state.body_rate = Vec3::new(0.3, 6.0, 0.2);
        let mut body = Quadrotor::new(params, state).unwrap();
        let j = params.inertia_kg_m2;
        let momentum = |s: &VehicleState| s.attitude * j.component_mul(&s.body_rate);
        let energy = |s: &VehicleState| 0.5 * s.body_rate.dot(&j.component_mul(&s.body_rate));
        let (l0, e0) = (momentum(body.state()), energy(body.state()));
        // Free fall (zero thrust) so that no force couples in; torque-free.
        let cmd = Command {
            thrust: 0.0,
            torque: Vec3::zeros(),
        };
        for _ in 0..5000 {
            body.step(&cmd, 0.002).unwrap();
            assert_relative_eq!(body.state().attitude.norm(), 1.0, epsilon = 1e-12);
        }
        assert_relative_eq!(momentum(body.state()), l0, max_relative = 1e-6);
        assert_relative_eq!(energy(body.state()), e0, max_relative = 1e-6);
        // It really tumbled (the intermediate axis is unstable).
        assert!((body.state().body_rate - state.body_rate).norm() > 1.0);
    }

    #[test]
    fn constant_torque_spins_up_as_euler_predicts() {
        // About a principal axis the gyroscopic term vanishes: ω̇ = M / J.
        let mut body = body_at_rest();
        let cmd = Command {
            thrust: body.params().hover_thrust_n(),
            torque: Vec3::new(0.0, 0.0, 0.017),
        };
        for _ in 0..100 {
            body.step(&cmd, 0.002).unwrap();
        }
        assert_relative_eq!(body.state().body_rate.z, 2.0, epsilon = 1e-10);
        let (_, _, yaw) = body.state().attitude.euler_angles();
        assert_relative_eq!(yaw, 0.5 * 10.0 * 0.2 * 0.2, epsilon = 1e-10);
    }

    #[test]
    fn limits_are_applied() {
        let mut body = body_at_rest();
        let cmd = Command {
            thrust: 1e3,
            torque: Vec3::new(-10.0, 0.1, 10.0),
        };
        let (applied, sat) = body.saturate(&cmd);
        assert!(sat.thrust && sat.torque);
        assert_eq!(applied.thrust, body.params().max_thrust_n);
        assert_eq!(applied.torque.x, -body.params().max_torque_n_m.x);
        assert_eq!(applied.torque.y, 0.1);
        let mut rate_hit = false;
        for _ in 0..200 {
            let sat = body.step(&cmd, 0.002).unwrap();
            rate_hit |= sat.body_rate;
            let w = body.state().body_rate;
            let l = body.params().max_body_rate_rad_s;
            assert!(w.x.abs() <= l.x && w.y.abs() <= l.y && w.z.abs() <= l.z);
        }
        assert!(rate_hit);
    }

    #[test]
    fn bad_step_inputs_are_errors_and_leave_the_state_alone() {
        let mut body = body_at_rest();
        let before = body.clone();
        let hover = Command::hover(body.params());
        for dt in [0.0, -0.002, f64::NAN, f64::INFINITY] {
            let err = body.step(&hover, dt).unwrap_err();
            assert!(err.to_string().contains("dt"), "{err}");
        }
        let nan = Command {
            thrust: f64::NAN,
            torque: Vec3::zeros(),
        };
        assert!(
            body.step(&nan, 0.002)
                .unwrap_err()
                .to_string()
                .contains("command.thrust")
        );
        let inf = Command {
            thrust: 1.0,
            torque: Vec3::new(0.0, f64::INFINITY, 0.0),
        };
        assert!(
            body.step(&inf, 0.002)
                .unwrap_err()
                .to_string()
                .contains("command.torque.y")
        );
        assert_eq!(body, before);
    }
}
