//! Regression tests for the bugs `cargo xtask fuzz` (crates/fuzz) and issue 11 found at the edges of
//! f64, each named after the bug.

use trust_geometry::{
    Aabb, GeometryError, Shape, Sphere, StaticMap, Vec3, box_sdf, cylinder_sdf, scale, sphere_sdf,
};

fn cloud_map() -> StaticMap {
    let bounds = Aabb::new(Vec3::new(-10.0, -10.0, 0.0), Vec3::new(10.0, 10.0, 5.0)).unwrap();
    let cloud: Vec<Vec3> = (0..50)
        .map(|i| Vec3::new(2.0, -3.0 + 0.1 * f64::from(i), 1.0))
        .collect();
    StaticMap::new(bounds)
        .unwrap()
        .with_point_cloud(&cloud, 0.25)
        .unwrap()
}

#[test]
fn esdf_segment_clear_whose_length_overflows_returns_not_clear() {
    // Issue 11: the step count became infinite and the tracer never returned.
    let map = cloud_map();
    assert!(!map.segment_clear(&Vec3::zeros(), &Vec3::new(1e155, 0.0, 0.0), 0.0));
    assert!(!map.segment_clear(
        &Vec3::new(-1e300, 0.0, 0.0),
        &Vec3::new(1e300, 0.0, 0.0),
        0.1
    ));
}

#[test]
fn segment_clear_at_1e300_does_not_reach_parry() {
    // Issue 11: parry's GJK asserted that a bound is finite. Shapes that far out are rejected at
    // construction, and segment ends beyond the scale policy are "not clear".
    let e = Sphere::new(Vec3::new(1e300, 0.0, 0.0), 1.0).unwrap_err();
    assert!(e.to_string().contains("sphere.center.x"), "{e}");
    assert!(e.to_string().contains("1.0e300"), "{e}");
    let bounds = Aabb::new(Vec3::repeat(-1e6), Vec3::repeat(1e6)).unwrap();
    let s = Sphere::new(Vec3::new(1e6, 1e6, 1e6), 1e6).unwrap();
    let map = StaticMap::from_shapes(bounds, vec![s.into()]).unwrap();
    assert!(!map.segment_clear(&Vec3::repeat(1e300), &Vec3::repeat(-1e300), 0.0));
}

#[test]
fn long_segment_through_sphere_centre_is_blocked() {
    // Issue 11: reported clear once the segment was long enough.
    let bounds = Aabb::new(Vec3::repeat(-1e6), Vec3::repeat(1e6)).unwrap();
    for (c, r) in [
        (Vec3::new(-33912.478, 1e-9, -68754.667), 1e-3),
        (Vec3::new(0.5, 0.25, 0.125), 0.01),
        (Vec3::new(9e5, -9e5, 1.0), 1e-2),
    ] {
        let map = StaticMap::from_shapes(bounds, vec![Sphere::new(c, r).unwrap().into()]).unwrap();
        for len in [1.0, 1e3, 1e5, 9e5] {
            let d = Vec3::new(0.3, -0.5, 0.81).normalize() * len;
            let (a, b) = (c - d, c + d);
            assert!(!map.segment_clear(&a, &b, 0.0), "{c:?} r {r} len {len}");
        }
    }
}

#[test]
fn distance_queries_beyond_query_limit_are_not_free_never_nan() {
    // Fuzz: an infinite or 1e300 query point gave inf/inf = NaN gradients.
    let c = Vec3::new(1.0, 2.0, 3.0);
    for p in [
        Vec3::new(f64::NEG_INFINITY, 2.0, 0.0),
        Vec3::new(1e300, -1e155, 0.0),
        Vec3::new(f64::NAN, 0.0, 0.0),
    ] {
        let outs = [
            sphere_sdf(&c, 1.0, &p),
            cylinder_sdf(&c, 1.0, 2.0, &p),
            box_sdf(&c, &(c + Vec3::repeat(1.0)), &p),
            Shape::from(Sphere::new(c, 1.0).unwrap()).distance_and_gradient(&p),
        ];
        for (d, g) in outs {
            assert_eq!(d, f64::NEG_INFINITY);
            assert_eq!(g, Vec3::zeros());
        }
    }
    // Huge but finite shape parameters through the free functions.
    let (d, g) = cylinder_sdf(&Vec3::new(1e155, 0.0, 0.0), 1.0, f64::MAX, &c);
    assert!(!d.is_nan() && g.iter().all(|x| !x.is_nan()));
}

