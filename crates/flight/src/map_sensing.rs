//! The static map as sensed (`[sensing.static]` other than `"known"`, issue 34): the vehicle's
//! depth camera or LiDAR ray-casts the true static shapes from its pose at the sensor's rate,
//! the scans go into a rolling-window `trust_sensing::LocalMap`, and the planner plans in the
//! map it exports (unknown space free) while the simulator still judges collisions against
//! the truth.
//!
//! * **When.** The first scan at `t = 0`, then one per sensor period (at the first physics step
//!   at or after it); the window is re-centred on the vehicle before each scan. A depth
//!   camera's frames go in by projection (`LocalMap::insert_depth_frame`, decision 0048), a
//!   LiDAR's scans by walking each ray.
//! * **The planner's map.** Rebuilt at a planning cycle if a scan came in since the last one
//!   (`LocalMap::to_static_map` over the world's bounds); shared with the manager's worker.
//! * **Commitment.** The committed part of a plan and its braking must lie in observed free
//!   voxels with the vehicle's radius as clearance ([`KnownFree`], FASTER's rule): the manager
//!   consults it through `trust_manager::CommitCheck`. Two kinds of space count as known free
//!   without a measurement, because the vehicle is physically there: at take-off the ball
//!   around the start of radius `r + blind + voxel diagonal` (`r` the vehicle's radius, `blind`
//!   the sensor's blind reach for it, `StaticSensor::blind_reach_m`: the first stretch of any
//!   path has parts the sensor cannot see from the start, e.g. below and above the camera's 58°
//!   vertical field within 0.54 m; FASTER's initial condition, the vehicle starts in known
//!   free space), and at every scan the voxels that lie wholly inside the vehicle's body
//!   (centres within `r` minus half a voxel diagonal): nothing else is certain. A ball as wide
//!   as the voxels the commit check asks about for the vehicle's own place (0.52 m for
//!   r = 0.3 m, decisions 0047–0049) let a vehicle hovering above a slab its camera never saw
//!   creep down onto it: each scan marked the slab's top voxels free, 0.3 m below the centre,
//!   and the next plan sank into them (decision 0050). The price: a vehicle beside surfaces
//!   its camera has not seen (above, below, behind) cannot commit to leave, and holds. Where a
//!   plan approaches unseen space it keeps the planner's tracking margin beyond the radius
//!   ([`OnlineMap::with_commit_margin`], decision 0054): at exactly the radius the vehicle's
//!   tracking error grazed a building face it had not seen.
//! * **Heading.** A forward-looking camera must look where the vehicle goes: the commanded yaw
//!   turns toward the direction of the best branch (main, else the best-ranked kept one) one
//!   second ahead, else toward the goal, at most [`YAW_RATE_RAD_S`]. A known map keeps yaw 0.
//! * **Moving obstacles** are not inserted into the map (the scans see the static truth only):
//!   the obstacle trackers handle them, as with a known map.
//! * **Cost.** The time of the scans, the insertions and the export is perception, not
//!   planning: it is the cycle record's `map_ms`, not part of its `wall_ms`.
//! * **Shared.** The map half ([`OnlineMap`]: the take-off ball, the insertion re-centred on
//!   the vehicle with its body's ball, the export, the commit check) serves any source of scans:
//!   the ROS 2 node feeds it point clouds (`trust_ros2::sensing`).
//! * **Randomness.** The sensor noise comes from its own stream of the trial seed
//!   (`mix_seed(seed, 5)`), so the same seed gives the same flight.

use std::sync::Arc;
use std::time::Instant;

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use trust_core::{StaticMap, Vec3};
use trust_manager::CommitCheck;
use trust_planner::AnyManager;
use trust_sensing::{
    BodyBall, DEFAULT_MEMORY_CELL_M, DepthCamera, Lidar, LocalMap, MapMemory, Pose, RaySensor,
    Scan, Truth, Unseen,
};
use trust_vehicle::VehicleState;
use trust_world::World;
use trust_world::map_sensing::StaticSensor;

use crate::FlightError;

