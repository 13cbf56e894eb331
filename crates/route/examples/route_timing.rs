//! Prints the cells expanded and the route length for several heuristic weights on the bench
//! maps (a measurement aid; timings come from `cargo bench -p trust-route`).

use trust_geometry::Vec3;
use trust_route::scenes::e4_like;
use trust_route::{RouteParams, RoutePlanner};

fn main() {
    let (s, t) = (Vec3::new(2.0, 37.5, 5.0), Vec3::new(248.0, 37.5, 5.0));
    for wall in [false, true] {
        let map = e4_like(0, wall).expect("E4-like map");
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
