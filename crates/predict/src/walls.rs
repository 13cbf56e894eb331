//! Forecasts of obstacles that stay inside a box: the mirror images of a constant-velocity
//! forecast at the box's walls (beyond the paper).
//!
//! A person walking toward a room's wall turns there; a constant-velocity forecast walks them
//! through it, and a planner that believes it passes behind them into the space they are about to
//! walk back through. An obstacle confined to a box `[lo, hi]` (its shape kept fully inside) moves
//! along the **fold** of its straight line: each coordinate reflects at `lo + e` and `hi − e`,
//! where `e` is the shape's half extent along that axis (the radius `r_o`; a cylinder's
//! half-height vertically). The folded motion is piecewise straight, and each straight piece is a
//! mirror image of the line — the line reflected across one or more of the six planes. So the
//! union of the forecast and its images contains the folded motion at every instant, and every
//! user of forecasts (the safety check, the penalty, the predictive cones) handles the images as
//! ordinary forecasts of the same size, margin and growth.
//!
//! [`wall_images`] returns the images whose piece of the fold overlaps a time window (each image
//! is a full straight-line forecast; outside its piece it lies beyond a wall, where a vehicle
//! inside the box never is). Only the centre's line is folded: the uncertainty `mu·(t − t0)` of
//! an image grows around the mirrored line, which is the mirror of the original's ball.

use crate::{Aabb, Forecast, ObstacleShape, Vec3};

/// Most reflections followed per axis within one window: a person at 1.5 m/s in a 3 m wide room
/// reflects about once every 2 s, so four cover an 8 s window.
pub const MAX_REFLECTIONS_PER_AXIS: usize = 4;

/// Speeds (m/s) below this along an axis do not reach a wall within any window worth forecasting.
const MIN_AXIS_SPEED: f64 = 1e-9;

/// One straight piece of the folded motion along one axis: `x(t) = q + w·(t − t0)` for
/// `t ∈ [from, until]`; `reflected` says whether it is an image (not the forecast's own line).
#[derive(Debug, Clone, Copy)]
struct AxisPiece {
    q: f64,
    w: f64,
    from: f64,
    until: f64,
    reflected: bool,
}

/// The mirror images of `forecast` at the walls of `walls` whose piece of the folded motion
/// overlaps `[from, until]` (absolute times), at most [`MAX_REFLECTIONS_PER_AXIS`] reflections
/// per axis. Empty when the obstacle stays clear of the walls over the window, does not move,
/// or is larger than the box along every axis it moves on (such an axis is not folded). The
/// images keep the forecast's shape, size, margin, growth and `t0`; they are valid forecasts
/// whenever the inputs are finite.
///
/// ```
/// use trust_predict::{Aabb, Forecast, ObstacleShape, Vec3, wall_images};
///
/// // A 0.25 m ball 1 m from the wall x = 4 of a 4 m room, walking toward it at 1 m/s.
/// let room = Aabb { min: Vec3::zeros(), max: Vec3::new(4.0, 4.0, 3.0) };
/// let ball = Forecast::sphere(Vec3::new(2.75, 2.0, 1.0), Vec3::x(), 0.0, 0.25, 0.0, 0.0)?;
/// let images = wall_images(&ball, &room, 0.0, 2.0);
/// assert_eq!(images.len(), 1);
/// // It touches the wall at t = 1 s and is back at x = 3.25 at t = 1.5 s.
/// assert!((images[0].center(1.5) - Vec3::new(3.25, 2.0, 1.0)).norm() < 1e-12);
/// # Ok::<(), trust_predict::PredictError>(())
/// ```
pub fn wall_images(forecast: &Forecast, walls: &Aabb, from: f64, until: f64) -> Vec<Forecast> {
    let half_extent = half_extents(forecast.shape, forecast.r_o);
    let axes: [Vec<AxisPiece>; 3] = std::array::from_fn(|a| {
        axis_pieces(
            forecast.p0[a],
            forecast.v0[a],
            forecast.t0,
            walls.min[a] + half_extent[a],
            walls.max[a] - half_extent[a],
            until,
        )
    });
    let mut images = Vec::new();
    for x in &axes[0] {
        for y in &axes[1] {
            for z in &axes[2] {
                if !(x.reflected || y.reflected || z.reflected) {
                    continue;
                }
                let start = x.from.max(y.from).max(z.from);
                let end = x.until.min(y.until).min(z.until);
                if start <= end && start <= until && end >= from {
                    images.push(Forecast {
                        p0: Vec3::new(x.q, y.q, z.q),
                        v0: Vec3::new(x.w, y.w, z.w),
                        ..*forecast
                    });
                }
            }
        }
    }
    images
}

