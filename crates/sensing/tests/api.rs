//! The public API of trust-sensing: sensors against known geometry, the occupancy update, the
//! rolling window, the incremental distance field against a brute-force one, degenerate input
//! and determinism.

use approx::assert_abs_diff_eq;
use nalgebra::UnitQuaternion;
use proptest::prelude::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, Sphere, StaticMap, Vec3};
use trust_sensing::{
    DepthCamera, DepthCameraParams, Lidar, LidarParams, LocalMap, LocalMapParams, LogOddsParams,
    Pose, RayMeasurement, RaySensor, ReturnKind, SUGGESTED_RECALL_BLOCKS, Scan, SensingError,
    Truth, VoxelState, logit,
};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn bounds() -> Aabb {
    Aabb::new(v(-20.0, -20.0, -5.0), v(20.0, 20.0, 10.0)).unwrap()
}

/// A wall filling the camera's view: the face x = `x`.
fn wall_at(x: f64) -> StaticMap {
    let wall = AaBox::new(v(x, -100.0, -100.0), v(x + 1.0, 100.0, 100.0)).unwrap();
    StaticMap::from_shapes(bounds(), vec![wall.into()]).unwrap()
}

fn rng(seed: u64) -> ChaCha8Rng {
    ChaCha8Rng::seed_from_u64(seed)
}

fn camera(noise_k: f64) -> DepthCamera {
    DepthCamera::new(DepthCameraParams {
        noise_k_per_m: noise_k,
        ..DepthCameraParams::default()
    })
    .unwrap()
}

#[test]
fn camera_sees_a_wall_at_its_depth() {
    let map = wall_at(4.0);
    let pose = Pose::at(v(1.0, 0.0, 0.0));
    let mut scan = Scan::default();
    // Noise off: every pixel hits at depth 3 exactly.
    let cam = camera(0.0);
    cam.scan(&pose, &Truth::static_only(&map), &mut rng(1), &mut scan)
        .unwrap();
    assert_eq!(scan.rays.len(), 160 * 120);
    assert_eq!(scan.count(ReturnKind::Hit), 160 * 120);
    for d in cam.depth_image(&scan) {
        assert_abs_diff_eq!(d, 3.0, epsilon = 1e-9);
    }
    for p in scan.points() {
        assert_abs_diff_eq!(p.x, 4.0, epsilon = 1e-9);
    }
    // With noise: within 5 σ of 3 m, σ = k z², and not all equal.
    let k = DepthCameraParams::default().noise_k_per_m;
    let cam = camera(k);
    cam.scan(&pose, &Truth::static_only(&map), &mut rng(1), &mut scan)
        .unwrap();
    let depths = cam.depth_image(&scan);
    let sigma = k * 9.0;
    assert!(depths.iter().all(|d| (d - 3.0).abs() < 5.0 * sigma));
    let mean = depths.iter().sum::<f64>() / depths.len() as f64;
    let sd = (depths.iter().map(|d| (d - mean).powi(2)).sum::<f64>() / depths.len() as f64).sqrt();
    assert!((sd - sigma).abs() < 0.05 * sigma, "sd {sd}, σ {sigma}");
    assert!((mean - 3.0).abs() < 0.01 * sigma * 10.0);
}

#[test]
fn camera_geometry_follows_the_attitude_and_the_field_of_view() {
    let cam = camera(0.0);
    let p = DepthCameraParams::default();
    // Corner pixel rays open at (almost) half the field of view.
    let d = cam.pixel_direction(0, 0).unwrap();
    let half_h = (d.y / d.x).atan();
    let half_v = (d.z / d.x).atan();
    let px_h = p.hfov_rad / 160.0;
    let px_v = p.vfov_rad / 120.0;
    assert!((half_h - 0.5 * p.hfov_rad).abs() < px_h, "{half_h}");
    assert!((half_v - 0.5 * p.vfov_rad).abs() < px_v, "{half_v}");
    assert!(cam.pixel_direction(160, 0).is_none());
    // Yawed by 90°: the camera looks along +y and sees a wall at y = 3 at depth 3.
    let wall = AaBox::new(v(-100.0, 3.0, -100.0), v(100.0, 4.0, 100.0)).unwrap();
    let map = StaticMap::from_shapes(bounds(), vec![wall.into()]).unwrap();
    let mut scan = Scan::default();
    let pose = Pose::level(Vec3::zeros(), std::f64::consts::FRAC_PI_2);
    cam.scan(&pose, &Truth::static_only(&map), &mut rng(0), &mut scan)
        .unwrap();
    assert!(
        cam.depth_image(&scan)
            .iter()
            .all(|d| (d - 3.0).abs() < 1e-9)
    );
}

