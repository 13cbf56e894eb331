//! Tests of [`Pdc`] against its definition: the union of the slices `K(λ)` (centre, radius and
//! half-height interpolated between the end shapes), sampled densely in `λ` and along segments.

use super::*;
use crate::convex::{NormMinusAffine2d, Vec2, min_over_convex_polygon};
use approx::assert_relative_eq;
use proptest::prelude::*;
use std::f64::consts::SQRT_2;

fn v3(r: f64) -> impl Strategy<Value = Vec3> {
    (-r..r, -r..r, -r..r).prop_map(|(x, y, z)| Vec3::new(x, y, z))
}

/// Spheres, short cylinders and cylinders taller than the test region (whose queries take the
/// core's fast path).
fn shape() -> impl Strategy<Value = ObstacleShape> {
    prop_oneof![
        Just(ObstacleShape::Sphere),
        (0.2..1.5f64).prop_map(|half_height| ObstacleShape::Cylinder { half_height }),
        Just(ObstacleShape::Cylinder { half_height: 20.0 }),
    ]
}

/// General velocities, and horizontal ones (the usual case for cylinders).
fn velocity() -> impl Strategy<Value = Vec3> {
    prop_oneof![
        v3(2.0),
        (-2.0..2.0f64, -2.0..2.0f64).prop_map(|(x, y)| Vec3::new(x, y, 0.0)),
    ]
}

/// A forecast made at t0 = 0.5 and a PDC over `[t0 + lag, t0 + lag + horizon]`; a negative lag
/// starts the window before the forecast time.
fn pdc_strategy() -> impl Strategy<Value = Pdc> {
    (
        shape(),
        v3(1.0),
        velocity(),
        0.2..1.0f64,
        0.0..0.3f64,
        0.0..0.6f64,
        -0.3..0.5f64,
        0.0..3.0f64,
    )
        .prop_map(|(shape, p0, v0, r_o, r_safe, mu, lag, horizon)| {
            let f = Forecast::new(shape, p0, v0, 0.5, r_o, r_safe, mu).unwrap();
            Pdc::over_window(&f, 0.5 + lag, 0.5 + lag + horizon).unwrap()
        })
}

/// The slice at `λ ∈ [0, 1]`: centre, radius, vertical half-extent.
fn slice(pdc: &Pdc, l: f64) -> (Vec3, f64, f64) {
    let [(a, ra, ha), (b, rb, hb)] = pdc.ends();
    (a + (b - a) * l, ra + (rb - ra) * l, ha + (hb - ha) * l)
}

/// Signed distance to one slice: Euclidean, or the square-rim `max(ρ, ζ)` for a cylinder.
fn slice_distance(pdc: &Pdc, x: &Vec3, l: f64, square_rim: bool) -> f64 {
    let (c, r, h) = slice(pdc, l);
    match pdc.forecast().shape {
        ObstacleShape::Sphere => (x - c).norm() - r,
        ObstacleShape::Cylinder { .. } => {
            let q = x - c;
            let (rho, zeta) = (q.x.hypot(q.y) - r, q.z.abs() - h);
            if square_rim || (rho <= 0.0 && zeta <= 0.0) {
                rho.max(zeta)
            } else {
                rho.max(0.0).hypot(zeta.max(0.0))
            }
        }
    }
}

/// Lipschitz constant of a slice's distance in `λ`.
fn lipschitz_in_lambda(pdc: &Pdc) -> f64 {
    let [(a, ra, ha), (b, rb, hb)] = pdc.ends();
    (b - a).norm() + (rb - ra).abs() + (hb - ha).abs()
}

/// Dense minimum over `λ` of the square-rim slice distance, with the grid's slack.
fn dense_point(pdc: &Pdc, x: &Vec3, n: usize) -> (f64, f64) {
    let best = (0..=n)
        .map(|j| slice_distance(pdc, x, j as f64 / n as f64, true))
        .fold(f64::INFINITY, f64::min);
    (best, lipschitz_in_lambda(pdc) / n as f64)
}

/// Dense minimum over `(s, λ)` of the square-rim slice distance along `[a, b]`, with its slack.
fn dense_segment(pdc: &Pdc, a: &Vec3, b: &Vec3, n: usize) -> (f64, f64) {
    let mut best = f64::INFINITY;
    for i in 0..=n {
        let x = a + (b - a) * (i as f64 / n as f64);
        for j in 0..=n {
            best = best.min(slice_distance(pdc, &x, j as f64 / n as f64, true));
        }
    }
    (best, ((b - a).norm() + lipschitz_in_lambda(pdc)) / n as f64)
}

