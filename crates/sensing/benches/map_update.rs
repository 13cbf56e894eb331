//! One 160 × 120 depth frame into the online map, stage by stage: the ray cast against a
//! forest-like static map (trees as cylinders, a ground slab, two office-like walls), the
//! occupancy update (log-odds, free space by the 3-D DDA along each ray, or by projecting the
//! frustum's voxels into the depth image: `LocalMap::integrate_depth_frame`) and the
//! incremental distance field.
//!
//! Before measuring, the bench flies the camera through the forest at 2 m/s and 30 frames per
//! second (90 frames; 30 under `--test`) with the default map (112 × 112 × 48 voxels of 0.1 m,
//! field truncated at 1 m) and prints the median, p90 and maximum of each stage over the
//! flight's frames (the first, cold frame apart), for the exact ray update, for Fast-Planner's
//! stop-at-visited shortcut and for the projective update (same poses, same noise). Criterion then measures the steady frame (the next frame of that
//! flight, from a copy of the map) and the cold one (a first frame into an empty map); the
//! target is a whole map update (occupancy + distance) of one frame within 2 ms.

use std::time::Instant;

use criterion::{BatchSize, Criterion, criterion_group, criterion_main};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use trust_geometry::{AaBox, Aabb, Cylinder, Shape, StaticMap, Vec3};
use trust_sensing::{
    DepthCamera, DepthCameraParams, LocalMap, LocalMapParams, Pose, RaySensor, Scan, Truth,
};

const HEIGHT_M: f64 = 1.2;
const SPEED_M_S: f64 = 2.0;

fn forest() -> StaticMap {
    let mut rng = ChaCha8Rng::seed_from_u64(34);
    let bounds = Aabb::new(Vec3::new(-20.0, -15.0, -1.0), Vec3::new(20.0, 15.0, 6.0)).unwrap();
    let mut shapes: Vec<Shape> = vec![
        AaBox::new(Vec3::new(-20.0, -15.0, -1.0), Vec3::new(20.0, 15.0, 0.0))
            .unwrap()
            .into(),
        // Office-like: a wall with a gap on each side of the corridor, ahead.
        AaBox::new(Vec3::new(6.0, -15.0, 0.0), Vec3::new(6.2, -1.5, 3.0))
            .unwrap()
            .into(),
        AaBox::new(Vec3::new(6.0, 1.5, 0.0), Vec3::new(6.2, 15.0, 3.0))
            .unwrap()
            .into(),
    ];
    // About one tree per 5 m², none within 1 m of the flight line y = 0.
    while shapes.len() < 3 + 240 {
        let c = Vec3::new(
            rng.random_range(-20.0..20.0),
            rng.random_range(-15.0..15.0),
            3.0,
        );
        if c.y.abs() < 1.0 {
            continue;
        }
        let r = rng.random_range(0.15..0.4);
        shapes.push(Cylinder::new(c, r, 3.0).unwrap().into());
    }
    StaticMap::from_shapes(bounds, shapes).unwrap()
}

fn pose(frame: usize) -> Pose {
    let x = -10.0 + SPEED_M_S * frame as f64 / 30.0;
    Pose::level(Vec3::new(x, 0.0, HEIGHT_M), 0.0)
}

struct Stages {
    raycast: Vec<f64>,
    recentre: Vec<f64>,
    occupancy: Vec<f64>,
    distance: Vec<f64>,
}

fn ms(t: Instant) -> f64 {
    t.elapsed().as_secs_f64() * 1e3
}

/// Folds one frame into `map`: by the ray walk, or by projection (`projective`).
fn integrate(map: &mut LocalMap, camera: &DepthCamera, pose: &Pose, scan: &Scan, projective: bool) {
    if projective {
        map.integrate_depth_frame(camera, pose, scan).unwrap();
    } else {
        map.integrate_scan(scan).unwrap();
    }
}

/// Flies `frames` frames; returns the per-stage times (ms) and the map before the last frame.
fn fly(
    world: &StaticMap,
    params: LocalMapParams,
    projective: bool,
    frames: usize,
) -> (Stages, LocalMap) {
    let camera = DepthCamera::new(DepthCameraParams::default()).unwrap();
    let truth = Truth::static_only(world);
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let mut map = LocalMap::new(params, &pose(0).position).unwrap();
    let mut scan = Scan::default();
    let mut s = Stages {
        raycast: vec![],
        recentre: vec![],
        occupancy: vec![],
        distance: vec![],
    };
    for f in 0..frames {
        let p = pose(f);
        let t = Instant::now();
        map.recentre(&p.position).unwrap();
        s.recentre.push(ms(t));
        let t = Instant::now();
        camera.scan(&p, &truth, &mut rng, &mut scan).unwrap();
        s.raycast.push(ms(t));
        let t = Instant::now();
        integrate(&mut map, &camera, &p, &scan, projective);
        s.occupancy.push(ms(t));
        let t = Instant::now();
        map.update_distance();
        s.distance.push(ms(t));
    }
    (s, map)
}