#[test]
fn moving_obstacles_and_range_limits() {
    let map = wall_at(8.0);
    let cam = camera(0.0);
    let pose = Pose::at(Vec3::zeros());
    let person: Shape = Cylinder::new(v(2.0, 0.0, 0.0), 0.3, 1.0).unwrap().into();
    let moving = [person];
    let truth = Truth {
        map: &map,
        moving: &moving,
    };
    let mut scan = Scan::default();
    cam.scan(&pose, &truth, &mut rng(0), &mut scan).unwrap();
    // The centre pixel sees the person's front at 1.7 m; a corner pixel the wall at 8 m.
    let depth = cam.depth_image(&scan);
    assert_abs_diff_eq!(depth[60 * 160 + 80], 1.7, epsilon = 0.01);
    assert_abs_diff_eq!(depth[0], 8.0, epsilon = 1e-9);
    // Beyond 10 m nothing returns; closer than 0.3 m is invalid.
    let far = wall_at(12.0);
    cam.scan(&pose, &Truth::static_only(&far), &mut rng(0), &mut scan)
        .unwrap();
    assert_eq!(scan.count(ReturnKind::NoReturn), 160 * 120);
    let near = wall_at(0.2);
    cam.scan(&pose, &Truth::static_only(&near), &mut rng(0), &mut scan)
        .unwrap();
    assert_eq!(scan.count(ReturnKind::Invalid), 160 * 120);
}

#[test]
fn lidar_rings_hit_the_floor_where_trigonometry_says() {
    let floor = AaBox::new(v(-200.0, -200.0, -1.0), v(200.0, 200.0, 0.0)).unwrap();
    let map = StaticMap::from_shapes(bounds(), vec![floor.into()]).unwrap();
    let params = LidarParams {
        columns: 360,
        noise_sigma_m: 0.0,
        ..LidarParams::vlp16()
    };
    let lidar = Lidar::new(params).unwrap();
    let h = 1.5;
    let mut scan = Scan::default();
    lidar
        .scan(
            &Pose::at(v(0.0, 0.0, h)),
            &Truth::static_only(&map),
            &mut rng(0),
            &mut scan,
        )
        .unwrap();
    assert_eq!(scan.rays.len(), 16 * 360);
    for (i, ray) in scan.rays.iter().enumerate() {
        let (j, c) = (i / 16, i % 16);
        let el = params.elevation(c);
        let az = std::f64::consts::TAU * j as f64 / 360.0;
        assert_abs_diff_eq!(ray.direction.z, el.sin(), epsilon = 1e-12);
        assert_abs_diff_eq!(
            ray.direction
                .y
                .atan2(ray.direction.x)
                .rem_euclid(std::f64::consts::TAU),
            az,
            epsilon = 1e-9
        );
        if el < 0.0 {
            assert_eq!(ray.kind, ReturnKind::Hit, "channel {c}");
            assert_abs_diff_eq!(ray.range, h / (-el).sin(), epsilon = 1e-9);
        } else {
            assert_eq!(ray.kind, ReturnKind::NoReturn, "channel {c}");
            assert_eq!(ray.range, 100.0);
        }
    }
    // 2° between channels, ±15°.
    assert_abs_diff_eq!(
        params.elevation(1) - params.elevation(0),
        2f64.to_radians(),
        epsilon = 1e-12
    );
    assert_abs_diff_eq!(params.elevation(15), 15f64.to_radians(), epsilon = 1e-12);
}

