//! Public-API tests for trust-geometry: building maps, the documented conventions, serde.

use approx::assert_relative_eq;
use trust_geometry::{
    AaBox, Aabb, Cylinder, Esdf, GeometryError, Shape, Sphere, StaticMap, Vec3, box_sdf,
    cylinder_sdf, cylinder_sdf_with_size_gradient, edt_1d, edt_3d, sphere_sdf, voxel_index,
};

fn v(x: f64, y: f64, z: f64) -> Vec3 {
    Vec3::new(x, y, z)
}

fn world() -> Aabb {
    Aabb::new(v(0.0, 0.0, 0.0), v(10.0, 10.0, 5.0)).unwrap()
}

#[test]
fn mixed_map_combines_shapes_and_point_cloud() {
    let sphere = Sphere::new(v(2.0, 2.0, 2.0), 1.0).unwrap();
    // A wall of points filling the voxels between x = 7.0 and 7.1 (one voxel thick).
    let mut wall = Vec::new();
    for j in 0..100 {
        for k in 0..50 {
            wall.push(v(7.05, 0.05 + 0.1 * j as f64, 0.05 + 0.1 * k as f64));
        }
    }
    let map = StaticMap::from_shapes(world(), vec![sphere.into()])
        .unwrap()
        .with_point_cloud(&wall, 0.1)
        .unwrap();
    assert_eq!(map.resolution(), 0.1);
    assert!(!map.has_no_obstacles());
    // Near the sphere, its exact distance wins.
    let (d, g) = map.distance_and_gradient(&v(4.0, 2.0, 2.0));
    assert_relative_eq!(d, 1.0, epsilon = 1e-12);
    assert_relative_eq!(g, v(1.0, 0.0, 0.0), epsilon = 1e-12);
    // Near the wall, the ESDF: distances between voxel centres (the wall's centres are at
    // x = 7.05), zero level on the voxel faces x = 7.0 and x = 7.1.
    assert_relative_eq!(
        map.signed_distance(&v(6.05, 5.05, 2.05)),
        1.0,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        map.signed_distance(&v(6.0, 5.05, 2.05)),
        1.05,
        epsilon = 1e-9
    );
    assert_relative_eq!(map.signed_distance(&v(7.0, 3.0, 1.0)), 0.0, epsilon = 1e-9);
    assert_relative_eq!(
        map.signed_distance(&v(7.05, 5.05, 2.05)),
        -0.1,
        epsilon = 1e-9
    );
    assert_relative_eq!(
        map.distance_and_gradient(&v(6.5, 3.0, 1.0)).1,
        v(-1.0, 0.0, 0.0),
        epsilon = 1e-9
    );
    assert!(map.is_free(&v(5.0, 5.0, 2.0), 1.5));
    assert!(!map.segment_clear(&v(5.0, 5.0, 2.0), &v(9.0, 5.0, 2.0), 0.0));
    assert!(map.segment_clear(&v(5.0, 5.0, 2.0), &v(5.0, 9.0, 2.0), 0.5));
    let mut out = Vec::new();
    map.shapes_near(
        &Aabb::from_segment(&v(0.0, 0.0, 0.0), &v(1.5, 1.5, 1.5)),
        &mut out,
    );
    assert_eq!(out, vec![0]);
    // The restricted query agrees with the full one when the right shapes are listed.
    let p = v(3.5, 2.5, 2.0);
    assert_eq!(
        map.distance_and_gradient_among(&p, &out),
        map.distance_and_gradient(&p)
    );
    assert!(map.distance_and_gradient_among(&p, &[]).0 > map.signed_distance(&p));
    assert_eq!(
        map.distance_and_gradient_among(&p, &[99]).0,
        map.distance_and_gradient_among(&p, &[]).0
    );
}

#[test]
fn large_map_queries_use_the_bvh_and_agree_with_brute_force() {
    let mut shapes = Vec::new();
    for i in 0..1000 {
        let (x, y) = ((i % 40) as f64 * 2.5, (i / 40) as f64 * 2.5);
        let s: Shape = match i % 3 {
            0 => Sphere::new(v(x, y, 2.0), 0.5).unwrap().into(),
            1 => Cylinder::new(v(x, y, 2.0), 0.4, 2.0).unwrap().into(),
            _ => AaBox::from_center_half_extents(v(x, y, 1.0), v(0.3, 0.6, 1.0))
                .unwrap()
                .into(),
        };
        shapes.push(s);
    }
    let bounds = Aabb::new(v(-5.0, -5.0, 0.0), v(105.0, 70.0, 5.0)).unwrap();
    let map = StaticMap::from_shapes(bounds, shapes.clone()).unwrap();
    for k in 0..200 {
        let p = v(
            (k * 37 % 100) as f64 + 0.31,
            (k * 53 % 64) as f64 + 0.17,
            (k % 5) as f64 + 0.5,
        );
        let brute = shapes
            .iter()
            .map(|s| s.signed_distance(&p))
            .fold(f64::INFINITY, f64::min);
        assert_eq!(map.signed_distance(&p), brute, "at {p:?}");
    }
}

