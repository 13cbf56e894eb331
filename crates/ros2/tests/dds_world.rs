//! The simulator as the ROS 2 world (`trust_ros2::dds_world::fly`, what `trust-sim dds-world`
//! runs) against `trust-node` in a process of its own, over loopback on a domain of their own:
//! `scenarios/quickstart.toml` flies to the goal and the run log passes the audit.

use std::path::Path;
use std::process::{Command, Stdio};

use trust_ros2::dds_world::{DdsWorldOptions, fly};
use trust_runlog::Status;
use trust_runlog::audit::{AuditOptions, audit_file};
use trust_world::World;

#[test]
fn quickstart_flown_by_trust_node_over_dds_arrives_and_its_log_passes_the_audit() {
    let domain = (std::process::id() % 100) as u16 * 2 + 22;
    let scenario = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenarios/quickstart.toml");
    let mut node = Command::new(env!("CARGO_BIN_EXE_trust-node"))
        .arg(&scenario)
        .args(["--domain-id", &domain.to_string(), "--until-stdin-closes"])
        .stdin(Stdio::piped())
        .stdout(Stdio::null())
        .spawn()
        .expect("start trust-node");
    let s = trust_world::load_checked::<trust_planner::PlannerSpec>(&scenario).expect("quickstart");
    let world = World::build(&s).expect("world");
    let dir = std::env::temp_dir().join(format!("trust-dds-world-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temp dir");
    let log = dir.join("run.jsonl");
    let outcome = fly(&world, domain, &log, &DdsWorldOptions::default());
    drop(node.stdin.take());
    let _ = node.wait();
    let outcome = outcome.expect("the flight over DDS");
    let audit = audit_file(&log, AuditOptions { cycles: true }).expect("read the log");
    assert!(audit.passed(), "audit findings: {:?}", audit.findings);
    assert_eq!(outcome.status, Status::Arrived, "{outcome:?}");
    assert!(outcome.cycle_count > 0, "{outcome:?}");
    let _ = std::fs::remove_dir_all(&dir);
}
