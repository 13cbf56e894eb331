//! Initial guesses: piece count, waypoints, terminal state and total duration from a guide path
//! or from a previous trajectory (warm start).

use trust_core::{GuidePath, InitialGuess, Limits, PlanError, PolyTraj, State, Vec3};

use super::params::PieceParams;

/// The decision variables a backend starts from.
#[derive(Debug, Clone, PartialEq)]
pub struct InitialTrajectory {
    /// Inner waypoints `q_1 ..= q_{n−1}` (the piece count is `waypoints.len() + 1`).
    pub waypoints: Vec<Vec3>,
    /// Terminal position.
    pub end_position: Vec3,
    /// Terminal velocity (zero for a guide path; the previous trajectory's for a warm start).
    pub end_velocity: Vec3,
    /// Total duration `T_Σ` (s), at least `pieces · min_piece_duration_s`.
    pub total_duration: f64,
}

impl InitialTrajectory {
    /// Checks that the initial duration is inside the scale policy (`≤ 1e7` s) and otherwise
    /// names what drove it: the guide's length over the speed and acceleration limits (or the
    /// warm start's remaining time). Without this, tiny limits surfaced as an infinite cost at the
    /// start point that named nothing.
    ///
    /// # Errors
    /// [`PlanError::InvalidInput`] naming `limits.v_max` / `limits.a_max` and the guide length.
    pub fn check_duration(
        &self,
        guess: &InitialGuess<'_>,
        limits: &Limits,
    ) -> Result<(), PlanError> {
        let t = self.total_duration;
        if t.is_finite() && t <= trust_core::scale::MAX_TIME_S {
            return Ok(());
        }
        let sci = trust_core::scale::Sci;
        Err(match guess {
            InitialGuess::Guide(path) => PlanError::invalid(
                "limits.v_max / limits.a_max",
                format!("{} m/s, {} m/s²", sci(limits.v_max), sci(limits.a_max)),
                format!(
                    "limits under which the {} m guide takes at most {} s (it takes {} s)",
                    readable(path.length()),
                    sci(trust_core::scale::MAX_TIME_S),
                    sci(t)
                ),
            ),
            InitialGuess::WarmStart(_) => PlanError::invalid(
                "request.initial (warm start) remaining duration",
                sci(t).to_string(),
                format!("at most {} s", sci(trust_core::scale::MAX_TIME_S)),
            ),
        })
    }

    /// Number of pieces `n`.
    pub fn pieces(&self) -> usize {
        self.waypoints.len() + 1
    }

    /// Raises the duration of a guess from a guide path that starts at rest to at least the
    /// minimum-jerk rest-to-rest time within the jerk limit `j_max`
    /// ([`crate::costs::rest_to_rest_quintic_time`]); the waypoints keep their places (the
    /// guess is slowed uniformly). A warm start, a moving start or no jerk limit
    /// (`j_max = ∞`) leave it as it is.
    ///
    /// Why: the [`SpeedProfile`] knows no jerk limit. For a short guide (the last decimetres to
    /// the goal) its duration asks for many times the jerk limit, and from there the solver
    /// found it cheaper to shrink the move than to stretch the time: from rest 0.1 m before
    /// the goal, a Crazyflie's plan moved 1 cm.
    pub fn with_jerk_floor(
        mut self,
        guess: &InitialGuess<'_>,
        start: &State,
        limits: &Limits,
        j_max: f64,
    ) -> Self {
        if let InitialGuess::Guide(path) = guess {
            let at_rest = start.v.norm() <= 1e-3 * limits.v_max;
            let floor = crate::costs::rest_to_rest_quintic_time(path.length(), limits.a_max, j_max);
            if at_rest && floor.is_finite() && floor > self.total_duration {
                self.total_duration = floor;
            }
        }
        self
    }
}

/// Three decimals for ordinary magnitudes, scientific notation otherwise (messages).
fn readable(x: f64) -> String {
    if (1e-3..1e6).contains(&x.abs()) {
        format!("{x:.3}")
    } else {
        trust_core::scale::Sci(x).to_string()
    }
}

