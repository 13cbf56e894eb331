//! Exact minimization of convex functions along segments and over small parameter domains, the
//! building blocks of the predictive-directional-cone queries.
//!
//! Distances between a moving, growing sphere `‖x − c(t)‖ − r(t)` and a point or a segment `x(s)`
//! have the form `f(z) = ‖m + M z‖ − (k0 + kᵀz)` with `z = t` or `z = (s, t)`. Such an `f` is convex
//! (a norm of an affine map minus an affine function), so its minimum over an interval or a convex
//! polygon is either at the unconstrained stationary point (if that lies inside) or on the
//! boundary; both have closed forms ([`min_norm_minus_affine`] for an interval, the 2-D formula in
//! [`min_over_convex_polygon`]). The results are exact up to floating-point rounding.
//!
//! For a convex function of a point known only through its value and gradient (the signed distance
//! of a convex set), [`convex_segment_clear`] decides whether it stays above a level along a
//! segment with one-dimensional cutting planes, and [`segment_segment_distance`] gives the
//! capsule-versus-capsule distance used as a cheap accept/reject test before it.

use nalgebra::Vector2;
use trust_geometry::Vec3;

/// A 2-D point `(s, t)` of a parameter plane.
pub type Vec2 = Vector2<f64>;

/// The minimizer and minimum of a 1-D problem (see [`min_norm_minus_affine`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Min1d {
    /// Argument of the minimum.
    pub arg: f64,
    /// Minimum value.
    pub value: f64,
}

/// Minimizes `f(λ) = ‖w + λ·u‖ − (alpha + beta·λ)` over `λ ∈ [lo, hi]` in closed form.
///
/// `f` is convex. With `s = ‖u‖`, `x = w·û + sλ` and `b` the distance of the origin from the line
/// `w + λu`, `f' = s·x/√(x² + b²) − beta`; for `|beta| < s` the stationary point is
/// `x* = beta·b/√(s² − beta²)`, otherwise `f` is monotone. The unconstrained minimizer is clamped to
/// the interval (exact for a convex function of one variable). If `lo > hi` the two are swapped.
/// Inputs are assumed finite.
#[inline]
pub fn min_norm_minus_affine(w: &Vec3, u: &Vec3, alpha: f64, beta: f64, lo: f64, hi: f64) -> Min1d {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let s = u.norm();
    let arg = if s == 0.0 {
        if beta > 0.0 { hi } else { lo }
    } else if beta >= s {
        hi
    } else if beta <= -s {
        lo
    } else {
        let u_hat = u / s;
        let a_par = w.dot(&u_hat);
        let b = (w - u_hat * a_par).norm();
        let x_star = beta * b / ((s - beta) * (s + beta)).sqrt();
        ((x_star - a_par) / s).clamp(lo, hi)
    };
    Min1d {
        arg,
        value: (w + u * arg).norm() - (alpha + beta * arg),
    }
}

/// The affine-norm objective `f(z) = ‖m + z.x·mx + z.y·my‖ − (k0 + k·z)` over a parameter plane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NormMinusAffine2d {
    /// Constant part of the vector inside the norm.
    pub m: Vec3,
    /// Coefficient of `z.x` inside the norm.
    pub mx: Vec3,
    /// Coefficient of `z.y` inside the norm.
    pub my: Vec3,
    /// Constant part of the subtracted affine function.
    pub k0: f64,
    /// Linear part of the subtracted affine function.
    pub k: Vec2,
}

impl NormMinusAffine2d {
    /// Evaluates `f(z)`.
    pub fn eval(&self, z: &Vec2) -> f64 {
        (self.m + self.mx * z.x + self.my * z.y).norm() - (self.k0 + self.k.dot(z))
    }

    /// The unconstrained minimizer of `f` over the whole plane, if it exists and is unique.
    ///
    /// With `A = MᵀM` invertible, `κ² = kᵀA⁻¹k < 1` and `b` the distance of the origin from the plane
    /// `m + range(M)`, the stationary point has `‖m + Mz‖ = b/√(1 − κ²)` and
    /// `z = A⁻¹(k·‖m + Mz‖ − Mᵀm)`. Otherwise (`κ ≥ 1` or `M` rank-deficient) `f` has no unique
    /// minimizer and its minimum over any compact convex set is attained on the boundary.
    pub fn stationary_point(&self) -> Option<Vec2> {
        let (axx, axy, ayy) = (
            self.mx.dot(&self.mx),
            self.mx.dot(&self.my),
            self.my.dot(&self.my),
        );
        let det = axx * ayy - axy * axy;
        let well_conditioned = det > 1e-12 * axx * ayy && det > 0.0;
        if !well_conditioned {
            return None;
        }
        let solve = |r: Vec2| Vec2::new(ayy * r.x - axy * r.y, axx * r.y - axy * r.x) / det;
        let mt_m = Vec2::new(self.mx.dot(&self.m), self.my.dot(&self.m));
        let kappa2 = self.k.dot(&solve(self.k));
        let bounded_below = kappa2 < 1.0;
        if !bounded_below {
            return None;
        }
        let b2 = (self.m.norm_squared() - mt_m.dot(&solve(mt_m))).max(0.0);
        let rho = (b2 / (1.0 - kappa2)).sqrt();
        let z = solve(self.k * rho - mt_m);
        (z.x.is_finite() && z.y.is_finite()).then_some(z)
    }
}

