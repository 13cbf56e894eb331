//! Prints the cells expanded and the route length for several heuristic weights on the bench
//! maps (a measurement aid; timings come from `cargo bench -p trust-route`).

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, StaticMap, Vec3};
use trust_route::{RouteParams, RoutePlanner};

fn e4_like(seed: u64, wall: bool) -> StaticMap {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut shapes: Vec<Shape> = Vec::new();
    let x = |rng: &mut ChaCha8Rng| rng.random_range(12.0..238.0);
    let y = |rng: &mut ChaCha8Rng| rng.random_range(0.0..75.0);
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), rng.random_range(2.0..8.0));
        let half = Vec3::new(
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..3.0),
            rng.random_range(1.0..4.0),
        );
        shapes.push(AaBox::from_center_half_extents(c, half).unwrap().into());
    }
    for _ in 0..40 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        let half = if rng.random_bool(0.5) {
            Vec3::new(0.3, rng.random_range(2.0..6.0), 10.0)
        } else {
            Vec3::new(rng.random_range(2.0..6.0), 0.3, 10.0)
        };
        shapes.push(AaBox::from_center_half_extents(c, half).unwrap().into());
    }
    for _ in 0..320 {
        let c = Vec3::new(x(&mut rng), y(&mut rng), 10.0);
        shapes.push(
            Cylinder::new(c, rng.random_range(0.3..0.8), 10.0)
                .unwrap()
                .into(),
        );
    }
    if wall {
        let c = Vec3::new(27.0, 37.5, 10.0);
        shapes.push(
            AaBox::from_center_half_extents(c, Vec3::new(0.5, 15.0, 10.0))
                .unwrap()
                .into(),
        );
    }
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(250.0, 75.0, 20.0)).unwrap();
    StaticMap::from_shapes(bounds, shapes).unwrap()
}

fn main() {
    let (s, t) = (Vec3::new(2.0, 37.5, 5.0), Vec3::new(248.0, 37.5, 5.0));
    for wall in [false, true] {
        let map = e4_like(0, wall);
        for w in [1.0, 1.2, 1.5, 2.0, 3.0] {
            let p = RoutePlanner::new(RouteParams {
                heuristic_weight: w,
                ..RouteParams::default()
            })
            .unwrap();
            let t0 = std::time::Instant::now();
            let r = p.plan(&map, &s, &t, 0.3).unwrap();
            println!(
                "wall={wall} w={w}: expanded {} length {:.2} points {} cell {:?} ({:.0} ms, indicative)",
                r.expanded_count(),
                r.length(),
                r.points().len(),
                r.cell_m(),
                t0.elapsed().as_secs_f64() * 1e3
            );
        }
    }
}