#[test]
fn window_validation() {
    let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 1.0, 0.5, 0.0, 0.1).unwrap();
    assert!(
        matches!(Pdc::new(&f, -1.0), Err(PredictError::OutOfRange { ref field, .. }) if field == "horizon")
    );
    assert!(Pdc::new(&f, f64::NAN).is_err());
    assert!(matches!(
        Pdc::over_window(&f, 2.0, 1.5),
        Err(PredictError::InvalidWindow { .. })
    ));
    assert!(Pdc::at_time(&f, f64::INFINITY).is_err());
    let mut bad = f;
    bad.r_o = -1.0;
    assert!(Pdc::new(&bad, 1.0).is_err());
    let p = Pdc::over_window(&f, 1.5, 3.0).unwrap();
    assert_relative_eq!(p.t_end(), 3.0);
    assert_relative_eq!(p.horizon(), 1.5);
    assert_eq!(p.forecast(), &f);
    // A window starting before the forecast time: the hull of the end shapes.
    let early = Pdc::over_window(&f, 0.5, 2.0).unwrap();
    let [(a, ra, _), (b, rb, _)] = early.ends();
    assert_relative_eq!(a, f.center(0.5));
    assert_relative_eq!(ra, 0.5);
    assert_relative_eq!(b, f.center(2.0));
    assert_relative_eq!(rb, 0.6);
}

#[test]
fn sphere_cone_closed_form_on_axis_and_side() {
    // r(τ) = 1 + 0.5τ, c(τ) = (2τ, 0, 0), T = 2: end ball at x = 4 with r = 2.
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), 0.0, 1.0, 0.0, 0.5).unwrap();
    let pdc = f.pdc(2.0).unwrap();
    assert_relative_eq!(
        pdc.signed_distance(&Vec3::new(7.0, 0.0, 0.0)),
        1.0,
        epsilon = 1e-12
    );
    assert_relative_eq!(
        pdc.signed_distance(&Vec3::new(-3.0, 0.0, 0.0)),
        2.0,
        epsilon = 1e-12
    );
    // Beside the cone: the tangent line has slope sin α = 0.25.
    let p = Vec3::new(2.0, 5.0, 0.0);
    let brute = (0..=20000)
        .map(|i| f.signed_distance(&p, 2.0 * i as f64 / 20000.0))
        .fold(f64::INFINITY, f64::min);
    assert_relative_eq!(pdc.signed_distance(&p), brute, epsilon = 1e-6);
    assert!(pdc.contains(&Vec3::new(3.9, 1.9, 0.0)));
    assert!(!pdc.contains(&Vec3::new(0.0, 1.1, 0.0)));
}

#[test]
fn slow_sphere_cone_is_the_final_ball() {
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(0.0, 0.0, 0.3), 0.0, 1.0, 0.0, 0.5).unwrap();
    let pdc = f.pdc(2.0).unwrap();
    for p in [
        Vec3::new(0.0, 0.0, -3.0),
        Vec3::new(2.5, 0.0, 0.6),
        Vec3::new(0.1, 0.2, 0.3),
    ] {
        assert_relative_eq!(
            pdc.signed_distance(&p),
            f.signed_distance(&p, 2.0),
            epsilon = 1e-12
        );
    }
    let region = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
    let samples = pdc.surface_samples(5, 7, 0.2, &region).unwrap();
    assert_eq!(samples.len(), 37); // 5 rings of 7 and the two points beyond the ends
    for s in &samples {
        assert_relative_eq!(pdc.signed_distance(s), 0.2, epsilon = 1e-9);
    }
}

