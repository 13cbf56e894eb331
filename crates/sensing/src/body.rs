//! Space the vehicle's body fills: free whatever the sensor saw.
//!
//! A vehicle of radius `R` at `c` fills the ball `B(c, R)`; nothing else is there (or it would
//! have collided). The known-free commit check ([`crate::LocalMap::segment_known_free_beside`])
//! therefore accepts a voxel it has not observed free when the part of it the vehicle's
//! clearance tube reaches lies inside that ball: a vehicle at rest may commit to its own place,
//! and a plan leaving it needs observed free space only where it pokes out of the body
//! (decision 0051). The test here is conservative: a box is split at most [`SPLIT_DEPTH`] times
//! and a piece that still straddles both the tube and the body's surface counts as outside.

use trust_geometry::Vec3;

/// How many times a voxel box is halved along each axis before a piece that straddles the
/// body's surface counts as outside it: 2 (pieces of a quarter voxel, 2.5 cm at 0.1 m).
pub const SPLIT_DEPTH: u32 = 2;

/// How far a plan's end may lie from the body's centre and still count as the vehicle's own
/// place, in voxels: 0.05 (5 mm at 0.1 m). A plan's start and the measured position differ by
/// the tracking error (1–2 mm for a hovering vehicle in the simulator), and the smallest
/// difference leaves a sliver of tube beside the body; a plan held within it moves the vehicle
/// at most this far into unseen space per cycle.
pub const HOVER_VOXELS: f64 = 0.05;

/// A ball the vehicle's body fills.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyBall {
    /// The vehicle's position (m).
    pub center: Vec3,
    /// The vehicle's radius (m).
    pub radius: f64,
}

impl BodyBall {
    /// True if the centre and the radius are finite and the radius is not negative.
    pub fn is_valid(&self) -> bool {
        self.center.iter().all(|x| x.is_finite()) && self.radius.is_finite() && self.radius >= 0.0
    }
}

/// Squared distance from `p` to the box `[lo, hi]` (0 inside).
fn dist2_to_box(p: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    (0..3)
        .map(|i| (lo[i] - p[i]).max(0.0).max(p[i] - hi[i]).powi(2))
        .sum()
}

/// Squared distance from `p` to the farthest corner of the box `[lo, hi]`.
fn far2_to_box(p: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    (0..3)
        .map(|i| (p[i] - lo[i]).abs().max((hi[i] - p[i]).abs()).powi(2))
        .sum()
}

/// Distance from `p` to the segment `[a, b]`.
fn dist_to_segment(p: &Vec3, a: &Vec3, b: &Vec3) -> f64 {
    let ab = b - a;
    let l2 = ab.norm_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(&ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p - (a + t * ab)).norm()
}

/// A lower bound on the distance from the segment `[a, b]` to the box `[lo, hi]`, tight to
/// 1e-9 of the segment's length: the distance along the segment is convex, so a ternary
/// search brackets its minimum.
fn segment_box_distance(a: &Vec3, b: &Vec3, lo: &Vec3, hi: &Vec3) -> f64 {
    let at = |t: f64| dist2_to_box(&(a + t * (b - a)), lo, hi).sqrt();
    let (mut l, mut h) = (0.0, 1.0);
    for _ in 0..60 {
        let (m1, m2) = (l + (h - l) / 3.0, h - (h - l) / 3.0);
        if at(m1) <= at(m2) {
            h = m2;
        } else {
            l = m1;
        }
    }
    (at(0.5 * (l + h)) - 0.5 * (h - l) * (b - a).norm()).max(0.0)
}

/// One piece of a segment's clearance tube: the ball round an end, or the cylinder of points
/// whose nearest point of the segment lies strictly inside it.
enum Piece {
    Ball(Vec3),
    Cylinder(Vec3, Vec3),
}

