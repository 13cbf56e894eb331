//! `builtin_interfaces`: [`Time`] and [`Duration`].

use serde::{Deserialize, Serialize};

use crate::error::Ros2Error;

/// `builtin_interfaces/msg/Time`: seconds and nanoseconds since the clock's epoch.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Time {
    /// `int32 sec`.
    pub sec: i32,
    /// `uint32 nanosec`, in `[0, 1e9)`.
    pub nanosec: u32,
}
ros_message!(Time, "builtin_interfaces", "Time");

/// `builtin_interfaces/msg/Duration`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub struct Duration {
    /// `int32 sec`.
    pub sec: i32,
    /// `uint32 nanosec`, in `[0, 1e9)`.
    pub nanosec: u32,
}
ros_message!(Duration, "builtin_interfaces", "Duration");

/// Splits `seconds` into whole seconds (floor) and nanoseconds in `[0, 1e9)`.
fn split(field: &'static str, seconds: f64) -> Result<(i32, u32), Ros2Error> {
    if !seconds.is_finite() || seconds < i32::MIN as f64 || seconds >= i32::MAX as f64 {
        return Err(Ros2Error::invalid(
            field,
            seconds,
            "a finite time within the int32 seconds range",
        ));
    }
    let mut sec = seconds.floor();
    let mut nanosec = ((seconds - sec) * 1e9).round();
    if nanosec >= 1e9 {
        sec += 1.0;
        nanosec -= 1e9;
    }
    Ok((sec as i32, nanosec as u32))
}

impl Time {
    /// The time `seconds` after the epoch.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] for a non-finite time or one outside the `int32` seconds range.
    pub fn from_seconds(seconds: f64) -> Result<Self, Ros2Error> {
        let (sec, nanosec) = split("stamp", seconds)?;
        Ok(Time { sec, nanosec })
    }

    /// Seconds since the epoch.
    pub fn as_seconds(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}

impl Duration {
    /// A duration of `seconds`.
    ///
    /// # Errors
    /// [`Ros2Error::Invalid`] for a non-finite duration or one outside the `int32` seconds range.
    pub fn from_seconds(seconds: f64) -> Result<Self, Ros2Error> {
        let (sec, nanosec) = split("time_from_start", seconds)?;
        Ok(Duration { sec, nanosec })
    }

    /// The duration in seconds.
    pub fn as_seconds(&self) -> f64 {
        f64::from(self.sec) + f64::from(self.nanosec) * 1e-9
    }
}
