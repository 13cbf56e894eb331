//! `trust-node` against an independent DDS implementation: Eclipse Cyclone DDS through its
//! Python binding (`interop/peer.py`, types written from the ROS 2 `.msg` files), over loopback
//! on a ROS domain of the test's own. The peer publishes odometry, a goal and obstacles (and,
//! for a node with `--use-sim-time`, `/clock`) and checks every message type the node publishes
//! field by field; a field laid out differently on the two sides fails here, where the loopback
//! test (ros2-client on both ends) cannot see it. The last test observes a `dds-world` flight
//! (`trust_ros2::dds_world::fly`) and decodes its `/clock`; another has the peer publish point
//! clouds (`sensor_msgs/PointCloud2`, two layouts of its own) to a node in this process and
//! checks the node's online map point by point.
//!
//! The Python interpreter is `$TRUST_CYCLONE_PYTHON` (else `python3`). Without the `cyclonedds`
//! module the tests are skipped, unless `TRUST_REQUIRE_CYCLONE` is set (CI: `.ci/run` installs
//! the pinned wheel of `interop/requirements.txt` into `target/cyclone-venv`).

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::time::{Duration, Instant};

/// Cyclone DDS restricted to the loopback interface (multicast forced on `lo`, which Linux
/// does not flag as multicast-capable, and unicast discovery of 127.0.0.1 as well).
const CYCLONE_LOOPBACK: &str = "<CycloneDDS><Domain Id=\"any\"><General><Interfaces>\
    <NetworkInterface name=\"lo\" multicast=\"true\"/></Interfaces>\
    <AllowMulticast>true</AllowMulticast></General><Discovery>\
    <ParticipantIndex>auto</ParticipantIndex><Peers><Peer address=\"127.0.0.1\"/></Peers>\
    </Discovery></Domain></CycloneDDS>";

/// How long the peer waits for every message type (a debug build on a loaded machine).
const PEER_TIMEOUT_S: u64 = 60;

fn crate_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

/// The interpreter with the `cyclonedds` module, or `None` when the tests may be skipped.
fn cyclone_python() -> Option<PathBuf> {
    let python = std::env::var_os("TRUST_CYCLONE_PYTHON")
        .map(PathBuf::from)
        .unwrap_or_else(|| PathBuf::from("python3"));
    let found = Command::new(&python)
        .args(["-c", "import cyclonedds.idl"])
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    if found {
        return Some(python);
    }
    let why = format!(
        "{} cannot import cyclonedds (pip install -r crates/ros2/interop/requirements.txt, \
         then TRUST_CYCLONE_PYTHON=<that python>)",
        python.display()
    );
    assert!(
        std::env::var_os("TRUST_REQUIRE_CYCLONE").is_none(),
        "TRUST_REQUIRE_CYCLONE is set but {why}"
    );
    eprintln!("SKIPPED: {why}");
    None
}

/// A domain id in 21..=220 of this process and test (`k` < 5): parallel test processes, and
/// the tests of this one, do not meet.
fn domain_id(k: u32) -> u16 {
    ((std::process::id() % 40) * 5 + 21 + k) as u16
}

/// Waits for `child` at most `limit`, killing it after that (`None`).
fn wait_at_most(child: &mut Child, limit: Duration) -> Option<ExitStatus> {
    let deadline = Instant::now() + limit;
    while Instant::now() < deadline {
        if let Ok(Some(status)) = child.try_wait() {
            return Some(status);
        }
        std::thread::sleep(Duration::from_millis(50));
    }
    let _ = child.kill();
    let _ = child.wait();
    None
}

fn stderr_of(child: &mut Child) -> String {
    let mut s = String::new();
    if let Some(mut e) = child.stderr.take() {
        let _ = e.read_to_string(&mut s);
    }
    s
}

/// Runs `trust-node` (with `node_args`) and the Cyclone peer (with `peer_args`) on a domain of
/// their own and fails with both logs unless the peer's checks pass.
fn node_against_cyclone_peer(k: u32, node_args: &[&str], peer_args: &[&str]) {
    node_and_cyclone_peer_with(k, node_args, peer_args, |_| {});
}

