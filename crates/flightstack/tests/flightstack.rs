//! The public API on MINCO trajectories: every exported form, evaluated, agrees with the
//! trajectory it came from (to `f32` precision), and degenerate input gives typed errors.

use nalgebra::{Rotation3, Vector3};
use proptest::prelude::*;
use trust_core::{Piece, PolyTraj, Vec3, eval_piece};
use trust_flightstack::crazyflie::{
    self, CrazyflieParams, MAX_POLY4D_PIECES, Poly4d, UAV_TRAJECTORIES_CSV_HEADER, poly_derivative,
};
use trust_flightstack::frame::{FrameTransform, ned_to_enu, wrap_angle, yaw_ned_to_enu};
use trust_flightstack::px4::{self, Px4Params, TrajectorySetpoint};
use trust_flightstack::yaw::YawPolicy;
use trust_flightstack::{FlightStackError, trajectory_from_parts};
use trust_minco::MincoS3;

/// A MINCO (s = 3) trajectory from `start` (with velocity `v0`) through `waypoints` to `goal` at
/// rest, as the planner's backends build it.
fn minco(
    t_start: f64,
    start: Vec3,
    v0: Vec3,
    waypoints: &[Vec3],
    goal: Vec3,
    durations: &[f64],
) -> PolyTraj {
    let mut m = MincoS3::new(durations.len()).unwrap();
    let rest = Vec3::zeros();
    m.solve(
        &[start, v0, rest],
        &[goal, rest, rest],
        waypoints,
        durations,
    )
    .unwrap();
    PolyTraj::new(t_start, durations.to_vec(), m.to_pieces()).unwrap()
}

/// A MINCO trajectory of `n` pieces zig-zagging through the room.
fn zigzag(n: usize) -> PolyTraj {
    let waypoints: Vec<Vec3> = (1..n)
        .map(|i| Vec3::new(0.4 * i as f64, if i % 2 == 0 { 0.5 } else { -0.5 }, 1.0))
        .collect();
    minco(
        3.0,
        Vec3::new(0.0, 0.0, 1.0),
        Vec3::zeros(),
        &waypoints,
        Vec3::new(0.4 * n as f64, 0.0, 1.0),
        &vec![0.5; n],
    )
}

/// `|a − b| ≤ 1e-5 · (1 + scale) + extra` per component.
fn close(a: &Vec3, b: &Vec3, scale: f64, extra: f64) -> bool {
    (a - b).amax() <= 1e-5 * (1.0 + scale) + extra
}

/// `Σ_k k!/(k−r)! |c_k| s^(k−r)` over the three axes: the size of the terms a derivative of order
/// `r` sums, which bounds the effect of rounding the coefficients.
fn term_scale(piece: &Piece, order: usize, s: f64) -> f64 {
    (order..6)
        .map(|k| {
            let falling: f64 = ((k + 1 - order)..=k).map(|j| j as f64).product();
            falling * piece[k].amax() * s.abs().powi((k - order) as i32)
        })
        .sum()
}

/// The transform's rotation, built independently of `FrameTransform` (the oracle).
fn rotation(tf: &FrameTransform) -> Rotation3<f64> {
    Rotation3::from_axis_angle(&Vector3::z_axis(), tf.yaw_rad)
}

/// A setpoint's vectors back in our world frame (undoing NED and the transform).
fn back_to_world(sp: &TrajectorySetpoint, tf: &FrameTransform) -> [Vec3; 3] {
    let enu = |v: &[f32; 3]| ned_to_enu(&Vec3::new(v[0].into(), v[1].into(), v[2].into()));
    let inv = rotation(tf).inverse();
    [
        inv * (enu(&sp.position) - tf.offset_m),
        inv * enu(&sp.velocity),
        inv * enu(&sp.acceleration),
    ]
}

