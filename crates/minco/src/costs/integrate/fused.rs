//! The objective's integration rule: [`TrapezoidIntegrator::integrate_penalties`] runs the same
//! quadrature loop as [`TrapezoidIntegrator::integrate`] with a rule specialised to
//! [`PenaltyIntegrand`] that does the full work only at the nodes where a penalty can be active.
//!
//! Per piece, cheap conservative filters mark the nodes that may contribute; only those go
//! through the per-node evaluation of the generic path (same formulas, same order; node values
//! the filters computed column by column are reused, summed in the same order), so the result is
//! the same to the last bit. The filters:
//! - acceleration and speed: first a bound over the whole piece — the largest norm of the
//!   Bernstein (Bézier) control points of the acceleration (degree 3) or velocity (degree 4)
//!   bounds the norm everywhere on the piece (convex hull) — and only if that bound exceeds the
//!   limit, the squared norm at every node, computed column by column (vectorizable);
//! - obstacles: positions and node times column by column, then per candidate obstacle a
//!   squared-distance test against the inflated obstacle grown by
//!   [`FILTER_MARGIN_M`](crate::costs::integrand::FILTER_MARGIN_M).
//!
//! Every filter keeps a margin far above floating-point rounding, so a node it skips has a
//! violation `≤ 0` for every term also when evaluated exactly as in the generic path.
//!
//! On the E2 solves this path and the split L-BFGS solve cut the instructions per solve by about
//! 45 % (callgrind); on the representative benchmark problem, where nearly every node is active,
//! it costs about the same as the generic path.

use trust_core::{Aabb, Vec3, bernstein_points};

use super::{
    PieceContext, PieceIntegral, PieceRule, PiecewiseView, ScaledPiece, TrapezoidIntegrator,
    points_box,
};
use crate::costs::PenaltyIntegrand;
use crate::error::MincoError;

/// Relative margin of the speed and acceleration filters on squared norms.
const LIMIT_FILTER_MARGIN: f64 = 1e-9;

/// Relative margin of the whole-piece speed and acceleration bounds on squared norms.
const HULL_BOUND_MARGIN: f64 = 1e-6;

/// One quantity (position, velocity or acceleration) at every node of a piece, one column per
/// axis, and whether the columns hold the current piece's values.
#[derive(Debug, Clone)]
struct Columns {
    axes: [Vec<f64>; 3],
    filled: bool,
}

impl Columns {
    fn new(m: usize) -> Self {
        Self {
            axes: std::array::from_fn(|_| vec![0.0; m]),
            filled: false,
        }
    }

    /// The value at node `k`: the columns if filled, else `fallback()`. Both are the same
    /// numbers ([`NodeColumns::evaluate`] sums in [`ScaledPiece`]'s order).
    #[inline(always)]
    fn at(&self, k: usize, fallback: impl FnOnce() -> Vec3) -> Vec3 {
        if self.filled {
            Vec3::new(self.axes[0][k], self.axes[1][k], self.axes[2][k])
        } else {
            fallback()
        }
    }
}

/// Column-wise (structure of arrays) scratch for the nodes of one piece.
#[derive(Debug, Clone)]
pub(super) struct NodeColumns {
    /// `u_k^e` for `e = 0..=5`, each `κ + 1` long.
    powers: [Vec<f64>; 6],
    position: Columns,
    velocity: Columns,
    acceleration: Columns,
    jerk: Columns,
    /// Absolute node times.
    t: Vec<f64>,
    /// Nodes that need the full evaluation.
    flags: Vec<bool>,
}

impl NodeColumns {
    /// Columns for `kappa + 1` nodes at `u_k = k/κ` (the powers from `u_powers`).
    pub(super) fn new(u_powers: &[[f64; 6]]) -> Self {
        let m = u_powers.len();
        let powers = std::array::from_fn(|e| u_powers.iter().map(|u| u[e]).collect());
        Self {
            powers,
            position: Columns::new(m),
            velocity: Columns::new(m),
            acceleration: Columns::new(m),
            jerk: Columns::new(m),
            t: vec![0.0; m],
            flags: vec![false; m],
        }
    }

