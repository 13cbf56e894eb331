//! Worlds, true traffic and sensing: generators are deterministic per seed and keep their
//! promises (counts, bounds, clear start and goal); the planner's map never claims more room
//! than the truth gives beyond its stated error; obstacles stay in bounds and within their
//! maneuver bounds; forecasts track the truth and cover it within their `μ` at fault level 0.

use std::path::Path;

use rand::{Rng as _, SeedableRng};
use trust_core::{Rng, Vec3};
use trust_predict::EkfParams;
use trust_world::scenario::{PointCloudSpec, Scenario};
use trust_world::sensing::{Sensing, SensingParams};
use trust_world::traffic::{ManeuverParams, Motion, MovingObstacle, MovingShape, Traffic};
use trust_world::{PointTree, Seeds, World};

/// The presets' planning horizon `T_h` (s): `trust_manager::ManagerParams::horizon_s`.
const PRESET_HORIZON_S: f64 = 4.0;

fn scenario(text: &str) -> Scenario {
    Scenario::from_toml_str(text, Path::new("test.toml")).unwrap_or_else(|e| panic!("{e}"))
}

/// E4 at 0.5 m voxels (a debug build of the 0.2 m map takes too long for a unit test).
fn e4(seed: u64) -> Scenario {
    scenario(&format!(
        "name = \"e4\"\nseed = {seed}\n[world]\ngenerator = {{ kind = \"e4\" }}\n\
         [static.point_cloud]\nsource = \"shapes\"\nesdf_voxel_m = 0.5\n\
         [mission]\nstart = [2, 37.5, 5]\ngoal = [248, 37.5, 5]\n"
    ))
}

fn positions(w: &World) -> Vec<Vec3> {
    w.obstacles().iter().map(|o| o.position).collect()
}

#[test]
fn e4_worlds_keep_their_promises() {
    let a = World::build(&e4(3)).unwrap();
    let b = World::build(&e4(3)).unwrap();
    let c = World::build(&e4(4)).unwrap();
    // Deterministic per seed, different across seeds.
    assert_eq!(a.static_shapes(), b.static_shapes());
    assert_eq!(positions(&a), positions(&b));
    assert_ne!(a.static_shapes(), c.static_shapes());
    assert_ne!(positions(&a), positions(&c));
    for w in [&a, &c] {
        // Counts and bounds as documented: 40 blocks + 40 walls + 320 pillars, 100 movers.
        assert_eq!(w.static_shapes().len(), 400);
        assert_eq!(w.obstacles().len(), 100);
        let bounds = w.bounds();
        assert_eq!(bounds.max, Vec3::new(250.0, 75.0, 20.0));
        let mut ground = 0.0;
        for s in w.static_shapes() {
            let bb = s.aabb();
            assert!(bb.min.x >= 0.0 && bb.max.x <= 250.0 && bb.min.y >= 0.0 && bb.max.y <= 75.0);
            ground += match s {
                trust_geometry::Shape::Cylinder(c) => std::f64::consts::PI * c.radius * c.radius,
                _ => (bb.max.x - bb.min.x) * (bb.max.y - bb.min.y),
            };
        }
        let cover = ground / (250.0 * 75.0);
        assert!((0.07..0.12).contains(&cover), "ground cover {cover}");
        // Start and goal: 10 m from every static footprint (horizontally), clear of movers.
        for p in [w.start(), w.goal()] {
            assert!(w.true_static_clearance(&p) >= 10.0 - 1e-9);
            let (d, _) = w.traffic().unwrap().clearance(&p);
            assert!(d >= w.vehicle_radius_m() + 1.0, "{d}");
        }
        let spheres = w
            .obstacles()
            .iter()
            .filter(|o| matches!(o.shape, MovingShape::Sphere { .. }))
            .count();
        assert!((30..=70).contains(&spheres), "{spheres} spheres of 100");
        for o in w.obstacles() {
            assert_eq!(o.region.min.x, 10.0);
            assert_eq!(o.region.max.x, 240.0);
            let speed = o.velocity.norm();
            assert!((0.5 - 1e-12..=2.5 + 1e-12).contains(&speed));
            assert!(o.problems("o").is_empty());
            assert!(matches!(o.motion, Motion::RandomManeuvers(_)));
        }
        // The planner sees only the cloud; the truth is the shapes.
        let map = w.planner_map();
        assert!(map.shapes().is_empty());
        let esdf = map.esdf().expect("an ESDF");
        assert_eq!(esdf.dims(), [500, 150, 40]);
        assert!(w.stats().cloud_point_count > 100_000);
    }
}

