//! Separation of convex sets given by support mappings: the Gilbert–Johnson–Keerthi distance
//! iteration (Gilbert, Johnson & Keerthi 1988), used to clear a whole range of UVD chords, or a
//! whole roadmap region, against a swept obstacle at once.
//!
//! Only one answer is ever asserted: that two sets are at least `margin` apart. It rests on the
//! separating-axis bound alone — for any direction `v`, `dist(A, B) >= min over A−B of x·v/‖v‖`,
//! which the support mappings give exactly — so it is sound whatever the simplex bookkeeping does
//! with degenerate input; the iteration only makes the bound tight quickly.

use trust_core::Vec3;
use trust_predict::{ObstacleShape, Pdc};

/// Iteration cap of [`separated`]: GJK on a polytope of a few vertices and a smooth convex set
/// converges in a handful of steps; undecided cases after this many are reported as not separated.
const MAX_ITERATIONS: usize = 32;

/// Absolute tolerance (m) of the separation claim: [`separated`] answers `true` only for a bound of
/// at least `margin + SEPARATION_TOL`, so rounding never turns a touching pair into a clear one.
const SEPARATION_TOL: f64 = 1e-9;

/// A convex set described by its support mapping.
pub trait SupportMap {
    /// A point of the set that maximizes `x·d` (any point of the set for `d = 0`).
    fn support(&self, d: &Vec3) -> Vec3;
}

impl SupportMap for Pdc {
    fn support(&self, d: &Vec3) -> Vec3 {
        Pdc::support(self, d)
    }
}

/// The region that [`Pdc::segment_clear`] with `clearance` (≥ 0) treats as blocking: the cone
/// grown by `clearance` plus [`trust_predict::pdc::CLEAR_TOLERANCE`] — by a ball for a sphere cone,
/// by a vertical cylinder of that radius and half-height for a cylinder cone (the square rim of the
/// cylinder's segment test, not the rounded offset surface). A set proven [`separated`] from this
/// region at margin 0 contains no segment that the cone's own test calls blocked, for both shapes;
/// testing the bare cone at margin `clearance` instead would be exact Euclidean clearance, which
/// clears segments that pass a cylinder's rim between `clearance` and `√2·clearance` away although
/// [`Pdc::segment_clear`] (and therefore testing every chord) blocks them.
#[derive(Debug, Clone, Copy)]
pub struct Inflated<'a> {
    /// The cone.
    pub cone: &'a Pdc,
    /// The clearance of the segment test (m; negative values count as 0).
    pub clearance: f64,
}

impl SupportMap for Inflated<'_> {
    fn support(&self, d: &Vec3) -> Vec3 {
        let base = self.cone.support(d);
        let grow = self.clearance.max(0.0) + trust_predict::CLEAR_TOLERANCE;
        // Only the direction matters: rescale so that huge components cannot overflow the norm.
        let m = d.amax();
        if !(m.is_finite() && m > 0.0) {
            return base;
        }
        let d = d / m;
        if matches!(self.cone.forecast().shape, ObstacleShape::Cylinder { .. }) {
            let n = (d.x * d.x + d.y * d.y).sqrt();
            let (x, y) = if n > 0.0 {
                (d.x / n * grow, d.y / n * grow)
            } else {
                (0.0, 0.0)
            };
            let z = if d.z >= 0.0 { grow } else { -grow };
            base + Vec3::new(x, y, z)
        } else {
            base + d.normalize() * grow
        }
    }
}

/// The convex hull of a non-empty set of points.
#[derive(Debug, Clone, Copy)]
pub struct Hull<'a>(pub &'a [Vec3]);

impl SupportMap for Hull<'_> {
    fn support(&self, d: &Vec3) -> Vec3 {
        let mut best = self.0[0];
        let mut best_dot = best.dot(d);
        for p in &self.0[1..] {
            let dot = p.dot(d);
            if dot > best_dot {
                best = *p;
                best_dot = dot;
            }
        }
        best
    }
}

/// What [`proximity`] proved about two convex sets and a margin.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Proximity {
    /// At least `margin` apart.
    Apart,
    /// Closer than `margin` (or overlapping); only claimed for `margin > 0`.
    Within,
    /// Neither could be proven (the distance is within rounding of `margin`, or the input is not
    /// finite).
    Undecided,
}