#[test]
fn free_functions_match_the_shapes() {
    let p = v(0.3, -1.2, 2.5);
    let s = Sphere::new(v(0.0, 0.0, 1.0), 0.7).unwrap();
    assert_eq!(
        s.distance_and_gradient(&p),
        sphere_sdf(&s.center, s.radius, &p)
    );
    let c = Cylinder::new(v(0.0, 0.0, 1.0), 0.7, 0.4).unwrap();
    assert_eq!(
        c.distance_and_gradient(&p),
        cylinder_sdf(&c.center, c.radius, c.half_height, &p)
    );
    let full = cylinder_sdf_with_size_gradient(&c.center, c.radius, c.half_height, &p);
    assert!(full.d_radius <= 0.0 && full.d_half_height <= 0.0);
    let b = AaBox::new(v(-1.0, -1.0, 0.0), v(1.0, 1.0, 1.0)).unwrap();
    assert_eq!(b.distance_and_gradient(&p), box_sdf(&b.min, &b.max, &p));
}

#[test]
fn edt_building_blocks() {
    let f = [f64::INFINITY, 0.0, f64::INFINITY, f64::INFINITY, 1.0];
    let mut out = [0.0; 5];
    edt_1d(&f, &mut out);
    assert_eq!(out, [1.0, 0.0, 1.0, 2.0, 1.0]);
    let dims = [3, 3, 3];
    let mut grid = vec![f64::INFINITY; 27];
    grid[voxel_index(dims, 0, 0, 0)] = 0.0;
    edt_3d(&mut grid, dims).unwrap();
    assert_eq!(grid[voxel_index(dims, 2, 2, 2)], 12.0);
    assert_eq!(grid[voxel_index(dims, 1, 2, 0)], 5.0);
    let mut occupied = vec![false; 27];
    occupied[voxel_index(dims, 1, 1, 1)] = true;
    let esdf = Esdf::from_occupancy(Vec3::zeros(), 0.5, dims, &occupied).unwrap();
    assert_eq!(esdf.voxel_distance(0, 0, 0), Some(0.5 * 3f64.sqrt()));
    assert_eq!(esdf.voxel_distance(1, 1, 1), Some(-0.5));
}

#[test]
fn errors_name_the_field_and_value() {
    let cases: Vec<(Result<(), GeometryError>, &str)> = vec![
        (
            Aabb::new(v(1.0, 0.0, 0.0), v(0.0, 1.0, 1.0)).map(drop),
            "aabb: min.x = 1 exceeds max.x = 0",
        ),
        (
            Sphere::new(Vec3::zeros(), f64::NAN).map(drop),
            "sphere.radius must be finite, got NaN",
        ),
        (
            Cylinder::new(Vec3::zeros(), 1.0, -2.0).map(drop),
            "cylinder.half_height must be >= 0, got -2",
        ),
        (
            StaticMap::new(Aabb::new(Vec3::zeros(), v(0.0, 1.0, 1.0)).unwrap()).map(drop),
            "zero extent along x",
        ),
        (
            StaticMap::new(world())
                .unwrap()
                .with_point_cloud(&[], 0.0)
                .map(drop),
            "resolution must be > 0, got 0",
        ),
        (
            StaticMap::new(world())
                .unwrap()
                .with_point_cloud(&[], 1e-3)
                .map(drop),
            "voxel grid of 10000 x 10000 x 5000",
        ),
        (
            StaticMap::new(world())
                .unwrap()
                .with_point_cloud(&[v(1.0, 1.0, 1.0), v(1.0, f64::INFINITY, 1.0)], 0.5)
                .map(drop),
            "points[1].y must be finite, got inf",
        ),
    ];
    for (result, expected) in cases {
        let e = result.unwrap_err();
        assert!(
            e.to_string().contains(expected),
            "{e} should contain {expected}"
        );
    }
}

#[test]
fn shapes_round_trip_through_serde_and_validate_on_load() {
    let shapes: Vec<Shape> = vec![
        Sphere::new(v(1.0, 2.0, 3.0), 0.5).unwrap().into(),
        Cylinder::new(v(0.0, 0.0, 1.0), 0.3, 1.0).unwrap().into(),
        AaBox::new(v(0.0, 0.0, 0.0), v(1.0, 2.0, 3.0))
            .unwrap()
            .into(),
    ];
    let json = serde_json::to_string(&shapes).unwrap();
    assert!(
        json.contains(r#""kind":"sphere""#) && json.contains(r#""kind":"box""#),
        "{json}"
    );
    let back: Vec<Shape> = serde_json::from_str(&json).unwrap();
    assert_eq!(back, shapes);
    let bad = r#"{"kind":"sphere","center":[0,0,0],"radius":-1}"#;
    let e = serde_json::from_str::<Shape>(bad).unwrap_err();
    assert!(
        e.to_string().contains("sphere.radius must be >= 0, got -1"),
        "{e}"
    );
    let unknown = r#"{"kind":"sphere","center":[0,0,0],"radius":1,"colour":"red"}"#;
    assert!(serde_json::from_str::<Shape>(unknown).is_err());
    let inverted = r#"{"min":[0,0,1],"max":[1,1,0]}"#;
    assert!(serde_json::from_str::<Aabb>(inverted).is_err());
    let aabb: Aabb = serde_json::from_str(r#"{"min":[0,0,0],"max":[1,1,1]}"#).unwrap();
    assert_eq!(aabb.extent(), v(1.0, 1.0, 1.0));
}