/// The commanded yaw's largest rate while sensing (rad/s): 45°/s, PX4's default limit of the
/// yaw rate in its autonomous modes (`MPC_YAWRAUTO_MAX`).
pub const YAW_RATE_RAD_S: f64 = std::f64::consts::FRAC_PI_4;

/// How long every plan may be refused by the commit check before the camera looks around
/// ([`MapSensing::aim`]): 1 s.
pub const LOOK_AROUND_AFTER_S: f64 = 1.0;

/// How far ahead along the best branch the camera looks (s).
pub const LOOK_AHEAD_S: f64 = 1.0;

/// The stream of the trial seed the static sensor's noise draws from ([`trust_world::mix_seed`];
/// streams 1–4 are the world's `Seeds`).
pub const NOISE_STREAM: u64 = 5;

/// The online map of one flight and its sensor (module docs).
pub struct MapSensing {
    sensor: Box<dyn RaySensor>,
    /// The sensor again when it is a depth camera: its frames go in by projection.
    camera: Option<DepthCamera>,
    online: OnlineMap,
    rng: ChaCha8Rng,
    scan: Scan,
    period_s: f64,
    next_t: f64,
    /// The commanded yaw (rad).
    yaw: f64,
    /// The yaw it turns toward (rad).
    target_yaw: f64,
    /// Since when every cycle's main branch has been refused by the commit check (s).
    refused_since: Option<f64>,
}

/// The map half of [`MapSensing`], shared with any other source of scans (the ROS 2 node's
/// point clouds, `trust_ros2`): a `LocalMap` started round the vehicle's first position with
/// the take-off ball known free, fed scans re-centred on the vehicle with its body's ball known
/// free after each, the planner's map exported when a scan came in since the last export, and
/// the known-free commit check on it. Times its own work (`take_map_ms`).
pub struct OnlineMap {
    map: Arc<LocalMap>,
    /// The surfaces seen, kept for the flight, when the route has a map of its own
    /// ([`OnlineMap::with_route_memory`]).
    memory: Option<Arc<MapMemory>>,
    /// The sensor's range (m), for the route's map.
    range_m: f64,
    scans: usize,
    bounds: trust_core::Aabb,
    planner_map: Arc<StaticMap>,
    dirty: bool,
    clearance_m: f64,
    /// The commit check's margin beyond the clearance (m; [`OnlineMap::with_commit_margin`]).
    margin_m: f64,
    /// How far back a stalled vehicle backs off to look ([`KnownFree`]'s `retreat_m`).
    retreat_m: f64,
    /// The radius of the ball round the vehicle that counts as free at each scan (m): voxel
    /// centres within it have their whole box inside the body.
    body_m: f64,
    /// How far from the vehicle the commit check's voxels reach (m,
    /// `LocalMap::known_free_reach_m`): the route keeps this much round it open.
    reach_m: f64,
    /// The vehicle's body at the last scan: free whatever the sensor saw (decision 0051).
    body: BodyBall,
    map_ms: f64,
}

impl OnlineMap {
    /// A map of `params` centred on `start` (the vehicle's position), exported over `bounds`
    /// (the world's), for a vehicle of radius `radius_m` whose sensor cannot see within
    /// `blind_reach_m` of it (`StaticSensor::blind_reach_m`): the ball round `start` of radius
    /// `radius_m + blind_reach_m + voxel diagonal` starts known free, and after each scan the
    /// voxels wholly inside the vehicle's body (module docs).
    ///
    /// # Errors
    /// `SensingError` for invalid map parameters, a `start` out of scale or a map that cannot
    /// be exported.
    pub fn new(
        params: trust_sensing::LocalMapParams,
        start: &Vec3,
        bounds: trust_core::Aabb,
        radius_m: f64,
        blind_reach_m: f64,
    ) -> Result<Self, trust_sensing::SensingError> {
        let mut map = LocalMap::new(params, start)?;
        let diagonal = 3f64.sqrt() * params.resolution_m;
        map.assume_free(start, radius_m + blind_reach_m + diagonal);
        let planner_map = Arc::new(map.to_static_map(bounds)?);
        let body_m = (radius_m - 0.5 * diagonal).max(0.0);
        let reach_m = map.known_free_reach_m(radius_m).max(radius_m + diagonal);
        Ok(OnlineMap {
            map: Arc::new(map),
            memory: None,
            range_m: 0.0,
            scans: 0,
            bounds,
            planner_map,
            dirty: false,
            clearance_m: radius_m,
            margin_m: 0.0,
            retreat_m: RETREAT_REACHES * (radius_m + blind_reach_m),
            body_m,
            reach_m,
            body: BodyBall {
                center: *start,
                radius: radius_m,
            },
            map_ms: 0.0,
        })
    }

