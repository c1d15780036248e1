//! Writes the generated fuzz seed corpus (`fuzz_harness::seeds`: states,
//! messages, meshes and parameters built from the bundled workcell) to `DIR/<target>/`, for
//! `scripts/fuzz_campaign.sh`.
//!
//! `cargo run --example fuzz_seeds -- DIR` (default `fuzz/corpus`).

use fuzz_harness::seeds;
use std::path::PathBuf;

fn main() -> std::io::Result<()> {
    let root = std::env::args_os().nth(1).map(PathBuf::from).unwrap_or_else(|| PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("fuzz").join("corpus"));
    let mut written = 0;
    for (target, name, bytes) in seeds() {
        let dir = root.join(target);
        std::fs::create_dir_all(&dir)?;
        std::fs::write(dir.join(format!("seed_{name}")), bytes)?;
        written += 1;
    }
    println!("{written} seeds written under {}", root.display());
    Ok(())
}
