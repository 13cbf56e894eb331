use rand::SeedableRng;
use trust_core::Vec3;
use trust_flight::map_sensing::OnlineMap;
use trust_geometry::{AaBox, Aabb, StaticMap};
use trust_sensing::{DepthCamera, DepthCameraParams, LocalMapParams, Pose, RaySensor, Scan, Truth};

#[test]
fn scratch() {
    let bounds = Aabb::new(Vec3::zeros(), Vec3::new(120.0, 60.0, 20.0)).unwrap();
    let wall = AaBox::new(Vec3::new(25.0, 15.0, 0.0), Vec3::new(26.0, 45.0, 20.0)).unwrap();
    let world = StaticMap::from_shapes(bounds, vec![wall.into()]).unwrap();
    let start = Vec3::new(2.0, 30.0, 5.0);
    let params = LocalMapParams { dims: [200, 200, 48], stop_at_visited: true, ..Default::default() };
    let mut online = OnlineMap::new(params, &start, bounds, 0.3, 0.54).unwrap().with_route_memory(10.0).unwrap();
    let cam = DepthCamera::new(DepthCameraParams::default()).unwrap();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let mut scan = Scan::default();
    cam.scan(&Pose::at(start), &Truth::static_only(&world), &mut rng, &mut scan).unwrap();
    println!("kinds hit {} none {} invalid {}", scan.count(trust_sensing::ReturnKind::Hit), scan.count(trust_sensing::ReturnKind::NoReturn), scan.count(trust_sensing::ReturnKind::Invalid));
    online.insert(&scan, &start).unwrap();
    let w = online.map().window();
    println!("window {:?}", w);
    for zi in 0..30 {
        let z = 3.5 + 0.1 * zi as f64;
        let row: String = (0..60).map(|xi| match online.map().state(&Vec3::new(2.0 + 0.1 * xi as f64 + 0.05, 30.05, z + 0.05)) { trust_sensing::VoxelState::Free => '.', trust_sensing::VoxelState::Occupied => '#', _ => '?' }).collect();
        println!("{z:.1} {row}");
    }
    let check = online.commit_check();
    let map = check.route_map(&start, &Vec3::new(100.0, 30.0, 5.0)).unwrap();
    for x in [2.5, 3.0, 3.5, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0] {
        let p = Vec3::new(x, 30.0, 5.0);
        println!("x {x}: sd {:.3} known {:?}", map.signed_distance(&p), online.map().state(&p));
    }
    for z in [3.0, 4.0, 4.5, 5.5, 6.0, 7.0] {
        let p = Vec3::new(6.0, 30.0, z);
        println!("z {z}: sd {:.3} known {:?}", map.signed_distance(&p), online.map().state(&p));
    }
}