    /// Writes `Σ_e c_e u_k^e` for every node `k` into `out` (one column per axis), summed in
    /// ascending `e` exactly as [`ScaledPiece`] does, so the values are the same to the bit;
    /// `c` has 4, 5 or 6 terms.
    fn evaluate(powers: &[Vec<f64>; 6], c: &[Vec3], out: &mut Columns) {
        out.filled = true;
        for (axis, out) in out.axes.iter_mut().enumerate() {
            let m = out.len();
            let [_, u1, u2, u3, u4, u5] = powers;
            let (u1, u2, u3, u4, u5) = (&u1[..m], &u2[..m], &u3[..m], &u4[..m], &u5[..m]);
            let k0 = c[0][axis];
            match c.len() {
                3 => {
                    let (k1, k2) = (c[1][axis], c[2][axis]);
                    for i in 0..m {
                        out[i] = k0 + k1 * u1[i] + k2 * u2[i];
                    }
                }
                4 => {
                    let (k1, k2, k3) = (c[1][axis], c[2][axis], c[3][axis]);
                    for i in 0..m {
                        out[i] = k0 + k1 * u1[i] + k2 * u2[i] + k3 * u3[i];
                    }
                }
                5 => {
                    let (k1, k2, k3, k4) = (c[1][axis], c[2][axis], c[3][axis], c[4][axis]);
                    for i in 0..m {
                        out[i] = k0 + k1 * u1[i] + k2 * u2[i] + k3 * u3[i] + k4 * u4[i];
                    }
                }
                _ => {
                    let (k1, k2, k3, k4, k5) =
                        (c[1][axis], c[2][axis], c[3][axis], c[4][axis], c[5][axis]);
                    for i in 0..m {
                        out[i] =
                            k0 + k1 * u1[i] + k2 * u2[i] + k3 * u3[i] + k4 * u4[i] + k5 * u5[i];
                    }
                }
            }
        }
    }

    /// Flags every node where the squared norm of `columns` is not `≤ threshold` (NaN
    /// included).
    #[expect(
        clippy::neg_cmp_op_on_partial_ord,
        reason = "a NaN must count as possibly active"
    )]
    fn flag_norm_above(flags: &mut [bool], columns: &Columns, threshold: f64) {
        let m = flags.len();
        let [x, y, z] = &columns.axes;
        let (x, y, z) = (&x[..m], &y[..m], &z[..m]);
        for (i, flag) in flags.iter_mut().enumerate() {
            let n2 = x[i] * x[i] + y[i] * y[i] + z[i] * z[i];
            *flag |= !(n2 <= threshold);
        }
    }
}

impl TrapezoidIntegrator {
    /// Integrates the objective's penalties: the same value and gradients as
    /// [`TrapezoidIntegrator::integrate`] with `penalties` as the integrand, at a fraction of
    /// the cost (see the module documentation of the filters that make it cheap).
    ///
    /// The broad phase uses the box of each piece's Bézier control points (whose convex hull
    /// contains the whole piece and thus every node) instead of the box of the nodes.
    ///
    /// The filters assume finite coefficients, positive finite durations and a finite start time,
    /// which is what [`crate::MincoS3::solve`] guarantees for its output (it fails otherwise);
    /// that is why this fast path is crate-private and the public [`Self::integrate`] is the
    /// general one.
    ///
    /// Stops after the first piece where the running total exceeds `limit` (the penalties are
    /// non-negative, so the full total would exceed it too) and then returns `(total so far,
    /// false)`; the gradients are then incomplete. Otherwise `(total, true)`; pass
    /// `f64::INFINITY` for no limit.
    ///
    /// # Errors
    /// [`MincoError::LengthMismatch`] if the coefficient or gradient buffers do not match the
    /// number of durations.
    pub(crate) fn integrate_penalties(
        &mut self,
        traj: &PiecewiseView<'_>,
        penalties: &mut PenaltyIntegrand<'_>,
        grad_c: &mut [Vec3],
        grad_t: &mut [f64],
        limit: f64,
    ) -> Result<(f64, bool), MincoError> {
        debug_assert!(
            traj.coeffs.iter().all(|c| c.iter().all(|x| x.is_finite()))
                && traj.durations.iter().all(|t| t.is_finite() && *t > 0.0)
                && traj.t_start.is_finite(),
            "integrate_penalties needs a finite trajectory"
        );
        self.run(traj, &mut FlaggedNodes(penalties), grad_c, grad_t, limit)
    }
}

