//! The meshes of the bundled example workcell, generated here so that they are reproducible:
//! `tests/example_workcell.rs` regenerates them and fails if `config/example_workcell/` differs
//! (run it with `UPDATE_EXAMPLES=1` to rewrite the files).

use crate::math::{Pose, Real, Rotation, Vector};

use crate::mesh::generate::{self, Soup};

/// Name, description and triangles of each example mesh, and whether it is an open (thin) surface.
pub fn example_meshes() -> Vec<(&'static str, &'static str, Soup, bool)> {
    let mut out: Vec<(&'static str, &'static str, Soup, bool)> = thin_meshes().into_iter().map(|(n, c, s)| (n, c, s, true)).collect();
    out.push((
        "gripper.obj",
        "Gripper body of the example arm: a closed 6 x 10 x 8 cm box (the arm's mesh link).",
        generate::cuboid(Vector::new(0.03, 0.05, 0.04), 1),
        false,
    ));
    out
}

fn thin_meshes() -> Vec<(&'static str, &'static str, Soup)> {
    vec![
        (
            "guard_sheet.obj",
            "Corrugated sheet-metal guard, 1.0 x 0.8 m, 1 cm corrugation, one layer (front +z).",
            generate::height_field(40, 32, 1.0, 0.8, |x, _| 0.01 * (2.0 * std::f64::consts::PI * x / 0.1).sin()),
        ),
        ("shelf.obj", "Open shelf: bottom, back and two sides, 0.6 x 0.4 x 0.3 m, single-layer panels.", shelf(0.6, 0.4, 0.3, 12)),
        (
            "bent_panel.obj",
            "Panel bent along a line at 120 degrees (a ridge seen from the front), 2 x 0.3 m x 0.6 m.",
            generate::v_fold(120f64.to_radians(), true, 0.3, 0.6, 10),
        ),
    ]
}

/// Four open panels of a shelf, fronts facing the inside, sharing their edges.
fn shelf(w: Real, d: Real, h: Real, n: usize) -> Soup {
    let mut v: Vec<Vector> = Vec::new();
    let mut t: Vec<[u32; 3]> = Vec::new();
    // `flip` reverses the winding where the rotation leaves the panel's front facing out.
    let mut add = |soup: Soup, pose: Pose, flip: bool| {
        let base = v.len() as u32;
        let (pv, pt) = generate::transformed(soup, &pose);
        v.extend(pv);
        t.extend(pt.into_iter().map(|f| if flip { [f[0], f[2], f[1]] } else { f }).map(|f| f.map(|i| i + base)));
    };
    let q = std::f64::consts::FRAC_PI_2;
    // Bottom (front +z), back wall at y = d (front -y), sides at x = 0 (front +x) and x = w (front -x).
    add(generate::flat_grid(n, n, w, d), Pose::IDENTITY, false);
    add(generate::flat_grid(n, n, w, h), Pose::from_parts(Vector::new(0.0, d, 0.0), Rotation::from_rotation_x(q)), false);
    add(generate::flat_grid(n, n, h, d), Pose::from_parts(Vector::ZERO, Rotation::from_rotation_y(-q)), true);
    add(
        generate::flat_grid(n, n, h, d),
        Pose::from_parts(Vector::new(w, d, 0.0), Rotation::from_rotation_z(std::f64::consts::PI) * Rotation::from_rotation_y(-q)),
        true,
    );
    (v, t)
}

/// The peer benchmark's world at about `triangles` triangles: a corrugated guard sheet in front of
/// the robot (half the triangles), a scanned-looking wall behind it (noisy, a third) and an open
/// shelf beside it (the rest), all single-layer meshes. Each entry is (name, triangles in the
/// object's frame, pose of the object in the world). Deterministic.
pub fn peer_environment(triangles: usize) -> Vec<(String, Soup, Pose)> {
    use std::f64::consts::FRAC_PI_2;
    let side = |share: f64| (((triangles as f64 * share) / 2.0).sqrt().round() as usize).max(2);
    let n_guard = side(0.5);
    let n_wall = side(1.0 / 3.0);
    let n_shelf = ((triangles as f64 / 6.0 / 8.0).sqrt().round() as usize).max(2);
    // Vertical sheets: local x -> world -y (from +0.7), local y -> world z, front (local z) -> world -x.
    let stand = |x: Real, y: Real| Pose::from_parts(Vector::new(x, y, 0.0), Rotation::from_rotation_z(-FRAC_PI_2) * Rotation::from_rotation_x(FRAC_PI_2));
    let guard = generate::height_field(n_guard, n_guard, 1.4, 1.2, |x, y| {
        0.012 * (2.0 * std::f64::consts::PI * x / 0.08).sin() + 0.004 * (2.0 * std::f64::consts::PI * y / 0.3).cos()
    });
    // A scan: smooth bumps plus deterministic per-vertex noise of +-2 mm.
    let wall = generate::height_field(n_wall, n_wall, 1.6, 1.4, |x, y| {
        let mut k = x.to_bits().wrapping_mul(0x9E3779B97F4A7C15) ^ y.to_bits().rotate_left(29);
        k = (k ^ (k >> 31)).wrapping_mul(0xBF58476D1CE4E5B9);
        k ^= k >> 27;
        let noise = ((k >> 11) as Real / (1u64 << 53) as Real - 0.5) * 0.004;
        0.03 * (3.1 * x).sin() * (2.3 * y).cos() + noise
    });
    vec![
        ("guard_sheet".into(), guard, stand(0.55, 0.7)),
        // Facing +x (towards the robot): rotate the stand pose by pi about z.
        (
            "scanned_wall".into(),
            wall,
            Pose::from_parts(Vector::new(-0.6, -0.8, 0.0), Rotation::from_rotation_z(FRAC_PI_2) * Rotation::from_rotation_x(FRAC_PI_2)),
        ),
        ("shelf".into(), shelf(0.6, 0.4, 0.35, n_shelf), Pose::from_parts(Vector::new(0.3, -0.45, 0.25), Rotation::from_rotation_z(std::f64::consts::PI))),
    ]
}