/// True if the convex sets `a` and `b` are proven to be at least `margin` apart (distance between
/// their closest points). `false` means closer than `margin`, overlapping, or undecided within the
/// iteration cap and tolerance. Non-finite supports give `false`.
pub fn separated(a: &impl SupportMap, b: &impl SupportMap, margin: f64) -> bool {
    proximity(a, b, margin, &Vec3::x()) == Proximity::Apart
}

/// [`separated`] starting from the direction `guess` (from `b` toward `a`, e.g. between their
/// centres): a good guess decides most well-separated pairs in one support query each.
pub fn separated_along(
    a: &impl SupportMap,
    b: &impl SupportMap,
    margin: f64,
    guess: &Vec3,
) -> bool {
    proximity(a, b, margin, guess) == Proximity::Apart
}

/// Decides whether the distance between the convex sets `a` and `b` is at least `margin`
/// ([`Proximity::Apart`]) or below it ([`Proximity::Within`]), starting from the direction `guess`
/// (from `b` toward `a`). Both claims hold beyond a 1e-9 m tolerance; `Within` rests on a point of
/// `a − b` (a convex combination of support points) shorter than the margin, so it is only made for
/// `margin > 0`.
pub fn proximity(a: &impl SupportMap, b: &impl SupportMap, margin: f64, guess: &Vec3) -> Proximity {
    let goal = margin + SEPARATION_TOL;
    let within = margin - SEPARATION_TOL;
    let close = || {
        if within > 0.0 {
            Proximity::Within
        } else {
            Proximity::Undecided
        }
    };
    let first = if guess.iter().all(|x| x.is_finite()) && guess.norm_squared() > 0.0 {
        -guess
    } else {
        Vec3::x()
    };
    let mut v = a.support(&first) - b.support(&-first);
    let mut simplex = Simplex::default();
    for _ in 0..MAX_ITERATIONS {
        let vn = v.norm();
        if vn.is_nan() || vn.is_infinite() {
            return Proximity::Undecided;
        }
        if vn < within || vn <= 0.0 {
            // A point of A − B shorter than the margin, or the origin itself.
            return close();
        }
        let w = a.support(&-v) - b.support(&v);
        let lower = v.dot(&w) / vn;
        if lower.is_nan() {
            return Proximity::Undecided;
        }
        if lower >= goal {
            return Proximity::Apart;
        }
        // Converged (the bounds meet) or no progress: the distance is about `vn`.
        if vn - lower <= 1e-12 * vn.max(1.0) || simplex.contains(&w) {
            return Proximity::Undecided;
        }
        simplex.push(w);
        match simplex.closest_to_origin() {
            Some(p) => v = p,
            None => return close(),
        }
    }
    Proximity::Undecided
}

/// The GJK simplex: up to four points of the Minkowski difference.
#[derive(Debug, Clone, Copy, Default)]
struct Simplex {
    points: [Vec3; 4],
    len: usize,
}

impl Simplex {
    fn contains(&self, w: &Vec3) -> bool {
        self.points[..self.len].iter().any(|p| p == w)
    }

    fn push(&mut self, w: Vec3) {
        if self.len < 4 {
            self.points[self.len] = w;
            self.len += 1;
        } else {
            // Cannot happen after a reduction; keep the newest point rather than overflow.
            self.points[3] = w;
        }
    }

    /// Replaces the simplex by the smallest face containing its point closest to the origin and
    /// returns that point; `None` if the origin is inside a full tetrahedron.
    fn closest_to_origin(&mut self) -> Option<Vec3> {
        let p = self.points;
        let (point, keep): (Vec3, &[usize]) = match self.len {
            1 => (p[0], &[0]),
            2 => {
                let (q, k) = closest_on_segment(&p[0], &p[1]);
                (q, k)
            }
            3 => closest_on_triangle(&p[0], &p[1], &p[2]),
            _ => closest_on_tetrahedron(&p)?,
        };
        let mut kept = [Vec3::zeros(); 4];
        for (slot, &i) in kept.iter_mut().zip(keep) {
            *slot = p[i];
        }
        self.points = kept;
        self.len = keep.len();
        Some(point)
    }
}

/// Closest point of the segment `[a, b]` to the origin and the vertices of its feature.
fn closest_on_segment(a: &Vec3, b: &Vec3) -> (Vec3, &'static [usize]) {
    let ab = b - a;
    let len_sq = ab.norm_squared();
    if len_sq <= 0.0 {
        return (*a, &[0]);
    }
    let t = -a.dot(&ab) / len_sq;
    if t <= 0.0 {
        (*a, &[0])
    } else if t >= 1.0 {
        (*b, &[1])
    } else {
        (a + ab * t, &[0, 1])
    }
}