/// The objective's rule: the penalties at the nodes the filters flag.
struct FlaggedNodes<'p, 'a>(&'p mut PenaltyIntegrand<'a>);

impl PieceRule for FlaggedNodes<'_, '_> {
    #[inline(always)]
    fn piece_box(&mut self, _index: usize, piece: &ScaledPiece, _u_powers: &[[f64; 6]]) -> Aabb {
        points_box(&piece.bernstein_positions())
    }

    fn begin_trajectory(&mut self, t_begin: f64, t_end: f64, all: &Aabb) {
        self.0.begin_trajectory_obstacles(t_begin, t_end, all);
    }

    #[inline(always)]
    fn piece(&mut self, ctx: PieceContext<'_>) -> Option<PieceIntegral> {
        let penalties = &mut *self.0;
        let piece_end = ctx.start + ctx.duration;
        let obstacles = penalties.begin_piece_obstacles(ctx.start, piece_end, ctx.bounds);
        if !flag_nodes(
            ctx.columns,
            penalties,
            obstacles,
            ctx.scaled,
            ctx.start,
            ctx.duration,
        ) {
            return None;
        }
        Some(penalty_piece(
            penalties,
            obstacles,
            ctx.scaled,
            ctx.start,
            ctx.duration,
            ctx.kappa,
            ctx.u_powers,
            ctx.columns,
            ctx.coeffs,
        ))
    }
}

/// Sets `columns.flags` to the nodes of the piece where a penalty may be active; `false` if
/// there is none.
fn flag_nodes(
    columns: &mut NodeColumns,
    penalties: &PenaltyIntegrand<'_>,
    obstacles: bool,
    piece: &ScaledPiece,
    piece_start: f64,
    duration: f64,
) -> bool {
    let NodeColumns {
        powers,
        position,
        velocity,
        acceleration,
        jerk,
        t,
        flags,
    } = columns;
    flags.fill(false);
    position.filled = false;
    velocity.filled = false;
    acceleration.filled = false;
    jerk.filled = false;
    let (v2_max, a2_max) = penalties.squared_limits();
    if !within_by_hull(&bernstein_points(&piece.v), &piece.v, v2_max) {
        NodeColumns::evaluate(powers, &piece.v, velocity);
        NodeColumns::flag_norm_above(flags, velocity, v2_max * (1.0 - LIMIT_FILTER_MARGIN));
    }
    if !within_by_hull(&bernstein_points(&piece.a), &piece.a, a2_max) {
        NodeColumns::evaluate(powers, &piece.a, acceleration);
        NodeColumns::flag_norm_above(flags, acceleration, a2_max * (1.0 - LIMIT_FILTER_MARGIN));
    }
    if let Some(j2_max) = penalties.squared_jerk_limit()
        && !within_by_hull(&bernstein_points(&piece.j), &piece.j, j2_max)
    {
        NodeColumns::evaluate(powers, &piece.j, jerk);
        NodeColumns::flag_norm_above(flags, jerk, j2_max * (1.0 - LIMIT_FILTER_MARGIN));
    }
    if obstacles {
        NodeColumns::evaluate(powers, &piece.p, position);
        let m = t.len();
        for (t, u) in t.iter_mut().zip(&powers[1][..m]) {
            *t = piece_start + u * duration;
        }
        let [x, y, z] = &position.axes;
        penalties.flag_obstacle_nodes(x, y, z, t, flags);
    }
    flags.iter().any(|&f| f)
}

/// True if the Bézier control points `hull` of a polynomial with power-basis coefficients
/// `coeffs` prove its squared norm below `limit2` on the whole piece: the largest squared norm of
/// the control points is below `limit2 (1 − HULL_BOUND_MARGIN)`, and their rounding error
/// (at most about `1e-15 Σ_e |X_e|` per component; bounded here by `1e-14 Σ_e ‖X_e‖₁`) is below
/// `1e-7 · limit`, which that margin covers. Otherwise the caller filters node by node.
#[inline(always)]
fn within_by_hull(hull: &[Vec3], coeffs: &[Vec3], limit2: f64) -> bool {
    let rounding = 1e-14 * coeffs.iter().map(|c| c.abs().sum()).sum::<f64>();
    hull_norm_squared(hull) <= limit2 * (1.0 - HULL_BOUND_MARGIN)
        && rounding * rounding <= 1e-14 * limit2
}