    /// Re-centres the window on `vehicle` (the vehicle's position at the scan), folds `scan`
    /// in (`LocalMap::insert_scan`: free space along each ray), and marks the vehicle's body
    /// ball known free.
    ///
    /// # Errors
    /// `SensingError` for a non-finite or out-of-scale position or a malformed scan (the map
    /// is unchanged by a malformed scan).
    pub fn insert(
        &mut self,
        scan: &Scan,
        vehicle: &Vec3,
    ) -> Result<trust_sensing::ScanUpdate, trust_sensing::SensingError> {
        self.insert_with(scan, vehicle, None)
    }

    /// [`OnlineMap::insert`] for a frame `camera` took at `pose` (the vehicle's pose):
    /// free space by projecting the frustum's voxels into the depth image
    /// (`LocalMap::insert_depth_frame`, decision 0048) instead of walking each pixel's ray.
    ///
    /// # Errors
    /// As [`OnlineMap::insert`], and for a scan that is not `camera`'s frame at `pose`.
    pub fn insert_depth_frame(
        &mut self,
        scan: &Scan,
        camera: &DepthCamera,
        pose: &Pose,
    ) -> Result<trust_sensing::ScanUpdate, trust_sensing::SensingError> {
        self.insert_with(scan, &pose.position, Some((camera, pose)))
    }

    fn insert_with(
        &mut self,
        scan: &Scan,
        vehicle: &Vec3,
        camera: Option<(&DepthCamera, &Pose)>,
    ) -> Result<trust_sensing::ScanUpdate, trust_sensing::SensingError> {
        let started = Instant::now();
        let map = Arc::make_mut(&mut self.map);
        map.recentre(vehicle)?;
        let update = match camera {
            Some((camera, pose)) => map.insert_depth_frame(camera, pose, scan)?,
            None => map.insert_scan(scan)?,
        };
        map.assume_free(vehicle, self.body_m);
        self.body.center = *vehicle;
        if let Some(memory) = self.memory.as_mut() {
            let memory = Arc::make_mut(memory);
            memory.record(scan);
            self.scans += 1;
            if self.scans == 1 || self.scans.is_multiple_of(FOLD_EVERY_SCANS) {
                memory.fold(map);
            }
        }
        self.dirty = true;
        self.map_ms += started.elapsed().as_secs_f64() * 1e3;
        Ok(update)
    }

    /// The planner's map for a cycle: rebuilt if a scan came in since the last call.
    ///
    /// # Errors
    /// `SensingError` if the map cannot be exported.
    pub fn planner_map(&mut self) -> Result<Arc<StaticMap>, trust_sensing::SensingError> {
        if self.dirty {
            let started = Instant::now();
            self.planner_map = Arc::new(self.map.to_static_map(self.bounds)?);
            self.dirty = false;
            self.map_ms += started.elapsed().as_secs_f64() * 1e3;
        }
        Ok(Arc::clone(&self.planner_map))
    }

    /// The map's time since the last call (ms): insertions and exports.
    pub fn take_map_ms(&mut self) -> f64 {
        std::mem::take(&mut self.map_ms)
    }

    /// The commit check on the current map ([`KnownFree`]). Drop it (the manager's
    /// `set_commit_check(None)`) before the next scan, or the scan copies the map.
    pub fn commit_check(&self) -> Arc<dyn CommitCheck> {
        Arc::new(KnownFree {
            map: Arc::clone(&self.map),
            clearance_m: self.clearance_m,
            margin_m: self.margin_m,
            retreat_m: self.retreat_m,
            body: self.body,
            route: self.memory.as_ref().map(|memory| RouteView {
                memory: Arc::clone(memory),
                near: Arc::clone(&self.planner_map),
                keep_m: self.reach_m + self.clearance_m + ROUTE_KEEP_M,
                reach_m: ROUTE_BLOCKED_REACH * self.range_m,
            }),
        })
    }

