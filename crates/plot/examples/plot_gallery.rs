//! Writes one of each figure kind of `trust_plot` into a directory, for reviewing by eye.
//!
//! `cargo run -p trust-plot --example plot_gallery -- [DIR]` (default `target/plot-gallery`).

use std::f64::consts::TAU;
use std::path::PathBuf;

use nalgebra::Point2;
use trust_plot::{
    Band, Bar, BarChart, Bounds, Color, Distribution, DistributionKind, Figure, ForecastRings,
    HLine, MapView, Marker, Plane, Polyline, Series, Shape, TimeSeries, Written,
};

/// A small deterministic generator (SplitMix64), so the gallery needs no extra dependency.
struct SplitMix(u64);

impl SplitMix {
    fn next_f64(&mut self) -> f64 {
        self.0 = self.0.wrapping_add(0x9E37_79B9_7F4A_7C15);
        let mut z = self.0;
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
        (z >> 11) as f64 / (1u64 << 53) as f64
    }
}

fn report(w: &Written) {
    println!(
        "{} and {} ({}x{} px, {} skipped, {} thinned)",
        w.svg.display(),
        w.png.display(),
        w.width_px,
        w.height_px,
        w.skipped_count,
        w.thinned_count
    );
}

fn top_view(rng: &mut SplitMix) -> MapView {
    let pillars: Vec<(Point2<f64>, f64)> = (0..60)
        .map(|_| {
            let center = Point2::new(20.0 + 210.0 * rng.next_f64(), 5.0 + 65.0 * rng.next_f64());
            (center, 0.8 + 1.2 * rng.next_f64())
        })
        .collect();
    let walls = [
        Shape::Rect {
            min: Point2::new(60.0, 0.0),
            max: Point2::new(62.0, 25.0),
        },
        Shape::Rect {
            min: Point2::new(150.0, 50.0),
            max: Point2::new(152.0, 75.0),
        },
    ];
    // A dense cloud sampled on the pillar surfaces (10^6 points).
    let cloud: Vec<Point2<f64>> = (0..1_000_000)
        .map(|i| {
            let (center, radius) = pillars[i % pillars.len()];
            let a = TAU * rng.next_f64();
            Point2::new(center.x + radius * a.cos(), center.y + radius * a.sin())
        })
        .collect();
    let flown: Vec<Point2<f64>> = (0..=250)
        .map(|i| {
            let x = 5.0 + i as f64 * 0.96;
            Point2::new(x, 37.5 + 12.0 * (x / 40.0).sin())
        })
        .collect();
    let mut view = MapView::new(
        "Forest, top view (250 m × 75 m)",
        Bounds::new(Point2::new(0.0, 0.0), Point2::new(250.0, 75.0)),
    )
    .shapes(
        pillars
            .iter()
            .map(|&(center, radius)| Shape::Circle { center, radius }),
    )
    .shapes(walls)
    .point_cloud(cloud, Color::GREY, "point cloud")
    .polyline(Polyline::new(flown).label("flown path").width_px(3));
    // Three planned trajectories sharing one legend entry.
    for k in 0..3 {
        let x0 = 60.0 + 50.0 * k as f64;
        let planned: Vec<Point2<f64>> = (0..=30)
            .map(|i| {
                let x = x0 + i as f64;
                Point2::new(x, 37.5 + 12.0 * (x / 40.0).sin() + 0.01 * (i * i) as f64)
            })
            .collect();
        view = view.polyline(
            Polyline::new(planned)
                .label("planned")
                .color(Color::PALETTE[1])
                .dashed(),
        );
    }
    // Moving obstacles: tracks and growing forecast rings.
    let mut tracks = Vec::new();
    for k in 0..12 {
        let (x0, y0) = (30.0 + 18.0 * k as f64, 75.0 * rng.next_f64());
        let (vx, vy) = (2.0 * rng.next_f64() - 1.0, 2.0 * rng.next_f64() - 1.0);
        tracks.push(
            (0..40)
                .map(|i| Point2::new(x0 + vx * i as f64 * 0.5, y0 + vy * i as f64 * 0.5))
                .collect::<Vec<_>>(),
        );
        if k % 3 == 0 {
            let rings = (0..6)
                .map(|i| {
                    let t = 20.0 + 2.0 * i as f64;
                    (
                        Point2::new(x0 + vx * t * 0.5, y0 + vy * t * 0.5),
                        1.0 + 0.4 * i as f64,
                    )
                })
                .collect();
            view = view.forecast(ForecastRings::new(rings));
        }
    }
    view.tracks(tracks, Color::LIGHT_GREY, "obstacle tracks")
        .marker(Marker::start(Point2::new(5.0, 37.5)))
        .marker(Marker::goal(Point2::new(
            245.0,
            37.5 + 12.0 * (245.0f64 / 40.0).sin(),
        )))
}