/// A trapezoidal speed profile along a path of `length` metres: start at `initial_speed`,
/// accelerate at `a_max` up to at most `v_max`, cruise, and brake at `a_max` to rest at the end
/// (time-optimal for a point mass with those limits). Where the start speed is too high to stop
/// within the length, it brakes uniformly over the whole length instead.
///
/// UTF-MINCO needs it for its initial guess: with uniform piece durations, the waypoints must be
/// spaced like the vehicle's progress at uniform times, not uniformly in arc length (a start at
/// rest followed by a first waypoint a full piece length away means a huge initial jerk).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpeedProfile {
    length: f64,
    initial_speed: f64,
    peak_speed: f64,
    accel: f64,
    decel: f64,
    /// Durations of the acceleration, cruise and braking phases.
    phases: [f64; 3],
}

impl SpeedProfile {
    /// The profile for `length` metres from `initial_speed` (clamped to `[0, v_max]`).
    pub fn new(length: f64, initial_speed: f64, limits: &Limits) -> Self {
        let (v, a) = (limits.v_max, limits.a_max);
        let length = if length.is_finite() {
            length.max(0.0)
        } else {
            0.0
        };
        let u = if initial_speed.is_finite() {
            initial_speed.clamp(0.0, v)
        } else {
            0.0
        };
        if length <= 0.0 {
            return Self {
                length,
                initial_speed: 0.0,
                peak_speed: 0.0,
                accel: a,
                decel: a,
                phases: [0.0; 3],
            };
        }
        if u * u / (2.0 * a) >= length {
            // Cannot stop in time at a_max: brake uniformly over the whole length.
            let decel = u * u / (2.0 * length);
            return Self {
                length,
                initial_speed: u,
                peak_speed: u,
                accel: a,
                decel,
                phases: [0.0, 0.0, u / decel],
            };
        }
        let peak = (a * length + 0.5 * u * u).sqrt().min(v);
        let d_acc = (peak * peak - u * u) / (2.0 * a);
        let d_dec = peak * peak / (2.0 * a);
        let cruise = (length - d_acc - d_dec).max(0.0) / peak;
        Self {
            length,
            initial_speed: u,
            peak_speed: peak,
            accel: a,
            decel: a,
            phases: [(peak - u) / a, cruise, peak / a],
        }
    }

    /// Total duration (s); 0 for a zero length.
    pub fn duration(&self) -> f64 {
        self.phases.iter().sum()
    }

    /// Distance travelled at time `t` (clamped to `[0, duration]`).
    pub fn distance_at(&self, t: f64) -> f64 {
        let [t1, t2, t3] = self.phases;
        let t = if t.is_finite() {
            t.clamp(0.0, t1 + t2 + t3)
        } else {
            0.0
        };
        let (u, p) = (self.initial_speed, self.peak_speed);
        let d = if t <= t1 {
            u * t + 0.5 * self.accel * t * t
        } else if t <= t1 + t2 {
            (p * p - u * u) / (2.0 * self.accel) + p * (t - t1)
        } else {
            let tb = t - t1 - t2;
            (p * p - u * u) / (2.0 * self.accel) + p * t2 + p * tb - 0.5 * self.decel * tb * tb
        };
        d.clamp(0.0, self.length)
    }
}

/// The time a vehicle limited by `limits` needs to travel `length` metres from rest to rest
/// ([`SpeedProfile`] with zero initial speed).
pub fn rest_to_rest_time(length: f64, limits: &Limits) -> f64 {
    SpeedProfile::new(length, 0.0, limits).duration()
}

/// Builds the initial guess for a vehicle in state `start`: the piece count from the guess's
/// length ([`PieceParams::piece_count`]), then
/// - [`InitialGuess::Guide`]: a [`SpeedProfile`] along the path from the start velocity's
///   component along the path's first segment; the waypoints are the profile's positions at the
///   uniform times `iT_p/n` (`T_p` its duration); the terminal is the path's end, at rest; the
///   duration is `T_p`, but at least the braking time `‖v_0‖/a_max`;
/// - [`InitialGuess::WarmStart`]: the trajectory from `start.t` (clamped to its span) to its end,
///   sampled at `n + 1` uniform times; terminal position and velocity at its end; duration the
///   remaining time.
///
/// The duration is raised to at least `n · min_piece_duration_s · 2` so that the positive time
/// map starts well inside its range.
pub fn initial_trajectory(
    guess: &InitialGuess<'_>,
    start: &State,
    limits: &Limits,
    pieces: &PieceParams,
) -> InitialTrajectory {
    match guess {
        InitialGuess::Guide(path) => from_guide(path, &start.v, limits, pieces),
        InitialGuess::WarmStart(traj) => from_warm_start(traj, start.t, pieces),
    }
}

