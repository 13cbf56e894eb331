//! The roadmap's own cone geometry (`cone::Cone`) against `trust_predict::Pdc`, the reference
//! implementation of eq. PDC: the same answers for spheres, and never a less conservative one for
//! cylinders (our slab spans both end cylinders).

use proptest::prelude::*;
use trust_core::{Forecast, ObstacleShape, Vec3};
use trust_predict::Pdc;
use trust_topo_prm::cone::Cone;

fn v3(r: f64) -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(-r..r).prop_map(|a| Vec3::new(a[0], a[1], a[2]))
}

fn forecast(cyl: bool) -> impl Strategy<Value = Forecast> {
    (
        v3(3.0),
        v3(2.0),
        0.2..1.5f64,
        0.0..0.5f64,
        0.0..0.4f64,
        0.5..3.0f64,
    )
        .prop_map(move |(p0, v0, r_o, r_safe, mu, h)| {
            let shape = if cyl {
                ObstacleShape::Cylinder { half_height: h }
            } else {
                ObstacleShape::Sphere
            };
            Forecast::new(shape, p0, v0, 0.0, r_o, r_safe, mu).unwrap()
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    #[test]
    fn sphere_cones_agree_with_the_reference(
        f in forecast(false), t_start in 0.0..1.0f64, horizon in 0.0..3.0f64,
        a in v3(6.0), b in v3(6.0),
    ) {
        let ours = Cone::from_forecast(&f, t_start, horizon);
        let theirs = Pdc::over_window(&f, t_start, t_start + horizon).unwrap();
        // Exact tests on both sides; skip the razor-thin band where rounding may differ.
        let d = (0..=800)
            .map(|k| ours.signed_distance(&(a + (b - a) * (k as f64 / 800.0))))
            .fold(f64::INFINITY, f64::min);
        prop_assume!(d.abs() > 0.05);
        prop_assert_eq!(ours.segment_clear(&a, &b, 0.0), theirs.segment_clear(&a, &b, 0.0));
        prop_assert!((ours.signed_distance(&a) - theirs.signed_distance(&a)).abs() < 1e-6
            || ours.signed_distance(&a) < 0.0);
    }

    #[test]
    fn cylinder_cones_are_at_least_as_conservative(
        f in forecast(true), t_start in 0.0..1.0f64, horizon in 0.0..3.0f64,
        a in v3(6.0), b in v3(6.0),
    ) {
        let ours = Cone::from_forecast(&f, t_start, horizon);
        let theirs = Pdc::over_window(&f, t_start, t_start + horizon).unwrap();
        if !theirs.segment_clear(&a, &b, 0.0) {
            prop_assert!(!ours.segment_clear(&a, &b, 0.0));
        }
        if theirs.contains(&a) {
            prop_assert!(ours.contains(&a, 0.0));
        }
    }
}