    /// Gives the route a map of its own ([`MapMemory::route_map`]): the window with the
    /// unknown space within [`ROUTE_BLOCKED_REACH`] of the sensor's range `range_m` of the
    /// vehicle blocked, and beyond the window every surface the sensor has returned, remembered
    /// for the flight in cells of [`DEFAULT_MEMORY_CELL_M`]. Without it the route searches the
    /// planner's map (the window only, unknown free). For scans of the static world only: a
    /// moving obstacle's returns would be remembered as walls.
    ///
    /// # Errors
    /// `SensingError` for a range that is not positive and finite.
    pub fn with_route_memory(mut self, range_m: f64) -> Result<Self, trust_sensing::SensingError> {
        if !(range_m.is_finite() && range_m > 0.0) {
            return Err(trust_sensing::SensingError::OutOfRange {
                field: "route_memory.range_m".into(),
                value: range_m,
                expected: "finite and > 0",
            });
        }
        let mut memory = MapMemory::new(&self.bounds, DEFAULT_MEMORY_CELL_M)?;
        memory.fold(&self.map);
        self.memory = Some(Arc::new(memory));
        self.range_m = range_m;
        Ok(self)
    }

    /// Keeps committed plans `margin_m` beyond the vehicle's radius off space the sensor has
    /// not observed free, where they approach it (`LocalMap::segment_known_free_with_margin`,
    /// decision 0054): the flights give the planner's tracking margin, so that the vehicle's
    /// tracking error cannot carry it into a surface it has not seen. Default 0.
    ///
    /// # Errors
    /// `SensingError` for a margin that is negative or not finite.
    pub fn with_commit_margin(
        mut self,
        margin_m: f64,
    ) -> Result<Self, trust_sensing::SensingError> {
        if !(margin_m.is_finite() && margin_m >= 0.0) {
            return Err(trust_sensing::SensingError::OutOfRange {
                field: "commit_margin_m".into(),
                value: margin_m,
                expected: "finite and >= 0",
            });
        }
        self.margin_m = margin_m;
        Ok(self)
    }

    /// The surfaces seen, kept for the flight ([`OnlineMap::with_route_memory`]).
    pub fn memory(&self) -> Option<&MapMemory> {
        self.memory.as_deref()
    }

    /// The online map.
    pub fn map(&self) -> &LocalMap {
        &self.map
    }
}

impl MapSensing {
    /// Keeps committed plans `margin_m` beyond the vehicle's radius off unseen space they
    /// approach ([`OnlineMap::with_commit_margin`]).
    ///
    /// # Errors
    /// `SensingError` for a margin that is negative or not finite.
    pub fn with_commit_margin(
        mut self,
        margin_m: f64,
    ) -> Result<Self, trust_sensing::SensingError> {
        self.online = self.online.with_commit_margin(margin_m)?;
        Ok(self)
    }