fn from_guide(
    path: &GuidePath,
    start_velocity: &Vec3,
    limits: &Limits,
    params: &PieceParams,
) -> InitialTrajectory {
    let length = path.length();
    let n = params.piece_count(length);
    let direction = path
        .points
        .windows(2)
        .map(|w| w[1] - w[0])
        .find(|d| d.norm() > 0.0)
        .map_or(Vec3::zeros(), |d| d.normalize());
    let profile = SpeedProfile::new(length, start_velocity.dot(&direction), limits);
    // At least the time to brake from the start speed: a (nearly) zero-length guide with a moving
    // start would otherwise begin with a duration near 0, where the positive time map is flat.
    let total = profile.duration().max(start_velocity.norm() / limits.a_max);
    let waypoints = (1..n)
        .map(|i| {
            let s = profile.distance_at(profile.duration() * i as f64 / n as f64);
            if length > 0.0 {
                path.point_at_fraction(s / length)
            } else {
                path.start()
            }
        })
        .collect();
    InitialTrajectory {
        waypoints,
        end_position: path.end(),
        end_velocity: Vec3::zeros(),
        total_duration: floor_duration(total, n, params),
    }
}

fn from_warm_start(traj: &PolyTraj, t_now: f64, params: &PieceParams) -> InitialTrajectory {
    let t_end = traj.t_end();
    let t_begin = if t_now.is_finite() {
        t_now.clamp(traj.t_start(), t_end)
    } else {
        traj.t_start()
    };
    let remaining = t_end - t_begin;
    // Length of the remaining part, from a dense polyline.
    let dense = 8 * traj.piece_count().max(1);
    let mut length = 0.0;
    let mut prev = traj.position(t_begin);
    for k in 1..=dense {
        let p = traj.position(t_begin + remaining * k as f64 / dense as f64);
        length += (p - prev).norm();
        prev = p;
    }
    let n = params.piece_count(length);
    let waypoints = (1..n)
        .map(|i| traj.position(t_begin + remaining * i as f64 / n as f64))
        .collect();
    InitialTrajectory {
        waypoints,
        end_position: traj.position(t_end),
        end_velocity: traj.velocity(t_end),
        total_duration: floor_duration(remaining, n, params),
    }
}

