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