    /// The map sensing of a flight through `world`; `None` for `[sensing.static] = "known"`.
    ///
    /// # Errors
    /// [`FlightError::Sensing`] for invalid sensor or map parameters (`trust-sim validate`
    /// reports them first) or a world whose static obstacles include a point cloud (not
    /// ray-cast yet).
    pub fn new(world: &World) -> Result<Option<Self>, FlightError> {
        let scenario = world.scenario();
        let Some((sensor, map_params)) = scenario.sensing.static_map.sensor() else {
            return Ok(None);
        };
        let blind = sensor.blind_reach_m(world.vehicle_radius_m());
        if world.static_points().is_some() {
            return Err(FlightError::Sensing(trust_sensing::SensingError::Scan {
                field: "sensing.static".into(),
                problem: "a world with a static point cloud is not ray-cast yet; use \"known\""
                    .into(),
            }));
        }
        let range = match &sensor {
            StaticSensor::Depth(p) => p.max_depth_m,
            StaticSensor::Lidar(p) => p.max_range_m,
        };
        let (sensor, camera): (Box<dyn RaySensor>, _) = match sensor {
            StaticSensor::Depth(p) => {
                let camera = DepthCamera::new(p)?;
                (Box::new(camera.clone()), Some(camera))
            }
            StaticSensor::Lidar(p) => (Box::new(Lidar::new(p)?), None),
        };
        let start = world.start();
        let online = OnlineMap::new(
            map_params,
            &start,
            *world.bounds(),
            world.vehicle_radius_m(),
            blind,
        )?
        .with_route_memory(range)?;
        let goal = world.goal() - start;
        let yaw = 0.0;
        Ok(Some(MapSensing {
            period_s: 1.0 / sensor.rate_hz(),
            sensor,
            camera,
            online,
            rng: ChaCha8Rng::seed_from_u64(trust_world::mix_seed(scenario.seed, NOISE_STREAM)),
            scan: Scan::default(),
            next_t: 0.0,
            yaw,
            refused_since: None,
            target_yaw: if goal.xy().norm() > 1e-9 {
                goal.y.atan2(goal.x)
            } else {
                yaw
            },
        }))
    }

    /// Takes a scan from `vehicle`'s pose against the true static shapes if one is due at `t`
    /// (see the module docs), into the map.
    ///
    /// # Errors
    /// [`FlightError::Sensing`] for a pose the sensor rejects (non-finite, out of scale).
    pub fn sense(
        &mut self,
        t: f64,
        dt: f64,
        vehicle: &VehicleState,
        world: &World,
    ) -> Result<(), FlightError> {
        if t + 0.5 * dt < self.next_t {
            return Ok(());
        }
        self.next_t += self.period_s;
        let started = Instant::now();
        let pose = Pose::new(vehicle.p, vehicle.attitude);
        self.sensor.scan(
            &pose,
            &Truth::static_only(world.truth_map()),
            &mut self.rng,
            &mut self.scan,
        )?;
        self.online.map_ms += started.elapsed().as_secs_f64() * 1e3;
        match &self.camera {
            Some(camera) => self.online.insert_depth_frame(&self.scan, camera, &pose)?,
            None => self.online.insert(&self.scan, &vehicle.p)?,
        };
        Ok(())
    }

    /// The planner's map for a cycle: rebuilt if a scan came in since the last cycle.
    ///
    /// # Errors
    /// [`FlightError::Sensing`] if the map cannot be exported.
    pub fn planner_map(&mut self) -> Result<Arc<StaticMap>, FlightError> {
        Ok(self.online.planner_map()?)
    }

    /// The map's time since the last call (ms): scans, insertions and exports.
    pub fn take_map_ms(&mut self) -> f64 {
        self.online.take_map_ms()
    }

    /// The commit check on the current map ([`KnownFree`]). Drop it (the manager's
    /// `set_commit_check(None)`) before the next scan, or the scan copies the map.
    pub fn commit_check(&self) -> Arc<dyn CommitCheck> {
        self.online.commit_check()
    }

    /// The online map.
    pub fn map(&self) -> &LocalMap {
        self.online.map()
    }

    /// Points the camera after a cycle: toward the best branch one [`LOOK_AHEAD_S`] ahead of
    /// `t`, else toward `goal` (unchanged when the vehicle is above either). When the cycle's
    /// main branch was `refused` by the commit check, and every cycle's since
    /// [`LOOK_AROUND_AFTER_S`], it turns on instead: the space beside and behind a vehicle held
    /// in place is what its plans need seen (a full turn in 8 s at [`YAW_RATE_RAD_S`]).
    pub fn aim(&mut self, t: f64, p: &Vec3, goal: &Vec3, manager: &AnyManager, refused: bool) {
        if !refused {
            self.refused_since = None;
        } else if t - *self.refused_since.get_or_insert(t) >= LOOK_AROUND_AFTER_S {
            self.target_yaw = self.yaw + std::f64::consts::FRAC_PI_2;
            return;
        }
        let best = manager
            .main()
            .and_then(|id| manager.branches().iter().find(|b| b.id == id))
            .or(manager.branches().first());
        let ahead = best.map(|b| b.traj().position(t + LOOK_AHEAD_S) - p);
        let toward = ahead.filter(|d| d.xy().norm() > 0.05).unwrap_or(goal - p);
        if toward.xy().norm() > 0.05 {
            self.target_yaw = toward.y.atan2(toward.x);
        }
    }

