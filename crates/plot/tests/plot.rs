//! Public API of `trust_plot`: every figure kind writes SVG + PNG, deterministically, and
//! degenerate input gives either a drawing or a typed error, never a panic.

use std::fs;
use std::path::{Path, PathBuf};

use nalgebra::{Point2, Vector3};
use trust_plot::{
    Band, Bar, BarChart, Bounds, BoxStats, Color, Distribution, DistributionKind, Figure,
    ForecastRings, HLine, MapView, Marker, Plane, PlotError, Polyline, Series, Shape, TimeSeries,
    Whiskers, Written,
};

const PNG_SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', 0x0D, 0x0A, 0x1A, 0x0A];

/// A fresh, empty directory under the system temp dir, unique per test and process.
fn scratch(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("trust-plot-{}-{test}", std::process::id()));
    let _ = fs::remove_dir_all(&dir);
    dir
}

/// Width and height from the PNG's IHDR chunk.
fn png_size(bytes: &[u8]) -> (u32, u32) {
    let be = |b: &[u8]| u32::from_be_bytes([b[0], b[1], b[2], b[3]]);
    (be(&bytes[16..20]), be(&bytes[20..24]))
}

/// Checks both files of a written figure and returns the SVG text.
fn check_written(w: &Written, title: &str) -> String {
    let svg = fs::read_to_string(&w.svg).expect("svg readable");
    assert!(svg.starts_with("<svg"), "{}", &svg[..svg.len().min(80)]);
    assert!(svg.contains(title), "svg lacks the title {title:?}");
    assert!(
        svg.contains("DejaVu Sans"),
        "svg text does not use the bundled font family"
    );
    let png = fs::read(&w.png).expect("png readable");
    assert!(
        png.len() > 1000,
        "png suspiciously small: {} bytes",
        png.len()
    );
    assert_eq!(png[..8], PNG_SIGNATURE);
    assert_eq!(png_size(&png), (w.width_px, w.height_px));
    assert!(w.svg.extension().is_some_and(|e| e == "svg"));
    assert!(w.png.extension().is_some_and(|e| e == "png"));
    svg
}

fn p(x: f64, y: f64) -> Point2<f64> {
    Point2::new(x, y)
}

fn sample_map() -> MapView {
    let flown: Vec<Point2<f64>> = (0..=100)
        .map(|i| {
            p(
                2.5 * f64::from(i),
                37.5 + 10.0 * (f64::from(i) / 15.0).sin(),
            )
        })
        .collect();
    MapView::new(
        "Top view of the forest",
        Bounds::new(p(0.0, 0.0), p(250.0, 75.0)),
    )
    .shapes((0..20).map(|k| Shape::Circle {
        center: p(10.0 + 12.0 * f64::from(k), 20.0 + 2.0 * f64::from(k % 7)),
        radius: 1.5,
    }))
    .shape(Shape::Rect {
        min: p(100.0, 50.0),
        max: p(102.0, 75.0),
    })
    .point_cloud(
        (0..5000).map(|i| p(f64::from(i) * 0.05, 60.0)).collect(),
        Color::GREY,
        "cloud",
    )
    .tracks(
        vec![
            vec![p(50.0, 10.0), p(60.0, 20.0)],
            vec![p(150.0, 60.0), p(140.0, 50.0)],
        ],
        Color::LIGHT_GREY,
        "tracks",
    )
    .forecast(ForecastRings::new(
        (0..5)
            .map(|i| (p(60.0 + f64::from(i), 20.0), 1.0 + 0.3 * f64::from(i)))
            .collect(),
    ))
    .polyline(Polyline::new(flown).label("flown"))
    .polyline(
        Polyline::new(vec![p(50.0, 40.0), p(80.0, 45.0)])
            .label("planned")
            .dashed(),
    )
    .marker(Marker::start(p(0.0, 37.5)))
    .marker(Marker::goal(p(250.0, 37.5)))
}

fn sample_series() -> TimeSeries {
    let speed = (0..200)
        .map(|i| {
            (
                0.1 * f64::from(i),
                3.0 * (1.0 - (-0.1 * f64::from(i)).exp()),
            )
        })
        .collect();
    let accel = (0..200)
        .map(|i| (0.1 * f64::from(i), 3.0 * (-0.1 * f64::from(i)).exp()))
        .collect();
    TimeSeries::new("Speed and acceleration")
        .axis_labels("t [s]", "value")
        .series(Series::new("|v| [m/s]", speed))
        .series(Series::new("|a| [m/s²]", accel).dashed())
        .band(Band::new("band", vec![(0.0, 0.5, 1.0), (19.9, 0.5, 1.0)]))
        .limit(HLine::new("v_max", 3.2))
        .limit(HLine::new("a_max", 3.5).color(Color::GOAL_RED))
}

