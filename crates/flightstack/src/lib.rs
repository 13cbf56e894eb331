//! # trust-flightstack — planned trajectories as PX4 setpoints and Crazyflie pieces
//!
//! The planner's output, a piecewise-quintic [`trust_core::PolyTraj`] (paper eq. Polynomials, the
//! MINCO trajectory of Sec. III-D), in the forms two flight stacks take, as plain data: no ROS,
//! no MAVLink library, no I/O beyond a CSV writer.
//!
//! - [`px4`]: `px4_msgs/msg/TrajectorySetpoint` of PX4 [`px4::PX4_RELEASE`] (NED; NaN = "not
//!   controlled"), one at a time ([`px4::setpoint_at`]) or as a stream ([`px4::sample_setpoints`]),
//!   and the same setpoint as MAVLink `SET_POSITION_TARGET_LOCAL_NED`.
//! - [`crazyflie`]: the firmware's `poly4d` pieces ([`crazyflie::to_poly4d`]; our quintics are
//!   its degree-7 pieces exactly), the Crazyswarm `uav_trajectories` CSV and Crazyswarm2's
//!   `TrajectoryPolynomialPiece`, within the 31-piece trajectory memory.
//! - [`frame`]: ENU ↔ NED for vectors and yaw, and a rigid world-to-target transform.
//! - [`yaw`]: the yaw policy (the planner plans positions only): fixed, facing the velocity, or
//!   not controlled.
//!
//! Use it to fly a plan on a vehicle, or to feed a ROS 2 node (the message structs list their
//! fields in message order, so a serde-based client can publish them). Every function checks its
//! input and returns a typed [`FlightStackError`]; no controlled value is ever NaN. Frames,
//! releases, limits and sources: `docs/flight-stacks.md`.
//!
//! ```
//! use trust_core::{PolyTraj, Vec3};
//! use trust_flightstack::crazyflie::{self, CrazyflieParams};
//! use trust_flightstack::px4::{self, Px4Params};
//!
//! // One second from (0, 0, 1) towards the east at 1 m/s (our world: x east, y north, z up).
//! let mut piece = [Vec3::zeros(); 6];
//! piece[0] = Vec3::new(0.0, 0.0, 1.0);
//! piece[1] = Vec3::new(1.0, 0.0, 0.0);
//! let traj = PolyTraj::new(0.0, vec![1.0], vec![piece])?;
//!
//! // PX4 at 50 Hz, PX4's clock at 5 s when the trajectory starts: NED, so east is y, up is −z.
//! let setpoints = px4::sample_setpoints(&traj, 5_000_000, 50.0, &Px4Params::default())?;
//! assert_eq!(setpoints.len(), 51);
//! assert_eq!(setpoints[50].timestamp, 6_000_000);
//! assert_eq!(setpoints[50].position, [0.0, 1.0, -1.0]);
//!
//! // The Crazyflie: one poly4d piece, as a Crazyswarm CSV.
//! let pieces = crazyflie::to_poly4d(&traj, &CrazyflieParams::default())?;
//! assert_eq!(pieces[0].x, [0.0, 1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
//! let csv = crazyflie::uav_trajectories_csv(&pieces)?;
//! assert!(csv.starts_with("Duration,x^0,"));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

pub mod crazyflie;
mod error;
pub mod frame;
mod input;
pub mod px4;
pub mod yaw;

pub use error::FlightStackError;
pub use input::trajectory_from_parts;