/// Largest squared norm among Bézier control points; `NaN` if any is NaN (the callers then
/// fall back to the per-node filter).
#[inline(always)]
fn hull_norm_squared(points: &[Vec3]) -> f64 {
    let mut max = 0.0f64;
    for b in points {
        let n2 = b.norm_squared();
        if n2.is_nan() {
            return f64::NAN;
        }
        max = max.max(n2);
    }
    max
}

/// The flagged nodes of one piece: eqs. dI-a, dI-b and dI-c as in `integrate_piece`, for the
/// penalties.
#[allow(clippy::too_many_arguments)]
#[inline(always)]
fn penalty_piece(
    penalties: &mut PenaltyIntegrand<'_>,
    obstacles: bool,
    piece: &ScaledPiece,
    piece_start: f64,
    duration: f64,
    kappa: usize,
    u_powers: &[[f64; 6]],
    columns: &NodeColumns,
    coeffs: &[Vec3],
) -> PieceIntegral {
    let jerk_limited = penalties.squared_jerk_limit().is_some();
    let inv_kappa = 1.0 / kappa as f64;
    let h = duration * inv_kappa;
    let mut out = PieceIntegral::ZERO;
    let flags = &columns.flags;
    for (k, (u, _)) in u_powers
        .iter()
        .zip(flags)
        .enumerate()
        .filter(|(_, (_, f))| **f)
    {
        let omega = if k == 0 || k == kappa { 0.5 } else { 1.0 };
        let weight = omega * h;
        let v = columns.velocity.at(k, || piece.velocity(u));
        let a = columns.acceleration.at(k, || piece.acceleration(u));
        let (mut gv, mut ga) = (Vec3::zeros(), Vec3::zeros());
        let mut value = penalties.feasibility_at(&v, &a, weight, &mut gv, &mut ga);
        let (mut gp, mut gt) = (Vec3::zeros(), 0.0);
        let mut touched = value != 0.0 || gv != Vec3::zeros() || ga != Vec3::zeros();
        if obstacles {
            let s = u[1] * duration;
            let p = columns.position.at(k, || piece.position(u));
            let l = penalties.obstacles_at(&p, piece_start + s, weight, &mut gp, &mut gt);
            if l != 0.0 || gp != Vec3::zeros() || gt != 0.0 {
                touched = true;
                value += l;
                out.moments.add_order(0, &gp, weight, u);
                out.coupling += weight * gt;
            }
        }
        // The jerk term last, as the generic path sums it.
        let mut gj = Vec3::zeros();
        if jerk_limited {
            let j = columns.jerk.at(k, || piece.jerk(u));
            let lj = penalties.jerk_at(&j, weight, &mut gj);
            if lj != 0.0 || gj != Vec3::zeros() {
                touched = true;
                value += lj;
            }
        }
        if !touched {
            continue;
        }
        out.active = true;
        out.value += weight * value;
        // The total derivative along the piece, summed in the generic path's order.
        let mut along = gp.dot(&v) + gv.dot(&a);
        if gv != Vec3::zeros() {
            out.moments.add_order(1, &gv, weight, u);
        }
        if ga != Vec3::zeros() {
            along += ga.dot(&piece.jerk(u));
            out.moments.add_order(2, &ga, weight, u);
        }
        along += gt;
        if gj != Vec3::zeros() {
            out.moments.add_order(3, &gj, weight, u);
            let s = u[1] * duration;
            let snap = coeffs[4] * 24.0 + coeffs[5] * (120.0 * s);
            along += gj.dot(&snap);
        }
        out.grad_t += omega * inv_kappa * value + weight * u[1] * along;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::costs::{CostWeights, PenaltyParams};
    use proptest::prelude::*;
    use trust_core::{Forecast, Limits, ObstacleShape, StaticMap};
    use trust_geometry::{AaBox, Cylinder, Shape, Sphere};

    /// Position of the trajectory at absolute time `t` (clamped to its span).
    fn position_at(coeffs: &[Vec3], durations: &[f64], t_start: f64, t: f64) -> Vec3 {
        let mut local = t - t_start;
        for (c, &d) in coeffs.chunks_exact(6).zip(durations) {
            if local <= d {
                let s = local.max(0.0);
                return (0..6).rev().fold(Vec3::zeros(), |acc, k| acc * s + c[k]);
            }
            local -= d;
        }
        let c = &coeffs[coeffs.len() - 6..];
        let s = durations[durations.len() - 1];
        (0..6).rev().fold(Vec3::zeros(), |acc, k| acc * s + c[k])
    }

    /// Value, `∂I/∂c`, `∂I/∂T` and the five unweighted integrals of one integration.
    type Outcome = (f64, Vec<Vec3>, Vec<f64>, [f64; 5]);

    /// Generic and fused integration of the same penalties over the same trajectory.
    fn both(
        coeffs: &[Vec3],
        durations: &[f64],
        forecasts: &[Forecast],
        map: &StaticMap,
        limits: Limits,
        jerk_ramp_s: f64,
    ) -> [Outcome; 2] {
        let view = PiecewiseView {
            t_start: 0.3,
            coeffs,
            durations,
        };
        let params = PenaltyParams {
            jerk_ramp_s,
            ..PenaltyParams::default()
        };
        let weights = CostWeights::default();
        let n = durations.len();
        let mut integrator = TrapezoidIntegrator::new(params.samples_per_piece);
        std::array::from_fn(|path| {
            let mut penalties = PenaltyIntegrand::new(forecasts, map, limits, &weights, &params);
            let (mut gc, mut gt) = (vec![Vec3::zeros(); 6 * n], vec![0.0; n]);
            let value = if path == 0 {
                integrator.integrate(&view, &mut penalties, &mut gc, &mut gt)
            } else {
                integrator
                    .integrate_penalties(&view, &mut penalties, &mut gc, &mut gt, f64::INFINITY)
                    .map(|(value, complete)| {
                        assert!(complete);
                        value
                    })
            }
            .expect("matching buffers");
            let i = penalties.integrals();
            (
                value,
                gc,
                gt,
                [i.dynamic, i.static_map, i.speed, i.acceleration, i.jerk],
            )
        })
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

        /// The filters never skip a node that contributes: on random trajectories that cross,
        /// graze and miss moving and static obstacles of every kind and exceed the speed and
        /// acceleration limits (and, with a jerk ramp, the jerk limit) at some nodes, the fused
        /// path equals the generic one bit for bit
        /// (the same nodes, the same sums in the same order).
        #[test]
        fn fused_path_equals_the_generic_one(
            raw in proptest::collection::vec(-1.5..1.5f64, 54),
            durations in proptest::collection::vec(0.3..1.2f64, 3),
            hits in proptest::collection::vec((0.0..1.0f64, 0.05..0.9f64, -0.6..0.6f64, any::<bool>()), 4),
            v_max in 0.5..4.0f64,
            a_max in 1.0..8.0f64,
            jerk_ramp_s in prop_oneof![Just(0.0), 0.05..2.0f64],
        ) {
            let coeffs: Vec<Vec3> = raw.chunks_exact(3).map(|c| Vec3::new(c[0], c[1], c[2])).collect();
            let total: f64 = durations.iter().sum();
            let mut forecasts = Vec::new();
            let mut shapes = Vec::new();
            for (k, &(u, radius, offset, cylinder)) in hits.iter().enumerate() {
                // An obstacle near the trajectory's position at time 0.3 + u·T (moving ones
                // are there at that time), shifted sideways by `offset`.
                let t = 0.3 + u * total;
                let p = position_at(&coeffs, &durations, 0.3, t) + Vec3::new(offset, -offset, 0.5 * offset);
                let velocity = Vec3::new(0.4 - offset, offset, 0.1);
                let shape = if cylinder {
                    ObstacleShape::Cylinder { half_height: 0.5 + radius }
                } else {
                    ObstacleShape::Sphere
                };
                let p0 = p - velocity * t;
                forecasts.push(Forecast::new(shape, p0, velocity, 0.0, radius, 0.1, 0.05).expect("forecast"));
                shapes.push(match k % 3 {
                    0 => Shape::Sphere(Sphere { center: p, radius }),
                    1 => Shape::Cylinder(Cylinder { center: p, radius, half_height: 2.0 * radius }),
                    _ => Shape::AaBox(AaBox { min: p.add_scalar(-radius), max: p.add_scalar(radius) }),
                });
            }
            let bounds = trust_core::Aabb { min: Vec3::repeat(-50.0), max: Vec3::repeat(50.0) };
            let map = StaticMap::from_shapes(bounds, shapes).expect("shapes");
            let limits = Limits::new(v_max, a_max).expect("limits");
            let [generic, fused] = both(&coeffs, &durations, &forecasts, &map, limits, jerk_ramp_s);
            prop_assert_eq!(generic.0.to_bits(), fused.0.to_bits(), "value {} vs {}", generic.0, fused.0);
            prop_assert_eq!(&generic.1, &fused.1);
            prop_assert_eq!(&generic.2, &fused.2);
            prop_assert_eq!(generic.3, fused.3);
        }
    }

    /// With only moving obstacles and limits, the fused path is the generic one bit for bit
    /// (the same nodes in the same order), and it is exercised: some nodes are active.
    #[test]
    fn fused_path_is_bit_identical_without_static_shapes() {
        let coeffs: Vec<Vec3> = (0..18)
            .map(|i| {
                let x = i as f64;
                Vec3::new((0.7 * x).sin(), (1.3 * x).cos(), 0.2 * (0.5 * x).sin())
            })
            .collect();
        let durations = [0.8, 0.6, 1.0];
        let forecasts: Vec<Forecast> = [0.4, 1.1, 1.9]
            .iter()
            .map(|&t| {
                let p = position_at(&coeffs, &durations, 0.3, t);
                Forecast::sphere(p, Vec3::new(0.3, 0.0, 0.0), t, 0.3, 0.1, 0.05).expect("sphere")
            })
            .collect();
        let map = StaticMap::empty(trust_core::Aabb {
            min: Vec3::repeat(-50.0),
            max: Vec3::repeat(50.0),
        })
        .expect("bounds");
        let limits = Limits::new(1.0, 2.0).expect("limits");
        for jerk_ramp_s in [0.0, 0.3] {
            let [generic, fused] = both(&coeffs, &durations, &forecasts, &map, limits, jerk_ramp_s);
            assert!(generic.3[0] > 0.0 && generic.3[2] > 0.0, "{:?}", generic.3);
            assert_eq!(generic.3[4] > 0.0, jerk_ramp_s > 0.0, "{:?}", generic.3);
            assert_eq!(generic.0.to_bits(), fused.0.to_bits());
            assert_eq!(generic.1, fused.1);
            assert_eq!(generic.2, fused.2);
            assert_eq!(generic.3, fused.3);
        }
    }

    #[test]
    fn bernstein_bounds_contain_the_curves() {
        let v = [
            Vec3::new(1.0, -2.0, 0.5),
            Vec3::new(0.3, 4.0, -1.0),
            Vec3::new(-2.0, 1.0, 0.7),
            Vec3::new(0.9, -3.0, 0.2),
            Vec3::new(0.4, 0.8, -0.6),
        ];
        let a = [v[0], v[1], v[2], v[3]];
        let (hv, ha) = (
            hull_norm_squared(&bernstein_points(&v)),
            hull_norm_squared(&bernstein_points(&a)),
        );
        for k in 0..=100 {
            let u = k as f64 / 100.0;
            let vel = (0..5).rev().fold(Vec3::zeros(), |acc, e| acc * u + v[e]);
            let acc = (0..4).rev().fold(Vec3::zeros(), |s, e| s * u + a[e]);
            assert!(vel.norm_squared() <= hv * (1.0 + 1e-12));
            assert!(acc.norm_squared() <= ha * (1.0 + 1e-12));
        }
        // The end points are control points: the bound is attained there.
        let end = v.iter().fold(Vec3::zeros(), |s, x| s + x);
        assert!(hv >= end.norm_squared());
        assert!(hull_norm_squared(&[Vec3::new(f64::NAN, 0.0, 0.0)]).is_nan());
    }
}