#[test]
fn zero_velocity_and_zero_horizon_are_fine() {
    let region = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
    for shape in [
        ObstacleShape::Sphere,
        ObstacleShape::Cylinder { half_height: 1.0 },
    ] {
        let f = Forecast::new(
            shape,
            Vec3::new(1.0, 1.0, 1.0),
            Vec3::zeros(),
            0.0,
            0.5,
            0.1,
            0.0,
        )
        .unwrap();
        for horizon in [0.0, 2.0] {
            let pdc = f.pdc(horizon).unwrap();
            let samples = pdc.surface_samples(3, 6, 0.1, &region).unwrap();
            assert_eq!(samples.len(), 6); // one slice: the obstacle does not move
            for s in &samples {
                assert_relative_eq!(pdc.signed_distance(s), 0.1, epsilon = 1e-9);
            }
            assert!(pdc.contains(&f.p0));
            assert!(!pdc.segment_clear(&Vec3::new(-5.0, 1.0, 1.0), &Vec3::new(5.0, 1.0, 1.0), 0.0));
            assert!(pdc.segment_clear(&Vec3::new(-5.0, 3.0, 1.0), &Vec3::new(5.0, 3.0, 1.0), 0.5));
            // A degenerate segment behaves like a point.
            let p = Vec3::new(1.0, 1.75, 1.0);
            assert_eq!(pdc.segment_clear(&p, &p, 0.1), pdc.point_clear(&p, 0.1));
        }
    }
}

#[test]
fn vertical_velocity_frames_work() {
    let region = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
    for shape in [
        ObstacleShape::Sphere,
        ObstacleShape::Cylinder { half_height: 0.5 },
    ] {
        let f = Forecast::new(
            shape,
            Vec3::zeros(),
            Vec3::new(0.0, 0.0, -2.0),
            0.0,
            0.5,
            0.0,
            0.2,
        )
        .unwrap();
        let pdc = f.pdc(1.5).unwrap();
        let samples = pdc.surface_samples(4, 6, 0.05, &region).unwrap();
        assert!(!samples.is_empty());
        for s in &samples {
            assert!(s.iter().all(|x| x.is_finite()));
            assert_relative_eq!(pdc.signed_distance(s), 0.05, epsilon = 1e-9);
        }
    }
    for axis in [Vec3::z(), -Vec3::z() * 3.0, Vec3::new(1.0, -2.0, 0.5)] {
        let [x, y, z] = frame_along(&axis);
        assert_relative_eq!(x, axis.normalize());
        assert_relative_eq!(y.z, 0.0);
        assert_relative_eq!(x.dot(&y), 0.0, epsilon = 1e-15);
        assert_relative_eq!(x.cross(&y), z);
    }
    assert_eq!(
        frame_along(&Vec3::zeros()),
        [Vec3::x(), Vec3::y(), Vec3::z()]
    );
}

#[test]
fn non_finite_queries_are_blocked_and_bad_margin_is_an_error() {
    let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 0.0, 0.5, 0.0, 0.1).unwrap();
    let pdc = f.pdc(1.0).unwrap();
    let nan = Vec3::new(f64::NAN, 0.0, 0.0);
    let far = Vec3::new(9.0, 9.0, 9.0);
    assert!(pdc.contains(&nan));
    assert!(!pdc.point_clear(&far, f64::NAN));
    assert!(pdc.point_clear(&far, 0.0));
    assert!(!pdc.segment_clear(&nan, &Vec3::zeros(), 0.1));
    assert!(pdc.segment_clear(&far, &(far + Vec3::x()), 0.0));
    assert!(!pdc.segment_clear(&far, &Vec3::new(9.0, 9.0, 8.0), f64::INFINITY));
    let region = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
    assert!(pdc.surface_samples(2, 2, -0.1, &region).is_err());
    assert!(pdc.surface_samples(2, 2, f64::NAN, &region).is_err());
    assert!(pdc.surface_samples(usize::MAX, 2, 0.1, &region).is_err());
    assert!(pdc.surface_samples(2, usize::MAX, 0.1, &region).is_err());
    assert!(pdc.surface_samples(0, 5, 0.1, &region).unwrap().is_empty());
    assert_eq!(pdc.support(&Vec3::zeros()), pdc.ends()[0].0);
    assert_eq!(pdc.support(&nan), pdc.ends()[0].0);
}

#[test]
fn tall_cylinder_crossing_a_horizontal_segment() {
    // A pillar (r = 0.3, h = 2) walking along +y at 1 m/s crosses the segment x ∈ [-3, 3], y = 2.
    let f = Forecast::new(
        ObstacleShape::Cylinder { half_height: 2.0 },
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::new(0.0, 1.0, 0.0),
        0.0,
        0.3,
        0.0,
        0.0,
    )
    .unwrap();
    let (a, b) = (Vec3::new(-3.0, 2.0, 1.0), Vec3::new(3.0, 2.0, 1.0));
    assert!(!f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.1));
    assert!(f.pdc(1.5).unwrap().segment_clear(&a, &b, 0.1)); // it has not arrived yet
    // Flying above it is clear; a clearance reaching down to the top is not.
    let (a, b) = (Vec3::new(-3.0, 2.0, 3.5), Vec3::new(3.0, 2.0, 3.5));
    assert!(f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.4));
    assert!(!f.pdc(3.0).unwrap().segment_clear(&a, &b, 0.6));
}