fn side_view() -> MapView {
    let path: Vec<Point2<f64>> = (0..=250)
        .map(|i| {
            let x = i as f64;
            Point2::new(x, 1.5 + 0.8 * (x / 25.0).sin().max(0.0))
        })
        .collect();
    MapView::new(
        "Side view (x–z), vertical exaggeration 5×",
        Bounds::new(Point2::new(0.0, 0.0), Point2::new(250.0, 5.0)),
    )
    .plane(Plane::Xz)
    .vertical_exaggeration(5.0)
    .shapes((0..25).map(|k| Shape::Rect {
        min: Point2::new(8.0 + 10.0 * k as f64, 0.0),
        max: Point2::new(9.0 + 10.0 * k as f64, 5.0),
    }))
    .shape_style(Color::DARK_GREY, "pillars")
    .polyline(Polyline::new(path).label("flown path"))
    .marker(Marker::start(Point2::new(0.0, 1.5)))
    .marker(Marker::goal(Point2::new(250.0, 1.5)))
}

fn speed(rng: &mut SplitMix) -> TimeSeries {
    let mut series = Vec::new();
    for (k, name) in ["TRUST-Planner", "Baseline 1", "Baseline 2"]
        .into_iter()
        .enumerate()
    {
        let top = 2.6 + 0.15 * k as f64;
        let points = (0..=400)
            .map(|i| {
                let t = 0.05 * i as f64;
                (
                    t,
                    (top * (1.0 - (-t / 2.0).exp()) + 0.08 * (rng.next_f64() - 0.5)).max(0.0),
                )
            })
            .collect();
        series.push(Series::new(name, points));
    }
    let mut fig = TimeSeries::new("Speed along the flight")
        .axis_labels("t [s]", "|v| [m/s]")
        .limit(HLine::new("v_max = 3 m/s", 3.0));
    for s in series {
        fig = fig.series(s);
    }
    fig
}

fn clearance() -> TimeSeries {
    let mean: Vec<(f64, f64)> = (0..=200)
        .map(|i| {
            let t = 0.1 * i as f64;
            (t, 1.2 + 0.9 * (t / 2.3).sin() + 0.3 * (t / 0.7).cos())
        })
        .collect();
    let band = mean.iter().map(|&(t, c)| (t, c - 0.35, c + 0.35)).collect();
    TimeSeries::new("Clearance to the nearest obstacle")
        .axis_labels("t [s]", "clearance [m]")
        .band(Band::new("min–max over 100 trials", band))
        .series(Series::new("mean", mean))
        .limit(HLine::new("clearance 0 (collision)", 0.0))
}

fn success_rate() -> BarChart {
    // (name, successes out of 100, paper's number): Wilson 95 % intervals computed below.
    let rows = [
        ("TRUST-Planner", 97, 96.0),
        ("Baseline 1: V-PRM", 71, 74.0),
        ("Baseline 2: DEV-PRM", 84, 81.0),
        ("Baseline 3: no TVD", 90, 92.0),
    ];
    let mut chart = BarChart::new("Success rate over 100 trials")
        .y_label("success rate [%]")
        .value_format(0, " %")
        .y_range(0.0, 110.0);
    for (name, k, paper) in rows {
        let (lo, hi) = wilson(k, 100);
        chart = chart.bar(
            Bar::new(name, f64::from(k))
                .interval(100.0 * lo, 100.0 * hi)
                .reference(paper),
        );
    }
    chart
}

/// Wilson score interval at 95 % (z = 1.96) for `k` successes in `n` trials.
fn wilson(k: u32, n: u32) -> (f64, f64) {
    let (k, n, z) = (f64::from(k), f64::from(n), 1.96f64);
    let p = k / n;
    let denom = 1.0 + z * z / n;
    let centre = (p + z * z / (2.0 * n)) / denom;
    let half = z * (p * (1.0 - p) / n + z * z / (4.0 * n * n)).sqrt() / denom;
    (centre - half, centre + half)
}

fn durations(rng: &mut SplitMix, kind: DistributionKind, title: &str) -> Distribution {
    let mut fig = Distribution::new(title)
        .y_label("flight duration [s]")
        .kind(kind)
        .show_mean(true);
    for (k, name) in [
        "TRUST-Planner",
        "Baseline 1: V-PRM",
        "Baseline 2: DEV-PRM",
        "Baseline 3: no TVD",
    ]
    .into_iter()
    .enumerate()
    {
        let base = 95.0 + 6.0 * k as f64;
        let samples = (0..100)
            .map(|i| {
                let u = rng.next_f64() + rng.next_f64() + rng.next_f64() - 1.5;
                base + 6.0 * u + if i % 37 == 5 { 25.0 } else { 0.0 }
            })
            .collect();
        fig = fig.category(name, samples);
    }
    fig
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let dir = std::env::args_os()
        .nth(1)
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("target/plot-gallery"));
    let mut rng = SplitMix(7);
    let figures: Vec<(&str, Box<dyn Figure>)> = vec![
        ("map_top", Box::new(top_view(&mut rng))),
        ("map_side", Box::new(side_view())),
        ("speed", Box::new(speed(&mut rng))),
        ("clearance", Box::new(clearance())),
        ("success_rate", Box::new(success_rate())),
        (
            "duration_box",
            Box::new(durations(
                &mut rng,
                DistributionKind::Box,
                "Flight duration (box plot)",
            )),
        ),
        (
            "duration_strip",
            Box::new(durations(
                &mut rng,
                DistributionKind::BoxAndStrip,
                "Flight duration (box + strip)",
            )),
        ),
    ];
    for (name, figure) in &figures {
        report(&figure.write(&dir, name)?);
    }
    Ok(())
}
