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