fn summary(label: &str, v: &[f64]) -> String {
    let mut v = v.to_vec();
    v.sort_by(f64::total_cmp);
    let q = |q: f64| v[((v.len() as f64 * q) as usize).min(v.len() - 1)];
    format!(
        "{label} median {:.3} ms, p90 {:.3}, max {:.3}",
        q(0.5),
        q(0.9),
        v[v.len() - 1]
    )
}

fn report(world: &StaticMap, params: LocalMapParams, projective: bool, name: &str, frames: usize) {
    let (s, map) = fly(world, params, projective, frames);
    // The first frame is the cold one (everything new); the rest are the steady state.
    let warm = |v: &[f64]| v[1..].to_vec();
    let total: Vec<f64> = (1..frames)
        .map(|i| s.recentre[i] + s.occupancy[i] + s.distance[i])
        .collect();
    eprintln!(
        "map_update {name}, {} steady frames (cold first frame: occupancy {:.3} ms, distance \
         {:.3} ms):\n  {}\n  {}\n  {}\n  {}\n  {}\n  occupied voxels at the end: {}",
        frames - 1,
        s.occupancy[0],
        s.distance[0],
        summary("ray cast   ", &warm(&s.raycast)),
        summary("recentre   ", &warm(&s.recentre)),
        summary("occupancy  ", &warm(&s.occupancy)),
        summary("distance   ", &warm(&s.distance)),
        summary("map update (recentre + occupancy + distance)", &total),
        map.occupied_count(),
    );
}

fn bench_map_update(c: &mut Criterion) {
    let smoke = std::env::args().any(|a| a == "--test");
    let frames = if smoke { 30 } else { 90 };
    let world = forest();
    let exact = LocalMapParams::default();
    let shortcut = LocalMapParams {
        stop_at_visited: true,
        ..exact
    };
    report(&world, exact, false, "exact rays", frames);
    report(&world, shortcut, false, "stop at visited", frames);
    report(&world, exact, true, "projective", frames);

    let camera = DepthCamera::new(DepthCameraParams::default()).unwrap();
    let truth = Truth::static_only(&world);
    let next = pose(frames);
    let mut scan = Scan::default();
    c.bench_function("raycast_160x120_forest", |b| {
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        b.iter(|| camera.scan(&next, &truth, &mut rng, &mut scan).unwrap())
    });
    camera
        .scan(&next, &truth, &mut ChaCha8Rng::seed_from_u64(2), &mut scan)
        .unwrap();
    for (params, projective, tag) in [
        (exact, false, "exact"),
        (shortcut, false, "stop_at_visited"),
        (exact, true, "projective"),
    ] {
        let (_, mut warm) = fly(&world, params, projective, frames);
        warm.recentre(&next.position).unwrap();
        let cam = &camera;
        let (scan, next) = (&scan, &next);
        c.bench_function(&format!("occupancy_160x120_steady_{tag}"), |b| {
            b.iter_batched(
                || warm.clone(),
                |mut m| integrate(&mut m, cam, next, scan, projective),
                BatchSize::LargeInput,
            )
        });
        let mut integrated = warm.clone();
        integrate(&mut integrated, cam, next, scan, projective);
        c.bench_function(&format!("distance_160x120_steady_{tag}"), |b| {
            b.iter_batched(
                || integrated.clone(),
                |mut m| m.update_distance(),
                BatchSize::LargeInput,
            )
        });
        c.bench_function(&format!("map_update_160x120_steady_{tag}"), |b| {
            b.iter_batched(
                || warm.clone(),
                |mut m| {
                    integrate(&mut m, cam, next, scan, projective);
                    m.update_distance()
                },
                BatchSize::LargeInput,
            )
        });
        let empty = LocalMap::new(params, &next.position).unwrap();
        c.bench_function(&format!("map_update_160x120_cold_{tag}"), |b| {
            b.iter_batched(
                || empty.clone(),
                |mut m| {
                    integrate(&mut m, cam, next, scan, projective);
                    m.update_distance()
                },
                BatchSize::LargeInput,
            )
        });
    }
    let mut done = LocalMap::new(exact, &next.position).unwrap();
    done.insert_scan(&scan).unwrap();
    c.bench_function("to_esdf_112x112x48", |b| b.iter(|| done.to_esdf().unwrap()));
}

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(20);
    targets = bench_map_update
}
criterion_main!(benches);