/// Closest point of the triangle `abc` to the origin (Voronoi regions of vertices, edges and face)
/// and the vertices of its feature (indices into `[a, b, c]`).
fn closest_on_triangle(a: &Vec3, b: &Vec3, c: &Vec3) -> (Vec3, &'static [usize]) {
    let ab = b - a;
    let ac = c - a;
    let d1 = -ab.dot(a);
    let d2 = -ac.dot(a);
    if d1 <= 0.0 && d2 <= 0.0 {
        return (*a, &[0]);
    }
    let d3 = -ab.dot(b);
    let d4 = -ac.dot(b);
    if d3 >= 0.0 && d4 <= d3 {
        return (*b, &[1]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let t = d1 / (d1 - d3);
        return (a + ab * t, &[0, 1]);
    }
    let d5 = -ab.dot(c);
    let d6 = -ac.dot(c);
    if d6 >= 0.0 && d5 <= d6 {
        return (*c, &[2]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let t = d2 / (d2 - d6);
        return (a + ac * t, &[0, 2]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let t = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + (c - b) * t, &[1, 2]);
    }
    let sum = va + vb + vc;
    if !(sum.is_finite() && sum > 0.0) {
        // Degenerate (collinear) triangle: fall back to the best edge.
        let edges: [(usize, usize); 3] = [(0, 1), (0, 2), (1, 2)];
        let pts = [a, b, c];
        let mut best: Option<(f64, Vec3, &'static [usize])> = None;
        for (i, j) in edges {
            let (q, k) = closest_on_segment(pts[i], pts[j]);
            let keep = edge_keep(k, i, j);
            let n = q.norm_squared();
            if best.is_none_or(|(m, _, _)| n < m) {
                best = Some((n, q, keep));
            }
        }
        let (_, q, keep) = best.expect("three edges were tried");
        return (q, keep);
    }
    let v = vb / sum;
    let w = vc / sum;
    (a + ab * v + ac * w, &[0, 1, 2])
}

/// Maps the feature `k` of edge `(i, j)` of a triangle (indices into the edge) to triangle vertex
/// indices.
fn edge_keep(k: &[usize], i: usize, j: usize) -> &'static [usize] {
    const VERTEX: [&[usize]; 3] = [&[0], &[1], &[2]];
    match k {
        [0] => VERTEX[i],
        [1] => VERTEX[j],
        _ => match (i, j) {
            (0, 1) => &[0, 1],
            (0, 2) => &[0, 2],
            _ => &[1, 2],
        },
    }
}

/// Closest point of the tetrahedron `p` to the origin and the vertices of its feature; `None` if the
/// origin is inside (or on) it.
fn closest_on_tetrahedron(p: &[Vec3; 4]) -> Option<(Vec3, &'static [usize])> {
    // Faces with the index of the opposite vertex.
    const FACES: [([usize; 3], usize); 4] = [
        ([0, 1, 2], 3),
        ([0, 2, 3], 1),
        ([0, 3, 1], 2),
        ([1, 3, 2], 0),
    ];
    let mut best: Option<(f64, Vec3, &'static [usize])> = None;
    for (face, opposite) in FACES {
        let [i, j, k] = face;
        let n = (p[j] - p[i]).cross(&(p[k] - p[i]));
        let origin_side = -n.dot(&p[i]);
        let opposite_side = n.dot(&(p[opposite] - p[i]));
        // The origin is outside this face if it lies strictly on the other side from the opposite
        // vertex (a degenerate, flat tetrahedron counts every side as outside).
        if origin_side * opposite_side < 0.0 || opposite_side == 0.0 {
            let (q, keep) = closest_on_triangle(&p[i], &p[j], &p[k]);
            let n2 = q.norm_squared();
            if best.is_none_or(|(m, _, _)| n2 < m) {
                best = Some((n2, q, face_keep(keep, face)));
            }
        }
    }
    best.map(|(_, q, keep)| (q, keep))
}

/// Maps a feature of a tetrahedron face (indices into the face) to tetrahedron vertex indices.
fn face_keep(keep: &[usize], face: [usize; 3]) -> &'static [usize] {
    // All subsets of {0, 1, 2, 3} in a fixed table, looked up by bit mask.
    const SUBSETS: [&[usize]; 16] = [
        &[],
        &[0],
        &[1],
        &[0, 1],
        &[2],
        &[0, 2],
        &[1, 2],
        &[0, 1, 2],
        &[3],
        &[0, 3],
        &[1, 3],
        &[0, 1, 3],
        &[2, 3],
        &[0, 2, 3],
        &[1, 2, 3],
        &[0, 1, 2, 3],
    ];
    let mask = keep.iter().fold(0usize, |m, &f| m | (1 << face[f]));
    SUBSETS[mask]
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    /// A ball, for tests.
    struct Ball(Vec3, f64);

    impl SupportMap for Ball {
        fn support(&self, d: &Vec3) -> Vec3 {
            let n = d.norm();
            if n > 0.0 {
                self.0 + d * (self.1 / n)
            } else {
                self.0
            }
        }
    }

    fn v3() -> impl Strategy<Value = Vec3> {
        prop::array::uniform3(-4.0..4.0f64).prop_map(|a| Vec3::new(a[0], a[1], a[2]))
    }

    /// Distance from `c` to the triangle `abc` by dense sampling.
    fn brute_triangle_distance(tri: &[Vec3; 3], c: &Vec3) -> f64 {
        let n = 120;
        let mut best = f64::INFINITY;
        for i in 0..=n {
            for j in 0..=(n - i) {
                let (u, v) = (i as f64 / n as f64, j as f64 / n as f64);
                let p = tri[0] + (tri[1] - tri[0]) * u + (tri[2] - tri[0]) * v;
                best = best.min((p - c).norm());
            }
        }
        best
    }

    proptest! {
        #[test]
        fn separation_claims_are_sound_and_tight(
            a in v3(), b in v3(), c in v3(), center in v3(), r in 0.1..2.0f64, margin in 0.0..1.0f64
        ) {
            let tri = [a, b, c];
            let exact = brute_triangle_distance(&tri, &center) - r;
            let claimed = separated(&Hull(&tri), &Ball(center, r), margin);
            // Sound: never claims separation that is not there (sampling error is below 0.1 m).
            if claimed {
                prop_assert!(exact >= margin - 0.1, "claimed {margin} but distance {exact}");
            }
            // Tight: a clear gap is found.
            if exact > margin + 0.1 {
                prop_assert!(claimed, "missed a gap: distance {exact} vs margin {margin}");
            }
            // The other side: `Within` is sound, and found for a clear overlap of the margin.
            let p = proximity(&Hull(&tri), &Ball(center, r), margin, &(a - center));
            if p == Proximity::Within {
                prop_assert!(exact < margin + 0.1, "claimed within {margin} but distance {exact}");
            }
            if exact < margin - 0.1 {
                prop_assert_eq!(p, Proximity::Within);
            }
        }

        #[test]
        fn tetrahedra_and_segments_work_too(
            pts in prop::array::uniform4(v3()), center in v3(), r in 0.1..1.0f64
        ) {
            let hull = Hull(&pts);
            let ball = Ball(center, r);
            if separated(&hull, &ball, 0.0) {
                // No vertex and no edge midpoint is inside the ball.
                for p in &pts {
                    prop_assert!((p - center).norm() >= r - 1e-9);
                }
            }
            let seg = Hull(&pts[..2]);
            let exact = {
                let ab = pts[1] - pts[0];
                let t = if ab.norm_squared() > 0.0 {
                    ((center - pts[0]).dot(&ab) / ab.norm_squared()).clamp(0.0, 1.0)
                } else {
                    0.0
                };
                (pts[0] + ab * t - center).norm() - r
            };
            if exact > 0.06 {
                prop_assert!(separated(&seg, &ball, 0.05));
            }
            if exact < 0.04 {
                prop_assert!(!separated(&seg, &ball, 0.05));
            }
        }
    }

    #[test]
    fn overlapping_and_degenerate_sets_are_not_separated() {
        let ball = Ball(Vec3::zeros(), 1.0);
        let through = [Vec3::new(-3.0, 0.0, 0.0), Vec3::new(3.0, 0.0, 0.0)];
        assert!(!separated(&Hull(&through), &ball, 0.0));
        let point = [Vec3::new(0.0, 0.0, 2.5)];
        assert!(separated(&Hull(&point), &ball, 1.0));
        assert!(!separated(&Hull(&point), &ball, 2.0));
        // Collinear "triangle" and flat "tetrahedron".
        let line = [
            Vec3::new(-1.0, 2.0, 0.0),
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(1.0, 2.0, 0.0),
        ];
        assert!(separated(&Hull(&line), &ball, 0.5));
        assert!(!separated(&Hull(&line), &ball, 1.5));
        let flat = [
            Vec3::new(-1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, -1.0),
            Vec3::new(1.0, 2.0, 1.0),
            Vec3::new(-1.0, 2.0, 1.0),
        ];
        assert!(separated(&Hull(&flat), &ball, 0.9));
        let nan = [Vec3::new(f64::NAN, 0.0, 0.0)];
        assert!(!separated(&Hull(&nan), &ball, 0.0));
        assert_eq!(
            proximity(&Hull(&nan), &ball, 0.5, &Vec3::x()),
            Proximity::Undecided
        );
    }

    #[test]
    fn proximity_proves_both_sides_of_a_positive_margin() {
        let ball = Ball(Vec3::zeros(), 1.0);
        let seg = [Vec3::new(-3.0, 1.5, 0.0), Vec3::new(3.0, 1.5, 0.0)];
        let toward = Vec3::y();
        assert_eq!(
            proximity(&Hull(&seg), &ball, 0.4, &toward),
            Proximity::Apart
        );
        assert_eq!(
            proximity(&Hull(&seg), &ball, 0.6, &toward),
            Proximity::Within
        );
        // Overlap: within any positive margin, undecided at margin 0 (touching or overlapping).
        let through = [Vec3::new(-3.0, 0.2, 0.0), Vec3::new(3.0, 0.2, 0.0)];
        assert_eq!(
            proximity(&Hull(&through), &ball, 0.1, &toward),
            Proximity::Within
        );
        assert_eq!(
            proximity(&Hull(&through), &ball, 0.0, &toward),
            Proximity::Undecided
        );
        // A bad guess direction still works.
        assert_eq!(
            proximity(&Hull(&seg), &ball, 0.4, &Vec3::new(f64::NAN, 0.0, 0.0)),
            Proximity::Apart
        );
    }

    /// Issue 18: a segment passing a cylinder's rim diagonally, `c` to `√2·c` away, is blocked by
    /// the cylinder's segment test (square rim) although it is more than `c` away in Euclidean
    /// distance; only the inflated region gives the test's answer.
    #[test]
    fn inflated_cylinder_has_the_square_rim_of_the_segment_test() {
        use trust_predict::{Forecast, ObstacleShape};
        let f = Forecast::new(
            ObstacleShape::Cylinder { half_height: 1.0 },
            Vec3::zeros(),
            Vec3::zeros(),
            0.0,
            1.0,
            0.0,
            0.0,
        )
        .unwrap();
        let cone = Pdc::at_time(&f, 0.0).unwrap();
        let c = 0.1;
        for (offset, blocked) in [(0.085, true), (0.12, false)] {
            // Beyond the rim corner (1, ·, 1) by `offset` both horizontally and vertically: the
            // Euclidean distance is `√2·offset` > c, the square-rim distance `offset`.
            let (a, b) = (
                Vec3::new(1.0 + offset, -2.0, 1.0 + offset),
                Vec3::new(1.0 + offset, 2.0, 1.0 + offset),
            );
            assert_eq!(!cone.segment_clear(&a, &b, c), blocked);
            assert!(separated(&Hull(&[a, b]), &cone, c), "Euclidean margin");
            let inflated = Inflated {
                cone: &cone,
                clearance: c,
            };
            assert_eq!(separated(&Hull(&[a, b]), &inflated, 0.0), !blocked);
        }
        // A sphere grows by a ball: the same as a Euclidean margin.
        let f = Forecast::new(
            ObstacleShape::Sphere,
            Vec3::zeros(),
            Vec3::zeros(),
            0.0,
            1.0,
            0.0,
            0.0,
        )
        .unwrap();
        let ball = Pdc::at_time(&f, 0.0).unwrap();
        let inflated = Inflated {
            cone: &ball,
            clearance: 0.1,
        };
        for gap in [0.09, 0.11] {
            let seg = [
                Vec3::new(-2.0, 1.0 + gap, 0.0),
                Vec3::new(2.0, 1.0 + gap, 0.0),
            ];
            assert_eq!(separated(&Hull(&seg), &inflated, 0.0), gap > 0.1);
            assert_eq!(ball.segment_clear(&seg[0], &seg[1], 0.1), gap > 0.1);
        }
    }
}