/// Minimum of `f` (see [`NormMinusAffine2d`]) over the convex polygon with vertices `poly` in
/// counter-clockwise order (degenerate polygons — a segment or a point — are allowed). Returns
/// `f64::INFINITY` for an empty polygon.
///
/// Exact: the minimum of a convex function over a convex polygon is at the unconstrained
/// stationary point when that lies inside, and otherwise on an edge, where [`min_norm_minus_affine`]
/// solves the restriction in closed form.
pub fn min_over_convex_polygon(f: &NormMinusAffine2d, poly: &[Vec2]) -> f64 {
    let n = poly.len();
    if n == 0 {
        return f64::INFINITY;
    }
    let mut best = f64::INFINITY;
    for i in 0..n {
        let zi = poly[i];
        let dz = poly[(i + 1) % n] - zi;
        let w = f.m + f.mx * zi.x + f.my * zi.y;
        let u = f.mx * dz.x + f.my * dz.y;
        let edge = min_norm_minus_affine(&w, &u, f.k0 + f.k.dot(&zi), f.k.dot(&dz), 0.0, 1.0);
        best = best.min(edge.value);
    }
    if n >= 3
        && let Some(z) = f.stationary_point()
        && in_convex_polygon(poly, &z)
    {
        best = best.min(f.eval(&z));
    }
    best
}

/// Whether `z` lies in the closed convex polygon `poly` (counter-clockwise).
pub fn in_convex_polygon(poly: &[Vec2], z: &Vec2) -> bool {
    let n = poly.len();
    (0..n).all(|i| {
        let a = poly[i];
        let e = poly[(i + 1) % n] - a;
        let r = z - a;
        e.x * r.y - e.y * r.x >= 0.0
    })
}

/// Clips a convex polygon by the half-plane `a·z ≤ c` (Sutherland–Hodgman), keeping the vertex
/// order. Returns the clipped polygon (possibly empty).
pub fn clip_half_plane(poly: &[Vec2], a: &Vec2, c: f64) -> Vec<Vec2> {
    let n = poly.len();
    let mut out = Vec::with_capacity(n + 1);
    for i in 0..n {
        let p = poly[i];
        let q = poly[(i + 1) % n];
        let (fp, fq) = (a.dot(&p) - c, a.dot(&q) - c);
        if fp <= 0.0 {
            out.push(p);
        }
        if (fp < 0.0 && fq > 0.0) || (fp > 0.0 && fq < 0.0) {
            let t = fp / (fp - fq);
            out.push(p + (q - p) * t);
        }
    }
    out
}

/// Iteration cap of [`convex_segment_clear`] (each step shrinks the bracket by at least 5 %; in
/// practice a handful of steps decide).
const CUTTING_PLANE_ITERATIONS: usize = 200;

