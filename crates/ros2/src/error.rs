//! [`Ros2Error`], the crate's one error type.

use thiserror::Error;

/// What went wrong, naming the field, the value and what was expected.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum Ros2Error {
    /// A message or parameter field holds an unusable value.
    #[error("invalid {field} = {value}: expected {expected}")]
    Invalid {
        /// The field's path (`odom.pose.pose.orientation`).
        field: String,
        /// The offending value, as text.
        value: String,
        /// What was expected.
        expected: String,
    },
    /// The planner could not be assembled or rejected its input.
    #[error("planner: {0}")]
    Planner(#[from] trust_planner::PlannerError),
    /// The planner rejected its input (`trust_core::PlanError`).
    #[error("plan: {0}")]
    Plan(#[from] trust_core::PlanError),
    /// The obstacle filter rejected a measurement or a forecast.
    #[error("obstacle tracking: {0}")]
    Predict(#[from] trust_predict::PredictError),
    /// The scenario file (map, vehicle, planner) could not be read or is invalid.
    #[error("scenario: {0}")]
    World(#[from] trust_world::WorldError),
    /// A flight-stack conversion (PX4 setpoint) failed.
    #[error("flight stack: {0}")]
    FlightStack(#[from] trust_flightstack::FlightStackError),
    /// The online map rejected its parameters, a position or a scan.
    #[error("online map: {0}")]
    Sensing(#[from] trust_sensing::SensingError),
    /// CDR encoding or decoding failed.
    #[error("CDR: {0}")]
    Cdr(String),
    /// The DDS layer failed (participant, topic, reader or writer).
    #[error("DDS: {what}: {cause}")]
    Dds {
        /// What was being done (`create topic odom`).
        what: String,
        /// The middleware's message.
        cause: String,
    },
    /// Reading a file failed.
    #[error("{path}: {cause}")]
    Io {
        /// The file.
        path: String,
        /// The system's message.
        cause: String,
    },
}

impl Ros2Error {
    /// An [`Ros2Error::Invalid`].
    pub fn invalid(
        field: impl Into<String>,
        value: impl std::fmt::Display,
        expected: impl Into<String>,
    ) -> Self {
        Ros2Error::Invalid {
            field: field.into(),
            value: value.to_string(),
            expected: expected.into(),
        }
    }

    /// A [`Ros2Error::Dds`].
    pub fn dds(what: impl Into<String>, cause: impl std::fmt::Debug) -> Self {
        Ros2Error::Dds {
            what: what.into(),
            cause: format!("{cause:?}"),
        }
    }
}
