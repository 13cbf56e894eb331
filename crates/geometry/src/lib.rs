//! Geometry for TRUST-Planner: analytic obstacle shapes, static maps and the distance queries the
//! planner needs.
//!
//! * Shapes — [`Sphere`], vertical [`Cylinder`], axis-aligned [`AaBox`] and the [`Shape`] enum —
//!   with exact signed distances and gradients. The closed forms are also public free functions
//!   ([`sphere_sdf`], [`cylinder_sdf`], [`cylinder_sdf_with_size_gradient`], [`box_sdf`]) so that
//!   moving obstacles with time-varying radius (`trust-predict`) and the collision costs of the
//!   trajectory optimizer (`trust-minco`, the static-map penalty and the DDF cost of paper eq.
//!   design-of-Io) reuse them.
//! * [`StaticMap`] — the static part of the world (paper Sec. III: the map the front end samples
//!   and checks visibility in, and the back end keeps clear of): bounds, shapes in a BVH, and an
//!   optional voxel [`Esdf`] built from a point cloud (the dense static clouds of experiment E4).
//!   Queries: signed distance and gradient, point freedom with a clearance, segment line of sight
//!   with a clearance, and AABB broad phase.
//! * [`Esdf`], [`edt_1d`], [`edt_3d`] — exact Euclidean distance transforms (Felzenszwalb &
//!   Huttenlocher) and a trilinearly interpolated signed distance field.
//!
//! Use this crate whenever something needs to know how far a point or segment is from static
//! obstacles. All public math is `f64` and nalgebra ([`Vec3`]); parry3d-f64 is used inside for the
//! BVH and the segment–shape distance queries and never appears in the API.
//!
//! Scale policy: every public constructor accepts only the magnitudes listed in [`scale`]
//! (positions `|x| ≤ 1e6` m, sizes `≤ 1e6` m, speeds `≤ 1e4` m/s, times `≤ 1e7` s, generated counts
//! `≤ 1e6`); the other crates of the planner apply the same policy at their entry points, so that
//! every internal computation stays finite. Out-of-range input is a [`ScaleError`].
//!
//! Signs and conventions: distances are negative inside obstacles; gradients are unit outward
//! directions, defined (never NaN) at non-differentiable points as documented in [`shapes`]; a map
//! with no obstacles reports `f64::INFINITY` with a zero gradient; a non-finite query point, or one
//! beyond [`scale::QUERY_LIMIT`], reports `f64::NEG_INFINITY` ("not free") with a zero gradient.
//!
//! ```
//! use trust_geometry::{Aabb, Sphere, StaticMap, Vec3};
//!
//! let bounds = Aabb::new(Vec3::zeros(), Vec3::new(20.0, 20.0, 10.0))?;
//! let ball = Sphere::new(Vec3::new(10.0, 10.0, 5.0), 2.0)?;
//! let map = StaticMap::from_shapes(bounds, vec![ball.into()])?;
//! assert!((map.signed_distance(&Vec3::new(10.0, 10.0, 8.0)) - 1.0).abs() < 1e-9);
//! // A segment through the ball is blocked, one beside it is clear with 0.5 m to spare.
//! assert!(!map.segment_clear(&Vec3::new(2.0, 10.0, 5.0), &Vec3::new(18.0, 10.0, 5.0), 0.0));
//! assert!(map.segment_clear(&Vec3::new(2.0, 15.0, 5.0), &Vec3::new(18.0, 15.0, 5.0), 0.5));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod aabb;
mod error;
pub mod esdf;
mod map;
mod parry_conv;
pub mod scale;
pub mod shapes;

/// The public vector type: `nalgebra::Vector3<f64>`.
pub type Vec3 = nalgebra::Vector3<f64>;

pub use aabb::Aabb;
pub use error::GeometryError;
pub use esdf::{
    EdtScratch, Esdf, MAX_VOXELS, checked_voxel_count, edt_1d, edt_1d_with_scratch, edt_3d,
    voxel_index,
};
pub use map::{DEFAULT_RESOLUTION, MAX_TRACE_STEPS, MapWork, StaticMap};
pub use scale::{CountError, Quantity, ScaleError, Sci, SciCount};
pub use shapes::{
    AaBox, Cylinder, CylinderSdf, Shape, Sphere, box_sdf, cylinder_sdf,
    cylinder_sdf_with_size_gradient, sphere_sdf,
};
