//! The scenario scale policy: the magnitudes and counts a scenario file may set.
//!
//! The planning crates accept the library-wide policy of `trust_core::scale` (coordinates within
//! ±1e6 m, speeds up to 1e4 m/s, …); a scenario is checked against tighter, drone-sized limits,
//! so that every value the file sets — and every parameter derived from it (the presets'
//! goal radius `1.5 v_max²/a_max`, the tracking margin `0.01 + 0.0015 a_max`, noisy
//! measurements `p + noise`) — stays inside the library's policy, and a file `trust-sim
//! validate` accepts can be flown. Each limit is reported on the field the file wrote.
//!
//! | what | accepted | constant |
//! |---|---|---|
//! | coordinates (bounds, regions, shapes, positions, start, goal, points, samples, curve centres and coefficients) | `|x| ≤ 1e5` m | [`MAX_COORD_M`] |
//! | sizes, distances, clearances, tolerances, margins | `≤ 1e5` m | [`MAX_SIZE_M`] |
//! | obstacle speeds and velocity components | `≤ 1e3` m/s | [`MAX_SPEED_M_S`] |
//! | obstacle acceleration bounds (random maneuvers) | `≤ 1e3` m/s² | [`MAX_OBSTACLE_ACCEL_M_S2`] |
//! | `vehicle.limits.v_max` | `[0.01, 100]` m/s | [`V_MAX_RANGE`] |
//! | `vehicle.limits.a_max` | `[0.1, 100]` m/s² | [`A_MAX_RANGE`] |
//! | `vehicle.radius_m` | `≤ 100` m | [`MAX_VEHICLE_RADIUS_M`] |
//! | `sensing.position_noise_m` | `≤ 1e3` m and `≤` the world's diagonal | [`MAX_NOISE_M`] |
//! | `sensing.warmup_s` | `≤ 3600` s | [`MAX_WARMUP_S`] |
//! | `traffic.fault_level` | `≤ 100` | [`MAX_FAULT_LEVEL`] |
//! | `sim.physics_dt_s` | `[1e-5, 0.1]` s | [`PHYSICS_DT_RANGE`] |
//! | `time_limit_s` | `≤ 86 400` s | [`MAX_TIME_LIMIT_S`] |
//! | a Fourier `period_s`, a maneuver's `mean_interval_s` | `≥ sim.physics_dt_s` | |
//! | a Fourier `phase_s` | `|φ| ≤ 1e7` s | |
//! | moving obstacles in all (explicit, random groups, generators) | `≤ 10 000` | [`MAX_OBSTACLE_COUNT`] |
//! | static shapes in all (explicit and E4's blocks, walls, pillars) | `≤ 10 000` | [`MAX_STATIC_SHAPE_COUNT`] |
//! | cloud points (inline, file, or sampled from shapes: counted before sampling) | `≤ 2e7` | [`MAX_CLOUD_POINTS`] |
//! | sampling lattice of `spacing_m` over the bounds | `≤ trust_geometry::MAX_VOXELS` | |
//! | samples of a track, harmonics of a Fourier list | `≤ 1e5`, `≤ 64` | [`crate::script::MAX_SAMPLES`], [`crate::script::MAX_HARMONICS`] |
//! | track files of all obstacles (each read once per obstacle naming it) | `≤ 64 MiB` and `≤ 1e6` samples in all | [`MAX_TRACK_BYTES_TOTAL`], [`MAX_TRACK_SAMPLES_TOTAL`] |
//! | random draws of `[mission] random` | `≤ 40 200`, and draws × static shapes `≤ 4e6` | [`MAX_ENDPOINT_WORK`] |
//! | placement work of random obstacles and E4's static shapes | `≤ 2e7` distance tests per world | [`MAX_PLACEMENT_WORK`] |
//!
//! Counts are checked before anything is allocated or drawn for them; files are read under the
//! caps of [`super::files`].

use trust_core::Aabb;
use trust_geometry::Shape;

use crate::problem::{Problems, fmt_count, fmt_num};