#[test]
fn scans_are_deterministic_for_a_seed() {
    let map = StaticMap::from_shapes(
        bounds(),
        vec![
            Sphere::new(v(4.0, 0.5, 0.0), 1.0).unwrap().into(),
            AaBox::new(v(6.0, -5.0, -2.0), v(7.0, 5.0, 3.0))
                .unwrap()
                .into(),
        ],
    )
    .unwrap();
    let truth = Truth::static_only(&map);
    let pose = Pose::new(
        v(0.0, 0.0, 0.5),
        UnitQuaternion::from_euler_angles(0.1, -0.05, 0.2),
    );
    let sensors: Vec<Box<dyn RaySensor>> = vec![
        Box::new(camera(0.0036)),
        Box::new(
            Lidar::new(LidarParams {
                columns: 200,
                ..LidarParams::vlp16()
            })
            .unwrap(),
        ),
    ];
    for s in &sensors {
        let (mut a, mut b, mut c) = (Scan::default(), Scan::default(), Scan::default());
        s.scan(&pose, &truth, &mut rng(42), &mut a).unwrap();
        s.scan(&pose, &truth, &mut rng(42), &mut b).unwrap();
        s.scan(&pose, &truth, &mut rng(43), &mut c).unwrap();
        assert_eq!(a, b, "{}", s.name());
        assert_ne!(a, c, "{}", s.name());
        assert!(a.rays.iter().all(|r| r.range.is_finite()));
    }
}

