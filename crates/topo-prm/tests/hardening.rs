//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) and issue 11 found, named after
//! the bug.

use trust_core::{Aabb, GuidePath, HomotopyChecker, PlanError, Scene, StaticMap, Vec3};
use trust_topo_prm::{Uvd, shortcut, straight, uvd};

fn map() -> StaticMap {
    StaticMap::new(Aabb::new(Vec3::repeat(-50.0), Vec3::repeat(50.0)).unwrap()).unwrap()
}

#[test]
fn uvd_with_an_empty_polyline_is_an_error_not_equivalent() {
    // Issue 11: an empty polyline was "equivalent" to anything.
    let map = map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let empty = GuidePath { points: vec![] };
    let other = GuidePath::new(vec![Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0)]).unwrap();
    assert!(Uvd::default().equivalent(&empty, &other, &scene).is_err());
    assert!(Uvd::default().equivalent(&other, &empty, &scene).is_err());
    assert!(uvd::equivalent(&empty, &other, 0.1, |_, _| true).is_err());
}

#[test]
fn uvd_with_a_vertex_1e8_m_away_answers_at_once() {
    // Issue 11: UVD took seconds when one vertex was 1e8 m away.
    let map = map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let far = GuidePath {
        points: vec![
            Vec3::zeros(),
            Vec3::new(1e8, 0.0, 0.0),
            Vec3::new(5.0, 0.0, 0.0),
        ],
    };
    let near = GuidePath::new(vec![Vec3::zeros(), Vec3::new(5.0, 0.0, 0.0)]).unwrap();
    let e = Uvd::default().equivalent(&far, &near, &scene).unwrap_err();
    assert!(matches!(e, PlanError::Count(_)), "{e:?}");
}

#[test]
fn discretize_output_is_capped_and_finite() {
    let mut out = Vec::new();
    shortcut::discretize(
        &[Vec3::zeros(), Vec3::new(1e6, 0.0, 0.0), Vec3::zeros()],
        1e-9,
        &mut out,
    );
    assert!(out.len() <= trust_core::scale::MAX_SAMPLE_COUNT + 3);
    // Fuzz case 10103411442046952351: finite vertices whose difference overflows.
    shortcut::discretize(
        &[
            Vec3::new(1e300, 0.0, -1e155),
            Vec3::new(-f64::MAX, 0.0, 0.0),
        ],
        0.5,
        &mut out,
    );
    assert!(out.iter().all(|p| !p.iter().any(|c| c.is_nan())));
}

#[test]
fn straight_end_with_huge_points_is_not_nan() {
    // Fuzz case 4040574827635797336.
    let end = straight::straight_end(
        &Vec3::new(1.0, -4.8, 1.0),
        &Vec3::new(-17.6, -4.0, f64::MAX),
        3.0,
    );
    assert!(end.iter().all(|c| !c.is_nan()));
}

#[test]
fn sparse_astar_with_usize_max_turn_branches_is_rejected() {
    // Fuzz (params::frontends): every expansion looped over `usize::MAX` headings.
    let params = trust_topo_prm::SparseAStarParams {
        turn_branches: usize::MAX,
        ..trust_topo_prm::SparseAStarParams::default()
    };
    assert!(trust_topo_prm::SparseAStar::new(params).is_err());
}

/// The longest run of decimal digits in `s`.
fn longest_digit_run(s: &str) -> usize {
    s.split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0)
}

#[test]
fn tvd_equivalent_rejects_a_forecast_with_negative_r_safe() {
    // Issue 18: a `Scene` built as a struct literal (its fields are public) with a forecast of
    // negative `r_safe` was accepted by `Tvd::equivalent`; every other component rejects it.
    use trust_core::{Forecast, ObstacleShape, PolyTraj};
    let map = map();
    let bad = [Forecast {
        shape: ObstacleShape::Sphere,
        p0: Vec3::new(0.0, 0.0, 0.0),
        v0: Vec3::zeros(),
        t0: 0.0,
        r_o: 0.5,
        r_safe: -1.0,
        mu: 0.0,
        growth_s: f64::INFINITY,
        walls: None,
    }];
    let scene = Scene {
        map: &map,
        forecasts: &bad,
        t0: 0.0,
    };
    let a = PolyTraj::hold(0.0, Vec3::new(0.0, 3.0, 0.0), 2.0).unwrap();
    let b = PolyTraj::hold(0.0, Vec3::new(0.0, -3.0, 0.0), 2.0).unwrap();
    let e = trust_topo_prm::Tvd::default()
        .equivalent(&a, &b, &scene)
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("scene.forecasts[0]") && e.contains("r_safe"),
        "{e}"
    );
    assert!(trust_topo_prm::tvd::equivalent(&a, &b, &scene, 0.05).is_err());
}