/// Largest coordinate magnitude (m).
pub const MAX_COORD_M: f64 = 1.0e5;
/// Largest size, distance, clearance, tolerance or margin (m).
pub const MAX_SIZE_M: f64 = 1.0e5;
/// Largest obstacle speed or velocity component (m/s).
pub const MAX_SPEED_M_S: f64 = 1.0e3;
/// Largest obstacle acceleration bound (m/s²).
pub const MAX_OBSTACLE_ACCEL_M_S2: f64 = 1.0e3;
/// Accepted `vehicle.limits.v_max` (m/s).
pub const V_MAX_RANGE: (f64, f64) = (0.01, 100.0);
/// Accepted `vehicle.limits.a_max` (m/s²).
pub const A_MAX_RANGE: (f64, f64) = (0.1, 100.0);
/// Largest `vehicle.radius_m` (m).
pub const MAX_VEHICLE_RADIUS_M: f64 = 100.0;
/// Largest `sensing.position_noise_m` (m); it must not exceed the world's diagonal either.
pub const MAX_NOISE_M: f64 = 1.0e3;
/// Largest `sensing.warmup_s` (s).
pub const MAX_WARMUP_S: f64 = 3600.0;
/// Largest `traffic.fault_level`.
pub const MAX_FAULT_LEVEL: f64 = 100.0;
/// Accepted `sim.physics_dt_s` (s).
pub const PHYSICS_DT_RANGE: (f64, f64) = (1.0e-5, 0.1);
/// Largest `time_limit_s` (s): a day.
pub const MAX_TIME_LIMIT_S: f64 = 86_400.0;
/// Largest absolute time offset (s) of a script.
pub const MAX_SCRIPT_TIME_S: f64 = 1.0e7;
/// Most moving obstacles in a world.
pub const MAX_OBSTACLE_COUNT: usize = 10_000;
/// Most static shapes in a world.
pub const MAX_STATIC_SHAPE_COUNT: usize = 10_000;
/// Most points of a cloud (480 MB of coordinates).
pub const MAX_CLOUD_POINTS: usize = 20_000_000;
/// Most bytes of track files read for one scenario, over all its obstacles (a file named by
/// several obstacles counts for each): four files at [`crate::files::MAX_TRACK_BYTES`].
pub const MAX_TRACK_BYTES_TOTAL: u64 = 64 << 20;
/// Most samples of all the tracks of one scenario: ten tracks at
/// [`crate::script::MAX_SAMPLES`] (56 MB of interpolants); without it, 10 000 obstacles naming
/// one 16 MiB track would read 160 GB and hold 10⁹ samples.
pub const MAX_TRACK_SAMPLES_TOTAL: usize = 1_000_000;
/// Most shape distance tests of the `[mission] random` draw (draws × static shapes).
pub const MAX_ENDPOINT_WORK: usize = 4_000_000;
/// Most distance tests of the placements of one world's random obstacles and E4 shapes.
pub const MAX_PLACEMENT_WORK: u64 = 20_000_000;

/// Upper bound on the points [`crate::sample_shapes`] makes of `shapes` at `spacing` over
/// `bounds`, computed without sampling: the lattice points of each shape's inflated box.
pub(crate) fn sampled_point_bound(shapes: &[Shape], bounds: &Aabb, spacing: f64) -> f64 {
    let h = spacing * 3f64.sqrt() / 2.0;
    shapes
        .iter()
        .map(|s| {
            let b = s.aabb().inflated(h);
            (0..3)
                .map(|k| {
                    let lo = b.min[k].max(bounds.min[k]);
                    let hi = b.max[k].min(bounds.max[k]);
                    if hi < lo {
                        0.0
                    } else {
                        ((hi - lo) / spacing).floor() + 1.0
                    }
                })
                .product::<f64>()
        })
        .sum()
}

/// Checks `count` (with a description of where it comes from) against [`MAX_CLOUD_POINTS`].
pub(crate) fn check_sampled_points(p: &mut Problems, field: &str, value: f64, count: f64) {
    if count > MAX_CLOUD_POINTS as f64 {
        p.push(
            field,
            fmt_num(value),
            format!(
                "a spacing giving at most {} sampled points (scale policy; this one gives up to \
                 {})",
                fmt_count(MAX_CLOUD_POINTS as u128),
                fmt_num(count.round())
            ),
        );
    }
}

/// The grid [`esdf_dims`] counts, for a message: `nx x ny x nz = total`, every count readable
/// ([`fmt_num`]) and as large as it is (not the placeholder `esdf_dims` clamps a huge count to).
pub(crate) fn fmt_grid(bounds: &Aabb, resolution: f64) -> String {
    let ext = bounds.extent();
    let n: Vec<f64> = (0..3)
        .map(|i| (ext[i] / resolution * (1.0 - 1e-12)).ceil().max(1.0))
        .collect();
    format!(
        "{} x {} x {} = {}",
        fmt_num(n[0]),
        fmt_num(n[1]),
        fmt_num(n[2]),
        fmt_num(n[0] * n[1] * n[2])
    )
}

/// Most voxels per axis [`esdf_dims`] reports: a larger count is reported as this one (far
/// beyond `MAX_VOXELS` either way), so that the product of three stays within `u128`
/// (`trust_geometry::checked_voxel_count` multiplies them unchecked; with the former
/// placeholder `usize::MAX / 4` it overflowed, a panic in debug builds).
const MAX_AXIS_VOXELS: usize = 1 << 40;

/// Voxels per axis of an ESDF of `resolution` over `bounds`, as `Esdf::from_points` computes
/// them (without allocating), each at most [`MAX_AXIS_VOXELS`].
pub(crate) fn esdf_dims(bounds: &Aabb, resolution: f64) -> [usize; 3] {
    let ext = bounds.extent();
    let mut dims = [0usize; 3];
    for i in 0..3 {
        let n = (ext[i] / resolution * (1.0 - 1e-12)).ceil().max(1.0);
        dims[i] = if n < MAX_AXIS_VOXELS as f64 {
            n as usize
        } else {
            MAX_AXIS_VOXELS
        };
    }
    dims
}