/// Checks a PX4 stream against the trajectory at the stream's times.
fn check_px4_stream(traj: &PolyTraj, rate_hz: f64, start_us: u64, params: &Px4Params) {
    let sps = px4::sample_setpoints(traj, start_us, rate_hz, params).unwrap();
    let times = px4::stream_times(traj, rate_hz).unwrap();
    assert_eq!(sps.len(), times.len());
    assert_eq!(sps[0].timestamp, start_us);
    assert_eq!(*times.last().unwrap(), traj.t_end());
    for (sp, &t) in sps.iter().zip(&times) {
        let expected_us = start_us + ((t - traj.t_start()) * 1e6).round() as u64;
        assert_eq!(sp.timestamp, expected_us);
        let s = traj.state(t);
        let [p, v, a] = back_to_world(sp, &params.world_to_enu);
        let off = params.world_to_enu.offset_m.amax();
        assert!(
            close(&p, &s.p, s.p.amax() + off, 0.0),
            "t {t}: {p:?} vs {:?}",
            s.p
        );
        assert!(
            close(&v, &s.v, s.v.amax(), 0.0),
            "t {t}: {v:?} vs {:?}",
            s.v
        );
        assert!(
            close(&a, &s.a, s.a.amax(), 0.0),
            "t {t}: {a:?} vs {:?}",
            s.a
        );
        assert!(sp.jerk.iter().all(|x| x.is_finite()));
        match params.yaw {
            YawPolicy::Uncontrolled => assert!(sp.yaw.is_nan() && sp.yawspeed.is_nan()),
            _ => {
                assert!(sp.yaw.is_finite() && sp.yawspeed.is_finite());
                assert!(f64::from(sp.yaw).abs() <= std::f64::consts::PI + 1e-6);
            }
        }
        if let YawPolicy::FaceVelocity { min_speed_m_s, .. } = params.yaw {
            let speed = s.v.xy().norm();
            if speed > 1.01 * min_speed_m_s {
                let want = s.v.y.atan2(s.v.x) + params.world_to_enu.yaw_rad;
                let got = yaw_ned_to_enu(f64::from(sp.yaw));
                assert!(
                    wrap_angle(got - want).abs() < 1e-5,
                    "t {t}: {got} vs {want}"
                );
            }
        }
    }
}

/// Checks Crazyflie pieces against the trajectory, piece by piece in local time.
fn check_poly4d(traj: &PolyTraj, pieces: &[Poly4d], tf: &FrameTransform) {
    assert_eq!(pieces.len(), traj.piece_count());
    for (i, (q, (piece, &d))) in pieces
        .iter()
        .zip(traj.pieces().iter().zip(traj.durations()))
        .enumerate()
    {
        assert!((f64::from(q.duration) - d).abs() <= d * 1e-7, "piece {i}");
        assert_eq!(&q.x[6..], &[0.0, 0.0]);
        for j in 0..=16 {
            let s = d * j as f64 / 16.0;
            let e = q.evaluate(s);
            let r = rotation(tf);
            let want = [
                r * eval_piece(piece, 0, s) + tf.offset_m,
                r * eval_piece(piece, 1, s),
                r * eval_piece(piece, 2, s),
            ];
            let got = [e.position, e.velocity, e.acceleration];
            for (order, (g, w)) in got.iter().zip(&want).enumerate() {
                let scale =
                    term_scale(piece, order, s) + if order == 0 { tf.offset_m.amax() } else { 0.0 };
                assert!(
                    close(g, w, scale, 0.0),
                    "piece {i} s {s} order {order}: {g:?} vs {w:?}"
                );
            }
        }
    }
}

/// Parses a `uav_trajectories` CSV (as Crazyswarm's loader does: skip the header row, 33 columns).
fn parse_csv(text: &str) -> Vec<(f64, [[f32; 8]; 4])> {
    let mut lines = text.lines();
    assert_eq!(lines.next(), Some(UAV_TRAJECTORIES_CSV_HEADER));
    lines
        .map(|l| {
            let v: Vec<f32> = l.split(',').map(|x| x.parse().unwrap()).collect();
            assert_eq!(v.len(), 33);
            let mut axes = [[0.0f32; 8]; 4];
            for (a, axis) in axes.iter_mut().enumerate() {
                axis.copy_from_slice(&v[1 + 8 * a..9 + 8 * a]);
            }
            (f64::from(v[0]), axes)
        })
        .collect()
}

