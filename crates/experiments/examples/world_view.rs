//! Builds the world of a scenario, prints what the build took, and writes a top view (x–y) of it:
//! the planner's point cloud (or the static shapes when the planner sees shapes), the moving
//! obstacles at `t = 0` and their true tracks over the first 10 s, start and goal.
//!
//! ```text
//! cargo run --release -p trust-experiments --example world_view -- [SCENARIO] [OUT_DIR] [--seed N] [--voxel M]
//! ```
//!
//! Defaults: `scenarios/e4.toml`, `target/world-view`. `--seed` replaces the scenario's trial
//! seed; `--voxel` the ESDF voxel size of a point-cloud scenario. On Linux the peak resident
//! memory of the process (`VmHWM`) is printed after the build.

use std::path::PathBuf;
use std::process::ExitCode;

use nalgebra::Point2;
use trust_plot::{Bounds, Color, Figure, ForecastRings, MapView, Marker, Shape};
use trust_world::scenario::PointCloudSpec;
use trust_world::{World, sample_shapes};

fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let mut positional = Vec::new();
    let mut seed = None;
    let mut voxel = None;
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--seed" => seed = Some(args.next().ok_or("--seed needs a value")?.parse::<u64>()?),
            "--voxel" => voxel = Some(args.next().ok_or("--voxel needs a value")?.parse::<f64>()?),
            _ => positional.push(a),
        }
    }
    let path = PathBuf::from(
        positional
            .first()
            .map_or("scenarios/e4.toml", String::as_str),
    );
    let out_dir = PathBuf::from(
        positional
            .get(1)
            .map_or("target/world-view", String::as_str),
    );
    let mut scenario = trust_flight::scenario::load(&path)?;
    if let Some(s) = seed {
        scenario = scenario.with_seed(s);
    }
    if let Some(v) = voxel {
        match &mut scenario.static_map.point_cloud {
            Some(
                PointCloudSpec::Shapes { esdf_voxel_m, .. }
                | PointCloudSpec::Inline { esdf_voxel_m, .. }
                | PointCloudSpec::File { esdf_voxel_m, .. },
            ) => *esdf_voxel_m = v,
            None => return Err("--voxel needs a scenario with a point cloud".into()),
        }
    }
    let rss_before = peak_rss_mb();
    let world = World::build(&scenario)?;
    let s = world.stats();
    println!(
        "{}: seed {}, {} static shapes, {} moving obstacles, {} cloud points",
        scenario.name, scenario.seed, s.shape_count, s.obstacle_count, s.cloud_point_count
    );
    if let Some(d) = s.esdf_dims {
        println!(
            "ESDF {} x {} x {} = {:.1} M voxels ({:.0} MB kept), {} occupied",
            d[0],
            d[1],
            d[2],
            (d[0] * d[1] * d[2]) as f64 / 1e6,
            s.esdf_bytes as f64 / 1e6,
            s.esdf_occupied_count
        );
    }
    println!(
        "build: layout {:.1} ms, cloud {:.1} ms, map {:.1} ms, total {:.1} ms",
        s.layout_ms, s.cloud_ms, s.map_ms, s.total_ms
    );
    if let (Some(before), Some(after)) = (rss_before, peak_rss_mb()) {
        println!("peak resident memory: {before:.0} MB before the build, {after:.0} MB after");
    }
    let b = world.bounds();
    let ground: f64 = world
        .static_shapes()
        .iter()
        .map(|sh| {
            let a = sh.aabb();
            match sh {
                trust_geometry::Shape::Cylinder(c) => std::f64::consts::PI * c.radius * c.radius,
                _ => (a.max.x - a.min.x) * (a.max.y - a.min.y),
            }
        })
        .sum();
    println!(
        "static footprints cover {:.1} % of the ground",
        100.0 * ground / ((b.max.x - b.min.x) * (b.max.y - b.min.y))
    );

    let top = |p: &trust_core::Vec3| Point2::new(p.x, p.y);
    let mut view = MapView::new(
        format!(
            "{} (seed {}), top view {:.0} m × {:.0} m",
            scenario.name,
            scenario.seed,
            b.max.x - b.min.x,
            b.max.y - b.min.y
        ),
        Bounds::new(Point2::new(b.min.x, b.min.y), Point2::new(b.max.x, b.max.y)),
    )
    .width_px(1600);
    match &scenario.static_map.point_cloud {
        Some(PointCloudSpec::Shapes {
            esdf_voxel_m,
            spacing_m,
        }) => {
            let pts = sample_shapes(world.static_shapes(), b, spacing_m.unwrap_or(*esdf_voxel_m));
            view = view.point_cloud(
                pts.iter().map(top).collect(),
                Color::DARK_GREY,
                "static point cloud (planner's view)",
            );
        }
        _ => {
            view = view.shapes(world.static_shapes().iter().map(|sh| match sh {
                trust_geometry::Shape::Sphere(s) => Shape::Circle {
                    center: top(&s.center),
                    radius: s.radius,
                },
                trust_geometry::Shape::Cylinder(c) => Shape::Circle {
                    center: top(&c.center),
                    radius: c.radius,
                },
                trust_geometry::Shape::AaBox(a) => Shape::Rect {
                    min: top(&a.min),
                    max: top(&a.max),
                },
            }));
            if let Some(points) = world.static_points() {
                view = view.point_cloud(
                    points.iter().map(top).collect(),
                    Color::DARK_GREY,
                    "static points",
                );
            }
        }
    }
    let mut traffic = world.traffic()?;
    let mut tracks: Vec<Vec<Point2<f64>>> =
        traffic.positions().iter().map(|p| vec![top(p)]).collect();
    for step in 1..=1000 {
        traffic.step(0.01)?;
        if step % 10 == 0 {
            for (t, p) in tracks.iter_mut().zip(traffic.positions()) {
                t.push(top(p));
            }
        }
    }
    view = view.tracks(tracks, Color::PALETTE[1], "moving obstacles, first 10 s");
    for o in world.obstacles() {
        view = view.forecast(
            ForecastRings::new(vec![(top(&o.position), o.shape.radius())])
                .color(Color::PALETTE[1])
                .alpha(0.9, 0.9)
                .label("moving obstacles at t = 0"),
        );
    }
    view = view
        .marker(Marker::start(top(&world.start())))
        .marker(Marker::goal(top(&world.goal())));
    let name = format!("{}_seed{}", scenario.name, scenario.seed);
    let written = view.write(&out_dir, &name)?;
    println!(
        "wrote {} and {}",
        written.svg.display(),
        written.png.display()
    );
    Ok(())
}

fn main() -> ExitCode {
    match run() {
        Ok(()) => ExitCode::SUCCESS,
        Err(e) => {
            eprintln!("error: {e}");
            ExitCode::FAILURE
        }
    }
}