#[test]
fn growing_cylinder_is_exact_above_its_shorter_end() {
    // A growing pillar: half-height 1 at the start, 2 at the end (mu = 0.5, T = 2), moving along x.
    // Above the start, between heights 1 and 2, there is free space that a slab spanning both
    // ends would block.
    let f = Forecast::new(
        ObstacleShape::Cylinder { half_height: 1.0 },
        Vec3::zeros(),
        Vec3::new(3.0, 0.0, 0.0),
        0.0,
        0.5,
        0.0,
        0.5,
    )
    .unwrap();
    let pdc = f.pdc(2.0).unwrap();
    let above_start = Vec3::new(0.0, 0.0, 1.6);
    assert!(pdc.point_clear(&above_start, 0.1));
    assert!(!pdc.point_clear(&Vec3::new(6.0, 0.0, 1.6), 0.0));
    assert!(pdc.segment_clear(&Vec3::new(0.0, -3.0, 1.6), &Vec3::new(0.0, 3.0, 1.6), 0.1));
    assert!(!pdc.segment_clear(&Vec3::new(5.0, -3.0, 1.6), &Vec3::new(5.0, 3.0, 1.6), 0.1));
    // The segment through the point above the start keeps exactly the point's distance.
    let exact = 0.6 - 1.1 / 6.0;
    let (left, right) = (Vec3::new(0.0, -3.0, 1.6), Vec3::new(0.0, 3.0, 1.6));
    assert!(pdc.segment_clear(&left, &right, exact - 1e-6));
    assert!(!pdc.segment_clear(&left, &right, exact + 1e-6));
    // Slice λ: centre x = 6λ, radius 0.5 + λ, top 1 + λ. The square-rim distance of the point is
    // min_λ max(5λ − 0.5, 0.6 − λ), attained where the two cross (λ = 1.1/6).
    assert_relative_eq!(
        pdc.signed_distance(&above_start),
        0.6 - 1.1 / 6.0,
        epsilon = 1e-12
    );
}

#[test]
fn degenerate_cones_are_spheres_and_cylinders() {
    let c = Vec3::new(1.0, 2.0, 3.0);
    let ball = Forecast::sphere(c, Vec3::zeros(), 0.0, 1.0, 0.0, 0.0).unwrap();
    let s = Pdc::at_time(&ball, 4.0).unwrap();
    assert_relative_eq!(s.signed_distance(&Vec3::new(3.0, 2.0, 3.0)), 1.0);
    let pillar = Forecast::new(
        ObstacleShape::Cylinder { half_height: 2.0 },
        c,
        Vec3::x(),
        0.0,
        1.0,
        0.0,
        0.3,
    )
    .unwrap();
    let cyl = Pdc::at_time(&pillar, 0.0).unwrap();
    assert_relative_eq!(cyl.signed_distance(&Vec3::new(1.0, 2.0, 6.0)), 1.0);
    assert_relative_eq!(cyl.signed_distance(&Vec3::new(3.0, 2.0, 3.0)), 1.0);
    assert!(cyl.contains(&c));
    // Containing ball: the larger one wins.
    let big = round_cone_sdf(
        &c,
        &(c + Vec3::x() * 0.5),
        0.1,
        2.0,
        &(c + Vec3::new(0.5, 3.0, 0.0)),
    );
    assert_relative_eq!(big.0, 1.0, epsilon = 1e-12);
}

#[test]
fn surface_samples_stay_in_the_region_and_on_the_offset_surface() {
    let region = Aabb::new(Vec3::new(-10.0, -10.0, 0.0), Vec3::new(10.0, 10.0, 4.0)).unwrap();
    for shape in [
        ObstacleShape::Sphere,
        ObstacleShape::Cylinder { half_height: 1.5 },
        ObstacleShape::Cylinder { half_height: 10.0 },
    ] {
        for v0 in [Vec3::new(2.0, 0.5, 0.0), Vec3::zeros()] {
            let f = Forecast::new(shape, Vec3::new(0.0, 0.0, 2.0), v0, 0.0, 0.8, 0.0, 0.3).unwrap();
            let pdc = f.pdc(2.0).unwrap();
            let out = pdc.surface_samples(3, 8, 0.4, &region).unwrap();
            assert!(!out.is_empty());
            assert!(out.len() <= 26);
            assert!(out.iter().all(|p| region.contains(p)));
            for p in &out {
                assert!(
                    (pdc.signed_distance(p) - 0.4).abs() < 1e-6,
                    "{shape:?} {p:?}: {}",
                    pdc.signed_distance(p)
                );
            }
        }
    }
}

