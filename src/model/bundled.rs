//! The bundled example workcell, wherever the binary runs.
//!
//! The default robot, environment and parameters live in `config/`. A binary installed with
//! `cargo install` (or copied to another machine) has no source tree, so the files are also
//! compiled in and written out on first use to a cache folder of their own; a folder named by
//! `THICKNESS_COLLISION_CONFIG`, or a `share/thickness_collision/config` beside the binary's `bin/`
//! (an install prefix), comes first.

use std::path::{Path, PathBuf};

/// The files of `config/`, by path relative to it, as compiled in.
const FILES: [(&str, &[u8]); 7] = [
    ("params.yaml", include_bytes!("../../config/params.yaml")),
    ("example_workcell/robot.urdf", include_bytes!("../../config/example_workcell/robot.urdf")),
    ("example_workcell/environment.urdf", include_bytes!("../../config/example_workcell/environment.urdf")),
    ("example_workcell/gripper.obj", include_bytes!("../../config/example_workcell/gripper.obj")),
    ("example_workcell/guard_sheet.obj", include_bytes!("../../config/example_workcell/guard_sheet.obj")),
    ("example_workcell/shelf.obj", include_bytes!("../../config/example_workcell/shelf.obj")),
    ("example_workcell/bent_panel.obj", include_bytes!("../../config/example_workcell/bent_panel.obj")),
];

/// The bundled example workcell's folder (the robot, environment and parameters of `config/`):
/// `THICKNESS_COLLISION_CONFIG` if set; else `share/thickness_collision/config` under the
/// binary's install prefix; else the source tree it was built from, while it exists; else the
/// compiled-in copy, written to the user's cache folder. Without any of them (no cache folder can
/// be written) the source path is returned and reading it gives the error.
pub fn bundled_config_dir() -> PathBuf {
    if let Some(dir) = std::env::var_os("THICKNESS_COLLISION_CONFIG") {
        return PathBuf::from(dir);
    }
    let prefix = std::env::current_exe().ok().and_then(|exe| exe.parent().and_then(Path::parent).map(|p| p.join("share/thickness_collision/config")));
    let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
    resolve(prefix.as_deref(), &source, cache_root().as_deref())
}

/// The bundled example arm's URDF: the robot when no file names one.
pub(crate) fn bundled_robot() -> PathBuf {
    bundled_config_dir().join("example_workcell/robot.urdf")
}

/// The bundled example workcell's URDF: the environment when no file names one.
pub(crate) fn bundled_environment() -> PathBuf {
    bundled_config_dir().join("example_workcell/environment.urdf")
}

/// The first of `prefix` and `source` that holds the workcell, else the compiled-in copy under
/// `cache` (written if missing or different).
pub(crate) fn resolve(prefix: Option<&Path>, source: &Path, cache: Option<&Path>) -> PathBuf {
    let complete = |dir: &Path| FILES.iter().all(|(name, _)| dir.join(name).is_file());
    if let Some(p) = prefix.filter(|p| complete(p)) {
        return p.to_owned();
    }
    if complete(source) {
        return source.to_owned();
    }
    match cache.map(|c| c.join(format!("thickness_collision-{}", env!("CARGO_PKG_VERSION"))).join("config")) {
        Some(dir) if write_files(&dir).is_ok() => dir,
        _ => source.to_owned(),
    }
}

/// `$XDG_CACHE_HOME`, else `~/.cache`, else the temporary folder.
fn cache_root() -> Option<PathBuf> {
    let nonempty = |v: std::ffi::OsString| (!v.is_empty()).then(|| PathBuf::from(v));
    std::env::var_os("XDG_CACHE_HOME")
        .and_then(nonempty)
        .or_else(|| std::env::var_os("HOME").and_then(nonempty).map(|h| h.join(".cache")))
        .or_else(|| Some(std::env::temp_dir()))
}

/// Writes every file that is missing or differs; each through a temporary name and a rename, so a
/// concurrent reader sees the old file or the new one, never half of one.
fn write_files(dir: &Path) -> std::io::Result<()> {
    for (name, bytes) in FILES {
        let path = dir.join(name);
        if std::fs::read(&path).is_ok_and(|old| old == bytes) {
            continue;
        }
        if let Some(parent) = path.parent() {
            std::fs::create_dir_all(parent)?;
        }
        let tmp = path.with_extension(format!("tmp{}", std::process::id()));
        std::fs::write(&tmp, bytes)?;
        std::fs::rename(&tmp, &path)?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every file of `config/` and its workcell is compiled in, so nothing the defaults read is
    /// missing once the source tree is gone.
    #[test]
    fn every_config_file_is_compiled_in() {
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        let mut on_disk: Vec<String> = std::fs::read_dir(source.join("example_workcell"))
            .unwrap()
            .map(|e| format!("example_workcell/{}", e.unwrap().file_name().to_string_lossy()))
            .chain(["params.yaml".to_owned()])
            .collect();
        on_disk.sort();
        let mut compiled: Vec<String> = FILES.iter().map(|(n, _)| n.to_string()).collect();
        compiled.sort();
        assert_eq!(compiled, on_disk);
    }

    #[test]
    fn without_a_source_tree_the_compiled_copy_is_written_and_used() {
        let cache = std::env::temp_dir().join(format!("tc_bundled_{}", std::process::id()));
        let gone = cache.join("no_such_source");
        let dir = resolve(None, &gone, Some(&cache));
        assert!(dir.starts_with(&cache), "{}", dir.display());
        let source = Path::new(env!("CARGO_MANIFEST_DIR")).join("config");
        for (name, _) in FILES {
            assert_eq!(std::fs::read(dir.join(name)).unwrap(), std::fs::read(source.join(name)).unwrap(), "{name}");
        }
        // A damaged copy is repaired on the next use.
        std::fs::write(dir.join("example_workcell/robot.urdf"), "broken").unwrap();
        assert_eq!(resolve(None, &gone, Some(&cache)), dir);
        assert_eq!(std::fs::read(dir.join("example_workcell/robot.urdf")).unwrap(), std::fs::read(source.join("example_workcell/robot.urdf")).unwrap());
        // An install prefix that holds the workcell comes first.
        assert_eq!(resolve(Some(&dir), &source, Some(&cache)), dir);
        std::fs::remove_dir_all(&cache).unwrap();
    }
}