#[test]
fn a_minco_trajectory_streams_to_px4_in_ned() {
    let traj = zigzag(6);
    for yaw in [
        YawPolicy::default(),
        YawPolicy::Uncontrolled,
        YawPolicy::FaceVelocity {
            min_speed_m_s: 0.05,
            initial_yaw_rad: 1.0,
        },
    ] {
        let params = Px4Params {
            world_to_enu: FrameTransform {
                yaw_rad: 0.3,
                offset_m: Vec3::new(-2.0, 1.0, 0.0),
            },
            yaw,
        };
        check_px4_stream(&traj, 50.0, 123_456_789, &params);
        check_px4_stream(&traj, 2.0, 0, &params);
    }
    // The MAVLink form of every setpoint controls everything.
    let sps = px4::sample_setpoints(&traj, 0, 20.0, &Px4Params::default()).unwrap();
    for sp in &sps {
        let m = sp.to_mavlink(1, 1).unwrap();
        assert_eq!(m.type_mask, 0);
        assert_eq!([m.x, m.y, m.z], sp.position);
    }
}

#[test]
fn a_minco_trajectory_becomes_crazyflie_pieces() {
    let traj = zigzag(8);
    let tf = FrameTransform {
        yaw_rad: -1.0,
        offset_m: Vec3::new(0.5, 0.5, 0.2),
    };
    let params = CrazyflieParams {
        world_to_crazyflie: tf,
        yaw: YawPolicy::FaceVelocity {
            min_speed_m_s: 0.05,
            initial_yaw_rad: 0.0,
        },
        ..CrazyflieParams::default()
    };
    let pieces = crazyflie::to_poly4d(&traj, &params).unwrap();
    check_poly4d(&traj, &pieces, &tf);
    // Yaw: continuous, and the velocity's heading at every boundary where the vehicle moves.
    let mut t = traj.t_start();
    for (i, q) in pieces.iter().enumerate() {
        let end = q.evaluate(f64::from(q.duration)).yaw_rad;
        if let Some(next) = pieces.get(i + 1) {
            assert!((next.evaluate(0.0).yaw_rad - end).abs() < 1e-5);
        }
        t += traj.durations()[i];
        let v = traj.velocity(t.min(traj.t_end()));
        if v.xy().norm() > 0.1 {
            let want = v.y.atan2(v.x) + tf.yaw_rad;
            assert!(
                wrap_angle(end - want).abs() < 1e-5,
                "piece {i}: {end} vs {want}"
            );
        }
    }
}

#[test]
fn the_csv_evaluates_to_the_trajectory() {
    let traj = zigzag(5);
    let pieces = crazyflie::to_poly4d(&traj, &CrazyflieParams::default()).unwrap();
    let rows = parse_csv(&crazyflie::uav_trajectories_csv(&pieces).unwrap());
    assert_eq!(rows.len(), 5);
    // How far the f32 piece boundaries drift from ours.
    let drift: f64 = rows
        .iter()
        .zip(traj.durations())
        .map(|((d, _), ours)| (d - ours).abs())
        .sum();
    let (v_max, a_max) = traj.max_speed_and_acceleration(64);
    // Evaluate at absolute times as Crazyswarm's `Trajectory.eval` does: find the piece by the
    // running sum of durations, then Horner in local time.
    let total: f64 = rows.iter().map(|r| r.0).sum();
    for j in 0..=200 {
        let tau = total * j as f64 / 200.0;
        let mut begin = 0.0;
        let (d, axes) = rows
            .iter()
            .find(|(d, _)| {
                let hit = tau <= begin + d;
                if !hit {
                    begin += d;
                }
                hit
            })
            .unwrap_or(rows.last().unwrap());
        let s = (tau - begin).clamp(0.0, *d);
        let at = |order| {
            Vec3::new(
                poly_derivative(&axes[0], order, s),
                poly_derivative(&axes[1], order, s),
                poly_derivative(&axes[2], order, s),
            )
        };
        let t = (traj.t_start() + tau).min(traj.t_end());
        let st = traj.state(t);
        assert!(
            close(&at(0), &st.p, st.p.amax(), v_max * drift),
            "tau {tau}"
        );
        assert!(
            close(&at(1), &st.v, st.v.amax(), a_max * drift),
            "tau {tau}"
        );
    }
}