#[test]
fn degenerate_input_gives_typed_errors_or_defined_answers() {
    let map = wall_at(4.0);
    let cam = camera(0.0);
    let mut scan = Scan::default();
    let e = cam
        .scan(
            &Pose::at(v(f64::NAN, 0.0, 0.0)),
            &Truth::static_only(&map),
            &mut rng(0),
            &mut scan,
        )
        .unwrap_err();
    assert_eq!(e.to_string(), "pose.position.x must be finite, got NaN");
    let bad = Pose::new(
        Vec3::zeros(),
        UnitQuaternion::new_unchecked(nalgebra::Quaternion::new(2.0, 0.0, 0.0, 0.0)),
    );
    let e = cam
        .scan(&bad, &Truth::static_only(&map), &mut rng(0), &mut scan)
        .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("pose.attitude.norm = 2 is out of range"),
        "{e}"
    );
    // Parameters.
    let e = DepthCamera::new(DepthCameraParams {
        width: 0,
        ..DepthCameraParams::default()
    })
    .unwrap_err();
    assert_eq!(
        e.to_string(),
        "camera.width = 0 is out of range; expected in 1..=4096"
    );
    let e = DepthCamera::new(DepthCameraParams {
        max_depth_m: 0.1,
        ..DepthCameraParams::default()
    })
    .unwrap_err();
    assert!(
        matches!(e, SensingError::OutOfRange { ref field, .. } if field == "camera.max_depth_m"),
        "{e}"
    );
    let e = Lidar::new(LidarParams {
        max_range_m: f64::INFINITY,
        ..LidarParams::vlp16()
    })
    .unwrap_err();
    assert!(matches!(e, SensingError::NonFinite { .. }), "{e}");
    assert!(
        LocalMap::new(
            LocalMapParams {
                dims: [1, 10, 10],
                ..LocalMapParams::default()
            },
            &Vec3::zeros()
        )
        .is_err()
    );
    let e = LocalMap::new(
        LocalMapParams {
            max_distance_m: 0.0,
            ..LocalMapParams::default()
        },
        &Vec3::zeros(),
    )
    .unwrap_err();
    assert!(
        e.to_string()
            .starts_with("map.max_distance_m = 0 is out of range"),
        "{e}"
    );
    let e = LocalMap::new(LocalMapParams::default(), &v(0.0, f64::INFINITY, 0.0)).unwrap_err();
    assert_eq!(e.to_string(), "center.y must be finite, got inf");
    // Sensor inside an obstacle: every ray hits at 0 (invalid for the camera, closer than its
    // minimum; a hit at 0 for a LiDAR without a minimum range).
    let inside = Pose::at(v(4.5, 0.0, 0.0));
    cam.scan(&inside, &Truth::static_only(&map), &mut rng(0), &mut scan)
        .unwrap();
    assert_eq!(scan.count(ReturnKind::Invalid), scan.rays.len());
    let lidar = Lidar::new(LidarParams {
        min_range_m: 0.0,
        columns: 10,
        noise_sigma_m: 0.0,
        ..LidarParams::vlp16()
    })
    .unwrap();
    lidar
        .scan(&inside, &Truth::static_only(&map), &mut rng(0), &mut scan)
        .unwrap();
    assert!(
        scan.rays
            .iter()
            .all(|r| r.kind == ReturnKind::Hit && r.range == 0.0)
    );
    // An empty world: nothing returns; the map clears the frustum and has no obstacle.
    let empty = StaticMap::new(bounds()).unwrap();
    cam.scan(
        &Pose::at(Vec3::zeros()),
        &Truth::static_only(&empty),
        &mut rng(0),
        &mut scan,
    )
    .unwrap();
    assert_eq!(scan.count(ReturnKind::NoReturn), scan.rays.len());
    let mut local = LocalMap::new(LocalMapParams::default(), &Vec3::zeros()).unwrap();
    local.insert_scan(&scan).unwrap();
    assert_eq!(local.occupied_count(), 0);
    assert!(local.is_known_free(&v(3.0, 0.0, 0.0)));
    assert_eq!(local.distance(&v(3.0, 0.0, 0.0)), Some(1.0));
    assert!(local.to_static_map(bounds()).unwrap().has_no_obstacles());
    // Scans with bad rays are rejected, naming the ray, and change nothing.
    let ray = |direction, range| RayMeasurement {
        direction,
        range,
        kind: ReturnKind::Hit,
    };
    let bad_scan = Scan {
        origin: Vec3::zeros(),
        rays: vec![ray(v(1.0, 0.0, 0.0), 1.0), ray(v(2.0, 0.0, 0.0), 1.0)],
    };
    let e = local.integrate_scan(&bad_scan).unwrap_err();
    assert!(e.to_string().starts_with("scan.rays[1].direction"), "{e}");
    let bad_scan = Scan {
        origin: Vec3::zeros(),
        rays: vec![ray(v(1.0, 0.0, 0.0), f64::NAN)],
    };
    let e = local.integrate_scan(&bad_scan).unwrap_err();
    assert_eq!(e.to_string(), "scan.rays[0].range must be finite, got NaN");
    assert_eq!(local.occupied_count(), 0);
    // A zero-range hit marks the sensor's own voxel occupied.
    let zero = Scan {
        origin: v(0.05, 0.05, 0.05),
        rays: vec![ray(v(1.0, 0.0, 0.0), 0.0)],
    };
    local.insert_scan(&zero).unwrap();
    assert_eq!(local.state(&v(0.05, 0.05, 0.05)), VoxelState::Occupied);
    // Queries with non-finite input answer "unknown" / "not free" / none.
    assert_eq!(local.state(&v(f64::NAN, 0.0, 0.0)), VoxelState::Unknown);
    assert!(!local.segment_known_free(&v(f64::NAN, 0.0, 0.0), &Vec3::zeros(), 0.0));
    assert!(!local.segment_known_free(&v(1.0, 0.0, 0.0), &v(2.0, 0.0, 0.0), f64::NAN));
    assert_eq!(local.distance(&v(0.0, f64::INFINITY, 0.0)), None);
}

/// A scan from `origin` with one ray per end point (a hit there).
fn scan_to(origin: Vec3, ends: &[Vec3]) -> Scan {
    Scan {
        origin,
        rays: ends
            .iter()
            .map(|e| {
                let d = e - origin;
                RayMeasurement {
                    direction: d.normalize(),
                    range: d.norm(),
                    kind: ReturnKind::Hit,
                }
            })
            .collect(),
    }
}

