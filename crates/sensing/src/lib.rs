//! Simulated onboard sensing and an online map for TRUST-Planner: what the vehicle would see
//! with its own sensors, and the local map it would build from it, in the form the planner
//! already consumes (a `trust_geometry::StaticMap`).
//!
//! * Sensors ([`RaySensor`]): a pinhole [`DepthCamera`] (defaults of an Intel RealSense D435,
//!   160 × 120 for planning; depth noise `σ = k z²`) and a spinning [`Lidar`] (Velodyne VLP-16),
//!   ray-cast from a [`Pose`] against the [`Truth`]: the true static map (shapes through
//!   `StaticMap::cast_ray`, point-cloud ESDFs by sphere tracing) and the moving obstacles at the
//!   sensing time. A [`Scan`] has one [`RayMeasurement`] per ray — a hit, "no return within
//!   range" (free-space evidence) or invalid — in the world frame. Noise comes from a seeded
//!   `ChaCha8Rng` passed in: the same seed gives the same scan.
//! * The online map ([`LocalMap`]): log-odds voxels with OctoMap's sensor model
//!   ([`LogOddsParams`]), free space cleared along each ray by the 3-D DDA
//!   ([`VoxelTraversal`], Amanatides & Woo 1987; a depth frame's by projecting the frustum's
//!   voxels into its image, [`LocalMap::insert_depth_frame`]), a rolling window in a ring
//!   buffer, states unknown / free / occupied ([`VoxelState`]), and a truncated signed distance
//!   field kept exact incrementally: after each scan only the box of the voxels that flipped,
//!   grown by the truncation distance, is recomputed.
//! * To the planner: [`LocalMap::to_static_map`] (through `Esdf::from_signed_distances`); the
//!   unknown-space policy: unknown is free for planning, but what the vehicle commits to must
//!   pass [`LocalMap::segment_known_free`] (FASTER's rule), or with the vehicle's body counted
//!   free point by point, [`LocalMap::segment_known_free_beside`] ([`BodyBall`]).
//!
//! Use it to fly the planner on what it could sense instead of the true map, or to test a
//! perception-dependent part (the safety check, the route) against partial knowledge. The paper
//! (Sec. IV) gives the planner the map; this crate is beyond it (issue 34). Sources of every
//! default and the policy in full: `docs/sensing.md`.
//!
//! ```
//! use rand::SeedableRng;
//! use trust_geometry::{Aabb, AaBox, StaticMap, Vec3};
//! use trust_sensing::{
//!     DepthCamera, DepthCameraParams, LocalMap, LocalMapParams, Pose, RaySensor, Scan, Truth,
//! };
//!
//! // A wall 4 m ahead of a camera at (1, 5, 2) looking along +x.
//! let bounds = Aabb::new(Vec3::zeros(), Vec3::new(10.0, 10.0, 4.0))?;
//! let wall = AaBox::new(Vec3::new(5.0, 0.0, 0.0), Vec3::new(5.5, 10.0, 4.0))?;
//! let world = StaticMap::from_shapes(bounds, vec![wall.into()])?;
//! let camera = DepthCamera::new(DepthCameraParams::default())?;
//! let pose = Pose::at(Vec3::new(1.0, 5.0, 2.0));
//! let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
//! let mut scan = Scan::default();
//! camera.scan(&pose, &Truth::static_only(&world), &mut rng, &mut scan)?;
//!
//! let mut map = LocalMap::new(LocalMapParams::default(), &pose.position)?;
//! map.insert_scan(&scan)?;
//! assert!(map.is_known_free(&Vec3::new(3.0, 5.0, 2.0)));
//! assert!(map.segment_known_free(&Vec3::new(2.0, 5.0, 2.0), &Vec3::new(4.0, 5.0, 2.0), 0.1));
//! assert!(!map.segment_known_free(&pose.position, &Vec3::new(6.0, 5.0, 2.0), 0.0)); // the wall
//! let d = map.distance(&Vec3::new(4.5, 5.0, 2.0)).unwrap();
//! assert!((d - 0.5).abs() < 0.2, "{d}");
//! // The planner's view: a StaticMap whose ESDF holds the sensed wall.
//! let planner_map = map.to_static_map(bounds)?;
//! assert!(!planner_map.segment_clear(&pose.position, &Vec3::new(7.0, 5.0, 2.0), 0.0));
//! # Ok::<(), Box<dyn std::error::Error>>(())
//! ```
#![warn(missing_docs)]

mod body;
mod camera;
mod distance;
mod error;
mod lidar;
mod map;
mod memory;
mod occupancy;
mod pose;
mod projective;
mod recall;
mod ring;
mod scan;
mod sensor;
mod traversal;
mod truth;

pub use body::BodyBall;
pub use camera::{DepthCamera, DepthCameraParams};
pub use error::SensingError;
pub use lidar::{Lidar, LidarParams};
pub use map::{LocalMap, LocalMapParams, MAX_WINDOW_VOXELS, ScanUpdate};
pub use memory::{DEFAULT_MEMORY_CELL_M, MAX_MEMORY_CELLS, MapMemory, Unseen};
pub use occupancy::{LogOddsParams, VoxelState, logit};
pub use pose::Pose;
pub use recall::{RECALL_BLOCK, SUGGESTED_RECALL_BLOCKS};
pub use scan::{RayMeasurement, ReturnKind, Scan};
pub use sensor::RaySensor;
pub use traversal::{VoxelKey, VoxelTraversal, voxel_key};
pub use truth::Truth;