fn floor_duration(duration: f64, n: usize, params: &PieceParams) -> f64 {
    let floor = 2.0 * n as f64 * params.min_piece_duration_s;
    if duration.is_finite() {
        duration.max(floor)
    } else {
        floor
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn rest_to_rest_time_matches_the_closed_form() {
        let l = Limits::new(10.0, 15.0).unwrap();
        assert_eq!(rest_to_rest_time(0.0, &l), 0.0);
        assert_relative_eq!(rest_to_rest_time(50.0, &l), 5.0 + 10.0 / 15.0);
        // Short: accelerate half way, brake half way.
        assert_relative_eq!(rest_to_rest_time(1.5, &l), 2.0 * 0.1f64.sqrt());
    }

    #[test]
    fn speed_profile_phases() {
        let l = Limits::new(10.0, 15.0).unwrap();
        let p = SpeedProfile::new(50.0, 0.0, &l);
        assert_relative_eq!(p.distance_at(0.0), 0.0);
        assert_relative_eq!(p.distance_at(p.duration()), 50.0, epsilon = 1e-12);
        // 1/3 s into the acceleration phase.
        assert_relative_eq!(p.distance_at(1.0 / 3.0), 0.5 * 15.0 / 9.0, epsilon = 1e-12);
        // Continuous at the phase boundaries.
        for t in [10.0 / 15.0, p.duration() - 10.0 / 15.0] {
            assert_relative_eq!(
                p.distance_at(t - 1e-9),
                p.distance_at(t + 1e-9),
                epsilon = 1e-7
            );
        }
        // Starting fast: shorter than from rest.
        assert!(SpeedProfile::new(50.0, 8.0, &l).duration() < p.duration());
        // Too fast to stop at a_max within 1 m: uniform braking, ends at the length.
        let fast = SpeedProfile::new(1.0, 10.0, &l);
        assert_relative_eq!(fast.duration(), 0.2, epsilon = 1e-12);
        assert_relative_eq!(fast.distance_at(0.2), 1.0, epsilon = 1e-12);
        assert_eq!(SpeedProfile::new(0.0, 3.0, &l).duration(), 0.0);
    }

    #[test]
    fn guide_waypoints_follow_the_profile() {
        let path = GuidePath::new(vec![
            Vec3::zeros(),
            Vec3::new(6.0, 0.0, 0.0),
            Vec3::new(6.0, 6.0, 0.0),
        ])
        .unwrap();
        let limits = Limits::default();
        let start = State::at_rest(0.0, Vec3::zeros());
        let pieces = PieceParams {
            target_piece_length_m: 3.0,
            ..PieceParams::default()
        };
        let init = initial_trajectory(&InitialGuess::Guide(&path), &start, &limits, &pieces);
        assert_eq!(init.pieces(), 4);
        let profile = SpeedProfile::new(12.0, 0.0, &limits);
        assert_relative_eq!(init.total_duration, profile.duration());
        let s1 = profile.distance_at(profile.duration() / 4.0);
        assert_relative_eq!(init.waypoints[0], Vec3::new(s1, 0.0, 0.0), epsilon = 1e-12);
        // Symmetric profile: the middle waypoint is the path's middle.
        assert_relative_eq!(init.waypoints[1], Vec3::new(6.0, 0.0, 0.0), epsilon = 1e-9);
        assert_relative_eq!(init.end_position, Vec3::new(6.0, 6.0, 0.0));
    }

    #[test]
    fn single_point_guide_hovers() {
        let path = GuidePath::new(vec![Vec3::new(1.0, 2.0, 3.0)]).unwrap();
        let params = PieceParams::default();
        let init = initial_trajectory(
            &InitialGuess::Guide(&path),
            &State::at_rest(0.0, path.start()),
            &Limits::default(),
            &params,
        );
        assert_eq!(init.pieces(), params.min_pieces);
        assert!(
            init.waypoints
                .iter()
                .all(|w| *w == Vec3::new(1.0, 2.0, 3.0))
        );
        assert!(init.total_duration > 0.0);
    }

    #[test]
    fn moving_start_on_a_point_guide_gets_the_braking_time() {
        let path = GuidePath::new(vec![Vec3::new(1.0, 2.0, 3.0)]).unwrap();
        let start = State {
            v: Vec3::new(0.0, 6.0, 0.0),
            ..State::at_rest(0.0, path.start())
        };
        let limits = Limits::default();
        let init = initial_trajectory(
            &InitialGuess::Guide(&path),
            &start,
            &limits,
            &PieceParams::default(),
        );
        assert_relative_eq!(init.total_duration, 6.0 / limits.a_max);
    }

    #[test]
    fn warm_start_samples_the_remaining_part() {
        let mut c = [Vec3::zeros(); 6];
        c[1] = Vec3::new(2.0, 0.0, 0.0);
        let traj = PolyTraj::new(10.0, vec![6.0], vec![c]).unwrap();
        let init = initial_trajectory(
            &InitialGuess::WarmStart(&traj),
            &State::at_rest(13.0, Vec3::zeros()),
            &Limits::default(),
            &PieceParams::default(),
        );
        // 6 m remaining → 2 pieces.
        assert_eq!(init.pieces(), 2);
        assert_relative_eq!(init.waypoints[0], Vec3::new(9.0, 0.0, 0.0), epsilon = 1e-12);
        assert_relative_eq!(
            init.end_position,
            Vec3::new(12.0, 0.0, 0.0),
            epsilon = 1e-12
        );
        assert_relative_eq!(init.end_velocity, Vec3::new(2.0, 0.0, 0.0), epsilon = 1e-12);
        assert_relative_eq!(init.total_duration, 3.0, epsilon = 1e-12);
    }
}
