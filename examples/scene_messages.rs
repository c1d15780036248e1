//! Writes `moveit_msgs/CollisionObject` messages as CDR files (the bytes a client publishes), for
//! the scene-latency instrument's Fast DDS publisher (`benches/run_scene_latency.sh`): `VARIANTS`
//! ADDs of a flat square sheet of about `TRIANGLES` triangles 0.6 m above the table, id `sheet`,
//! each shifted by another millimetre (new geometry: every ADD builds its cells), as
//! `add_K.cdr`, and its REMOVE as `remove.cdr`.
//!
//!     cargo run --release --example scene_messages -- DIR [TRIANGLES] [VARIANTS]   # 10000 4

use thickness_collision::fuzz_access::collision_object_cdr;
use thickness_collision::math::Vector;

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(dir) = args.first().map(std::path::PathBuf::from) else {
        eprintln!("usage: scene_messages DIR [TRIANGLES] [VARIANTS]");
        std::process::exit(2);
    };
    let number = |k: usize, default: usize| match args.get(k).map(|a| a.parse::<usize>()) {
        None => default,
        Some(Ok(n)) if n > 0 => n,
        Some(_) => {
            eprintln!("scene_messages: argument {k} '{}' is not a positive whole number", args[k]);
            std::process::exit(2);
        }
    };
    let (triangles, variants) = (number(1, 10_000), number(2, 4));
    let n = ((triangles / 2) as f64).sqrt().max(1.0) as u32;
    let h = 1.0 / f64::from(n);
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..n {
            let a = i * (n + 1) + j;
            t.push([a, a + n + 1, a + n + 2]);
            t.push([a, a + n + 2, a + 1]);
        }
    }
    let identity = [0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0];
    let write = |name: &str, bytes: Vec<u8>| {
        std::fs::write(dir.join(name), bytes).unwrap_or_else(|e| {
            eprintln!("scene_messages: cannot write {}: {e}", dir.join(name).display());
            std::process::exit(1);
        })
    };
    for k in 0..variants {
        let v: Vec<Vector> =
            (0..=n).flat_map(|i| (0..=n).map(move |j| Vector::new(f64::from(i) * h - 0.5, f64::from(j) * h - 0.5, 0.6 + 0.001 * k as f64))).collect();
        write(&format!("add_{k}.cdr"), collision_object_cdr("sheet", 0, identity, Some((&v, &t))));
    }
    write("remove.cdr", collision_object_cdr("sheet", 1, identity, None));
    println!("{} triangles, {variants} variants in {}", t.len(), dir.display());
}