fn sample_bars() -> BarChart {
    BarChart::new("Success rate")
        .y_label("success [%]")
        .value_format(0, " %")
        .bar(
            Bar::new("TRUST-Planner", 96.0)
                .interval(90.2, 98.4)
                .reference(95.0),
        )
        .bar(
            Bar::new("Baseline 1", 72.0)
                .interval(62.5, 79.9)
                .reference(70.0),
        )
        .bar(Bar::new("Baseline 2", 81.0))
}

fn sample_distribution() -> Distribution {
    let samples = |base: f64| {
        (0..100)
            .map(|i| base + f64::from((i * 37) % 23) * 0.5)
            .collect::<Vec<_>>()
    };
    let mut with_outlier = samples(110.0);
    with_outlier.push(200.0);
    Distribution::new("Flight duration")
        .y_label("duration [s]")
        .category("TRUST-Planner", samples(100.0))
        .category("Baseline 1", with_outlier)
        .category_colored("Baseline 2", samples(105.0), Color::PALETTE[4])
}

fn all_figures() -> Vec<(&'static str, Box<dyn Figure>)> {
    vec![
        ("map", Box::new(sample_map())),
        ("series", Box::new(sample_series())),
        ("bars", Box::new(sample_bars())),
        ("distribution", Box::new(sample_distribution())),
        (
            "strip",
            Box::new(
                sample_distribution()
                    .kind(DistributionKind::Strip)
                    .show_mean(true),
            ),
        ),
        (
            "box_and_strip",
            Box::new(
                sample_distribution()
                    .kind(DistributionKind::BoxAndStrip)
                    .whiskers(Whiskers::MinMax),
            ),
        ),
    ]
}

