//! The flight crate's one error type.

use std::path::PathBuf;

/// Why a flight could not be set up or its log not written. Planning *failures* are not errors;
/// they are in the manager's step reports and the run log.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum FlightError {
    /// The scenario, the world or the planner could not be set up.
    #[error(transparent)]
    World(#[from] trust_world::WorldError),
    /// The planner could not be assembled for the world's vehicle.
    #[error(transparent)]
    Planner(#[from] trust_planner::PlannerError),
    /// Invalid input to a vehicle model or controller.
    #[error(transparent)]
    Vehicle(#[from] trust_vehicle::VehicleError),
    /// Invalid input reported by a planning crate.
    #[error(transparent)]
    Plan(#[from] trust_core::PlanError),
    /// Invalid input to the sensors or the online map (`[sensing.static]`).
    #[error(transparent)]
    Sensing(#[from] trust_sensing::SensingError),
    /// The run log could not be written.
    #[error(transparent)]
    Log(#[from] trust_runlog::LogError),
    /// A file could not be written.
    #[error("cannot write {}: {source}", path.display())]
    Write {
        /// The file.
        path: PathBuf,
        /// The operating system's reason.
        source: std::io::Error,
    },
}