impl Piece {
    /// True if the piece (of radius `r`) surely misses the cell of centre `m` and half
    /// extents `half`.
    fn misses(&self, m: &Vec3, half: &Vec3, r: f64) -> bool {
        match self {
            Piece::Ball(p) => {
                let lo = m - half;
                let hi = m + half;
                dist2_to_box(p, &lo, &hi) > r * r
            }
            Piece::Cylinder(a, b) => {
                let ab = b - a;
                let len = ab.norm();
                let u = ab / len;
                let along = (m - a).dot(&u);
                let spread: f64 = (0..3).map(|i| half[i] * u[i].abs()).sum();
                along + spread < 0.0
                    || along - spread > len
                    || dist_to_segment(m, a, b) - half.norm() > r
            }
        }
    }
}

/// True if no point of the box `[lo, hi]` lies within `r` of the segment `[a, b]` and farther
/// than `reach` from `c`: `h(p) = |p − c|² − dist(p, [a, b])²` exceeds `reach² − r²` at every
/// such point, and `h` is convex (the largest of the functions `|p − c|² − |p − q|²`, linear
/// in `p`, over the segment's points `q`), so the box's corners bound it. Exact where the
/// body's surface cuts the tube at a shallow angle, where halving the box cannot resolve it.
fn tube_beyond_excluded(
    lo: &Vec3,
    hi: &Vec3,
    a: &Vec3,
    b: &Vec3,
    r: f64,
    c: &Vec3,
    reach: f64,
) -> bool {
    let bound = reach * reach - r * r;
    (0..8).all(|corner: usize| {
        let x = Vec3::from_fn(|i, _| if corner >> i & 1 == 1 { hi[i] } else { lo[i] });
        (x - c).norm_squared() - dist_to_segment(&x, a, b).powi(2) <= bound
    })
}

/// The segment, the clearance and the body a cell is judged for.
struct Tube<'a> {
    a: &'a Vec3,
    b: &'a Vec3,
    r: f64,
    body: &'a BodyBall,
    /// How far beyond the body's surface the tube may reach (m).
    hover_m: f64,
}

/// True if every point of the cell `[lo, hi]` in `piece` (radius `tube.r`) lies in the body
/// (grown by `tube.hover_m` for [`tube_beyond_excluded`]): the cell is halved `depth` more
/// times where it straddles both.
fn cell_in_body(lo: &Vec3, hi: &Vec3, piece: &Piece, tube: &Tube<'_>, depth: u32) -> bool {
    let (r, body) = (tube.r, tube.body);
    let (m, half) = (0.5 * (lo + hi), 0.5 * (hi - lo));
    if piece.misses(&m, &half, r)
        || far2_to_box(&body.center, lo, hi) <= body.radius.powi(2)
        || tube_beyond_excluded(
            lo,
            hi,
            tube.a,
            tube.b,
            r,
            &body.center,
            body.radius + tube.hover_m,
        )
    {
        return true;
    }
    if depth == 0 || dist2_to_box(&body.center, lo, hi) >= body.radius.powi(2) {
        return false;
    }
    (0..8).all(|octant: usize| {
        let pick = |i: usize| octant >> i & 1 == 1;
        let l = Vec3::from_fn(|i, _| if pick(i) { m[i] } else { lo[i] });
        let h = Vec3::from_fn(|i, _| if pick(i) { hi[i] } else { m[i] });
        cell_in_body(&l, &h, piece, tube, depth - 1)
    })
}

/// True if every point of the box `[lo, hi]` within `clearance` of the segment `[a, b]` lies in
/// `body`, up to `hover_m` (conservative otherwise). The tube is the balls round the ends and
/// the cylinder between them; a ball round an end within `hover_m` of the body's centre counts
/// as the body (a vehicle holding its place: the plan's start and the measured position differ
/// by the tracking error), and so does the tube's part within `hover_m` of the body's surface
/// where a convexity bound shows it (`tube_beyond_excluded`). The box is halved
/// [`SPLIT_DEPTH`] times where a piece and the body's surface both cross it.
pub fn tube_part_in_body(
    lo: &Vec3,
    hi: &Vec3,
    a: &Vec3,
    b: &Vec3,
    clearance: f64,
    body: &BodyBall,
    hover_m: f64,
) -> bool {
    let r = clearance;
    if segment_box_distance(a, b, lo, hi) > r {
        return true;
    }
    let held = |p: &Vec3| (p - body.center).norm() + r <= body.radius + hover_m;
    if held(a) && held(b) {
        return true;
    }
    if dist2_to_box(&body.center, lo, hi) >= body.radius.powi(2) {
        return false;
    }
    let tube = Tube {
        a,
        b,
        r,
        body,
        hover_m,
    };
    let mut pieces = Vec::with_capacity(3);
    for p in [a, b] {
        if !held(p) {
            pieces.push(Piece::Ball(*p));
        }
    }
    if (b - a).norm() > 0.0 {
        pieces.push(Piece::Cylinder(*a, *b));
    }
    pieces
        .iter()
        .all(|piece| cell_in_body(lo, hi, piece, &tube, SPLIT_DEPTH))
}