#[test]
fn log_odds_update_and_clamp() {
    let lo = LogOddsParams::default();
    assert_abs_diff_eq!(lo.hit, 0.847_297_860_387_203_8, epsilon = 1e-12);
    assert_abs_diff_eq!(lo.miss, logit(0.4), epsilon = 1e-15);
    let mut map = LocalMap::new(LocalMapParams::default(), &Vec3::zeros()).unwrap();
    let o = v(0.05, 0.05, 0.05);
    let target = v(1.05, 0.05, 0.05);
    let between = v(0.55, 0.05, 0.05);
    for i in 0..20 {
        map.insert_scan(&scan_to(o, &[target])).unwrap();
        let expected = (lo.hit * (i + 1) as f64).min(lo.clamp_max);
        assert_abs_diff_eq!(map.log_odds(&target).unwrap(), expected, epsilon = 1e-5);
        let expected = (lo.miss * (i + 1) as f64).max(lo.clamp_min);
        assert_abs_diff_eq!(map.log_odds(&between).unwrap(), expected, epsilon = 1e-5);
    }
    assert_eq!(map.state(&target), VoxelState::Occupied);
    // From the upper clamp, 3.511 / 0.405 → 9 misses to flip to free.
    let beyond = v(2.05, 0.05, 0.05);
    let mut misses = 0;
    while map.state(&target) == VoxelState::Occupied {
        map.insert_scan(&scan_to(o, &[beyond])).unwrap();
        misses += 1;
    }
    assert_eq!(misses, (lo.clamp_max / -lo.miss).floor() as usize + 1);
    assert_eq!(map.state(&target), VoxelState::Free);
    // Two rays ending in one voxel update it once; a ray passing a voxel another ray ends in
    // does not count as a miss there (hits win).
    let mut map = LocalMap::new(LocalMapParams::default(), &Vec3::zeros()).unwrap();
    let u = map
        .insert_scan(&scan_to(o, &[target, v(1.06, 0.06, 0.06), beyond]))
        .unwrap();
    assert_abs_diff_eq!(map.log_odds(&target).unwrap(), lo.hit, epsilon = 1e-6);
    assert_eq!(u.ray_count, 3);
    assert_eq!(map.state(&v(3.0, 0.05, 0.05)), VoxelState::Unknown);
}

#[test]
fn rolling_window_keeps_what_stays_and_forgets_what_leaves() {
    let params = LocalMapParams {
        dims: [40, 40, 20],
        ..LocalMapParams::default()
    };
    // Without the recall (`rolling_window_recalls_what_left_it` has it).
    let mut map = LocalMap::new(params, &Vec3::zeros())
        .unwrap()
        .with_recall_blocks(0);
    let o = v(0.05, 0.05, 0.05);
    let a = v(1.05, 0.05, 0.05);
    let b = v(-1.55, 0.05, 0.05);
    for _ in 0..3 {
        map.insert_scan(&scan_to(o, &[a, b])).unwrap();
    }
    assert_eq!(map.state(&a), VoxelState::Occupied);
    assert_eq!(map.state(&b), VoxelState::Occupied);
    let before = map.distance(&v(1.35, 0.05, 0.05)).unwrap();
    assert_abs_diff_eq!(before, 0.3, epsilon = 1e-9);
    // Move 0.6 m along +x: the window is [-1.4, 2.6) in x; a stays, b (at -1.55) leaves.
    map.recentre(&v(0.65, 0.05, 0.05)).unwrap();
    assert_abs_diff_eq!(map.window().min.x, -1.4, epsilon = 1e-12);
    assert_eq!(map.state(&a), VoxelState::Occupied);
    assert_eq!(map.state(&b), VoxelState::Unknown);
    assert!(map.is_known_free(&v(0.55, 0.05, 0.05)));
    assert_eq!(map.distance(&v(1.35, 0.05, 0.05)), Some(before));
    assert_eq!(map.occupied_count(), 1);
    assert_eq!(map.distance_slots(), map.recompute_distance_from_scratch());
    // Back again: b's slot was reused for the far side and comes back unknown.
    map.recentre(&Vec3::zeros()).unwrap();
    assert_eq!(map.state(&b), VoxelState::Unknown);
    assert_eq!(map.state(&a), VoxelState::Occupied);
    assert_eq!(map.distance_slots(), map.recompute_distance_from_scratch());
    // A jump beyond the window forgets everything.
    map.recentre(&v(50.0, 0.0, 0.0)).unwrap();
    assert_eq!(map.occupied_count(), 0);
    map.recentre(&Vec3::zeros()).unwrap();
    assert_eq!(map.state(&a), VoxelState::Unknown);
}