#[test]
fn out_of_scale_errors_name_field_value_and_range() {
    let e = Aabb::new(Vec3::zeros(), Vec3::new(f64::MAX, 1.0, 1.0)).unwrap_err();
    assert!(matches!(e, GeometryError::Scale(_)), "{e:?}");
    let msg = e.to_string();
    assert!(msg.contains("aabb.max.x"), "{msg}");
    assert!(msg.contains("1.7976931348623157e308"), "{msg}");
    assert!(msg.contains("[-1.0e6, 1.0e6] m"), "{msg}");
    // Bounds built directly (public fields) are validated by the map.
    let raw = Aabb {
        min: Vec3::repeat(-1e300),
        max: Vec3::repeat(1e300),
    };
    assert!(matches!(StaticMap::new(raw), Err(GeometryError::Scale(_))));
    // Sizes have the same range.
    let e = Sphere::new(Vec3::zeros(), 2e6).unwrap_err();
    assert!(e.to_string().contains("sphere.radius"), "{e}");
    assert!(scale::Quantity::Length.accepts(1e6));
}

#[test]
fn negative_zero_sizes_do_not_trip_parry_assertions() {
    // Fuzz case 4898001090487889764: a cylinder with half_height -0.0 passed validation, then
    // parry asserted `half_height.is_sign_positive()` in `segment_clear`.
    let bounds = Aabb::new(Vec3::repeat(-10.0), Vec3::repeat(10.0)).unwrap();
    let shapes: Vec<Shape> = vec![
        trust_geometry::Cylinder::new(Vec3::zeros(), -0.0, -0.0)
            .unwrap()
            .into(),
        Sphere::new(Vec3::new(1.0, 0.0, 0.0), -0.0).unwrap().into(),
        trust_geometry::AaBox::new(Vec3::new(2.0, 0.0, 0.0), Vec3::new(2.0, 0.0, 0.0))
            .unwrap()
            .into(),
    ];
    let map = StaticMap::from_shapes(bounds, shapes).unwrap();
    assert!(!map.segment_clear(&Vec3::new(-5.0, 0.0, 0.0), &Vec3::new(5.0, 0.0, 0.0), 0.0));
    assert!(map.segment_clear(&Vec3::new(-5.0, 5.0, 0.0), &Vec3::new(5.0, 5.0, 0.0), 0.0));
}

#[test]
fn voxel_grid_above_the_cap_is_an_error_before_allocating() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::repeat(1e3)).unwrap();
    let e = StaticMap::new(bounds)
        .unwrap()
        .with_point_cloud(&[Vec3::repeat(1.0)], 0.1)
        .unwrap_err();
    assert!(matches!(e, GeometryError::GridTooLarge { .. }), "{e:?}");
}

/// A point on the surface of each shape kind (sphere, cylinder side and cap rim, box face, edge and
/// corner) with the outward direction there.
fn touching_points() -> Vec<(Shape, Vec3, Vec3)> {
    use trust_geometry::{AaBox, Cylinder};
    let sphere = Sphere::new(Vec3::new(3.0, 2.0, 2.0), 1.5).unwrap();
    let cyl = Cylinder::new(Vec3::new(-5.0, 4.0, 4.0), 1.0, 2.0).unwrap();
    let bx = AaBox::new(Vec3::new(6.0, -8.0, 1.0), Vec3::new(9.0, -5.0, 4.0)).unwrap();
    let x = Vec3::x();
    let diag2 = Vec3::new(1.0, 0.0, 1.0).normalize();
    let diag3 = Vec3::new(1.0, 1.0, 1.0).normalize();
    vec![
        (sphere.into(), Vec3::new(4.5, 2.0, 2.0), x),
        (cyl.into(), Vec3::new(-4.0, 4.0, 4.0), x),
        (cyl.into(), Vec3::new(-5.0, 4.0, 6.0), Vec3::z()),
        (cyl.into(), Vec3::new(-4.0, 4.0, 6.0), diag2),
        (bx.into(), Vec3::new(9.0, -6.5, 2.5), x),
        (bx.into(), Vec3::new(9.0, -6.5, 4.0), diag2),
        (bx.into(), Vec3::new(9.0, -5.0, 4.0), diag3),
    ]
}

#[test]
fn segment_clear_at_clearance_0_touching_is_blocked_for_every_length() {
    // Issue 18: a zero-length segment touching a sphere at clearance 0 was clear (it fell back to
    // `is_free`, which accepts distance == clearance) while a 1 µm segment there was blocked.
    let bounds = Aabb::new(Vec3::new(-20.0, -20.0, 0.0), Vec3::new(20.0, 20.0, 8.0)).unwrap();
    for (shape, p, out) in touching_points() {
        let map = StaticMap::from_shapes(bounds, vec![shape]).unwrap();
        assert!(map.signed_distance(&p).abs() < 1e-12, "{shape:?} at {p:?}");
        for len in [0.0, 1e-12, 1e-9, 1e-6, 1e-3, 1.0] {
            for dir in [out, -out, out.cross(&Vec3::new(0.3, 0.5, 0.7)).normalize()] {
                assert!(
                    !map.segment_clear(&p, &(p + dir * len), 0.0),
                    "{shape:?}: segment of {len} m from the touching point {p:?} along {dir:?} \
                     reported clear"
                );
                assert!(!map.segment_clear(&(p + dir * len), &p, 0.0));
            }
        }
        // Just outside: clear for 0 m and for a tiny segment leading away, alike.
        let q = p + out * 1e-3;
        for len in [0.0, 1e-9, 1e-6] {
            assert!(
                map.segment_clear(&q, &(q + out * len), 0.0),
                "{shape:?}: {len} m at 1 mm outside reported blocked"
            );
        }
    }
}

