//! Query benchmark: a Panda-sized convex hull (~200 faces) against a 1,000,000-triangle wavy wall,
//! 1 cm in front of it and penetrating it, beside parry3d-f64's `intersection_test` of the same
//! hull against the plain `TriMesh` (no thickness) in the same run.
//!
//! `cargo bench --bench query`

#[path = "wall_1m.rs"]
mod wall_1m;
// Only the mesh-to-area helper: the rest of the tests' scaffolding is unused here.
#[allow(dead_code)]
#[path = "../tests/common/scaffold.rs"]
mod scaffold;

use criterion::{black_box, criterion_group, criterion_main, Criterion};
use parry3d_f64::query;
use parry3d_f64::shape::TriMesh;
use std::sync::Arc;
use std::time::Duration;
use thickness_collision::collision::{CollideSettings, ConvexHull, Scene, Target, TargetShape};
use thickness_collision::math::{Pose, Real, Rotation, Vector};
use wall_1m::{wall, AMPLITUDE, WAVELENGTH};

/// ~200 faces: 102 points on an elongated ellipsoid the size of a Panda link (8 x 8 x 16 cm).
fn panda_sized_hull() -> ConvexHull {
    let mut pts = Vec::new();
    let n = 102;
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    for i in 0..n {
        let z = 1.0 - 2.0 * (i as Real + 0.5) / n as Real;
        let r = (1.0 - z * z).sqrt();
        let th = golden * i as Real;
        pts.push(Vector::new(0.04 * r * th.cos(), 0.04 * r * th.sin(), 0.08 * z));
    }
    ConvexHull::from_points(&pts).expect("hull")
}

fn wall_height(x: Real, y: Real) -> Real {
    AMPLITUDE * (2.0 * std::f64::consts::PI * x / WAVELENGTH).sin() * (2.0 * std::f64::consts::PI * y / WAVELENGTH).cos()
}

fn bench_query(c: &mut Criterion) {
    // 708 x 708 quads = 1,002,528 triangles over 7 x 7 m (about 1 cm triangles).
    let (v, t) = wall(708, 708);
    let area = scaffold::thin_area(&v, &t, 0.02);
    let mut scene = Scene::new();
    let _ = scene.add_surface("wall", Pose::IDENTITY, area);
    let hull = Arc::new(panda_sized_hull());
    eprintln!("hull: {} faces, {} vertices; wall: {} triangles", hull.face_count(), hull.points().len(), t.len());

    // Tilted, over a wave trough: its bounding box reaches the rising wall around it while the
    // hull itself keeps 1 cm of vertical clearance above the surface (checked at its vertices and
    // at 1 mm samples of its footprint against its lowest point).
    let rot = Rotation::from_axis_angle(Vector::new(1.0, 1.0, 0.0).normalize(), 0.8);
    let (cx, cy) = (3.0 + 3.0 * WAVELENGTH / 4.0, 3.0);
    let gap_at = |z0: Real| {
        hull.points()
            .iter()
            .map(|p| {
                let q = rot * *p;
                z0 + q.z - wall_height(cx + q.x, cy + q.y)
            })
            .fold(Real::INFINITY, Real::min)
    };
    let z_front = 0.01 - gap_at(0.0);
    let front = Target::new(TargetShape::Polytope(hull.clone()), Pose::from_parts(Vector::new(cx, cy, z_front), rot));
    let through = Target::new(TargetShape::Polytope(hull.clone()), Pose::from_parts(Vector::new(cx, cy, z_front - 0.04), rot));

    let settings = CollideSettings::default();
    let r_front = scene.collide(&front, &settings);
    let r_through = scene.collide(&through, &settings);
    eprintln!("1 cm in front: {} candidate cells, colliding {}", r_front.candidates, r_front.in_collision());
    eprintln!(
        "penetrating:   {} candidate cells, colliding {}, depth {:?}",
        r_through.candidates,
        r_through.in_collision(),
        r_through.deepest().map(|c| c.depth)
    );
    // The front case must give a broad phase work: the hull's world box meets the surface.
    let world_box = front.aabb_in(&front.pose);
    let under_box = t
        .iter()
        .filter(|tri| {
            let (lo, hi) = tri
                .iter()
                .map(|&i| v[i as usize])
                .fold((Vector::splat(Real::INFINITY), Vector::splat(Real::NEG_INFINITY)), |(lo, hi), p| (lo.min(p), hi.max(p)));
            lo.cmple(world_box.maxs).all() && world_box.mins.cmple(hi).all()
        })
        .count();
    eprintln!("1 cm in front: {under_box} triangles meet the hull's world box");
    assert!(under_box >= 10 && !r_front.in_collision());
    assert!(r_through.in_collision());

    let trimesh = TriMesh::new(v.clone(), t.clone()).expect("trimesh");
    let peer = |target: &Target| query::intersection_test(&target.pose, hull.as_parry(), &Pose::IDENTITY, &trimesh).expect("supported").intersecting;
    assert!(!peer(&front) && peer(&through));

    let mut g = c.benchmark_group("query_1M_wall");
    g.sample_size(200).measurement_time(Duration::from_secs(3)).warm_up_time(Duration::from_secs(1));
    g.bench_function("thickness: 1 cm in front", |b| b.iter(|| scene.collide(black_box(&front), &settings)));
    g.bench_function("thickness: penetrating (deepest + point)", |b| b.iter(|| scene.collide(black_box(&through), &settings)));
    let flag = CollideSettings { flag_only: true, ..Default::default() };
    g.bench_function("thickness: penetrating (flag only)", |b| b.iter(|| scene.collide(black_box(&through), &flag)));
    g.bench_function("parry TriMesh intersection_test: 1 cm in front", |b| b.iter(|| peer(black_box(&front))));
    g.bench_function("parry TriMesh intersection_test: penetrating", |b| b.iter(|| peer(black_box(&through))));
    g.finish();
}

criterion_group!(benches, bench_query);
criterion_main!(benches);