/// Every voxel of the window: its centre, state and log-odds.
fn window_states(map: &LocalMap) -> Vec<(Vec3, VoxelState, Option<f64>)> {
    let res = map.params().resolution_m;
    let w = map.window();
    let n = map.params().dims;
    let mut out = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let c = w.min + res * v(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5);
                out.push((c, map.state(&c), map.log_odds(&c)));
            }
        }
    }
    out
}

#[test]
fn rolling_window_recalls_what_left_it() {
    let params = LocalMapParams {
        dims: [40, 40, 20],
        ..LocalMapParams::default()
    };
    let mut map = LocalMap::new(params, &Vec3::zeros())
        .unwrap()
        .with_recall_blocks(SUGGESTED_RECALL_BLOCKS);
    let o = v(0.05, 0.05, 0.05);
    let (a, b) = (v(1.05, 0.05, 0.05), v(-1.55, 0.05, 0.05));
    for _ in 0..3 {
        map.insert_scan(&scan_to(o, &[a, b])).unwrap();
    }
    let before = window_states(&map);
    let field = map.distance_slots().to_vec();
    // b leaves the window and comes back occupied, the field with it.
    map.recentre(&v(0.65, 0.05, 0.05)).unwrap();
    assert_eq!(map.state(&b), VoxelState::Unknown);
    assert!(map.recall_block_count() > 0);
    map.recentre(&Vec3::zeros()).unwrap();
    assert_eq!(map.state(&b), VoxelState::Occupied);
    assert_eq!(window_states(&map), before);
    assert_eq!(map.distance_slots(), &field[..]);
    assert_eq!(
        map.distance_slots(),
        &map.recompute_distance_from_scratch()[..]
    );
    // A jump beyond the window and back, too.
    map.recentre(&v(50.0, 0.0, 0.0)).unwrap();
    assert_eq!(map.occupied_count(), 0);
    map.recentre(&Vec3::zeros()).unwrap();
    assert_eq!(window_states(&map), before);
    assert_eq!(map.distance_slots(), &field[..]);
    // A bounded recall forgets (unknown), and never invents: one block is not enough for the
    // scan's free voxels.
    let mut small = LocalMap::new(params, &Vec3::zeros())
        .unwrap()
        .with_recall_blocks(1);
    for _ in 0..3 {
        small.insert_scan(&scan_to(o, &[a, b])).unwrap();
    }
    small.recentre(&v(50.0, 0.0, 0.0)).unwrap();
    assert_eq!(small.recall_block_count(), 1);
    small.recentre(&Vec3::zeros()).unwrap();
    let after = window_states(&small);
    assert!(after.iter().any(|x| {
        x.1 == VoxelState::Unknown
            && before
                .iter()
                .any(|y| y.0 == x.0 && y.1 != VoxelState::Unknown)
    }));
    for (x, y) in after.iter().zip(&before) {
        assert!(x.1 == VoxelState::Unknown || x == y, "{x:?} vs {y:?}");
    }
    assert_eq!(
        small.distance_slots(),
        &small.recompute_distance_from_scratch()[..]
    );
}