#[test]
fn tvd_on_a_long_hold_names_the_trajectories_not_tvd_dt_s() {
    // Issue 18: two 1e6 s holds need 2e7 samples at the default step; the error blamed the valid
    // `tvd.dt_s`.
    use trust_core::PolyTraj;
    let map = map();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let a = PolyTraj::hold(0.0, Vec3::new(0.0, 3.0, 0.0), 1e6).unwrap();
    let b = PolyTraj::hold(0.0, Vec3::new(0.0, -3.0, 0.0), 1e6).unwrap();
    let e = trust_topo_prm::Tvd::default()
        .equivalent(&a, &b, &scene)
        .unwrap_err();
    match &e {
        PlanError::InvalidInput { field, .. } => {
            assert_eq!(field, "common time span of the two trajectories", "{e}")
        }
        other => panic!("{other:?}"),
    }
    assert!(longest_digit_run(&e.to_string()) <= 17, "{e}");
    // A span that fits is fine.
    let a = PolyTraj::hold(0.0, Vec3::new(0.0, 3.0, 0.0), 100.0).unwrap();
    let b = PolyTraj::hold(0.0, Vec3::new(0.0, -3.0, 0.0), 100.0).unwrap();
    assert!(
        trust_topo_prm::Tvd::default()
            .equivalent(&a, &b, &scene)
            .unwrap()
    );
}

#[test]
fn devprm_surface_offset_extremes_are_rejected_at_construction_or_work() {
    // Issue 18: an extreme `surface_offset` was accepted, then the search failed on `margin`.
    use trust_core::{Forecast, Limits, PathFrontend, PathQuery, Rng, State};
    use trust_topo_prm::{DevPrm, DevPrmParams};
    for bad in [1e300, f64::MAX, 1e7, f64::INFINITY, f64::NAN, -1.0, 0.1] {
        let e = DevPrm::new(DevPrmParams {
            surface_offset: bad,
            ..DevPrmParams::default()
        })
        .unwrap_err()
        .to_string();
        assert!(e.contains("devprm.surface_offset"), "{bad}: {e}");
        assert!(longest_digit_run(&e) <= 17, "{e}");
    }
    let map = map();
    let forecasts = [Forecast::sphere(
        Vec3::new(0.0, 0.0, 0.0),
        Vec3::new(0.0, 1.0, 0.0),
        0.0,
        1.0,
        0.1,
        0.2,
    )
    .unwrap()];
    let scene = Scene::new(&map, &forecasts, 0.0).unwrap();
    let q = PathQuery {
        start: State::at_rest(0.0, Vec3::new(-10.0, 0.0, 0.0)),
        goal: Vec3::new(10.0, 0.0, 0.0),
        limits: Limits::default(),
        horizon_s: 2.0,
        exploration: 1.0,
    };
    for offset in [0.3, 1e3, trust_core::scale::MAX_LENGTH_M] {
        let f = DevPrm::new(DevPrmParams {
            surface_offset: offset,
            budget_ms: 1e4,
            max_samples: 200,
            ..DevPrmParams::default()
        })
        .unwrap();
        let mut rng = <Rng as rand::SeedableRng>::seed_from_u64(1);
        let r = f.search(&q, &scene, &mut rng);
        assert!(r.is_ok(), "surface_offset {offset}: {r:?}");
    }
}

#[test]
fn uvd_point_count_error_prints_no_long_integers() {
    // Issue 18: the UVD resolution error printed the point count as a 31-digit integer.
    let map = StaticMap::new(Aabb::new(Vec3::repeat(-1e6), Vec3::repeat(1e6)).unwrap()).unwrap();
    let scene = Scene::new(&map, &[], 0.0).unwrap();
    let a = GuidePath::new(vec![Vec3::repeat(-1e6), Vec3::repeat(1e6)]).unwrap();
    let b = GuidePath::new(vec![Vec3::repeat(-1e6), Vec3::zeros(), Vec3::repeat(1e6)]).unwrap();
    let uvd = Uvd::new(trust_topo_prm::UvdParams {
        resolution: 1e-9,
        ..trust_topo_prm::UvdParams::default()
    })
    .unwrap();
    let e = uvd.equivalent(&a, &b, &scene).unwrap_err().to_string();
    assert!(e.contains("uvd.resolution"), "{e}");
    assert!(longest_digit_run(&e) <= 17, "{e}");
    // The free function takes any positive resolution: a subnormal one gave 1e30 points, printed
    // with 31 digits.
    let e = uvd::check_curves(&a, &b, 5e-324).unwrap_err().to_string();
    assert!(e.contains("1.0e30"), "{e}");
    assert!(longest_digit_run(&e) <= 17, "{e}");
}

