//! Writes the benchmark's wavy wall (the mesh of `benches/build.rs` and `benches/query.rs`) to a
//! binary file, so that a peer (`benches/coal_build.py`) builds from the very same triangles.
//!
//! `cargo run --release --example dump_wall -- OUT.bin [NX NY]` (default 708 x 708 quads,
//! 1,002,528 triangles over 7 x 7 m, amplitude 5 cm, wavelength 50 cm).
//!
//! Format, little-endian: the 8 bytes `TCWALL01`, `u64` vertex count `V`, `u64` triangle count
//! `T`, `V * 3` `f64` coordinates (x, y, z per vertex), `T * 3` `u32` vertex indices. The
//! checksum printed (and recomputed by the reader) is, over the flattened arrays,
//! `sum_k bits(coord_k) * (2k + 1)` and `sum_k index_k * (2k + 1)`, both wrapping mod 2^64.

#[path = "../benches/wall_1m.rs"]
mod wall_1m;

use std::io::{BufWriter, Write};
use wall_1m::{checksum, wall};

fn main() -> std::io::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        eprintln!("usage: dump_wall OUT.bin [NX NY]");
        std::process::exit(2);
    };
    let nx: usize = args.get(1).map_or(708, |s| s.parse().expect("NX"));
    let ny: usize = args.get(2).map_or(nx, |s| s.parse().expect("NY"));
    let (v, t) = wall(nx, ny);
    let mut w = BufWriter::new(std::fs::File::create(out)?);
    w.write_all(b"TCWALL01")?;
    w.write_all(&(v.len() as u64).to_le_bytes())?;
    w.write_all(&(t.len() as u64).to_le_bytes())?;
    for p in &v {
        for x in [p.x, p.y, p.z] {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    for tri in &t {
        for i in tri {
            w.write_all(&i.to_le_bytes())?;
        }
    }
    w.flush()?;
    let (cv, ct) = checksum(&v, &t);
    println!("wall: {} vertices, {} triangles -> {out}", v.len(), t.len());
    println!("checksum: vertices={cv:016x} triangles={ct:016x}");
    Ok(())
}