/// As [`node_against_cyclone_peer`], running `meanwhile(domain)` once both have started.
fn node_and_cyclone_peer_with(
    k: u32,
    node_args: &[&str],
    peer_args: &[&str],
    meanwhile: impl FnOnce(u16),
) {
    let Some(python) = cyclone_python() else {
        return;
    };
    let domain_number = domain_id(k);
    let domain = domain_number.to_string();
    let scenario = crate_dir().join("../../scenarios/quickstart.toml");
    let mut node = Command::new(env!("CARGO_BIN_EXE_trust-node"))
        .arg(&scenario)
        .args(["--domain-id", &domain, "--until-stdin-closes"])
        .args(node_args)
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start trust-node");
    let started = Instant::now();
    let mut peer = Command::new(&python)
        .arg(crate_dir().join("interop/peer.py"))
        .args([
            "--domain",
            &domain,
            "--timeout",
            &PEER_TIMEOUT_S.to_string(),
        ])
        .args(peer_args)
        .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the Cyclone DDS peer");
    meanwhile(domain_number);
    // The peer's stderr is read after it exits: its output is a few lines.
    let peer_status = wait_at_most(&mut peer, Duration::from_secs(PEER_TIMEOUT_S + 20));
    let peer_log = stderr_of(&mut peer);
    drop(node.stdin.take()); // --until-stdin-closes: the node stops and prints its counters
    let node_status = wait_at_most(&mut node, Duration::from_secs(10));
    let node_log = stderr_of(&mut node);
    eprintln!(
        "domain {domain}, {:.1} s\n--- peer ---\n{peer_log}--- trust-node ---\n{node_log}",
        started.elapsed().as_secs_f64()
    );
    assert!(
        peer_status.is_some_and(|s| s.success()),
        "the Cyclone DDS peer failed ({peer_status:?}); its log and the node's are above"
    );
    assert!(
        node_status.is_some_and(|s| s.success()),
        "trust-node did not stop cleanly when its stdin closed ({node_status:?})"
    );
    assert!(
        node_log.contains(" 0 rejected"),
        "the node rejected messages of the peer: {node_log}"
    );
}

#[test]
fn every_message_type_round_trips_with_cyclone_dds() {
    node_against_cyclone_peer(0, &[], &[]);
}

#[test]
fn px4_setpoints_decode_in_cyclone_dds() {
    node_against_cyclone_peer(1, &["--px4"], &["--px4"]);
}

/// The peer is the node's clock: its `/clock` starts at 1000 s, far from the system time, and
/// every stamp the node publishes must be on it.
#[test]
fn a_node_with_use_sim_time_follows_a_cyclone_clock() {
    node_against_cyclone_peer(2, &["--use-sim-time"], &["--sim-time", "1000"]);
}

/// `trust-sim dds-world`'s flight (quickstart, its clock from 1000 s) with `trust-node
/// --use-sim-time`, observed by the peer: the world's `/clock` decoded field by field, the
/// node's `/tf` equal to the world's odometry, its trajectories on the world's clock; the
/// flight arrives.
#[test]
fn cyclone_decodes_the_world_clock_and_the_node_follows_it() {
    let scenario = crate_dir().join("../../scenarios/quickstart.toml");
    node_and_cyclone_peer_with(
        3,
        &["--use-sim-time"],
        &["--observe-world", "1000"],
        |domain| {
            let s = trust_world::load_checked::<trust_planner::PlannerSpec>(&scenario)
                .expect("quickstart");
            let world = trust_world::World::build(&s).expect("world");
            let dir = std::env::temp_dir().join(format!("trust-cyclone-world-{domain}"));
            std::fs::create_dir_all(&dir).expect("temp dir");
            let options = trust_ros2::dds_world::DdsWorldOptions {
                clock_start_s: Some(1000.0),
                ..Default::default()
            };
            let outcome =
                trust_ros2::dds_world::fly(&world, domain, &dir.join("run.jsonl"), &options)
                    .expect("the flight on the world's clock");
            let _ = std::fs::remove_dir_all(&dir);
            assert_eq!(outcome.status, trust_runlog::Status::Arrived, "{outcome:?}");
        },
    );
}