#[test]
fn unknown_space_policy() {
    // A wall at 4 m: free before it, occupied at it, unknown behind it.
    let world = wall_at(4.0);
    let cam = camera(0.0);
    let pose = Pose::at(v(0.05, 0.05, 0.05));
    let mut scan = Scan::default();
    cam.scan(&pose, &Truth::static_only(&world), &mut rng(0), &mut scan)
        .unwrap();
    let mut map = LocalMap::new(LocalMapParams::default(), &pose.position).unwrap();
    map.insert_scan(&scan).unwrap();
    assert_eq!(map.state(&v(2.0, 0.05, 0.05)), VoxelState::Free);
    assert_eq!(map.state(&v(4.05, 0.05, 0.05)), VoxelState::Occupied);
    assert_eq!(map.state(&v(4.55, 0.05, 0.05)), VoxelState::Unknown);
    assert_eq!(map.state(&v(-1.0, 0.05, 0.05)), VoxelState::Unknown);
    // With a clearance the start must be away from the unknown space behind the camera.
    assert!(map.segment_known_free(&v(1.0, 0.05, 0.05), &v(3.0, 0.3, 0.2), 0.2));
    assert!(!map.segment_known_free(&pose.position, &v(3.0, 0.3, 0.2), 0.2));
    // Into the wall, behind the camera (unknown), too close to the wall with a clearance.
    assert!(!map.segment_known_free(&pose.position, &v(4.55, 0.05, 0.05), 0.0));
    assert!(!map.segment_known_free(&pose.position, &v(-1.0, 0.05, 0.05), 0.0));
    assert!(map.segment_known_free(&pose.position, &v(3.75, 0.05, 0.05), 0.0));
    assert!(!map.segment_known_free(&pose.position, &v(3.75, 0.05, 0.05), 0.3));
    // The planner's map: the wall is an obstacle, unknown space is not.
    let planner = map.to_static_map(bounds()).unwrap();
    assert!(!planner.segment_clear(&pose.position, &v(6.0, 0.05, 0.05), 0.0));
    assert!(planner.segment_clear(&pose.position, &v(-3.0, 0.05, 0.05), 0.5));
    for x in [2.0, 3.0, 3.5] {
        let p = v(x + 0.05, 0.05, 0.05);
        assert_abs_diff_eq!(
            planner.signed_distance(&p),
            map.distance(&p).unwrap(),
            epsilon = 1e-9
        );
    }
    // The distance field's gradient points away from the wall.
    let (_, g) = map.distance_and_gradient(&v(3.5, 0.07, 0.02)).unwrap();
    assert!(g.x < -0.9, "{g}");
}

