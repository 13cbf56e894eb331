//! Obstacle prediction for TRUST-Planner: constant-velocity forecasts with a linearly growing
//! uncertainty radius, the predictive directional cone (PDC) swept by such a forecast, and a
//! constant-velocity Kalman tracker that produces the forecasts from noisy position measurements.
//!
//! Use it wherever the planner needs to know where a moving obstacle may be:
//!
//! * [`Forecast`] — `center(t) = p0 + v0·(t − t0)`, `radius(t) = r_o + r_safe + mu·(t − t0)`, their
//!   time derivatives, and the signed distance with its gradients in `p` and `t` — the dynamic
//!   distance field (DDF) of paper Sec. III-D (eq. design-of-Io; `∂d/∂t` is term (b) of eq.
//!   gradients-of-Io). Spheres and vertical cylinders ([`ObstacleShape`]).
//! * [`Pdc`] — the predictive directional cone of paper Sec. III-B (eq. PDC): the union of the
//!   growing obstacle over a horizon (or at one instant, [`Pdc::at_time`]), with exact point and
//!   segment tests for spheres (provably conservative for cylinders with a positive clearance), a
//!   signed distance with its gradient, a bounding box, a support mapping and the obstacle-aware
//!   surface samples on slices along `v0` used by DEV-PRM. The PDC is the convex hull of its two
//!   end shapes (see the [`pdc`] module); its queries are closed forms tuned for the roadmap's hot
//!   path, and every user of the cone (DEV-PRM, UVD, TVD, safety checks) shares them.
//! * [`CvEkf`] — the dynamic-obstacle estimator of paper Sec. IV ("EKF"): constant-velocity model,
//!   position measurements with dropouts, and `mu` derived from the velocity covariance.
//! * [`wall_images`] — the mirror images of a forecast at the walls of the box its obstacle stays
//!   inside: a person walking at a room's wall turns there (beyond the paper).
//! * [`convex`] — the minimizers behind the PDC queries (closed forms over intervals and polygons,
//!   cutting planes along a segment, segment–segment distance), reusable on their own.
//!
//! ```
//! use trust_predict::{Aabb, Forecast, ObstacleShape, Vec3};
//!
//! // A 0.5 m ball at the origin moving along +x at 2 m/s, 0.2 m margin, 0.3 m/s uncertainty growth.
//! let f = Forecast::new(ObstacleShape::Sphere, Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), 0.0, 0.5, 0.2, 0.3)?;
//! assert!((f.radius(1.0) - 1.0).abs() < 1e-12);
//! let (d, d_p, d_t) = f.distance_and_gradients(&Vec3::new(3.0, 0.0, 0.0), 1.0);
//! assert!((d - 0.0).abs() < 1e-12 && d_p.x > 0.0 && d_t < 0.0); // the obstacle is approaching
//!
//! // Its cone over a 2 s horizon blocks the segment crossing its path at x = 2 m…
//! let pdc = f.pdc(2.0)?;
//! assert!(!pdc.segment_clear(&Vec3::new(2.0, -5.0, 0.0), &Vec3::new(2.0, 5.0, 0.0), 0.1));
//! // …but not one behind it.
//! assert!(pdc.segment_clear(&Vec3::new(-2.0, -5.0, 0.0), &Vec3::new(-2.0, 5.0, 0.0), 0.1));
//! // Obstacle-aware samples in a region: 4 slices along v0, 8 points each, and one beyond each
//! // end of the sweep, 0.1 m outside the surface.
//! let region = Aabb { min: Vec3::repeat(-10.0), max: Vec3::repeat(10.0) };
//! let samples = pdc.surface_samples(4, 8, 0.1, &region)?;
//! assert_eq!(samples.len(), 34);
//! assert!(samples.iter().all(|p| (pdc.signed_distance(p) - 0.1).abs() < 1e-9));
//! # Ok::<(), trust_predict::PredictError>(())
//! ```
//!
//! All inputs are validated at construction ([`PredictError`]); query methods assume finite
//! arguments (the boolean tests treat non-finite ones as blocked).
#![warn(missing_docs)]

pub mod convex;
mod ekf;
mod error;
mod forecast;
pub mod pdc;
mod walls;

pub use ekf::{
    CHI2_3_95, CvEkf, EkfParams, LAG_NOISE_THRESHOLD, LAG_WARMUP_S, MAX_ACCEL_PSD,
    MAX_MANOEUVRE_GATE, MAX_SIGMA_SCALE,
};
pub use error::PredictError;
pub use forecast::{Forecast, ObstacleShape};
pub use pdc::{CLEAR_TOLERANCE, Pdc, frame_along, round_cone_sdf};
pub use trust_geometry::{Aabb, Vec3};
pub use walls::{MAX_REFLECTIONS_PER_AXIS, wall_images};