#[test]
fn crazyswarm2_upload_carries_the_same_numbers() {
    let traj = zigzag(4);
    let pieces = crazyflie::to_poly4d(&traj, &CrazyflieParams::default()).unwrap();
    let req = crazyflie::upload_trajectory_request(2, 0, &pieces, MAX_POLY4D_PIECES).unwrap();
    assert_eq!((req.trajectory_id, req.piece_offset), (2, 0));
    for (m, q) in req.pieces.iter().zip(&pieces) {
        assert_eq!(m.poly_x, q.x);
        assert_eq!(m.poly_y, q.y);
        assert_eq!(m.poly_z, q.z);
        assert_eq!(m.poly_yaw, q.yaw);
        assert!((m.duration.as_seconds() - f64::from(q.duration)).abs() <= 0.5e-9 + 1e-15);
    }
}

#[test]
fn hovering_on_the_goal_exports_a_still_setpoint() {
    // Start on the goal: MINCO gives a trajectory that never moves.
    let p = Vec3::new(1.0, -2.0, 0.8);
    let traj = minco(0.0, p, Vec3::zeros(), &[p], p, &[1.0, 1.0]);
    let params = Px4Params {
        yaw: YawPolicy::FaceVelocity {
            min_speed_m_s: 0.05,
            initial_yaw_rad: 0.7,
        },
        ..Px4Params::default()
    };
    let sps = px4::sample_setpoints(&traj, 0, 10.0, &params).unwrap();
    assert_eq!(sps.len(), 21);
    for sp in &sps {
        assert!((f64::from(sp.position[0]) - p.y).abs() < 1e-6);
        assert!((f64::from(sp.position[2]) + p.z).abs() < 1e-6);
        assert!(
            sp.velocity
                .iter()
                .chain(&sp.acceleration)
                .all(|x| x.abs() < 1e-6)
        );
        // The initial yaw, held: 0.7 rad ENU is π/2 − 0.7 NED.
        assert!((f64::from(sp.yaw) - (std::f64::consts::FRAC_PI_2 - 0.7)).abs() < 1e-6);
        assert_eq!(sp.yawspeed, 0.0);
    }
    let hold = PolyTraj::hold(5.0, p, 3.0).unwrap();
    let pieces = crazyflie::to_poly4d(&hold, &CrazyflieParams::default()).unwrap();
    assert_eq!(pieces.len(), 1);
    assert_eq!(pieces[0].x, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]);
    check_poly4d(&hold, &pieces, &FrameTransform::identity());
}

#[test]
fn a_single_piece_exports_both_ways() {
    let traj = minco(
        -4.0,
        Vec3::zeros(),
        Vec3::new(0.5, 0.0, 0.0),
        &[],
        Vec3::new(1.0, 1.0, 1.0),
        &[1.7],
    );
    check_px4_stream(&traj, 30.0, 42, &Px4Params::default());
    let pieces = crazyflie::to_poly4d(&traj, &CrazyflieParams::default()).unwrap();
    check_poly4d(&traj, &pieces, &FrameTransform::identity());
}

#[test]
fn a_trajectory_over_the_crazyflie_memory_is_refused_with_its_count() {
    let traj = zigzag(40);
    let e = crazyflie::to_poly4d(&traj, &CrazyflieParams::default()).unwrap_err();
    match e {
        FlightStackError::TooManyPieces { count, max, .. } => {
            assert_eq!((count, max), (40, MAX_POLY4D_PIECES));
        }
        other => panic!("expected TooManyPieces, got {other}"),
    }
    // Firmware with more memory takes it, and it still matches.
    let big = CrazyflieParams {
        max_pieces: 40,
        ..CrazyflieParams::default()
    };
    let pieces = crazyflie::to_poly4d(&traj, &big).unwrap();
    check_poly4d(&traj, &pieces, &FrameTransform::identity());
    // PX4 streams any length.
    check_px4_stream(&traj, 20.0, 0, &Px4Params::default());
}

#[test]
fn raw_pieces_are_checked_before_export() {
    let traj = zigzag(3);
    let (durations, pieces) = (traj.durations().to_vec(), traj.pieces().to_vec());
    // A zero-duration piece in the middle covers no time and is dropped.
    let mut d0 = durations.clone();
    d0.insert(1, 0.0);
    let mut p0 = pieces.clone();
    p0.insert(1, [Vec3::new(9.0, 9.0, 9.0); 6]);
    let same = trajectory_from_parts(traj.t_start(), &d0, &p0).unwrap();
    assert_eq!(same, traj);
    // Non-finite coefficients and an empty trajectory are typed errors naming the field.
    for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY] {
        let mut p = pieces.clone();
        p[2][5].x = bad;
        let e = trajectory_from_parts(0.0, &durations, &p).unwrap_err();
        assert!(matches!(e, FlightStackError::Trajectory(_)), "{e}");
        assert!(e.to_string().contains("traj.pieces[2][5]"), "{e}");
    }
    assert!(trajectory_from_parts(0.0, &[], &[]).is_err());
    assert!(trajectory_from_parts(0.0, &[0.0, 0.0], &pieces[..2]).is_err());
}