/// Points (map frame, voxel centres of the node's 0.1 m map) the peer publishes as clouds, all
/// within the map's window round the peer's vehicle at (2, 10, 3) and in directions apart (no
/// ray passes another's point). The first half goes in `map`, the rest in `base_link`.
const CLOUD_POINTS: [[f64; 3]; 6] = [
    [6.05, 10.05, 3.05],
    [2.05, 14.05, 3.05],
    [5.05, 7.05, 2.05],
    [-1.95, 10.05, 3.05],
    [2.05, 6.05, 4.05],
    [-0.95, 13.05, 1.55],
];

/// The peer (Cyclone DDS) publishes odometry and the points of [`CLOUD_POINTS`] as two
/// `PointCloud2` of layouts the node never writes (FLOAT32 little-endian after an intensity in
/// `map`; FLOAT64 big-endian, fields listed z, x, y, an organized 2-row cloud with a NaN hole
/// and padded rows, in `base_link`, moved there by the peer from the odometry's pose). The node
/// (`[cloud]`, in this process) must hold an occupied voxel at every point and free voxels
/// along the ray from the vehicle to it, the NaN hole skipped, nothing rejected.
#[test]
fn cyclone_point_clouds_decode_into_the_nodes_map_point_by_point() {
    use std::sync::Arc;
    use std::sync::atomic::{AtomicBool, Ordering};
    use trust_core::Vec3;
    use trust_sensing::VoxelState;

    let Some(python) = cyclone_python() else {
        return;
    };
    let domain = domain_id(4);
    let params = trust_ros2::NodeParams {
        cloud: Some(trust_ros2::sensing::CloudParams::default()),
        ..trust_ros2::NodeParams::default()
    };
    let stop = Arc::new(AtomicBool::new(false));
    let node_stop = Arc::clone(&stop);
    let node = std::thread::spawn(move || {
        let (mut core, mut node) =
            trust_ros2::test_support::quickstart_dds_node_with(domain, params)
                .expect("quickstart node with [cloud]");
        node.run(&mut core, &node_stop, &mut |what, e| {
            eprintln!("node warning ({what}): {e}");
        });
        core
    });
    let points: Vec<String> = CLOUD_POINTS
        .iter()
        .map(|p| format!("{},{},{}", p[0], p[1], p[2]))
        .collect();
    let mut peer = Command::new(&python)
        .arg(crate_dir().join("interop/peer.py"))
        .args([
            "--domain",
            &domain.to_string(),
            "--timeout",
            &PEER_TIMEOUT_S.to_string(),
            "--cloud",
            &points.join(";"),
        ])
        .env("CYCLONEDDS_URI", CYCLONE_LOOPBACK)
        .stdout(Stdio::null())
        .stderr(Stdio::piped())
        .spawn()
        .expect("start the Cyclone DDS peer");
    let peer_status = wait_at_most(&mut peer, Duration::from_secs(PEER_TIMEOUT_S + 20));
    let peer_log = stderr_of(&mut peer);
    stop.store(true, Ordering::Relaxed);
    let core = node.join().expect("the node's thread");
    let c = core.counters();
    eprintln!("domain {domain}\n--- peer ---\n{peer_log}--- node ---\n{c:?}");
    assert!(
        peer_status.is_some_and(|s| s.success()),
        "the Cyclone DDS peer failed ({peer_status:?}); its log is above"
    );
    assert_eq!(
        c.rejected_count, 0,
        "the node rejected messages of the peer"
    );
    assert!(c.cloud_count >= 2, "{} clouds", c.cloud_count);
    // Each cloud has 3 points; each body cloud one NaN hole (3 points in 2 rows of 2), the
    // map clouds none.
    assert_eq!(c.cloud_point_count, 3 * c.cloud_count, "3 points a cloud");
    assert!((1..c.cloud_count).contains(&c.cloud_skipped_point_count));
    let map = core.online_map().expect("started by the odometry");
    let start = Vec3::new(2.0, 10.0, 3.0);
    for p in CLOUD_POINTS {
        let p = Vec3::new(p[0], p[1], p[2]);
        assert_eq!(map.state(&p), VoxelState::Occupied, "the point {p:?}");
        for f in [0.3, 0.5, 0.7, 0.85] {
            let q = start + (p - start) * f;
            assert_eq!(
                map.state(&q),
                VoxelState::Free,
                "{f} of the way to {p:?}: {q:?}"
            );
        }
    }
}