#[test]
fn the_planners_cloud_map_is_conservative_within_its_stated_error() {
    // A small world with the E4 kinds of shapes, seen as a 0.2 m cloud.
    let s = scenario(
        "name = \"cloud\"\n[world]\nbounds = { min = [0, 0, 0], max = [20, 10, 6] }\n\
         [[static.shapes]]\nkind = \"cylinder\"\ncenter = [5, 5]\nradius = 0.8\nz_min = 0\nz_max = 6\n\
         [[static.shapes]]\nkind = \"box\"\nmin = [9, 2, 0]\nmax = [9.55, 8.3, 4.1]\n\
         [[static.shapes]]\nkind = \"box\"\nmin = [13, 3, 0]\nmax = [16.3, 6.7, 2.9]\n\
         [[static.shapes]]\nkind = \"sphere\"\ncenter = [17.5, 8, 3]\nradius = 1.1\n\
         [static.point_cloud]\nsource = \"shapes\"\nesdf_voxel_m = 0.2\n\
         [mission]\nstart = [1, 5, 3]\ngoal = [19, 2, 3]\n",
    );
    let w = World::build(&s).unwrap();
    let bound = w.static_map_error_m();
    assert!((bound - 0.2 * 3f64.sqrt()).abs() < 1e-12);
    let mut rng = Rng::seed_from_u64(11);
    let (mut worst, mut count) = (f64::NEG_INFINITY, 0);
    for _ in 0..20_000 {
        let p = Vec3::new(
            rng.random_range(0.0..20.0),
            rng.random_range(0.0..10.0),
            rng.random_range(0.0..6.0),
        );
        let truth = w.true_static_clearance(&p);
        if truth <= 0.0 {
            continue;
        }
        count += 1;
        worst = worst.max(w.planner_map().signed_distance(&p) - truth);
    }
    println!(
        "ESDF minus true distance over {count} free points: worst {worst:.4} m (bound {bound:.4} m)"
    );
    assert!(count > 10_000);
    assert!(
        worst <= bound,
        "the planner's map overestimates by {worst} m"
    );
}

#[test]
fn small_generators_are_deterministic_and_match_their_sources() {
    let e1 = |seed| {
        scenario(&format!(
            "name = \"e1\"\nseed = {seed}\n[world]\ngenerator = {{ kind = \"e1\", obstacle_count = 10 }}\n\
             [mission]\nstart = [1, 10, 5]\ngoal = [19, 10, 5]\n"
        ))
    };
    let a = World::build(&e1(1)).unwrap();
    assert_eq!(positions(&a), positions(&World::build(&e1(1)).unwrap()));
    assert_ne!(positions(&a), positions(&World::build(&e1(2)).unwrap()));
    assert_eq!(a.obstacles().len(), 10);
    assert_eq!(a.bounds().max, Vec3::new(20.0, 20.0, 10.0));
    for o in a.obstacles() {
        if let MovingShape::Cylinder { half_height, .. } = o.shape {
            assert_eq!(half_height, 5.0, "E1 cylinders are full height");
        }
        assert!((0.5..=3.0).contains(&o.velocity.norm()));
    }

    let e2 = |kind: &str| {
        World::build(&scenario(&format!(
            "name = \"e2\"\n[world]\ngenerator = {{ kind = \"{kind}\" }}\n\
             [mission]\nstart = [1, 10, 5]\ngoal = [49, 10, 5]\n"
        )))
        .unwrap()
    };
    let st = e2("e2-static");
    assert_eq!(
        st.static_shapes(),
        trust_scenes::e2::e2_static().map.shapes()
    );
    assert!(st.obstacles().is_empty());
    let dy = e2("e2-dynamic");
    let case = trust_scenes::e2::e2_dynamic();
    assert!(dy.static_shapes().is_empty());
    assert_eq!(dy.obstacles().len(), case.forecasts.len());
    for (o, f) in dy.obstacles().iter().zip(&case.forecasts) {
        assert_eq!(
            (o.position, o.velocity, o.shape.radius()),
            (f.p0, f.v0, f.r_o)
        );
    }

    let e3 = World::build(
        &Scenario::<toml::Table>::load(Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../scenarios/e3.toml"
        )))
        .unwrap(),
    )
    .unwrap();
    assert_eq!(e3.obstacles().len(), 10);
    for o in e3.obstacles() {
        assert_eq!((o.region.min.x, o.region.max.x), (5.0, 45.0));
    }
    // r_des = |p_s − p_g| − T_h·v_max = 65 − 4·10 = 25 m (Fig. Sim-A-1-1(a)).
    let r_des = (e3.goal() - e3.start()).norm() - PRESET_HORIZON_S * e3.limits().v_max;
    assert!((r_des - 25.0).abs() < 1e-9);
}

