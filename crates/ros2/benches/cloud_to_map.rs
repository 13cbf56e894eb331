//! One depth-camera cloud through the node: a `sensor_msgs/PointCloud2` of the simulator's
//! default camera (a D435 at 160 × 120, ray-cast in quickstart from the start, facing the goal)
//! as a CDR payload → decoded (`cdr::decode`, then `cloud::decode_points`) → folded into the
//! node's online map (`NodeCore::on_cloud`: scan, insertion, distance field), and the parts
//! alone. The node keeps up with a sensor while one cloud costs less than its period (33 ms at
//! 30 Hz) plus the cycle's share.

use std::hint::black_box;

use criterion::{Criterion, criterion_group, criterion_main};
use rand::SeedableRng;
use trust_core::Vec3;
use trust_ros2::msg::builtin_interfaces::Time;
use trust_ros2::msg::sensor_msgs::PointCloud2;
use trust_ros2::sensing::CloudParams;
use trust_ros2::test_support::{odometry, quickstart};
use trust_ros2::{NodeCore, NodeParams, NodeSetup, cdr, cloud};
use trust_sensing::{DepthCamera, DepthCameraParams, Pose, RaySensor, Scan, Truth};

fn bench(c: &mut Criterion) {
    let origin = Time {
        sec: 1_700_000_000,
        nanosec: 0,
    };
    let start = Vec3::new(2.0, 10.0, 3.0);
    let s =
        trust_world::load_checked::<trust_planner::PlannerSpec>(&quickstart()).expect("quickstart");
    let world = trust_world::World::build(&s).expect("world");
    let camera = DepthCamera::new(DepthCameraParams::default()).expect("camera");
    let mut scan = Scan::default();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(0);
    camera
        .scan(
            &Pose::at(start),
            &Truth::static_only(world.truth_map()),
            &mut rng,
            &mut scan,
        )
        .expect("scan");
    let msg = trust_ros2::dds_world::scan_cloud(
        &scan,
        &start,
        &nalgebra::UnitQuaternion::identity(),
        10.0,
        origin.into_header("base_link"),
    )
    .expect("cloud");
    let payload = cdr::encode(&msg).expect("encodes");
    let params = NodeParams {
        cloud: Some(CloudParams::default()),
        ..NodeParams::default()
    };
    let setup = NodeSetup::from_scenario(&quickstart()).expect("setup");
    let mut core = NodeCore::new(setup, params, origin).expect("core");
    core.on_odometry(&odometry(origin, "base_link", start, Vec3::zeros()))
        .expect("odometry");

    let mut g = c.benchmark_group("cloud_to_map");
    g.sample_size(20);
    g.bench_function("cdr_decode_160x120", |b| {
        b.iter(|| black_box(cdr::decode::<PointCloud2>(black_box(&payload)).expect("decodes")))
    });
    g.bench_function("decode_points_160x120", |b| {
        b.iter(|| black_box(cloud::decode_points(black_box(&msg)).expect("decodes")))
    });
    g.bench_function("on_cloud_160x120", |b| {
        b.iter(|| core.on_cloud(black_box(&msg)).expect("folds"))
    });
    g.bench_function("payload_to_map_160x120", |b| {
        b.iter(|| {
            let m = cdr::decode::<PointCloud2>(black_box(&payload)).expect("decodes");
            core.on_cloud(&m).expect("folds")
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