#[test]
fn params_read_from_json_strictly() {
    let p: Px4Params = serde_json::from_str(
        r#"{"world_to_enu": {"yaw_rad": 0.0, "offset_m": [0, 0, 0]},
            "yaw": {"kind": "face_velocity", "min_speed_m_s": 0.05, "initial_yaw_rad": 0}}"#,
    )
    .unwrap();
    assert!(matches!(p.yaw, YawPolicy::FaceVelocity { .. }));
    let c: CrazyflieParams = serde_json::from_str(
        r#"{"world_to_crazyflie": {"yaw_rad": 0.0, "offset_m": [0, 0, 0]},
            "yaw": {"kind": "fixed", "yaw_rad": 0.5}, "max_pieces": 31}"#,
    )
    .unwrap();
    assert_eq!(c.max_pieces, 31);
    assert!(
        serde_json::from_str::<CrazyflieParams>(
            r#"{"world_to_crazyflie": {"yaw_rad": 0.0, "offset_m": [0, 0, 0]},
                "yaw": {"kind": "fixed", "yaw_rad": 0.5}, "max_pieces": 31, "rate": 1}"#,
        )
        .is_err()
    );
}

fn vec3(lo: f64, hi: f64) -> impl Strategy<Value = Vec3> {
    prop::array::uniform3(lo..hi).prop_map(Vec3::from)
}

/// Random MINCO trajectories: 1–8 pieces of 0.2–2 s through waypoints in a 10 m box.
fn minco_strategy() -> impl Strategy<Value = PolyTraj> {
    (1usize..=8)
        .prop_flat_map(|n| {
            (
                -100.0..100.0f64,
                vec3(-5.0, 5.0),
                vec3(-2.0, 2.0),
                prop::collection::vec(vec3(-5.0, 5.0), n - 1),
                vec3(-5.0, 5.0),
                prop::collection::vec(0.2..2.0f64, n),
            )
        })
        .prop_map(|(t0, start, v0, wps, goal, durations)| {
            minco(t0, start, v0, &wps, goal, &durations)
        })
}

fn transform_strategy() -> impl Strategy<Value = FrameTransform> {
    (-4.0..4.0f64, vec3(-50.0, 50.0))
        .prop_map(|(yaw_rad, offset_m)| FrameTransform { yaw_rad, offset_m })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(32))]

    /// PX4 setpoints, mapped back from NED and the transform, are the trajectory at their times.
    #[test]
    fn px4_stream_agrees_with_the_trajectory(
        traj in minco_strategy(),
        tf in transform_strategy(),
        rate in 2.0..120.0f64,
        start_us in 0u64..1_000_000_000_000,
        face in any::<bool>(),
    ) {
        let yaw = if face {
            YawPolicy::FaceVelocity { min_speed_m_s: 0.05, initial_yaw_rad: 0.0 }
        } else {
            YawPolicy::Fixed { yaw_rad: 1.0 }
        };
        check_px4_stream(&traj, rate, start_us, &Px4Params { world_to_enu: tf, yaw });
    }

    /// Crazyflie pieces evaluate to the trajectory in every piece, after the transform.
    #[test]
    fn poly4d_pieces_agree_with_the_trajectory(traj in minco_strategy(), tf in transform_strategy()) {
        let params = CrazyflieParams { world_to_crazyflie: tf, ..CrazyflieParams::default() };
        let pieces = crazyflie::to_poly4d(&traj, &params).unwrap();
        check_poly4d(&traj, &pieces, &tf);
        // A fixed yaw is constant and in the target's frame.
        for q in &pieces {
            prop_assert!((f64::from(q.yaw[0]) - wrap_angle(tf.yaw_rad)).abs() < 1e-6);
            prop_assert!(q.yaw[1..].iter().all(|c| *c == 0.0));
        }
    }
}
