//! Generated meshes: the shapes the tests, the benchmarks and the example workcell are made of.
//!
//! Each returns an indexed triangle soup `(vertices, triangles)` with counter-clockwise winding
//! seen from the front (`+z` for sheets, outward for closed shapes). Sizes are in metres.

use crate::math::{Real, Vector};
use std::f64::consts::PI;

/// An indexed triangle soup.
pub type Soup = (Vec<Vector>, Vec<[u32; 3]>);

/// A sheet over `[0, sx] x [0, sy]` with `nx * ny` quads (two triangles each) and height
/// `z(x, y)`. The diagonal of each quad alternates, so the mesh has no preferred direction.
pub fn height_field(nx: usize, ny: usize, sx: Real, sy: Real, z: impl Fn(Real, Real) -> Real) -> Soup {
    let mut v = Vec::with_capacity((nx + 1) * (ny + 1));
    for j in 0..=ny {
        for i in 0..=nx {
            let (x, y) = (sx * i as Real / nx as Real, sy * j as Real / ny as Real);
            v.push(Vector::new(x, y, z(x, y)));
        }
    }
    let mut t = Vec::with_capacity(2 * nx * ny);
    let id = |i: usize, j: usize| (j * (nx + 1) + i) as u32;
    for j in 0..ny {
        for i in 0..nx {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            if (i + j) % 2 == 0 {
                t.push([a, b, c]);
                t.push([a, c, d]);
            } else {
                t.push([a, b, d]);
                t.push([b, c, d]);
            }
        }
    }
    (v, t)
}

/// A flat grid in the plane `z = 0`.
pub fn flat_grid(nx: usize, ny: usize, sx: Real, sy: Real) -> Soup {
    height_field(nx, ny, sx, sy, |_, _| 0.0)
}

/// A wavy sheet: `z = amplitude * sin(2 pi x / wavelength) * cos(2 pi y / wavelength)`.
pub fn wavy_sheet(nx: usize, ny: usize, sx: Real, sy: Real, amplitude: Real, wavelength: Real) -> Soup {
    height_field(nx, ny, sx, sy, |x, y| amplitude * (2.0 * PI * x / wavelength).sin() * (2.0 * PI * y / wavelength).cos())
}

/// A saddle `z = k (x - cx)^2 - k (y - cy)^2` over `[0, s]^2`.
pub fn saddle(n: usize, s: Real, k: Real) -> Soup {
    height_field(n, n, s, s, |x, y| k * ((x - s / 2.0).powi(2) - (y - s / 2.0).powi(2)))
}

/// Two flat strips of width `w` and length `l` meeting along the y axis at dihedral angle
/// `angle` (radians, `pi` is flat). With `ridge` the fold is convex seen from the front (a ridge,
/// front `+z` at the crease); otherwise concave (a valley). `n` quads across each strip.
pub fn v_fold(angle: Real, ridge: bool, w: Real, l: Real, n: usize) -> Soup {
    let half = (PI - angle) / 2.0; // tilt of each strip from the horizontal
    let s = if ridge { -1.0 } else { 1.0 };
    let (dx, dz) = (half.cos(), s * half.sin());
    let mut v = Vec::new();
    for j in 0..=n {
        let y = l * j as Real / n as Real;
        for i in 0..=2 * n {
            let u = w * (i as Real - n as Real) / n as Real; // -w .. w across both strips
            v.push(Vector::new(u * dx, y, u.abs() * dz));
        }
    }
    let row = 2 * n + 1;
    let id = |i: usize, j: usize| (j * row + i) as u32;
    let mut t = Vec::new();
    for j in 0..n {
        for i in 0..2 * n {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (v, t)
}

/// A UV sphere of `radius` centred at the origin, `rings` x `segments`, wound outward.
pub fn uv_sphere(radius: Real, rings: usize, segments: usize) -> Soup {
    let mut v = vec![Vector::new(0.0, 0.0, radius)];
    for r in 1..rings {
        let th = PI * r as Real / rings as Real;
        for s in 0..segments {
            let ph = 2.0 * PI * s as Real / segments as Real;
            v.push(radius * Vector::new(th.sin() * ph.cos(), th.sin() * ph.sin(), th.cos()));
        }
    }
    v.push(Vector::new(0.0, 0.0, -radius));
    let south = (v.len() - 1) as u32;
    let id = |r: usize, s: usize| (1 + (r - 1) * segments + s % segments) as u32;
    let mut t = Vec::new();
    for s in 0..segments {
        t.push([0, id(1, s), id(1, s + 1)]);
        t.push([south, id(rings - 1, s + 1), id(rings - 1, s)]);
    }
    for r in 1..rings - 1 {
        for s in 0..segments {
            t.push([id(r, s), id(r + 1, s), id(r + 1, s + 1)]);
            t.push([id(r, s), id(r + 1, s + 1), id(r, s + 1)]);
        }
    }
    (v, t)
}

/// An axis-aligned box `[-h, h]`, each face split into `n x n` quads, wound outward.
pub fn cuboid(h: Vector, n: usize) -> Soup {
    let mut v = Vec::new();
    let mut t = Vec::new();
    // Each face: origin corner, two in-plane axes (u x v = outward normal).
    let faces = [
        (Vector::new(h.x, -h.y, -h.z), Vector::new(0.0, 2.0 * h.y, 0.0), Vector::new(0.0, 0.0, 2.0 * h.z)),
        (Vector::new(-h.x, -h.y, -h.z), Vector::new(0.0, 0.0, 2.0 * h.z), Vector::new(0.0, 2.0 * h.y, 0.0)),
        (Vector::new(-h.x, h.y, -h.z), Vector::new(0.0, 0.0, 2.0 * h.z), Vector::new(2.0 * h.x, 0.0, 0.0)),
        (Vector::new(-h.x, -h.y, -h.z), Vector::new(2.0 * h.x, 0.0, 0.0), Vector::new(0.0, 0.0, 2.0 * h.z)),
        (Vector::new(-h.x, -h.y, h.z), Vector::new(2.0 * h.x, 0.0, 0.0), Vector::new(0.0, 2.0 * h.y, 0.0)),
        (Vector::new(-h.x, -h.y, -h.z), Vector::new(0.0, 2.0 * h.y, 0.0), Vector::new(2.0 * h.x, 0.0, 0.0)),
    ];
    for (o, du, dv) in faces {
        let base = v.len() as u32;
        for j in 0..=n {
            for i in 0..=n {
                v.push(o + du * (i as Real / n as Real) + dv * (j as Real / n as Real));
            }
        }
        let id = |i: usize, j: usize| base + (j * (n + 1) + i) as u32;
        for j in 0..n {
            for i in 0..n {
                t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
                t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
            }
        }
    }
    (v, t)
}

/// Applies a rigid transform `x -> rotation * x + translation` to a soup's vertices.
pub fn transformed(soup: Soup, pose: &crate::math::Pose) -> Soup {
    let (v, t) = soup;
    (v.into_iter().map(|p| pose * p).collect(), t)
}