#[test]
fn every_params_field_at_its_extremes_is_rejected_with_its_name() {
    // Issue 18: counts, budgets and lengths had no upper bound.
    use trust_topo_prm::{DevPrmParams, SparseAStarParams, TvdParams, UvdParams, VprmParams};
    let d = DevPrmParams::default;
    let cases: Vec<(Result<(), PlanError>, &str)> = vec![
        (
            DevPrmParams {
                max_samples: usize::MAX,
                ..d()
            }
            .validate(),
            "devprm.max_samples",
        ),
        (
            DevPrmParams {
                stall_samples: 1 << 40,
                ..d()
            }
            .validate(),
            "devprm.stall_samples",
        ),
        (
            DevPrmParams {
                beam_width: 1 << 40,
                ..d()
            }
            .validate(),
            "devprm.beam_width",
        ),
        (
            DevPrmParams {
                max_raw_paths: usize::MAX,
                ..d()
            }
            .validate(),
            "devprm.max_raw_paths",
        ),
        (
            DevPrmParams {
                max_expansions: usize::MAX,
                ..d()
            }
            .validate(),
            "devprm.max_expansions",
        ),
        (
            DevPrmParams {
                slices: 1 << 40,
                ..d()
            }
            .validate(),
            "devprm.slices",
        ),
        (
            DevPrmParams {
                budget_ms: 1e300,
                ..d()
            }
            .validate(),
            "devprm.budget_ms",
        ),
        (
            DevPrmParams {
                resolution: 1e-12,
                ..d()
            }
            .validate(),
            "devprm.resolution",
        ),
        (
            DevPrmParams {
                clearance: 1e300,
                ..d()
            }
            .validate(),
            "devprm.clearance",
        ),
        (
            DevPrmParams {
                inflate: Vec3::new(0.0, 1e300, 0.0),
                ..d()
            }
            .validate(),
            "devprm.inflate.y",
        ),
        (
            DevPrmParams {
                length_ratio: 1e300,
                ..d()
            }
            .validate(),
            "devprm.length_ratio",
        ),
        (
            DevPrmParams {
                pdc_horizon_s: Some(1e300),
                ..d()
            }
            .validate(),
            "devprm.pdc_horizon_s",
        ),
        (
            VprmParams {
                max_samples: usize::MAX,
                ..VprmParams::default()
            }
            .validate(),
            "vprm.max_samples",
        ),
        (
            VprmParams {
                budget_ms: f64::MAX,
                ..VprmParams::default()
            }
            .validate(),
            "vprm.budget_ms",
        ),
        (
            SparseAStarParams {
                step: 1e-300,
                ..SparseAStarParams::default()
            }
            .validate(),
            "sparse_astar.step",
        ),
        (
            SparseAStarParams {
                max_expansions: usize::MAX,
                ..SparseAStarParams::default()
            }
            .validate(),
            "sparse_astar.max_expansions",
        ),
        (
            UvdParams {
                resolution: 1e300,
                ..UvdParams::default()
            }
            .validate(),
            "uvd.resolution",
        ),
        (
            UvdParams {
                clearance: 1e300,
                ..UvdParams::default()
            }
            .validate(),
            "uvd.clearance",
        ),
        (
            TvdParams {
                dt_s: 1e300,
                ..TvdParams::default()
            }
            .validate(),
            "tvd.dt_s",
        ),
        (
            TvdParams {
                clearance: 1e300,
                ..TvdParams::default()
            }
            .validate(),
            "tvd.clearance",
        ),
    ];
    for (r, field) in cases {
        let e = r.unwrap_err().to_string();
        assert!(e.contains(field), "expected {field}: {e}");
        assert!(longest_digit_run(&e) <= 17, "{e}");
    }
}

#[test]
fn sparse_astar_turn_branches_at_usize_max_prints_a_readable_number() {
    // Fuzz (params::topo::frontends): the error printed 18446744073709551615.
    let e = trust_topo_prm::SparseAStarParams {
        turn_branches: usize::MAX,
        ..trust_topo_prm::SparseAStarParams::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("sparse_astar.turn_branches"), "{e}");
    assert!(longest_digit_run(&e) <= 17, "{e}");
}

#[test]
fn scene_margin_against_a_small_scene_size_names_scene_size() {
    // Fuzz (params::topo::SceneParams): shrinking `scene.size` blamed the valid `scene.margin`
    // alone.
    let e = trust_topo_prm::scenes::SceneParams {
        size: Vec3::new(1e-3, 20.0, 10.0),
        ..trust_topo_prm::scenes::SceneParams::default()
    }
    .validate()
    .unwrap_err()
    .to_string();
    assert!(e.contains("scene.size"), "{e}");
}