    /// The commanded yaw after one physics step `dt`: turned toward the target at most
    /// [`YAW_RATE_RAD_S`].
    pub fn turn(&mut self, dt: f64) -> f64 {
        let mut d = self.target_yaw - self.yaw;
        d = (d + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        let step = YAW_RATE_RAD_S * dt;
        self.yaw += d.clamp(-step, step);
        self.yaw = (self.yaw + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU)
            - std::f64::consts::PI;
        self.yaw
    }
}

/// The commit check of a sensed map: a segment passes if every voxel within the vehicle's
/// radius of it is observed free or inside its body, and it approaches no unseen voxel closer
/// than the radius plus the margin (`LocalMap::segment_known_free_with_margin`); with a route
/// memory the route is searched on its own map ([`MapMemory::route_map`]).
pub struct KnownFree {
    map: Arc<LocalMap>,
    clearance_m: f64,
    /// Beyond the clearance where a plan approaches unseen space (m).
    margin_m: f64,
    /// How far back a stalled vehicle backs off to look (m).
    retreat_m: f64,
    /// The vehicle's body at the map's last scan.
    body: BodyBall,
    route: Option<RouteView>,
}

/// What [`KnownFree::route_map`] builds the route's map from.
struct RouteView {
    memory: Arc<MapMemory>,
    near: Arc<StaticMap>,
    /// Unknown space within this of the vehicle is its own place (m).
    keep_m: f64,
    /// Unknown space beyond this stays free for the route (m).
    reach_m: f64,
}

/// How far back along its path a stalled vehicle backs off to look at space the commit check
/// refused (`trust_manager::retreat`), in units of its radius plus the sensor's blind reach for
/// it: 2 (1.7 m for a 0.3 m vehicle and the D435, whose field then covers ±0.9 m above and
/// below the place it stalled at, three times the clearance).
pub const RETREAT_REACHES: f64 = 2.0;

/// How many scans between two folds of the window into the memory: 4 (0.13 s at the
/// camera's 30 Hz, 0.4 s at the LiDAR's 10 Hz; a pass over the window costs a few
/// milliseconds), well within the time the window holds what it saw.
pub const FOLD_EVERY_SCANS: usize = 4;

/// Unknown space the route may cross round the vehicle beyond its body and clearance (m): a
/// camera's view is a pyramid from its lens, narrower than the route's clearance within the
/// first metre, and the route must get out of it.
pub const ROUTE_KEEP_M: f64 = 1.0;

/// How far round the vehicle the route treats unknown space as blocked, as a fraction of the
/// sensor's range: 0.6 (6 m for the D435's 10 m), so that what the sensor sees reaches past it
/// and the route leaves through seen space.
pub const ROUTE_BLOCKED_REACH: f64 = 0.6;

impl CommitCheck for KnownFree {
    fn name(&self) -> &str {
        "known free"
    }

    fn segment_free(&self, a: &Vec3, b: &Vec3) -> bool {
        self.map
            .segment_known_free_with_margin(a, b, self.clearance_m, self.margin_m, &self.body)
    }

    fn retreat_m(&self) -> Option<f64> {
        Some(self.retreat_m)
    }

    fn route_map(&self, from: &Vec3, goal: &Vec3) -> Option<Arc<StaticMap>> {
        let r = self.route.as_ref()?;
        let near = (*r.near).clone();
        r.memory
            .route_map(
                near,
                &self.map.window(),
                &|b| self.map.observed_in(b),
                &Unseen {
                    from: *from,
                    goal: *goal,
                    keep_m: r.keep_m,
                    reach_m: r.reach_m,
                },
            )
            .ok()
            .map(Arc::new)
    }
}