#[test]
fn the_core_fast_path_is_the_square_rim_distance() {
    let f = Forecast::new(
        ObstacleShape::Cylinder { half_height: 5.0 },
        Vec3::new(1.0, 2.0, 5.0),
        Vec3::new(1.5, -1.0, 0.0),
        0.0,
        0.7,
        0.1,
        0.25,
    )
    .unwrap();
    let pdc = f.pdc(2.0).unwrap();
    for p in [
        Vec3::new(4.0, 4.0, 1.0),
        Vec3::new(-2.0, 0.0, 9.5),
        Vec3::new(3.0, -1.5, 5.0),
    ] {
        let (fast, g_fast) = pdc.distance_and_gradient(&p);
        let (slow, g_slow) = pdc.square_rim_distance(&p);
        assert!(fast > 0.0);
        assert_relative_eq!(fast, slow, epsilon = 1e-12);
        assert_relative_eq!(g_fast, g_slow, epsilon = 1e-9);
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 192, ..ProptestConfig::default() })]

    #[test]
    fn signed_distance_matches_dense_slices(pdc in pdc_strategy(), p in v3(4.0)) {
        let (dense, slack) = dense_point(&pdc, &p, 4000);
        let d = pdc.signed_distance(&p);
        prop_assert!(d <= dense + 1e-9, "{d} above dense {dense}");
        prop_assert!(d >= dense - slack - 1e-9, "{d} below dense {dense}");
        // The square rim is within √2 of the Euclidean distance outside.
        if d > 0.0 {
            let euclid = (0..=4000)
                .map(|j| slice_distance(&pdc, &p, j as f64 / 4000.0, false))
                .fold(f64::INFINITY, f64::min);
            prop_assert!(euclid >= d - slack - 1e-9 && euclid <= SQRT_2 * d + slack + 1e-9,
                "euclid {euclid}, square rim {d}");
        }
    }

    #[test]
    fn gradient_matches_finite_differences(pdc in pdc_strategy(), p in v3(4.0)) {
        let (d, g) = pdc.distance_and_gradient(&p);
        prop_assume!(d.abs() > 0.02);
        prop_assert!(g.norm() <= 1.0 + 1e-9, "|g| = {}", g.norm());
        let h = 1e-6;
        for i in 0..3 {
            let mut e = Vec3::zeros();
            e[i] = h;
            let (up, down) = (pdc.signed_distance(&(p + e)), pdc.signed_distance(&(p - e)));
            // Skip kinks (where the one-sided slopes disagree).
            prop_assume!(((up - d) - (d - down)).abs() < 1e-9);
            let fd = trust_numdiff::central_difference(|s| pdc.signed_distance(&(p + Vec3::ith(i, s))), 0.0, h);
            prop_assert!((fd - g[i]).abs() < 1e-5, "axis {i}: fd {fd} vs {}", g[i]);
        }
    }

    #[test]
    fn point_clear_agrees_with_signed_distance(pdc in pdc_strategy(), p in v3(4.0), clearance in -0.2..0.5f64) {
        let d = pdc.signed_distance(&p);
        prop_assume!((d - clearance - CLEAR_TOLERANCE).abs() > 1e-9);
        prop_assert_eq!(pdc.point_clear(&p, clearance), d > clearance + CLEAR_TOLERANCE);
        prop_assert_eq!(pdc.contains(&p), !pdc.point_clear(&p, 0.0));
    }

    /// The segment test of every path (sphere, cylinder core, cylinder polygon) against dense
    /// `(s, λ)` sampling of the slices: a sampled hit is always reported, and a reported block is
    /// real up to the grid's slack.
    #[test]
    fn segment_clear_agrees_with_dense_sampling(
        pdc in pdc_strategy(), a in v3(4.0), b in v3(4.0), clearance in -0.2..0.5f64,
    ) {
        let clear = pdc.segment_clear(&a, &b, clearance);
        let (dense, slack) = dense_segment(&pdc, &a, &b, 120);
        if dense < clearance - 1e-9 {
            prop_assert!(!clear, "dense min {dense} < clearance {clearance} but reported clear");
        }
        if !clear {
            prop_assert!(dense <= clearance + slack + 1e-9,
                "blocked but dense min {dense} > clearance {clearance} + slack {slack}");
        }
    }

    /// Whatever the window, the cone contains the forecast obstacle at every time of it.
    #[test]
    fn segment_clear_never_misses_the_forecast(
        pdc in pdc_strategy(), a in v3(4.0), b in v3(4.0), clearance in 0.0..0.5f64,
    ) {
        prop_assume!(pdc.segment_clear(&a, &b, clearance));
        let f = pdc.forecast();
        for i in 0..=60 {
            let x = a + (b - a) * (i as f64 / 60.0);
            for j in 0..=60 {
                let t = pdc.t_start() + pdc.horizon() * j as f64 / 60.0;
                prop_assert!(f.signed_distance(&x, t) >= clearance - 1e-9);
            }
        }
    }

    #[test]
    fn surface_samples_lie_on_the_offset_surface(
        pdc in pdc_strategy(), slices in 1usize..6, per_slice in 1usize..9, margin in 0.0..0.5f64,
        lo in v3(4.0), size in v3(3.0),
    ) {
        let region = Aabb { min: lo, max: lo + size.abs() + Vec3::repeat(0.5) };
        let samples = pdc.surface_samples(slices, per_slice, margin, &region).unwrap();
        prop_assert!(samples.len() <= slices * per_slice + 2);
        for s in &samples {
            prop_assert!(region.contains(s));
            let d = pdc.signed_distance(s);
            prop_assert!((d - margin).abs() < 1e-6, "d = {d}, margin {margin}");
        }
    }

    #[test]
    fn aabb_contains_the_cone(pdc in pdc_strategy(), dirs in proptest::collection::vec(v3(1.0), 8)) {
        let b = pdc.aabb();
        for (j, dir) in dirs.iter().enumerate() {
            let (c, r, h) = slice(&pdc, j as f64 / 7.0);
            let corner = c + Vec3::new(r, r, h).component_mul(&dir.map(f64::signum));
            prop_assert!(b.inflated(1e-9).contains(&corner));
        }
    }

    /// The support point lies on the cone and no slice reaches farther along `d`.
    #[test]
    fn support_points_are_extreme_points_of_the_cone(pdc in pdc_strategy(), d in v3(2.0)) {
        prop_assume!(d.norm() > 1e-3);
        let s = pdc.support(&d);
        prop_assert!(pdc.signed_distance(&s).abs() < 1e-6, "{}", pdc.signed_distance(&s));
        let cylinder = matches!(pdc.forecast().shape, ObstacleShape::Cylinder { .. });
        for j in 0..=100 {
            let (c, r, h) = slice(&pdc, j as f64 / 100.0);
            let reach = if cylinder {
                c.dot(&d) + r * d.x.hypot(d.y) + h * d.z.abs()
            } else {
                c.dot(&d) + r * d.norm()
            };
            prop_assert!(reach <= s.dot(&d) + 1e-9 * (1.0 + d.norm()));
        }
    }

    /// The fast paths (cutting planes for spheres and in the cylinder core) against the closed-form
    /// minimum over the `(s, λ)` square or polygon, which is exact: the same answer except within
    /// `1e-7` of the clearance.
    #[test]
    fn fast_segment_tests_agree_with_the_closed_form(
        pdc in pdc_strategy(), a in v3(4.0), b in v3(4.0), clearance in 0.0..0.5f64,
    ) {
        let clear = pdc.segment_clear(&a, &b, clearance);
        let c = clearance + CLEAR_TOLERANCE;
        let (reference_clear_above, reference_clear_below) = match pdc.forecast().shape {
            ObstacleShape::Sphere => {
                let [(ca, ra, _), (cb, rb, _)] = pdc.ends();
                let square = [
                    Vec2::new(0.0, 0.0),
                    Vec2::new(1.0, 0.0),
                    Vec2::new(1.0, 1.0),
                    Vec2::new(0.0, 1.0),
                ];
                let f = |k0: f64| NormMinusAffine2d { m: a - ca, mx: b - a, my: ca - cb, k0, k: Vec2::new(0.0, rb - ra) };
                (
                    min_over_convex_polygon(&f(ra + c + 1e-7), &square) > 0.0,
                    min_over_convex_polygon(&f(ra + c - 1e-7), &square) > 0.0,
                )
            }
            ObstacleShape::Cylinder { .. } => (
                pdc.cylinder_segment_clear(&a, &b, c + 1e-7),
                pdc.cylinder_segment_clear(&a, &b, c - 1e-7),
            ),
        };
        if reference_clear_above {
            prop_assert!(clear, "the closed form is clear at clearance + 1e-7");
        }
        if !reference_clear_below {
            prop_assert!(!clear, "the closed form is blocked at clearance - 1e-7");
        }
    }

    /// E1's obstacles: cylinders taller than the region moving horizontally, segments inside the
    /// region — every test takes the core's 2-D path, and agrees with the polygon.
    #[test]
    fn core_segment_tests_agree_with_the_polygon(
        p0 in v3(3.0), v in (-2.0..2.0f64, -2.0..2.0f64), r_o in 0.3..1.5f64, mu in 0.0..0.4f64,
        horizon in 0.0..3.0f64, a in v3(5.0), b in v3(5.0), clearance in 0.0..0.5f64,
    ) {
        let f = Forecast::new(
            ObstacleShape::Cylinder { half_height: 5.0 },
            Vec3::new(p0.x, p0.y, 0.0),
            Vec3::new(v.0, v.1, 0.0),
            0.0,
            r_o,
            0.0,
            mu,
        ).unwrap();
        let pdc = f.pdc(horizon).unwrap();
        let c = clearance + CLEAR_TOLERANCE;
        let clear = pdc.segment_clear(&a, &b, clearance);
        if pdc.cylinder_segment_clear(&a, &b, c + 1e-7) {
            prop_assert!(clear);
        }
        if !pdc.cylinder_segment_clear(&a, &b, c - 1e-7) {
            prop_assert!(!clear);
        }
    }

    /// The temporal chord test of a forecast is the cone of a zero-length window, and matches dense
    /// sampling of the obstacle at that instant.
    #[test]
    fn forecast_segment_clear_is_the_instant_cone(
        pdc in pdc_strategy(), t in -1.0..3.0f64, a in v3(4.0), b in v3(4.0), clearance in 0.0..0.5f64,
    ) {
        let f = pdc.forecast();
        let clear = f.segment_clear(&a, &b, t, clearance);
        prop_assert_eq!(clear, Pdc::at_time(f, t).unwrap().segment_clear(&a, &b, clearance));
        let dense = (0..=400)
            .map(|i| f.signed_distance(&(a + (b - a) * (i as f64 / 400.0)), t))
            .fold(f64::INFINITY, f64::min);
        if dense < clearance {
            prop_assert!(!clear);
        }
        prop_assert!(!f.segment_clear(&a, &b, f64::NAN, clearance));
    }

    #[test]
    fn round_cone_gradient_matches_finite_differences(
        a in v3(4.0), b in v3(4.0), ra in 0.1..2.0f64, rb in 0.1..2.0f64, p in v3(4.0)
    ) {
        let (d, g) = round_cone_sdf(&a, &b, ra, rb, &p);
        prop_assume!(d > 0.05);
        prop_assert!((g.norm() - 1.0).abs() < 1e-9);
        let fd = Vec3::from(trust_numdiff::gradient_array(
            |q| round_cone_sdf(&a, &b, ra, rb, &Vec3::from(q)).0,
            p.into(),
            1e-6,
        ));
        prop_assert!((fd - g).norm() < 1e-4, "{fd:?} vs {g:?}");
    }
}

/// Growth that stops inside the window: every slice stays inside the cone (a cone growing
/// linearly between the end radii would cut the slices just after the stop).
#[test]
fn a_cone_whose_growth_stops_inside_the_window_contains_every_slice() {
    let f = Forecast::sphere(Vec3::zeros(), Vec3::new(2.0, 0.0, 0.0), 0.0, 0.5, 0.1, 1.0)
        .unwrap()
        .with_growth_for(0.5);
    let pdc = Pdc::over_window(&f, 0.0, 2.0).unwrap();
    for k in 0..=40 {
        let t = 2.0 * k as f64 / 40.0;
        let side = f.center(t) + Vec3::new(0.0, f.radius(t) - 1e-9, 0.0);
        assert!(pdc.contains(&side), "slice at t = {t} leaks");
    }
}
