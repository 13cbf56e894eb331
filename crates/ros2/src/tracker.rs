//! Obstacle tracks: each `trust_msgs/MovingObstacle` observation feeds the same constant-velocity
//! EKF the simulator's sensing uses ([`trust_predict::CvEkf`], one per obstacle id), and each
//! cycle gets the tracks' forecasts ([`trust_predict::CvEkf::forecast_at`], as
//! `trust_world::Sensing::forecasts`). A new track starts with an uncertain velocity, so its
//! forecast grows fast for its first second or two (the simulator warms its filters up before
//! take-off for this reason, `trust_world::sensing`).

use std::collections::BTreeMap;

use trust_core::{Forecast, Vec3};
use trust_predict::{CvEkf, EkfParams, ObstacleShape};

use crate::error::Ros2Error;
use crate::msg::trust_msgs::MovingObstacle;

/// One obstacle's filter, its shape and when it was last observed (node time, s).
#[derive(Debug, Clone)]
struct Track {
    filter: CvEkf,
    shape: ObstacleShape,
    radius_m: f64,
    last_seen_s: f64,
}

/// An observation checked: the centre, the forecast shape and its radius.
#[derive(Debug, Clone, Copy)]
pub struct Observation {
    /// The obstacle's id.
    pub id: u32,
    /// Its centre (m).
    pub position: Vec3,
    /// Its shape.
    pub shape: ObstacleShape,
    /// Its radius `r_o` (m).
    pub radius_m: f64,
}

/// Checks one obstacle of a message (`field` is its path, `obstacles[3]`).
///
/// # Errors
/// [`Ros2Error::Invalid`] naming the field: a non-finite position, an unknown shape, a size
/// that is not finite and `> 0` where the shape uses it.
pub fn observation(field: &str, o: &MovingObstacle) -> Result<Observation, Ros2Error> {
    let p = Vec3::new(o.position.x, o.position.y, o.position.z);
    if !p.iter().all(|c| c.is_finite()) {
        return Err(Ros2Error::invalid(
            format!("{field}.position"),
            format!("({}, {}, {})", p.x, p.y, p.z),
            "finite coordinates",
        ));
    }
    let positive = |name: &str, v: f64| {
        if v.is_finite() && v > 0.0 {
            Ok(v)
        } else {
            Err(Ros2Error::invalid(
                format!("{field}.size.{name}"),
                v,
                "a finite extent > 0 m",
            ))
        }
    };
    let diameter = positive("x", o.size.x)?;
    let shape = match o.shape {
        MovingObstacle::SHAPE_SPHERE => ObstacleShape::Sphere,
        MovingObstacle::SHAPE_CYLINDER => ObstacleShape::Cylinder {
            half_height: 0.5 * positive("z", o.size.z)?,
        },
        other => {
            return Err(Ros2Error::invalid(
                format!("{field}.shape"),
                other,
                "SHAPE_SPHERE (0) or SHAPE_CYLINDER (1)",
            ));
        }
    };
    Ok(Observation {
        id: o.id,
        position: p,
        shape,
        radius_m: 0.5 * diameter,
    })
}

/// The obstacle tracks of a node, by id (ordered: forecasts come out in id order).
#[derive(Debug, Clone)]
pub struct Tracker {
    ekf: EkfParams,
    r_safe_m: f64,
    timeout_s: f64,
    tracks: BTreeMap<u32, Track>,
}

impl Tracker {
    /// Tracks with filter parameters `ekf`, forecasts inflated by `r_safe_m` (vehicle radius +
    /// margin) and tracks dropped `timeout_s` after their last observation.
    pub fn new(ekf: EkfParams, r_safe_m: f64, timeout_s: f64) -> Self {
        Tracker {
            ekf,
            r_safe_m,
            timeout_s,
            tracks: BTreeMap::new(),
        }
    }

    /// How many tracks there are.
    pub fn len(&self) -> usize {
        self.tracks.len()
    }

    /// Whether there is no track.
    pub fn is_empty(&self) -> bool {
        self.tracks.is_empty()
    }

    /// Feeds the observations taken at `t` (node time, s): an existing track is stepped to `t`
    /// and updated, an unknown id starts a track. All or nothing: on error no track changed.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] if `t` is before a track's last observation (out-of-order
    /// messages) or a duplicate id; [`Ros2Error::Predict`] if a filter rejects the
    /// measurement.
    pub fn observe(&mut self, t: f64, observations: &[Observation]) -> Result<(), Ros2Error> {
        let mut next = self.tracks.clone();
        let mut seen = std::collections::BTreeSet::new();
        for o in observations {
            if !seen.insert(o.id) {
                return Err(Ros2Error::invalid(
                    "obstacles.id",
                    o.id,
                    "ids unique within a message",
                ));
            }
            match next.get_mut(&o.id) {
                Some(track) => {
                    if t < track.filter.time() {
                        return Err(Ros2Error::invalid(
                            "obstacles.header.stamp",
                            format!("{t} s (node time)"),
                            format!(
                                "not before obstacle {}'s last observation at {} s",
                                o.id,
                                track.filter.time()
                            ),
                        ));
                    }
                    track.filter.step(t, Some(o.position))?;
                    track.shape = o.shape;
                    track.radius_m = o.radius_m;
                    track.last_seen_s = t;
                }
                None => {
                    next.insert(
                        o.id,
                        Track {
                            filter: CvEkf::new(t, o.position, self.ekf.clone())?,
                            shape: o.shape,
                            radius_m: o.radius_m,
                            last_seen_s: t,
                        },
                    );
                }
            }
        }
        self.tracks = next;
        Ok(())
    }

    /// Drops the tracks not observed since `now − timeout_s`, then returns every track's
    /// forecast at `now`, in id order.
    ///
    /// # Errors
    /// [`Ros2Error::Predict`] if a prediction fails (only for absurd times).
    pub fn forecasts(&mut self, now: f64) -> Result<Vec<Forecast>, Ros2Error> {
        let timeout = self.timeout_s;
        self.tracks.retain(|_, t| now - t.last_seen_s <= timeout);
        self.tracks
            .values()
            .map(|t| {
                t.filter
                    .forecast_at(now, t.shape, t.radius_m, self.r_safe_m)
                    .map_err(Ros2Error::from)
            })
            .collect()
    }
}