#[test]
fn every_figure_kind_writes_svg_and_png_with_its_title() {
    let dir = scratch("kinds");
    for (name, figure) in all_figures() {
        let w = figure
            .write(&dir, name)
            .unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(w.svg, dir.join(format!("{name}.svg")));
        assert_eq!(w.png, dir.join(format!("{name}.png")));
        check_written(&w, figure.title());
        assert_eq!(w.skipped_count, 0, "{name}");
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn the_same_figure_gives_byte_identical_files() {
    let (a, b) = (scratch("determinism-a"), scratch("determinism-b"));
    for (name, figure) in all_figures() {
        let wa = figure.write(&a, name).expect("first write");
        let wb = figure.write(&b, name).expect("second write");
        assert_eq!(
            fs::read(&wa.svg).expect("svg a"),
            fs::read(&wb.svg).expect("svg b"),
            "{name}.svg differs"
        );
        assert_eq!(
            fs::read(&wa.png).expect("png a"),
            fs::read(&wb.png).expect("png b"),
            "{name}.png differs"
        );
    }
    let _ = fs::remove_dir_all(&a);
    let _ = fs::remove_dir_all(&b);
}

#[test]
fn a_missing_output_directory_is_created() {
    let dir = scratch("nested").join("a").join("b");
    let w = sample_bars()
        .write(&dir, "bars")
        .expect("nested dir created");
    assert!(w.png.is_file() && w.svg.is_file());
    let _ = fs::remove_dir_all(scratch("nested"));
}

#[test]
fn a_map_keeps_the_world_aspect_ratio() {
    let dir = scratch("aspect");
    let marker = || Marker::start(p(1.0, 1.0));
    let wide = MapView::new("wide", Bounds::new(p(0.0, 0.0), p(250.0, 75.0)))
        .marker(marker())
        .legend(false)
        .write(&dir, "wide")
        .expect("wide");
    let square = MapView::new("square", Bounds::new(p(0.0, 0.0), p(75.0, 75.0)))
        .marker(marker())
        .legend(false)
        .write(&dir, "square")
        .expect("square");
    // Same width and frame around both plots, so the heights differ by the plot heights alone:
    // the square plot is as high as it is wide, the wide one 75/250 of that.
    assert_eq!(wide.width_px, square.width_px);
    let plot_w = f64::from(square.height_px - wide.height_px) / (1.0 - 75.0 / 250.0);
    assert!(
        (plot_w - 900.0).abs() < 40.0,
        "implied plot width {plot_w}: wide {wide:?}, square {square:?}"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn figures_without_data_are_no_data_errors_naming_the_file() {
    let dir = scratch("empty");
    let figures: Vec<Box<dyn Figure>> = vec![
        Box::new(MapView::new(
            "empty map",
            Bounds::new(p(0.0, 0.0), p(1.0, 1.0)),
        )),
        Box::new(TimeSeries::new("empty series")),
        Box::new(TimeSeries::new("only a limit").limit(HLine::new("v_max", 3.0))),
        Box::new(BarChart::new("no bars")),
        Box::new(Distribution::new("no categories")),
        Box::new(Distribution::new("empty category").category("A", Vec::new())),
    ];
    for figure in figures {
        match figure.write(&dir, "fig") {
            Err(e @ PlotError::NoData { .. }) => {
                assert!(
                    e.to_string()
                        .contains(&dir.join("fig").display().to_string()),
                    "{e}"
                );
            }
            other => panic!("{}: expected NoData, got {other:?}", figure.title()),
        }
    }
    assert!(
        !dir.join("fig.svg").exists(),
        "no file is written for invalid data"
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn single_points_are_drawn() {
    let dir = scratch("single");
    let figures: Vec<Box<dyn Figure>> = vec![
        Box::new(
            MapView::new("one marker", Bounds::new(p(0.0, 0.0), p(10.0, 10.0)))
                .marker(Marker::goal(p(5.0, 5.0))),
        ),
        Box::new(
            MapView::new("one point", Bounds::new(p(0.0, 0.0), p(10.0, 10.0)))
                .polyline(Polyline::new(vec![p(5.0, 5.0)])),
        ),
        Box::new(TimeSeries::new("one sample").series(Series::new("s", vec![(1.0, 2.0)]))),
        Box::new(BarChart::new("one bar").bar(Bar::new("A", 0.0))),
        Box::new(Distribution::new("one sample").category("A", vec![3.0])),
    ];
    for (i, figure) in figures.iter().enumerate() {
        let w = figure
            .write(&dir, &format!("fig{i}"))
            .unwrap_or_else(|e| panic!("{}: {e}", figure.title()));
        check_written(&w, figure.title());
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn non_finite_values_are_skipped_and_counted() {
    let dir = scratch("nan");
    let series = TimeSeries::new("gaps").series(Series::new(
        "s",
        vec![
            (0.0, 1.0),
            (1.0, f64::NAN),
            (2.0, 2.0),
            (f64::INFINITY, 0.0),
            (3.0, 1.0),
        ],
    ));
    assert_eq!(
        series.write(&dir, "series").expect("drawn").skipped_count,
        2
    );

    let map = MapView::new("nan map", Bounds::new(p(0.0, 0.0), p(10.0, 10.0)))
        .shape(Shape::Circle {
            center: p(f64::NAN, 1.0),
            radius: 1.0,
        })
        .shape(Shape::Circle {
            center: p(5.0, 5.0),
            radius: -1.0,
        })
        .point_cloud(vec![p(1.0, 1.0), p(f64::NAN, 2.0)], Color::GREY, "cloud")
        .polyline(Polyline::new(vec![
            p(1.0, 1.0),
            p(2.0, f64::NEG_INFINITY),
            p(3.0, 3.0),
            p(4.0, 4.0),
        ]));
    assert_eq!(map.write(&dir, "map").expect("drawn").skipped_count, 4);

    let bars = BarChart::new("nan bar")
        .bar(Bar::new("A", f64::NAN))
        .bar(Bar::new("B", 1.0).interval(0.5, f64::NAN));
    let w = bars.write(&dir, "bars").expect("drawn");
    assert_eq!(w.skipped_count, 2);
    assert!(fs::read_to_string(&w.svg).expect("svg").contains("n/a"));

    let dist = Distribution::new("nan samples")
        .category("A", vec![1.0, f64::NAN, 2.0])
        .category("B", vec![f64::NAN]);
    let w = dist.write(&dir, "dist").expect("drawn");
    assert_eq!(w.skipped_count, 2);
    assert!(fs::read_to_string(&w.svg).expect("svg").contains("no data"));

    let all_nan = TimeSeries::new("all nan").series(Series::new("s", vec![(f64::NAN, 1.0)]));
    assert!(matches!(
        all_nan.write(&dir, "all_nan"),
        Err(PlotError::NoData { .. })
    ));
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn zero_width_ranges_are_padded() {
    let dir = scratch("zero-width");
    let flat = TimeSeries::new("constant").series(Series::new("c", vec![(0.0, 5.0), (1.0, 5.0)]));
    check_written(
        &flat.write(&dir, "flat").expect("constant series"),
        "constant",
    );
    let instant =
        TimeSeries::new("one instant").series(Series::new("c", vec![(2.0, 1.0), (2.0, 3.0)]));
    check_written(
        &instant.write(&dir, "instant").expect("zero-width x"),
        "one instant",
    );
    let fixed = TimeSeries::new("fixed ranges")
        .series(Series::new("c", vec![(0.0, 0.0)]))
        .x_range(1.0, 1.0)
        .y_range(0.0, 0.0);
    check_written(
        &fixed.write(&dir, "fixed").expect("equal range ends"),
        "fixed ranges",
    );
    let line_map = MapView::new(
        "zero-height bounds",
        Bounds::new(p(0.0, 2.0), p(100.0, 2.0)),
    )
    .polyline(Polyline::new(vec![p(0.0, 2.0), p(100.0, 2.0)]));
    check_written(
        &line_map.write(&dir, "line_map").expect("flat bounds"),
        "zero-height bounds",
    );
    let point_map = MapView::new("point bounds", Bounds::new(p(3.0, 3.0), p(3.0, 3.0)))
        .marker(Marker::start(p(3.0, 3.0)));
    check_written(
        &point_map.write(&dir, "point_map").expect("point bounds"),
        "point bounds",
    );
    let same = Distribution::new("identical samples").category("A", vec![4.0; 10]);
    check_written(
        &same.write(&dir, "same").expect("identical samples"),
        "identical samples",
    );
    let zeros = BarChart::new("all zero")
        .bar(Bar::new("A", 0.0))
        .bar(Bar::new("B", 0.0));
    check_written(&zeros.write(&dir, "zeros").expect("zero bars"), "all zero");
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn unusable_parameters_are_invalid_input() {
    let dir = scratch("invalid");
    let nan_bounds = MapView::new("nan bounds", Bounds::new(p(f64::NAN, 0.0), p(1.0, 1.0)))
        .marker(Marker::start(p(0.5, 0.5)));
    let e = nan_bounds.write(&dir, "map").expect_err("nan bounds");
    assert!(
        matches!(&e, PlotError::InvalidInput { field, .. } if field == "bounds"),
        "{e}"
    );
    let bad_range = TimeSeries::new("bad range")
        .series(Series::new("s", vec![(0.0, 1.0)]))
        .y_range(0.0, f64::INFINITY);
    assert!(matches!(
        bad_range.write(&dir, "s"),
        Err(PlotError::InvalidInput { .. })
    ));
    let nan_limit = TimeSeries::new("nan limit")
        .series(Series::new("s", vec![(0.0, 1.0)]))
        .limit(HLine::new("v_max", f64::NAN));
    assert!(matches!(
        nan_limit.write(&dir, "s"),
        Err(PlotError::InvalidInput { .. })
    ));
    let tiny = MapView::new("tiny", Bounds::new(p(0.0, 0.0), p(1.0, 1.0)))
        .width_px(10)
        .marker(Marker::start(p(0.5, 0.5)));
    assert!(matches!(
        tiny.write(&dir, "tiny"),
        Err(PlotError::InvalidInput { .. })
    ));
    for bad in ["", "a/b", ".."] {
        assert!(
            matches!(
                sample_bars().write(&dir, bad),
                Err(PlotError::InvalidName { .. })
            ),
            "{bad:?}"
        );
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_unwritable_output_directory_is_an_error_naming_it() {
    let dir = scratch("unwritable");
    fs::create_dir_all(&dir).expect("scratch dir");
    let file = dir.join("a-file");
    fs::write(&file, b"not a directory").expect("file");
    // A directory below a regular file cannot be created, whoever we are (root included).
    let below = file.join("figures");
    match sample_bars().write(&below, "bars") {
        Err(e @ PlotError::CreateDir { .. }) => {
            assert!(e.to_string().contains(&below.display().to_string()), "{e}")
        }
        other => panic!("expected CreateDir, got {other:?}"),
    }
    match sample_bars().write(&file, "bars") {
        Err(e @ PlotError::NotADirectory { .. }) => {
            assert!(e.to_string().contains("a-file"), "{e}")
        }
        other => panic!("expected NotADirectory, got {other:?}"),
    }
    // A directory squatting on the SVG's name makes the write itself fail.
    fs::create_dir_all(dir.join("taken.svg")).expect("squatter");
    match sample_bars().write(&dir, "taken") {
        Err(e @ PlotError::Write { .. }) => assert!(e.to_string().contains("taken.svg"), "{e}"),
        other => panic!("expected Write, got {other:?}"),
    }
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn a_million_point_cloud_is_thinned() {
    let dir = scratch("cloud");
    let n = 1_000_000u32;
    let cloud: Vec<Point2<f64>> = (0..n)
        .map(|i| {
            let t = f64::from(i) / f64::from(n);
            p(250.0 * t, 75.0 * (t * 7919.0).fract())
        })
        .collect();
    let map = MapView::new("Dense cloud", Bounds::new(p(0.0, 0.0), p(250.0, 75.0))).point_cloud(
        cloud,
        Color::GREY,
        "cloud",
    );
    let w = map.write(&dir, "cloud").expect("cloud drawn");
    check_written(&w, "Dense cloud");
    assert!(
        w.thinned_count > 800_000,
        "only {} of {n} points thinned",
        w.thinned_count
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn planes_project_and_name_their_axes() {
    let v = Vector3::new(1.0, 2.0, 3.0);
    assert_eq!(Plane::Xy.project(&v), p(1.0, 2.0));
    assert_eq!(Plane::Xz.project(&v), p(1.0, 3.0));
    assert_eq!(Plane::Yz.project(&v), p(2.0, 3.0));
    assert_eq!(Plane::Xz.axis_labels(), ("x [m]", "z [m]"));
}

#[test]
fn box_stats_are_public_building_blocks() {
    let st = BoxStats::from_samples(&[1.0, 2.0, 3.0, 4.0, 5.0], Whiskers::Tukey).expect("samples");
    assert_eq!((st.q1, st.median, st.q3, st.mean), (2.0, 3.0, 4.0, 3.0));
    assert!(BoxStats::from_samples(&[], Whiskers::MinMax).is_none());
}

#[test]
fn written_paths_live_in_the_given_directory() {
    let dir = scratch("paths");
    let w = sample_series().write(&dir, "speed").expect("written");
    assert_eq!(w.svg.parent(), Some(Path::new(&dir)));
    assert_eq!(
        w.png.file_name().and_then(|n| n.to_str()),
        Some("speed.png")
    );
    let _ = fs::remove_dir_all(&dir);
}

#[test]
fn an_animated_gif_has_one_frame_per_view_and_rejects_mixed_sizes() {
    use trust_plot::{MapView, Polyline, write_gif};
    let dir = std::env::temp_dir().join(format!("trust-plot-gif-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let bounds = Bounds::new(Point2::new(0.0, 0.0), Point2::new(10.0, 5.0));
    let frame = |k: usize| {
        MapView::new(format!("t = {k}"), bounds)
            .width_px(300)
            .polyline(
                Polyline::new(vec![Point2::new(0.0, 0.0), Point2::new(k as f64, 2.0)])
                    .label("path"),
            )
    };
    let frames: Vec<MapView> = (1..=4).map(frame).collect();
    let path = dir.join("anim.gif");
    let written = write_gif(&frames, &path, 100).unwrap();
    assert_eq!(written.frame_count, 4);
    let bytes = std::fs::read(&path).unwrap();
    assert!(bytes.starts_with(b"GIF89a"));
    // Width and height as written in the logical screen descriptor.
    let w = u32::from(u16::from_le_bytes([bytes[6], bytes[7]]));
    let h = u32::from(u16::from_le_bytes([bytes[8], bytes[9]]));
    assert_eq!((w, h), (written.width_px, written.height_px));

    // A frame of other bounds (so another height) is named, and nothing is written.
    let mut mixed = frames.clone();
    mixed[2] = MapView::new(
        "taller",
        Bounds::new(Point2::new(0.0, 0.0), Point2::new(10.0, 10.0)),
    )
    .width_px(300)
    .polyline(Polyline::new(vec![Point2::new(0.0, 0.0), Point2::new(1.0, 2.0)]).label("path"));
    let bad = dir.join("mixed.gif");
    let e = write_gif(&mixed, &bad, 100).unwrap_err();
    assert!(e.to_string().contains("frames[2] size"), "{e}");
    assert!(!bad.exists());
    assert!(write_gif(&[], &bad, 100).is_err());
    std::fs::remove_dir_all(&dir).ok();
}