#[test]
fn esdf_segment_clear_is_consistent_between_zero_and_tiny_lengths() {
    // Issue 18 (ESDF side): the tracer demanded `resolution / 1000` of slack at its first sample
    // but none at a zero-length segment's point, so a point at the zero level was clear as a
    // 0 m segment and blocked as a 1 µm one.
    // A wall three voxels thick, so that the field goes negative inside it.
    let bounds = Aabb::new(Vec3::new(-10.0, -10.0, 0.0), Vec3::new(10.0, 10.0, 5.0)).unwrap();
    let mut cloud = Vec::new();
    for i in 0..50 {
        for j in 0..4 {
            for k in 0..12 {
                cloud.push(Vec3::new(
                    1.8 + 0.2 * f64::from(j),
                    -3.0 + 0.1 * f64::from(i),
                    0.2 * f64::from(k),
                ));
            }
        }
    }
    let map = StaticMap::new(bounds)
        .unwrap()
        .with_point_cloud(&cloud, 0.25)
        .unwrap();
    let esdf = map.esdf().unwrap();
    // Walk from free space towards the wall of points at x = 2 and find the zero level.
    let (mut lo, mut hi) = (Vec3::new(0.0, -1.0, 1.0), Vec3::new(2.2, -1.0, 1.0));
    assert!(esdf.signed_distance(&lo) > 0.0 && esdf.signed_distance(&hi) < 0.0);
    for _ in 0..200 {
        let mid = (lo + hi) * 0.5;
        if esdf.signed_distance(&mid) > 0.0 {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    for p in [lo, hi] {
        assert!(esdf.signed_distance(&p).abs() < 1e-9);
        for len in [0.0, 1e-12, 1e-9, 1e-6] {
            assert!(
                !map.segment_clear(&p, &(p + Vec3::new(-len, 0.0, 0.0)), 0.0),
                "{len} m at the zero level reported clear"
            );
        }
    }
    // Points along the approach: the 0 m verdict equals the 1e-9 m verdict at every clearance.
    for k in 0..=400 {
        let p = Vec3::new(0.005 * f64::from(k), -1.0, 1.0);
        for clearance in [0.0, 0.1, 0.5] {
            let point = map.segment_clear(&p, &p, clearance);
            let tiny = map.segment_clear(&p, &(p - Vec3::new(1e-9, 0.0, 0.0)), clearance);
            assert_eq!(point, tiny, "at {p:?}, clearance {clearance}");
        }
    }
}

#[test]
fn count_and_grid_errors_print_readable_numbers() {
    // Issue 18: ESDF voxel counts and UVD point counts were 31–32-digit integers.
    let dims = [usize::MAX / 4, usize::MAX / 4, 3];
    let msg = trust_geometry::checked_voxel_count(dims)
        .unwrap_err()
        .to_string();
    assert!(msg.contains("e18") && msg.contains("e37"), "{msg}");
    let longest_digit_run = msg
        .split(|c: char| !c.is_ascii_digit())
        .map(str::len)
        .max()
        .unwrap_or(0);
    assert!(longest_digit_run <= 17, "{msg}");
}

#[test]
fn segment_clear_at_a_point_the_sdf_calls_touching_a_far_reaching_box_is_blocked() {
    // Fuzz (params::geometry::segment_clear_at_contact): a box reaching z = -1e6 rounds its
    // distance at ~1e-10 m, so a point 2e-11 m above its top is at distance 0 — touching — but
    // the broad phase, widened by the segment's ulps only, missed the box and called the
    // zero-length segment there clear.
    use trust_geometry::AaBox;
    let bx = AaBox::new(
        Vec3::new(-16.94189701270734, 8.33464692706599, -1e6),
        Vec3::new(15.502680238787654, 12.724988403958179, 4.068994616835775),
    )
    .unwrap();
    let bounds = Aabb::new(Vec3::new(-20.0, -20.0, 0.0), Vec3::new(20.0, 20.0, 8.0)).unwrap();
    let map = StaticMap::from_shapes(bounds, vec![bx.into()]).unwrap();
    let p = Vec3::new(-0.6618626225788837, 8.503699502489226, 4.068994616858216);
    assert!(map.signed_distance(&p) <= 0.0);
    for len in [0.0, 1e-12, 1e-9, 1e-6] {
        assert!(!map.segment_clear(&p, &(p + Vec3::z() * len), 0.0), "{len}");
    }
}