/// The shape's half extents along x, y and z: where its centre turns at a wall
/// (`r_o` horizontally; a cylinder's half-height vertically). Shared by [`wall_images`] and the
/// tracker's fold ([`crate::CvEkf::with_walls`]), so the two agree on where an obstacle turns.
pub(crate) fn half_extents(shape: ObstacleShape, r_o: f64) -> [f64; 3] {
    [
        r_o,
        r_o,
        match shape {
            ObstacleShape::Sphere => r_o,
            ObstacleShape::Cylinder { half_height } => half_height,
        },
    ]
}

/// The straight pieces of `q + w·(t − t0)` folded into `[lo, hi]`, from the unreflected line up
/// to the first piece that starts after `until` (exclusive) or the reflection cap.
fn axis_pieces(q: f64, w: f64, t0: f64, lo: f64, hi: f64, until: f64) -> Vec<AxisPiece> {
    let mut pieces = vec![AxisPiece {
        q,
        w,
        from: f64::NEG_INFINITY,
        until: f64::INFINITY,
        reflected: false,
    }];
    if w.abs() < MIN_AXIS_SPEED || lo >= hi {
        return pieces;
    }
    let (mut q, mut w) = (q, w);
    for _ in 0..MAX_REFLECTIONS_PER_AXIS {
        let plane = if w > 0.0 { hi } else { lo };
        let hit = t0 + (plane - q) / w;
        if !hit.is_finite() || hit > until {
            break;
        }
        if let Some(last) = pieces.last_mut() {
            last.until = hit;
        }
        q = 2.0 * plane - q;
        w = -w;
        pieces.push(AxisPiece {
            q,
            w,
            from: hit,
            until: f64::INFINITY,
            reflected: true,
        });
    }
    pieces
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    #[test]
    fn the_walls_an_obstacle_stays_inside_are_optional_and_round_trip() {
        let f = Forecast::sphere(Vec3::zeros(), Vec3::x(), 1.0, 0.5, 0.2, 0.4).unwrap();
        assert_eq!(f.walls, None);
        let json = serde_json::to_string(&f).unwrap();
        assert!(!json.contains("walls"), "{json}");
        let region = Aabb::new(Vec3::new(-5.0, -5.0, 0.0), Vec3::new(5.0, 5.0, 3.0)).unwrap();
        let w = f.with_walls(region);
        assert_eq!(w.walls, Some(region));
        assert_eq!(w.radius(3.0), f.radius(3.0));
        let json = serde_json::to_string(&w).unwrap();
        assert_eq!(serde_json::from_str::<Forecast>(&json).unwrap(), w);
        // The images at the walls keep them.
        let images = wall_images(&w, &region, 1.0, 10.0);
        assert!(!images.is_empty() && images.iter().all(|i| i.walls == Some(region)));
    }

    fn room() -> Aabb {
        Aabb {
            min: Vec3::zeros(),
            max: Vec3::new(6.0, 4.0, 2.5),
        }
    }

    /// Folds `x` into `[lo, hi]` by mirror reflections — written independently of
    /// `axis_pieces` (triangle wave).
    fn fold(x: f64, lo: f64, hi: f64) -> f64 {
        let span = hi - lo;
        let u = (x - lo).rem_euclid(2.0 * span);
        lo + if u <= span { u } else { 2.0 * span - u }
    }

    fn folded_centre(f: &Forecast, walls: &Aabb, t: f64, e: [f64; 3]) -> Vec3 {
        let c = f.center(t);
        Vec3::from_fn(|a, _| fold(c[a], walls.min[a] + e[a], walls.max[a] - e[a]))
    }

    #[test]
    fn no_images_away_from_the_walls_or_at_rest() {
        let walker =
            Forecast::sphere(Vec3::new(3.0, 2.0, 1.0), Vec3::x(), 0.0, 0.3, 0.1, 0.2).unwrap();
        assert!(wall_images(&walker, &room(), 0.0, 2.0).is_empty());
        let still =
            Forecast::sphere(Vec3::new(5.65, 2.0, 1.0), Vec3::zeros(), 0.0, 0.3, 0.1, 0.2).unwrap();
        assert!(wall_images(&still, &room(), 0.0, 100.0).is_empty());
    }

    #[test]
    fn an_obstacle_wider_than_the_room_is_not_folded() {
        let wide =
            Forecast::sphere(Vec3::new(3.0, 2.0, 1.0), Vec3::y(), 0.0, 2.5, 0.0, 0.0).unwrap();
        assert!(wall_images(&wide, &room(), 0.0, 10.0).is_empty());
        assert!(
            wall_images(&wide, &room(), 0.0, 10.0)
                .iter()
                .all(|f| f.validate().is_ok())
        );
    }

    #[test]
    fn a_cylinder_reflects_at_its_half_height_vertically() {
        // A 0.2 m radius, 0.8 m half-height cylinder rising at 1 m/s from z = 1: its top touches
        // the ceiling 2.5 at t = 0.7.
        let shape = ObstacleShape::Cylinder { half_height: 0.8 };
        let f = Forecast::new(
            shape,
            Vec3::new(3.0, 2.0, 1.0),
            Vec3::z(),
            0.0,
            0.2,
            0.0,
            0.0,
        )
        .unwrap();
        assert!(wall_images(&f, &room(), 0.0, 0.69).is_empty());
        let images = wall_images(&f, &room(), 0.0, 0.71);
        assert_eq!(images.len(), 1);
        assert!((images[0].center(0.9).z - 1.5).abs() < 1e-12);
    }

    #[test]
    fn a_corner_gives_the_two_single_and_the_double_reflection() {
        let f = Forecast::sphere(
            Vec3::new(5.5, 3.5, 1.0),
            Vec3::new(1.0, 1.0, 0.0),
            0.0,
            0.25,
            0.0,
            0.0,
        )
        .unwrap();
        let images = wall_images(&f, &room(), 0.0, 1.0);
        assert_eq!(images.len(), 3);
        let c = folded_centre(&f, &room(), 1.0, [0.25; 3]);
        assert!(images.iter().any(|g| (g.center(1.0) - c).norm() < 1e-12));
    }

    proptest! {
        /// The folded motion of the obstacle is, at every instant of the window, the centre of
        /// the forecast or of one of its images (the union covers where it really is), and every
        /// image is a valid forecast.
        #[test]
        fn the_images_cover_the_folded_motion(
            p in (0.3f64..5.7, 0.3f64..3.7, 0.3f64..2.2),
            v in (-2.0f64..2.0, -2.0f64..2.0, -1.0f64..1.0),
            r in 0.05f64..0.3,
            window in 0.1f64..3.0,
            cylinder in any::<bool>(),
            s in 0.0f64..1.0,
        ) {
            let shape = if cylinder {
                ObstacleShape::Cylinder { half_height: r }
            } else {
                ObstacleShape::Sphere
            };
            let f = Forecast::new(
                shape,
                Vec3::new(p.0, p.1, p.2),
                Vec3::new(v.0, v.1, v.2),
                0.5,
                r,
                0.1,
                0.2,
            )
            .unwrap();
            let images = wall_images(&f, &room(), 0.5, 0.5 + window);
            prop_assert!(images.iter().all(|g| g.validate().is_ok()));
            let t = 0.5 + s * window;
            let truth = folded_centre(&f, &room(), t, [r; 3]);
            let nearest = std::iter::once(&f)
                .chain(&images)
                .map(|g| (g.center(t) - truth).norm())
                .fold(f64::INFINITY, f64::min);
            prop_assert!(nearest < 1e-9, "t = {t}: nearest centre {nearest} m from the fold");
        }
    }
}