/// True if a plan along `[a, b]` may pass the box `[lo, hi]`, which the vehicle has not
/// observed free, keeping `clearance` (its radius) and a tracking `margin` beyond it: the
/// part of the box within `clearance` of the segment lies in `body` ([`tube_part_in_body`]),
/// and the segment comes within `clearance + margin` of the box only if it comes no nearer
/// to it than the body's centre is, up to `hover_m`. A vehicle beside unseen space may hold
/// its place or leave it, but not approach it closer than the margin: a plan that hugs what
/// the sensor has not seen leaves no room for the vehicle's tracking error (decision 0054).
/// With `margin` 0 this is [`tube_part_in_body`].
#[allow(clippy::too_many_arguments)]
pub fn unseen_box_passable(
    lo: &Vec3,
    hi: &Vec3,
    a: &Vec3,
    b: &Vec3,
    clearance: f64,
    margin: f64,
    body: &BodyBall,
    hover_m: f64,
) -> bool {
    let d = segment_box_distance(a, b, lo, hi);
    if d > clearance + margin {
        return true;
    }
    if margin > 0.0 && d + hover_m < dist2_to_box(&body.center, lo, hi).sqrt() {
        return false;
    }
    tube_part_in_body(lo, hi, a, b, clearance, body, hover_m)
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    const HOVER: f64 = 1e-3;

    fn v(x: f64, y: f64, z: f64) -> Vec3 {
        Vec3::new(x, y, z)
    }

    fn body(c: Vec3, radius: f64) -> BodyBall {
        BodyBall { center: c, radius }
    }

    /// Points of the box on a grid (its corners included).
    fn grid(lo: &Vec3, hi: &Vec3, n: usize) -> Vec<Vec3> {
        let f = |t: usize, i: usize| lo[i] + (hi[i] - lo[i]) * t as f64 / n as f64;
        let mut out = Vec::new();
        for i in 0..=n {
            for j in 0..=n {
                for k in 0..=n {
                    out.push(v(f(i, 0), f(j, 1), f(k, 2)));
                }
            }
        }
        out
    }

    #[test]
    fn a_vehicle_at_rest_fills_its_own_clearance() {
        let me = body(v(0.03, -0.02, 0.04), 0.3);
        let (lo, hi) = (v(0.2, 0.0, 0.0), v(0.3, 0.1, 0.1));
        let c = me.center;
        assert!(tube_part_in_body(&lo, &hi, &c, &c, 0.3, &me, HOVER));
        // Half a millimetre off its place: still its place.
        let near = c + v(0.0, 5e-4, 0.0);
        assert!(tube_part_in_body(&lo, &hi, &near, &near, 0.3, &me, HOVER));
        // A plan leaving it 5 cm towards the box pokes out of the body into the box.
        let toward = c + v(0.05, 0.0, 0.0);
        assert!(!tube_part_in_body(&lo, &hi, &c, &toward, 0.3, &me, HOVER));
        // Away from the box, the tube reaches the box only inside the body.
        let away = c - v(0.05, 0.0, 0.0);
        assert!(tube_part_in_body(&lo, &hi, &c, &away, 0.3, &me, HOVER));
    }

    #[test]
    fn a_plan_leaving_the_body_sweeps_beside_it() {
        // The box straddles the body's surface beside the motion: the tube's side leaves the
        // ball right where the motion starts, so a voxel there must be seen.
        let me = body(v(0.0, 0.0, 0.0), 0.2);
        let (lo, hi) = (v(-0.05, 0.15, -0.05), v(0.05, 0.25, 0.05));
        let ahead = v(0.1, 0.0, 0.0);
        assert!(!tube_part_in_body(
            &lo, &hi, &me.center, &ahead, 0.2, &me, HOVER
        ));
        assert!(tube_part_in_body(
            &lo, &hi, &me.center, &me.center, 0.2, &me, HOVER
        ));
    }

    #[test]
    fn a_plan_rising_off_an_unseen_voxel_below_may_leave() {
        // Hovering 3 mm off its plan above a voxel its camera never saw (the body's surface
        // cuts it 1 mm below its top), the plan rises and slides away: the tube stays in the
        // body there, although halving the box cannot show it (measured in a flight that
        // stalled 50 s on it).
        let me = body(Vec3::zeros(), 0.3);
        let (lo, hi) = (v(-0.127, -0.057, -0.342), v(-0.027, 0.043, -0.292));
        let a = v(-0.0001, -0.0033, 0.0004);
        let b = v(-0.0002, -0.0056, 0.0012);
        assert!(tube_part_in_body(&lo, &hi, &a, &b, 0.3, &me, 0.005));
        // Sinking 1 cm towards it is refused.
        assert!(!tube_part_in_body(
            &lo,
            &hi,
            &a,
            &v(0.0, 0.0, -0.01),
            0.3,
            &me,
            0.005
        ));
    }

    #[test]
    fn a_box_out_of_reach_needs_no_body() {
        let far = body(v(10.0, 10.0, 10.0), 0.0);
        let (lo, hi) = (v(1.0, 1.0, 1.0), v(1.1, 1.1, 1.1));
        let o = Vec3::zeros();
        assert!(tube_part_in_body(
            &lo,
            &hi,
            &o,
            &v(0.5, 0.0, 0.0),
            0.3,
            &far,
            HOVER
        ));
        assert!(!tube_part_in_body(
            &lo,
            &hi,
            &o,
            &v(1.05, 1.05, 0.9),
            0.3,
            &far,
            HOVER
        ));
    }

    #[test]
    fn a_body_must_be_finite() {
        assert!(!body(v(f64::NAN, 0.0, 0.0), 0.1).is_valid());
        assert!(!body(Vec3::zeros(), -0.1).is_valid());
        assert!(!body(Vec3::zeros(), f64::INFINITY).is_valid());
        assert!(body(Vec3::zeros(), 0.0).is_valid());
    }

    #[test]
    fn the_segment_box_distance_is_a_tight_lower_bound() {
        let (lo, hi) = (v(1.0, 0.0, 0.0), v(2.0, 1.0, 1.0));
        let d = segment_box_distance(&v(0.0, 2.0, 0.5), &v(3.0, 2.0, 0.5), &lo, &hi);
        assert!((d - 1.0).abs() < 1e-8, "{d}");
        assert_eq!(
            segment_box_distance(&v(0.0, 0.5, 0.5), &v(3.0, 0.5, 0.5), &lo, &hi),
            0.0
        );
        let p = v(0.0, -1.0, 0.5);
        assert!((segment_box_distance(&p, &p, &lo, &hi) - 2f64.sqrt()).abs() < 1e-12);
    }

    #[test]
    fn the_margin_keeps_a_plan_off_unseen_space_it_approaches() {
        // A 0.3 m vehicle, an unseen box 2 cm beyond its clearance on +x, a 3 cm margin.
        let me = body(v(0.0, 0.0, 0.0), 0.3);
        let (lo, hi) = (v(0.32, -0.05, -0.05), v(0.42, 0.05, 0.05));
        let c = me.center;
        let pass =
            |a: &Vec3, b: &Vec3, m: f64| unseen_box_passable(&lo, &hi, a, b, 0.3, m, &me, HOVER);
        // Holding its place or leaving: allowed.
        assert!(pass(&c, &c, 0.03));
        assert!(pass(&c, &v(-0.5, 0.0, 0.0), 0.03));
        // Along its face: no nearer to this box (the boxes ahead on the face are approached).
        assert!(pass(&c, &v(0.0, 0.4, 0.0), 0.03));
        // 1 cm nearer: refused with the margin, allowed without it (the tube keeps the
        // clearance); 3 cm nearer the tube itself reaches the box.
        let nearer = v(0.01, 0.0, 0.0);
        assert!(!pass(&c, &nearer, 0.03));
        assert!(pass(&c, &nearer, 0.0));
        assert!(!pass(&c, &v(0.03, 0.0, 0.0), 0.0));
        // Farther than clearance + margin: no question.
        let away = body(v(-0.1, 0.0, 0.0), 0.3);
        assert!(unseen_box_passable(
            &lo,
            &hi,
            &away.center,
            &v(-0.1, 1.0, 0.0),
            0.3,
            0.03,
            &away,
            HOVER
        ));
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(96))]

        /// With the margin, a passed box lies beyond `clearance + margin` of the segment or
        /// no nearer to it than to the body's centre; with margin 0 the rule is the body's.
        #[test]
        fn the_margin_only_refuses_approaches(
            c in prop::array::uniform3(-0.2f64..0.2),
            d in prop::array::uniform3(-0.3f64..0.3),
            corner in prop::array::uniform3(-0.6f64..0.5),
            r in 0.05f64..0.4,
            m in 0.0f64..0.05,
        ) {
            let me = body(v(c[0], c[1], c[2]), r);
            let (a, b) = (me.center, me.center + v(d[0], d[1], d[2]));
            let lo = v(corner[0], corner[1], corner[2]);
            let hi = lo + v(0.1, 0.1, 0.1);
            let passed = unseen_box_passable(&lo, &hi, &a, &b, r, m, &me, HOVER);
            let seg = segment_box_distance(&a, &b, &lo, &hi);
            if passed {
                prop_assert!(seg > r + m || seg + HOVER >= dist2_to_box(&me.center, &lo, &hi).sqrt());
                prop_assert!(tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER));
            }
            prop_assert_eq!(
                unseen_box_passable(&lo, &hi, &a, &b, r, 0.0, &me, HOVER),
                tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER)
            );
        }

        /// Sound: when the test accepts, no grid point of the box within the clearance of the
        /// segment lies outside the body (grown by the hover tolerance).
        #[test]
        fn an_accepted_box_has_no_point_in_the_tube_outside_the_body(
            c in prop::array::uniform3(-0.2f64..0.2),
            start in prop::array::uniform3(-0.05f64..0.05),
            d in prop::array::uniform3(-0.3f64..0.3),
            corner in prop::array::uniform3(-0.6f64..0.5),
            r in 0.05f64..0.4,
        ) {
            let me = body(v(c[0], c[1], c[2]), r);
            let a = me.center + v(start[0], start[1], start[2]);
            let b = a + v(d[0], d[1], d[2]);
            let lo = v(corner[0], corner[1], corner[2]);
            let hi = lo + v(0.1, 0.1, 0.1);
            if tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER) {
                for p in grid(&lo, &hi, 8) {
                    prop_assert!(
                        dist_to_segment(&p, &a, &b) > r || (p - me.center).norm() <= r + HOVER,
                        "{p:?} is in the tube and outside the body"
                    );
                }
            }
        }

        /// Not too conservative: a box well clear of the tube, or wholly inside the body,
        /// passes; so does any box for a vehicle holding its place.
        #[test]
        fn a_clear_box_passes(
            c in prop::array::uniform3(-0.2f64..0.2),
            d in prop::array::uniform3(-0.3f64..0.3),
            corner in prop::array::uniform3(-0.6f64..0.5),
            r in 0.05f64..0.4,
        ) {
            let me = body(v(c[0], c[1], c[2]), r);
            let a = me.center;
            let b = a + v(d[0], d[1], d[2]);
            let lo = v(corner[0], corner[1], corner[2]);
            let hi = lo + v(0.1, 0.1, 0.1);
            let clear = grid(&lo, &hi, 8).iter().all(|p| dist_to_segment(p, &a, &b) > r + 0.1);
            let inside = far2_to_box(&me.center, &lo, &hi) <= r * r;
            if clear || inside {
                prop_assert!(tube_part_in_body(&lo, &hi, &a, &b, r, &me, HOVER));
            }
            prop_assert!(tube_part_in_body(&lo, &hi, &a, &a, r, &me, HOVER));
        }
    }
}