/// Brute-force signed distance per voxel of the window, in the field's convention.
fn brute_force_field(map: &LocalMap) -> Vec<(Vec3, f64)> {
    let p = map.params();
    let res = p.resolution_m;
    let r = (p.max_distance_m / res - 1e-9).ceil();
    let w = map.window();
    let n = p.dims;
    let key = |i: usize, j: usize, k: usize| [i as i64, j as i64, k as i64];
    let center =
        |q: [i64; 3]| w.min + res * v(q[0] as f64 + 0.5, q[1] as f64 + 0.5, q[2] as f64 + 0.5);
    let mut occ = Vec::new();
    let mut free = Vec::new();
    let mut all = Vec::new();
    for k in 0..n[2] {
        for j in 0..n[1] {
            for i in 0..n[0] {
                let q = key(i, j, k);
                let c = center(q);
                if map.state(&c) == VoxelState::Occupied {
                    occ.push(q)
                } else {
                    free.push(q)
                }
                all.push(q);
            }
        }
    }
    let d2 = |a: [i64; 3], b: [i64; 3]| ((0..3).map(|i| (a[i] - b[i]).pow(2)).sum::<i64>()) as f64;
    all.iter()
        .map(|&q| {
            let d_occ = occ.iter().map(|&s| d2(q, s)).fold(f64::INFINITY, f64::min);
            let shell = (0..3)
                .map(|i| (q[i] + 1).min(n[i] as i64 - q[i]).pow(2) as f64)
                .fold(f64::INFINITY, f64::min);
            let d_free = free.iter().map(|&s| d2(q, s)).fold(shell, f64::min);
            (
                center(q),
                res * (d_occ.sqrt().min(r) - d_free.sqrt().min(r)),
            )
        })
        .collect()
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, ..ProptestConfig::default() })]

    /// After every scan and every move of the window, the incremental field equals a brute-force
    /// recomputation at every voxel centre.
    #[test]
    fn incremental_field_equals_brute_force(seed in any::<u64>(), stop_at_visited in any::<bool>()) {
        let params = LocalMapParams {
            resolution_m: 0.25,
            dims: [12, 10, 8],
            max_distance_m: 0.7,
            stop_at_visited,
            ..LocalMapParams::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let mut center = v(0.1, -0.2, 0.3);
        let mut map = LocalMap::new(params, &center).unwrap().with_recall_blocks(SUGGESTED_RECALL_BLOCKS);
        for step in 0..6 {
            if step % 2 == 1 {
                center += v(rng.random_range(-0.8..0.8), rng.random_range(-0.8..0.8), rng.random_range(-0.5..0.5));
                map.recentre(&center).unwrap();
            } else {
                let origin = center + v(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), rng.random_range(-0.3..0.3));
                let rays = (0..rng.random_range(1..40)).map(|_| {
                    let d = v(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                    let d = if d.norm() < 1e-3 { v(1.0, 0.0, 0.0) } else { d.normalize() };
                    let kind = match rng.random_range(0..10) { 0 => ReturnKind::NoReturn, 1 => ReturnKind::Invalid, _ => ReturnKind::Hit };
                    RayMeasurement { direction: d, range: rng.random_range(0.0..3.0), kind }
                }).collect();
                map.insert_scan(&Scan { origin, rays }).unwrap();
            }
            for (c, expected) in brute_force_field(&map) {
                let got = map.distance(&c).unwrap();
                prop_assert!((got - expected).abs() < 1e-9, "step {step} at {c:?}: {got} vs {expected}");
            }
        }
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 16, ..ProptestConfig::default() })]

    /// Scans, then an excursion of the window (no scans) ending where it started: every voxel
    /// comes back as it was, and the field with it.
    #[test]
    fn an_excursion_without_scans_changes_nothing(seed in any::<u64>()) {
        let params = LocalMapParams {
            resolution_m: 0.25,
            dims: [12, 10, 8],
            max_distance_m: 0.7,
            ..LocalMapParams::default()
        };
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let center = v(0.1, -0.2, 0.3);
        let mut map = LocalMap::new(params, &center).unwrap().with_recall_blocks(SUGGESTED_RECALL_BLOCKS);
        for _ in 0..3 {
            let origin = center + v(rng.random_range(-0.5..0.5), rng.random_range(-0.5..0.5), rng.random_range(-0.3..0.3));
            let rays = (0..rng.random_range(1..40)).map(|_| {
                let d = v(rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0), rng.random_range(-1.0..1.0));
                let d = if d.norm() < 1e-3 { v(1.0, 0.0, 0.0) } else { d.normalize() };
                let kind = if rng.random_range(0..10) == 0 { ReturnKind::NoReturn } else { ReturnKind::Hit };
                RayMeasurement { direction: d, range: rng.random_range(0.0..3.0), kind }
            }).collect();
            map.insert_scan(&Scan { origin, rays }).unwrap();
        }
        let before = window_states(&map);
        let field = map.distance_slots().to_vec();
        let mut at = center;
        for _ in 0..rng.random_range(1..6) {
            at += v(rng.random_range(-4.0..4.0), rng.random_range(-4.0..4.0), rng.random_range(-3.0..3.0));
            map.recentre(&at).unwrap();
            prop_assert_eq!(map.distance_slots(), &map.recompute_distance_from_scratch()[..]);
        }
        map.recentre(&center).unwrap();
        prop_assert_eq!(window_states(&map), before);
        prop_assert_eq!(map.distance_slots(), &field[..]);
    }
}

#[test]
fn params_deny_unknown_fields_and_round_trip() {
    let p = LocalMapParams::default();
    let json = serde_json::to_string(&p).unwrap();
    assert_eq!(serde_json::from_str::<LocalMapParams>(&json).unwrap(), p);
    let bad = json.replacen("{", "{\"voxel\":1,", 1);
    assert!(serde_json::from_str::<LocalMapParams>(&bad).is_err());
    let c = DepthCameraParams::default();
    let json = serde_json::to_string(&c).unwrap();
    assert_eq!(serde_json::from_str::<DepthCameraParams>(&json).unwrap(), c);
    assert_eq!((c.width, c.height), (160, 120));
    assert_eq!(DepthCameraParams::d435().width, 848);
}