#[test]
fn file_clouds_are_truth_and_seen_as_an_esdf() {
    let dir = std::env::temp_dir().join(format!("trust-sim-world-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let mut text = String::from("# a wall of points at x = 10\n");
    for iy in 0..=20 {
        for iz in 0..=10 {
            text.push_str(&format!(
                "10 {} {}\n",
                2.0 + 0.3 * iy as f64,
                0.5 * iz as f64
            ));
        }
    }
    std::fs::write(dir.join("wall.xyz"), text).unwrap();
    let path = dir.join("cloud.toml");
    std::fs::write(
        &path,
        "name = \"cloud\"\n[world]\nbounds = { min = [0, 0, 0], max = [20, 10, 6] }\n\
         [static.point_cloud]\nsource = \"file\"\npath = \"wall.xyz\"\nesdf_voxel_m = 0.25\n\
         [mission]\nstart = [1, 5, 3]\ngoal = [19, 5, 3]\n",
    )
    .unwrap();
    let w = World::build(&Scenario::<toml::Table>::load(&path).unwrap()).unwrap();
    assert_eq!(w.static_points_file(), Some(dir.join("wall.xyz").as_path()));
    assert_eq!(w.static_points().unwrap().len(), 21 * 11);
    // Truth: the distance to the nearest point.
    let p = Vec3::new(8.0, 5.0, 2.0);
    assert!((w.true_static_clearance(&p) - 2.0).abs() < 1e-12);
    // The planner sees the points through its ESDF, not farther than they are (within the bound).
    let seen = w.planner_map().signed_distance(&p);
    assert!(seen <= 2.0 + w.static_map_error_m(), "{seen}");
    assert!(w.planner_map().esdf().is_some());
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn point_tree_answers_at_physics_rate_sizes() {
    let mut rng = Rng::seed_from_u64(5);
    let pts: Vec<Vec3> = (0..50_000)
        .map(|_| {
            Vec3::new(
                rng.random_range(0.0..250.0),
                rng.random_range(0.0..75.0),
                rng.random_range(0.0..20.0),
            )
        })
        .collect();
    let tree = PointTree::new(pts.clone());
    for _ in 0..50 {
        let q = Vec3::new(
            rng.random_range(0.0..250.0),
            rng.random_range(0.0..75.0),
            rng.random_range(0.0..20.0),
        );
        let brute = pts
            .iter()
            .map(|p| (p - q).norm())
            .fold(f64::INFINITY, f64::min);
        assert!((tree.nearest(&q).unwrap().0 - brute).abs() < 1e-12);
    }
}

fn maneuvering(n: usize, seed: u64, m: ManeuverParams) -> Vec<MovingObstacle> {
    let mut rng = Rng::seed_from_u64(seed);
    let region = trust_core::Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(60.0, 40.0, 12.0),
    };
    (0..n)
        .map(|i| {
            let shape = if i % 2 == 0 {
                MovingShape::Sphere { radius: 0.6 }
            } else {
                MovingShape::Cylinder {
                    radius: 0.5,
                    half_height: 1.5,
                }
            };
            let yaw: f64 = rng.random_range(0.0..std::f64::consts::TAU);
            let speed = rng.random_range(0.5..2.5);
            let climb: f64 = if i % 2 == 0 {
                rng.random_range(-0.15..0.15)
            } else {
                0.0
            };
            MovingObstacle {
                shape,
                position: Vec3::new(
                    rng.random_range(2.0..58.0),
                    rng.random_range(2.0..38.0),
                    rng.random_range(2.0..10.0),
                ),
                velocity: Vec3::new(
                    yaw.cos() * climb.cos(),
                    yaw.sin() * climb.cos(),
                    climb.sin(),
                ) * speed,
                motion: Motion::RandomManeuvers(m.clone()),
                region,
            }
        })
        .collect()
}

#[test]
fn traffic_is_deterministic_bounded_and_respects_its_maneuver_bounds() {
    let m = ManeuverParams {
        mean_interval_s: 1.0,
        max_accel_m_s2: 0.6,
        max_turn_rate_rad_s: 0.4,
        speed_m_s: Some([0.5, 2.5]),
    };
    let obstacles = maneuvering(20, 2, m.clone());
    let run = |seed| {
        let mut t = Traffic::new(&obstacles, 0.0, seed).unwrap();
        for _ in 0..500 {
            t.step(0.01).unwrap();
        }
        t.positions().to_vec()
    };
    assert_eq!(run(7), run(7));
    assert_ne!(run(7), run(8));

    let dt = 0.01;
    let mut t = Traffic::new(&obstacles, 0.0, 7).unwrap();
    let (mut worst_accel, mut worst_turn) = (0.0f64, 0.0f64);
    let mut prev_v = t.velocities().to_vec();
    let mut prev_bounces = t.bounce_counts().to_vec();
    for _ in 0..60_000 {
        t.step(dt).unwrap();
        for (i, o) in obstacles.iter().enumerate() {
            let p = t.positions()[i];
            let e = o.shape.half_extents();
            for k in 0..3 {
                assert!(
                    p[k] >= o.region.min[k] + e[k] - 1e-9 && p[k] <= o.region.max[k] - e[k] + 1e-9
                );
            }
            let v = t.velocities()[i];
            if t.bounce_counts()[i] != prev_bounces[i] {
                continue; // a reflection is not a maneuver
            }
            let speed = v.norm();
            assert!((0.5 - 1e-9..=2.5 + 1e-9).contains(&speed), "speed {speed}");
            worst_accel = worst_accel.max((v - prev_v[i]).norm() / dt);
            let (h0, h1) = (prev_v[i].xy(), v.xy());
            if h0.norm() > 0.3 && h1.norm() > 0.3 {
                let turn = (h0.x * h1.y - h0.y * h1.x).atan2(h0.dot(&h1)).abs() / dt;
                worst_turn = worst_turn.max(turn);
            }
        }
        prev_v = t.velocities().to_vec();
        prev_bounces = t.bounce_counts().to_vec();
    }
    println!(
        "600 s, 20 obstacles: worst |a| {worst_accel:.4} m/s², worst turn rate {worst_turn:.4} rad/s"
    );
    assert!(
        worst_accel <= m.max_accel_m_s2 * (1.0 + 1e-6),
        "{worst_accel}"
    );
    assert!(
        worst_turn <= m.max_turn_rate_rad_s * (1.0 + 1e-6),
        "{worst_turn}"
    );
    assert!(
        t.maneuver_counts().iter().all(|&c| c > 300),
        "{:?}",
        t.maneuver_counts()
    );
    assert!(t.bounce_counts().iter().sum::<usize>() > 0);
    // Fault level 1 doubles the bounds.
    let mut f = Traffic::new(&obstacles, 1.0, 7).unwrap();
    let mut worst = 0.0f64;
    let mut prev = f.velocities().to_vec();
    let mut bounces = f.bounce_counts().to_vec();
    for _ in 0..20_000 {
        f.step(dt).unwrap();
        for i in 0..obstacles.len() {
            if f.bounce_counts()[i] == bounces[i] {
                worst = worst.max((f.velocities()[i] - prev[i]).norm() / dt);
            }
        }
        prev = f.velocities().to_vec();
        bounces = f.bounce_counts().to_vec();
    }
    assert!(
        worst > m.max_accel_m_s2 * 1.2 && worst <= 2.0 * m.max_accel_m_s2 * (1.0 + 1e-6),
        "{worst}"
    );
    assert!(Traffic::new(&obstacles, -1.0, 0).is_err());
    assert!(t.step(0.0).is_err() && t.step(f64::NAN).is_err());
}

/// Forecasts, true positions, true velocities and reflection counts at one instant.
type Snapshot = (Vec<trust_core::Forecast>, Vec<Vec3>, Vec<Vec3>, Vec<usize>);

/// Fraction of (obstacle, t0) pairs whose true position at `t0 + T` lies outside the forecast
/// made at `t0` (centre `center(t0+T)`, allowed deviation `inflation(t0+T)` with no vehicle
/// radius or margin), and the worst ratio of the truth's deviation from constant velocity to
/// `μ·T`. Pairs with a reflection between `t0 − 2 s` and `t0 + T` are skipped: a reflection is
/// an instantaneous velocity change no `μ` covers, and the filter needs time to re-converge after
/// one.
fn coverage(fault_level: f64) -> (f64, f64) {
    let horizon = 4.0;
    let mu = 0.2;
    let m = ManeuverParams {
        mean_interval_s: 1.0,
        max_accel_m_s2: ManeuverParams::covered_by(mu, horizon),
        max_turn_rate_rad_s: 0.5,
        speed_m_s: Some([0.5, 2.5]),
    };
    let obstacles = maneuvering(16, 4, m);
    let shapes: Vec<MovingShape> = obstacles.iter().map(|o| o.shape).collect();
    // The noise-free limit: millimetre noise, a filter that knows it.
    let params = SensingParams {
        position_noise_m: 1e-3,
        r_safe_margin_m: 0.0,
        ekf: EkfParams {
            meas_std: 1e-3,
            mu_min: mu,
            ..EkfParams::default()
        },
        ..SensingParams::default()
    };
    let mut traffic = Traffic::new(&obstacles, fault_level, 21).unwrap();
    let mut sensing = Sensing::new(&params, &shapes, 0.0, 22).unwrap();
    let dt = 0.01;
    let steps_per_t = (horizon / dt).round() as usize;
    let mut history: Vec<Snapshot> = Vec::new();
    let (mut outside, mut total, mut worst_ratio) = (0usize, 0usize, 0.0f64);
    for step in 0..=12_000usize {
        let t = step as f64 * dt;
        if step > 0 {
            traffic.step(dt).unwrap();
        }
        sensing.update(t, traffic.positions()).unwrap();
        if step % 100 == 0 {
            history.push((
                sensing.forecasts(t).unwrap(),
                traffic.positions().to_vec(),
                traffic.velocities().to_vec(),
                traffic.bounce_counts().to_vec(),
            ));
        }
        if step >= steps_per_t + 200 && step % 100 == 0 {
            let (forecasts, p0, v0, _) = &history[(step - steps_per_t) / 100];
            let b0 = &history[(step - steps_per_t - 200) / 100].3;
            for (i, f) in forecasts.iter().enumerate() {
                if traffic.bounce_counts()[i] != b0[i] {
                    continue;
                }
                total += 1;
                let truth = traffic.positions()[i];
                if (truth - f.center(t)).norm() > f.inflation(t) + 1e-9 {
                    outside += 1;
                }
                let deviation = (truth - p0[i] - v0[i] * horizon).norm();
                worst_ratio = worst_ratio.max(deviation / (f.mu * horizon));
            }
        }
    }
    assert!(total > 1000, "{total}");
    (outside as f64 / total as f64, worst_ratio)
}

#[test]
fn at_fault_level_zero_the_forecasts_cover_the_truth_and_beyond_it_they_do_not() {
    let (outside, ratio) = coverage(0.0);
    println!(
        "fault 0: {:.2} % outside, worst deviation / (mu T) = {ratio:.3}",
        100.0 * outside
    );
    assert_eq!(outside, 0.0);
    assert!(ratio <= 1.0, "{ratio}");
    let (outside, ratio) = coverage(3.0);
    println!(
        "fault 3: {:.2} % outside, worst deviation / (mu T) = {ratio:.3}",
        100.0 * outside
    );
    assert!(outside > 0.0 && ratio > 1.0, "{outside} {ratio}");
}

#[test]
fn forecasts_track_the_truth_handle_dropouts_and_validate() {
    let shapes = vec![
        MovingShape::Sphere { radius: 0.5 },
        MovingShape::Cylinder {
            radius: 0.4,
            half_height: 1.0,
        },
    ];
    let mut worst = [0.0f64; 2];
    for seed in 0..40u64 {
        for (k, dropout) in [0.0, 0.3].into_iter().enumerate() {
            let params = SensingParams {
                dropout_probability: dropout,
                ..SensingParams::default()
            };
            let mut s = Sensing::new(&params, &shapes, 0.3, seed).unwrap();
            let v = [Vec3::new(1.5, -0.5, 0.2), Vec3::new(-1.0, 0.8, 0.0)];
            let p0 = [Vec3::new(5.0, 5.0, 3.0), Vec3::new(10.0, 2.0, 2.0)];
            let truth = |t: f64| [p0[0] + v[0] * t, p0[1] + v[1] * t];
            for step in 0..=1000 {
                let t = step as f64 * 0.002;
                s.update(t, &truth(t)).unwrap();
            }
            let t = 2.0;
            let f = s.forecasts(t).unwrap();
            assert_eq!(f.len(), s.tracked_ids().len());
            for (fc, &i) in f.iter().zip(&s.tracked_ids()) {
                fc.validate().unwrap();
                assert_eq!(fc.t0, t);
                assert!(fc.r_safe >= 0.3 + 0.1);
                assert!(
                    [fc.p0, fc.v0]
                        .iter()
                        .all(|x| x.iter().all(|c| c.is_finite()))
                );
                let err = (fc.p0 - truth(t)[i]).norm() + (fc.v0 - v[i]).norm();
                worst[k] = worst[k].max(err);
                // The forecast one second ahead contains the truth.
                let t1 = t + 1.0;
                assert!((fc.center(t1) - (p0[i] + v[i] * t1)).norm() < fc.inflation(t1));
            }
            assert_eq!(s.stats().round_count, 41);
            if dropout == 0.0 {
                assert_eq!(s.stats().dropout_count, 0);
            }
        }
    }
    println!("worst |p error| + |v error| after 2 s over 40 seeds: {worst:?}");
    assert!(worst[0] < 0.4 && worst[1] < 0.5, "{worst:?}");

    // An obstacle never measured is absent; a high dropout leaves some untracked at first.
    let params = SensingParams {
        dropout_probability: 0.9,
        ..SensingParams::default()
    };
    let many = vec![MovingShape::Sphere { radius: 0.5 }; 30];
    let truth = vec![Vec3::new(1.0, 1.0, 1.0); 30];
    let mut s = Sensing::new(&params, &many, 0.3, 1).unwrap();
    s.update(0.0, &truth).unwrap();
    let n = s.tracked_ids().len();
    assert!(n < 30 && s.forecasts(0.0).unwrap().len() == n);
    assert!(s.update(0.01, &truth).is_ok_and(|measured| !measured));
    assert!(s.update(-1.0, &truth).is_ok_and(|measured| !measured));
    assert!(s.measure(0.02, &truth[..3]).is_err());
    assert!(s.forecasts(f64::NAN).is_err());
}

#[test]
fn worlds_can_be_shared_between_threads() {
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send_sync::<World>();
    assert_send_sync::<std::sync::Arc<World>>();
    assert_send_sync::<Traffic>();
    assert_send_sync::<Sensing>();
}

#[test]
fn streams_are_independent_of_each_other() {
    let w = World::build(&e4(5)).unwrap();
    assert_eq!(w.seeds(), Seeds::from_trial(5));
    // Two flights of one trial see identical traffic, whatever else happens in between.
    let mut a = w.traffic().unwrap();
    let mut b = w.traffic().unwrap();
    let mut sensing = w.sensing().unwrap();
    for step in 1..=2000 {
        a.step(0.002).unwrap();
        sensing.update(step as f64 * 0.002, a.positions()).unwrap();
    }
    for _ in 0..2000 {
        b.step(0.002).unwrap();
    }
    assert_eq!(a.positions(), b.positions());
    // Sensing draws do not depend on the planner's seed: a world with another planner stream
    // (same trial) gives the same forecasts.
    let f1 = sensing.forecasts(4.0).unwrap();
    let mut s2 = w.sensing().unwrap();
    let mut c = w.traffic().unwrap();
    for step in 1..=2000 {
        c.step(0.002).unwrap();
        s2.update(step as f64 * 0.002, c.positions()).unwrap();
    }
    assert_eq!(s2.forecasts(4.0).unwrap(), f1);
}

#[test]
fn explicit_point_cloud_override_in_scenarios() {
    // The voxel size of a shapes cloud can be changed after loading (what the tests above and
    // the world_view example do for E4).
    let mut s = e4(1);
    if let Some(PointCloudSpec::Shapes { esdf_voxel_m, .. }) = &mut s.static_map.point_cloud {
        *esdf_voxel_m = 1.0;
    }
    let w = World::build(&s).unwrap();
    assert_eq!(w.planner_map().esdf().unwrap().dims(), [250, 75, 20]);
}

#[test]
fn a_warmed_up_sensor_has_converged_tracks_at_take_off() {
    let s = Scenario::<toml::Table>::load(Path::new(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../scenarios/quickstart.toml"
    )))
    .unwrap();
    let w = World::build(&s).unwrap();
    let traffic = w.traffic().unwrap();
    let mut sensing = w.sensing().unwrap();
    assert_eq!(sensing.stats().round_count, 40, "2 s at 20 Hz before t = 0");
    sensing.update(0.0, traffic.positions()).unwrap();
    let forecasts = sensing.forecasts(0.0).unwrap();
    assert_eq!(forecasts.len(), w.obstacles().len());
    for (f, o) in forecasts.iter().zip(w.obstacles()) {
        assert!(f.mu < 0.6, "mu {} after the warm-up", f.mu);
        assert!((f.p0 - o.position).norm() < 0.3);
        assert!((f.v0 - o.velocity).norm() < 0.5);
    }
    // A cold sensor's first forecast grows at more than 10 m/s: the reason for the warm-up.
    let shapes: Vec<MovingShape> = w.obstacles().iter().map(|o| o.shape).collect();
    let mut cold = Sensing::new(&s.sensing, &shapes, 0.3, 1).unwrap();
    cold.update(0.0, traffic.positions()).unwrap();
    assert!(cold.forecasts(0.0).unwrap().iter().all(|f| f.mu > 10.0));
    assert!(
        cold.warm_up(traffic.positions(), traffic.velocities())
            .is_err()
    );
}

/// Scripted obstacles follow their script exactly (no reflection, no maneuvers, no fault level),
/// with the script's derivative as velocity; a moving box is judged on the box, and its forecast
/// is the circumscribing vertical cylinder.
#[test]
fn scripted_obstacles_follow_their_script_and_boxes_are_boxes() {
    let w = World::build(&scenario(
        "name = \"scripted\"\n[world]\nbounds = { min = [0, 0, 0], max = [10, 8, 3] }\n\
         [[obstacles]]\nshape = \"box\"\nhalf_extents = [0.4, 0.3, 0.5]\n\
         motion = { kind = \"fourier\", period_s = 8, center = [5, 4, 1.5], \
         cos = [[2, 0, 0]], sin = [[0, 0, 0], [0, 1.5, 0]] }\n\
         [[obstacles]]\nshape = \"sphere\"\nradius_m = 0.3\n\
         motion = { kind = \"samples\", end = \"hold\", \
         samples = [[0.5, 1, 1, 1], [1.5, 2, 1, 1], [2.5, 2, 2, 1.5]] }\n\
         [mission]\nstart = [0.5, 7.5, 1]\ngoal = [9.5, 7.5, 1]\n",
    ))
    .unwrap();
    // The script's position at t = 0 is the obstacle's initial state.
    let o = w.obstacles();
    assert!((o[0].position - Vec3::new(7.0, 4.0, 1.5)).norm() < 1e-12);
    assert_eq!(o[1].position, Vec3::new(1.0, 1.0, 1.0));
    assert_eq!(o[1].velocity, Vec3::zeros());
    let script = |i: usize| o[i].motion.script("m").unwrap().unwrap();
    let (box_script, sphere_script) = (script(0), script(1));
    // Fault level 3 would scale maneuvers; scripted truth ignores it.
    let mut traffic = Traffic::new(o, 3.0, 5).unwrap();
    for step in 1..=2000 {
        traffic.step(0.002).unwrap();
        let t = step as f64 * 0.002;
        for (i, s) in [&box_script, &sphere_script].into_iter().enumerate() {
            let (p, v) = s.evaluate(t);
            // (The traffic's clock sums the steps; `t` here multiplies: last-bit differences.)
            assert!(
                (traffic.positions()[i] - p).norm() < 1e-9,
                "obstacle {i} at t = {t}"
            );
            assert!(
                (traffic.velocities()[i] - v).norm() < 1e-9,
                "obstacle {i} at t = {t}"
            );
        }
    }
    assert_eq!(traffic.bounce_counts(), &[0, 0]);
    assert_eq!(traffic.maneuver_counts(), &[0, 0]);
    // Held at the last sample after t = 2.5 s.
    assert_eq!(traffic.positions()[1], Vec3::new(2.0, 2.0, 1.5));
    assert_eq!(traffic.velocities()[1], Vec3::zeros());
    // The box: 0.1 m off a face is clear, inside is negative; off a corner it is the corner
    // distance, not the cylinder's.
    let c = traffic.positions()[0];
    let shape = o[0].shape;
    let d = shape.signed_distance(&c, &(c + Vec3::new(0.5, 0.0, 0.0)));
    assert!((d - 0.1).abs() < 1e-12, "{d}");
    assert!(shape.signed_distance(&c, &(c + Vec3::new(0.3, 0.2, 0.0))) < 0.0);
    let corner = c + Vec3::new(0.45, 0.35, 0.0);
    let d = shape.signed_distance(&c, &corner);
    assert!((d - 0.05f64.hypot(0.05)).abs() < 1e-12, "{d}");
    let near_face = c + Vec3::new(0.42, 0.1, 0.0);
    assert!((shape.signed_distance(&c, &near_face) - 0.02).abs() < 1e-12);
    assert!(
        near_face.xy().metric_distance(&c.xy()) < shape.radius(),
        "a point clear of the box can be inside the forecast cylinder (conservative)"
    );
    assert_eq!(
        shape.forecast_shape(),
        trust_predict::ObstacleShape::Cylinder { half_height: 0.5 }
    );
    assert!((shape.radius() - 0.5).abs() < 1e-12, "√(0.4² + 0.3²)");
}

/// The dynamic forest's tier of `n` obstacles, trial seed `seed` (the file's setting).
fn forest(n: usize, seed: u64) -> Scenario {
    scenario(&format!(
        "name = \"forest\"\nseed = {seed}\ntime_limit_s = 100.0\n\
         [world]\ngenerator = {{ kind = \"dynamic-forest\", obstacle_count = {n} }}\n\
         [mission]\nstart = [0, 0, 2]\ngoal = [105, 0, 2]\ngoal_tolerance_m = 0.5\n\
         [vehicle]\nradius_m = 0.1\nlimits = {{ v_max = 5.0, a_max = 20.0 }}\nmodel = \"perfect\"\n"
    ))
}

#[test]
fn dynamic_forest_tiers_have_the_benchmarks_counts_and_are_deterministic() {
    use trust_geometry::Shape;
    // (obstacles, moving cubes, pillars, bars): 65 % move, 35 % of the rest are pillars.
    for (n, moving, pillars, bars) in [(50, 32, 7, 11), (100, 65, 13, 22), (200, 130, 25, 45)] {
        let w = World::build(&forest(n, 3)).unwrap();
        assert_eq!(w.obstacles().len(), moving, "N = {n}");
        assert_eq!(w.static_shapes().len(), n - moving, "N = {n}");
        let size = |s: &Shape| match s {
            Shape::AaBox(b) => (b.max - b.min, b.min.z),
            other => panic!("a pillar or a bar is a box, not {other:?}"),
        };
        let is = |s: &Shape, want: [f64; 3]| (size(s).0 - Vec3::from(want)).norm() < 1e-12;
        let standing = w
            .static_shapes()
            .iter()
            .filter(|s| is(s, [0.4, 0.4, 4.0]) && size(s).1 == 0.0)
            .count();
        let lying = w
            .static_shapes()
            .iter()
            .filter(|s| is(s, [0.4, 4.0, 0.4]))
            .count();
        assert_eq!((standing, lying), (pillars, bars), "N = {n}");
        // Pillars first, then bars, as drawn.
        assert!(
            w.static_shapes()[..pillars]
                .iter()
                .all(|s| is(s, [0.4, 0.4, 4.0]))
        );
        for o in w.obstacles() {
            assert_eq!(
                o.shape,
                MovingShape::Box {
                    half_extents: [0.4; 3]
                }
            );
        }
        // Same seed, same forest; another seed, another forest.
        let again = World::build(&forest(n, 3)).unwrap();
        assert_eq!(again.static_shapes(), w.static_shapes());
        assert_eq!(again.obstacles(), w.obstacles());
        let other = World::build(&forest(n, 4)).unwrap();
        assert_ne!(other.static_shapes(), w.static_shapes());
    }
}

#[test]
fn dynamic_forest_cubes_follow_the_trefoil_closed_form() {
    use trust_scenes::dynamic_forest::{FOREST_RANGES, ForestObstacle, generate};
    let seed = 5;
    let w = World::build(&forest(50, seed)).unwrap();
    // The generator is the world stream's first and only user.
    let mut rng = Rng::seed_from_u64(Seeds::from_trial(seed).world);
    let knots: Vec<_> = generate(50, &FOREST_RANGES, &mut rng)
        .into_iter()
        .filter_map(|o| match o {
            ForestObstacle::Moving(k) => Some(k),
            _ => None,
        })
        .collect();
    assert_eq!(knots.len(), w.obstacles().len());
    let mut traffic = w.traffic().unwrap();
    for (o, k) in w.obstacles().iter().zip(&knots) {
        let Motion::Fourier(f) = &o.motion else {
            panic!("a cube moves on a Fourier curve, not {:?}", o.motion);
        };
        assert!((f.period_s - std::f64::consts::TAU * k.slower).abs() < 1e-12);
        assert!((f.phase_s - k.offset * k.slower).abs() < 1e-12);
        let script = o.motion.script("m").unwrap().unwrap();
        for t in [0.0, 1.7, 12.5, 33.3, 99.9] {
            // x = x0 + sx/6 (sin u + 2 sin 2u), y = y0 + sy/5 (cos u − 2 cos 2u),
            // z = z0 − sz/2 sin 3u, u = t/slower + offset.
            let u = t / k.slower + k.offset;
            let (c, s) = (k.center, k.scale);
            let closed = Vec3::new(
                c.x + s.x / 6.0 * (u.sin() + 2.0 * (2.0 * u).sin()),
                c.y + s.y / 5.0 * (u.cos() - 2.0 * (2.0 * u).cos()),
                c.z - s.z / 2.0 * (3.0 * u).sin(),
            );
            let (p, v) = script.evaluate(t);
            assert!((p - closed).norm() < 1e-9, "t = {t}: {p} vs {closed}");
            assert!((v - k.velocity(t)).norm() < 1e-9, "t = {t}");
        }
        // Peak speed within the benchmark's "at most about 1.8 m/s".
        let peak = (0..2000)
            .map(|i| k.velocity(i as f64 * k.period_s() / 2000.0).norm())
            .fold(0.0, f64::max);
        assert!(peak < 1.9, "{peak}");
    }
    // The true traffic follows the same curves.
    for _ in 0..500 {
        traffic.step(0.02).unwrap();
    }
    for (p, k) in traffic.positions().iter().zip(&knots) {
        assert!((p - k.position(10.0)).norm() < 1e-6);
    }
}

#[test]
fn dynamic_forest_paths_stay_in_their_regions_and_clear_of_start_and_goal() {
    let half = Vec3::repeat(0.4);
    for n in [50, 100, 200] {
        for seed in 0..4 {
            let w = World::build(&forest(n, seed)).unwrap();
            let b = *w.bounds();
            assert_eq!(b.min, Vec3::new(-5.0, -15.0, 0.5));
            assert_eq!(b.max, Vec3::new(110.0, 15.0, 6.0));
            let (start, goal) = (w.start(), w.goal());
            for o in w.obstacles() {
                // The region is the world across (x, y) and wider in z: the knots go through
                // the ground and above the ceiling.
                let r = o.region;
                assert!(r.min.x >= b.min.x && r.max.x <= b.max.x);
                assert!(r.min.y >= b.min.y && r.max.y <= b.max.y);
                let script = o.motion.script("m").unwrap().unwrap();
                let Motion::Fourier(f) = &o.motion else {
                    unreachable!()
                };
                for i in 0..600 {
                    let (p, _) = script.evaluate(i as f64 * f.period_s / 600.0);
                    let (lo, hi) = (p - half, p + half);
                    assert!((0..3).all(|k| lo[k] >= r.min[k] && hi[k] <= r.max[k]));
                    assert!(lo.x >= 2.6 - 1e-9 && hi.x <= 102.4 + 1e-9);
                    assert!(o.shape.signed_distance(&p, &start) > 2.0);
                    assert!(o.shape.signed_distance(&p, &goal) > 2.0);
                }
            }
            for s in w.static_shapes() {
                // x0 in [5, 100]: no pillar or bar comes within 4.8 m of the start or the goal.
                assert!(s.signed_distance(&start) > 4.7, "{s:?}");
                assert!(s.signed_distance(&goal) > 4.7, "{s:?}");
            }
        }
    }
}

/// A sensor told the box each obstacle stays inside folds its tracks at the walls
/// (`SensingParams::fold_at_walls`, `Sensing::with_walls`): a column crossing a corridor at
/// 1.9 m/s that bounces off the wall is forecast moving away from it at once, where the paper's
/// filter still walks it into the wall; a box list of the wrong length is named.
#[test]
fn sensing_folds_the_tracks_at_the_obstacles_walls() {
    let region = trust_core::Aabb {
        min: Vec3::zeros(),
        max: Vec3::new(60.0, 20.0, 8.0),
    };
    let column = MovingObstacle {
        shape: MovingShape::Cylinder {
            radius: 0.5,
            half_height: 4.0,
        },
        // The centre turns at y = 0.5, 0.5 s after take-off.
        position: Vec3::new(30.0, 1.45, 4.0),
        velocity: Vec3::new(0.0, -1.9, 0.0),
        motion: Motion::ConstantVelocity {},
        region,
    };
    let shapes = [column.shape];
    let velocity_after_bounce = |fold: bool| {
        let params = SensingParams {
            fold_at_walls: fold,
            ..SensingParams::default()
        };
        let mut traffic = Traffic::new(std::slice::from_ref(&column), 0.0, 3).unwrap();
        let mut sensing = Sensing::new(&params, &shapes, 0.3, 4)
            .unwrap()
            .with_walls(vec![Some(region)])
            .unwrap();
        sensing
            .warm_up(&[column.position], &[column.velocity])
            .unwrap();
        let dt = 0.01;
        for step in 1..=65 {
            traffic.step(dt).unwrap();
            sensing
                .update(step as f64 * dt, traffic.positions())
                .unwrap();
        }
        assert!(traffic.velocities()[0].y > 0.0, "the column bounced");
        sensing.forecasts(0.65).unwrap()[0].v0.y
    };
    let (folded, paper) = (velocity_after_bounce(true), velocity_after_bounce(false));
    assert!(folded > 1.5, "folded track: v_y = {folded}");
    assert!(paper < -1.0, "the paper's filter: v_y = {paper}");

    let e = Sensing::new(&SensingParams::default(), &shapes, 0.3, 4)
        .unwrap()
        .with_walls(vec![])
        .unwrap_err();
    assert!(e.to_string().contains("walls"), "{e}");
}