/// Parameters `(s, t) ∈ [0, 1]²` of the closest points `p0 + s·(p1 − p0)` and `q0 + t·(q1 − q0)` of
/// the segments `[p0, p1]` and `[q0, q1]` (clamped projection; degenerate segments allowed).
/// Coordinates beyond `trust_geometry::scale::QUERY_LIMIT` (or non-finite) give `(0, 0)`.
#[inline]
pub fn segment_segment_params(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> (f64, f64) {
    if ![p0, p1, q0, q1]
        .iter()
        .all(|v| trust_geometry::scale::queryable(v.as_slice()))
    {
        // No meaningful closest points; the segments' start points, never NaN.
        return (0.0, 0.0);
    }
    let d1 = p1 - p0;
    let d2 = q1 - q0;
    let r = p0 - q0;
    let a = d1.dot(&d1);
    let e = d2.dot(&d2);
    let f = d2.dot(&r);
    let tiny = 1e-18;
    if a <= tiny && e <= tiny {
        (0.0, 0.0)
    } else if a <= tiny {
        (0.0, (f / e).clamp(0.0, 1.0))
    } else {
        let c = d1.dot(&r);
        if e <= tiny {
            ((-c / a).clamp(0.0, 1.0), 0.0)
        } else {
            let b = d1.dot(&d2);
            let denom = a * e - b * b;
            let mut s = if denom > tiny * a * e {
                ((b * f - c * e) / denom).clamp(0.0, 1.0)
            } else {
                0.0
            };
            let mut t = (b * s + f) / e;
            if t < 0.0 {
                t = 0.0;
                s = (-c / a).clamp(0.0, 1.0);
            } else if t > 1.0 {
                t = 1.0;
                s = ((b - c) / a).clamp(0.0, 1.0);
            }
            (s, t)
        }
    }
}

/// Distance between the segments `[p0, p1]` and `[q0, q1]` (closest points by clamped projection;
/// degenerate segments allowed).
#[inline]
pub fn segment_segment_distance(p0: &Vec3, p1: &Vec3, q0: &Vec3, q1: &Vec3) -> f64 {
    let (s, t) = segment_segment_params(p0, p1, q0, q1);
    ((p0 + (p1 - p0) * s) - (q0 + (q1 - q0) * t)).norm()
}

/// Whether a convex function `f` (value and gradient, or any subgradient at kinks) stays at or above
/// `c` along the segment `[p, q]`.
///
/// Kelley's cutting-plane method in one dimension: the tangent lines at the ends of the bracket
/// bound the function from below, so the search stops as soon as that bound reaches `c` (clear) or
/// a value below `c` is seen (blocked); otherwise it evaluates at the tangents' intersection and
/// shrinks the bracket by the sign of the derivative there. A NaN value counts as blocked.
#[inline]
pub fn convex_segment_clear(p: &Vec3, q: &Vec3, c: f64, f: impl Fn(&Vec3) -> (f64, Vec3)) -> bool {
    let d = q - p;
    let eval = |s: f64| {
        let (v, g) = f(&(p + d * s));
        (v, g.dot(&d))
    };
    let (mut lo, (mut f_lo, mut d_lo)) = (0.0, eval(0.0));
    if f_lo.is_nan() || f_lo < c {
        return false;
    }
    let (mut hi, (mut f_hi, mut d_hi)) = (1.0, eval(1.0));
    if f_hi.is_nan() || f_hi < c {
        return false;
    }
    for _ in 0..CUTTING_PLANE_ITERATIONS {
        if d_lo >= 0.0 || d_hi <= 0.0 {
            // Monotone on the bracket: the minimum is at an end, already checked.
            return true;
        }
        let width = hi - lo;
        let mut m = (f_hi - f_lo + d_lo * lo - d_hi * hi) / (d_lo - d_hi);
        let bound = f_lo + d_lo * (m - lo);
        if bound >= c {
            return true;
        }
        if width < 1e-12 {
            return true;
        }
        // Keep the new point away from the ends so that the bracket always shrinks.
        m = m.clamp(lo + 0.05 * width, hi - 0.05 * width);
        let (f_m, d_m) = eval(m);
        if f_m.is_nan() || f_m < c {
            return false;
        }
        if d_m > 0.0 {
            (hi, f_hi, d_hi) = (m, f_m, d_m);
        } else {
            (lo, f_lo, d_lo) = (m, f_m, d_m);
        }
    }
    true
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::prelude::*;

    fn v3() -> impl Strategy<Value = Vec3> {
        (-3.0..3.0f64, -3.0..3.0f64, -3.0..3.0f64).prop_map(|(x, y, z)| Vec3::new(x, y, z))
    }

    #[test]
    fn one_d_zero_direction_is_linear() {
        let w = Vec3::new(1.0, 0.0, 0.0);
        let m = min_norm_minus_affine(&w, &Vec3::zeros(), 0.5, 2.0, 0.0, 3.0);
        assert_eq!(m.arg, 3.0);
        approx::assert_relative_eq!(m.value, 1.0 - 0.5 - 6.0);
        let m = min_norm_minus_affine(&w, &Vec3::zeros(), 0.5, -2.0, 0.0, 3.0);
        assert_eq!(m.arg, 0.0);
    }

    #[test]
    fn one_d_swapped_interval() {
        let w = Vec3::new(-2.0, 1.0, 0.0);
        let u = Vec3::new(1.0, 0.0, 0.0);
        let a = min_norm_minus_affine(&w, &u, 0.0, 0.0, 0.0, 5.0);
        let b = min_norm_minus_affine(&w, &u, 0.0, 0.0, 5.0, 0.0);
        assert_eq!(a, b);
        approx::assert_relative_eq!(a.arg, 2.0);
        approx::assert_relative_eq!(a.value, 1.0);
    }

    #[test]
    fn empty_polygon_is_infinite() {
        let f = NormMinusAffine2d {
            m: Vec3::zeros(),
            mx: Vec3::x(),
            my: Vec3::y(),
            k0: 0.0,
            k: Vec2::zeros(),
        };
        assert_eq!(min_over_convex_polygon(&f, &[]), f64::INFINITY);
    }

    #[test]
    fn clip_keeps_and_cuts() {
        let sq = [
            Vec2::new(0.0, 0.0),
            Vec2::new(1.0, 0.0),
            Vec2::new(1.0, 1.0),
            Vec2::new(0.0, 1.0),
        ];
        assert_eq!(clip_half_plane(&sq, &Vec2::new(1.0, 0.0), 2.0).len(), 4);
        assert!(clip_half_plane(&sq, &Vec2::new(1.0, 0.0), -0.5).is_empty());
        let half = clip_half_plane(&sq, &Vec2::new(1.0, 1.0), 1.0);
        assert_eq!(half.len(), 3);
        assert!(in_convex_polygon(&half, &Vec2::new(0.2, 0.2)));
        assert!(!in_convex_polygon(&half, &Vec2::new(0.8, 0.8)));
    }

    proptest! {
        #[test]
        fn one_d_matches_dense_sampling(w in v3(), u in v3(), alpha in -2.0..2.0f64, beta in -4.0..4.0f64,
                                        lo in -2.0..2.0f64, len in 0.0..3.0f64) {
            let hi = lo + len;
            let m = min_norm_minus_affine(&w, &u, alpha, beta, lo, hi);
            prop_assert!(m.arg >= lo && m.arg <= hi);
            let f = |l: f64| (w + u * l).norm() - (alpha + beta * l);
            let n = 2000;
            let dense = (0..=n).map(|i| f(lo + len * i as f64 / n as f64)).fold(f64::INFINITY, f64::min);
            prop_assert!(m.value <= dense + 1e-9, "closed form {} above dense {}", m.value, dense);
            let lip = u.norm() + beta.abs();
            prop_assert!(m.value >= dense - lip * len / n as f64 - 1e-9);
        }

        #[test]
        fn segment_distance_matches_sampling(p0 in v3(), p1 in v3(), q0 in v3(), q1 in v3()) {
            let d = segment_segment_distance(&p0, &p1, &q0, &q1);
            let mut brute = f64::INFINITY;
            for i in 0..=200 {
                for j in 0..=200 {
                    let x = p0 + (p1 - p0) * (i as f64 / 200.0);
                    let y = q0 + (q1 - q0) * (j as f64 / 200.0);
                    brute = brute.min((x - y).norm());
                }
            }
            prop_assert!(d <= brute + 1e-9);
            prop_assert!(brute - d < 0.1);
        }

        /// The cutting-plane test against dense sampling of a convex function: the distance to a
        /// ball minus a linear term.
        #[test]
        fn cutting_planes_match_dense_sampling(p in v3(), q in v3(), center in v3(), r in 0.1..2.0f64,
                                               slope in v3(), c in -0.5..0.5f64) {
            let slope = slope * 0.2;
            let f = |x: &Vec3| {
                let d = x - center;
                let n = d.norm().max(1e-300);
                (n - r + slope.dot(x), d / n + slope)
            };
            let clear = convex_segment_clear(&p, &q, c, f);
            let n = 4000;
            let dense = (0..=n).map(|k| f(&(p + (q - p) * (k as f64 / n as f64))).0).fold(f64::INFINITY, f64::min);
            let slack = (1.0 + slope.norm()) * (q - p).norm() / n as f64 + 1e-9;
            if dense < c - 1e-9 {
                prop_assert!(!clear, "dense min {dense} < {c} but reported clear");
            }
            if dense > c + slack {
                prop_assert!(clear, "dense min {dense} > {c} but reported blocked");
            }
        }

        #[test]
        fn polygon_matches_dense_sampling(m in v3(), mx in v3(), my in v3(), k0 in -1.0..1.0f64,
                                          kx in -1.5..1.5f64, ky in -1.5..1.5f64) {
            let f = NormMinusAffine2d { m, mx, my, k0, k: Vec2::new(kx, ky) };
            let sq = [Vec2::new(0.0, 0.0), Vec2::new(1.0, 0.0), Vec2::new(1.0, 1.0), Vec2::new(0.0, 1.0)];
            let exact = min_over_convex_polygon(&f, &sq);
            let n = 150;
            let mut dense = f64::INFINITY;
            for i in 0..=n {
                for j in 0..=n {
                    dense = dense.min(f.eval(&Vec2::new(i as f64 / n as f64, j as f64 / n as f64)));
                }
            }
            prop_assert!(exact <= dense + 1e-9, "exact {} above dense {}", exact, dense);
            let lip = (mx.norm() + kx.abs()) + (my.norm() + ky.abs());
            prop_assert!(exact >= dense - lip / n as f64 - 1e-9, "exact {} far below dense {}", exact, dense);
        }
    }
}
