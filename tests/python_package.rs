//! Issue 35: the Python package (python/), built by maturin into the test peers' virtual
//! environment as an installed wheel would be, then its pytest suite (python/tests/): `check`
//! against `check --json` on 300 Panda states, `check_motion` against `check --motion`, batches
//! against single checks, bad input, the GIL released, threads, the geometry core, OMPL plans.

mod common;

use std::path::PathBuf;
use std::process::Command;

#[test]
fn the_python_package_passes_its_pytest_suite() {
    let python = common::python();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    common::develop_python_package(&python);
    let out = Command::new(&python)
        .args(["-m", "pytest", "-q", "-p", "no:cacheprovider", "python/tests"])
        .current_dir(&root)
        .env("TC_BIN", env!("CARGO_BIN_EXE_thickness_collision"))
        .output()
        .expect("pytest");
    let stdout = String::from_utf8_lossy(&out.stdout);
    eprintln!("{stdout}");
    assert!(out.status.success(), "pytest failed:\n{stdout}\n{}", String::from_utf8_lossy(&out.stderr));
    // Every test ran: none skipped, none deselected.
    let summary = stdout.lines().rev().find(|l| l.contains("passed")).unwrap_or_default();
    assert!(!summary.contains("skipped") && !summary.contains("deselected"), "{summary}");
}
