//! `package://` resolution, written here rather than urdf-rs's (which shells out to `rospack`,
//! panics without it, and misses package names with a hyphen such as `example-robot-data`).
//!
//! Order: the `package_map` parameter, then `ROS_PACKAGE_PATH` (`<dir>/<pkg>`, or `<dir>` itself
//! when it is named `<pkg>`), then `AMENT_PREFIX_PATH` (`<prefix>/share/<pkg>`).

use std::path::{Path, PathBuf};

/// Where packages are looked up.
#[derive(Clone, Debug, Default)]
pub struct PackageResolver {
    map: Vec<(String, PathBuf)>,
    ros_package_path: Vec<PathBuf>,
    ament_prefix_path: Vec<PathBuf>,
}

/// A URI that does not resolve.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum PackageError {
    /// The package is nowhere on the search path.
    #[error("cannot resolve {uri}: package '{package}' not found; searched: {}", display_list(.searched))]
    UnknownPackage {
        /// The URI.
        uri: String,
        /// The package name.
        package: String,
        /// Every directory tried.
        searched: Vec<PathBuf>,
    },
    /// A `package://` path that leaves its package (`..`, or an absolute path after the name).
    #[error("cannot resolve {0}: the path leaves its package (no '..' and no absolute path after package://<name>/)")]
    Escapes(String),
    /// The URI has a scheme other than `package://` and `file://`.
    #[error("cannot resolve {0}: unsupported URI scheme (expected package://, file:// or a path)")]
    Scheme(String),
}

fn display_list(paths: &[PathBuf]) -> String {
    if paths.is_empty() {
        return "nothing (package_map, ROS_PACKAGE_PATH and AMENT_PREFIX_PATH are all empty)".into();
    }
    paths.iter().map(|p| p.display().to_string()).collect::<Vec<_>>().join(", ")
}

fn split_env(var: &str) -> Vec<PathBuf> {
    std::env::var_os(var).map(|v| std::env::split_paths(&v).filter(|p| !p.as_os_str().is_empty()).collect()).unwrap_or_default()
}

impl PackageResolver {
    /// From `package_map` entries (`pkg=/path`) and the environment variables.
    pub fn new(package_map: &[String]) -> PackageResolver {
        let map = package_map.iter().filter_map(|e| e.split_once('=')).map(|(k, v)| (k.trim().to_owned(), PathBuf::from(v.trim()))).collect();
        PackageResolver { map, ros_package_path: split_env("ROS_PACKAGE_PATH"), ament_prefix_path: split_env("AMENT_PREFIX_PATH") }
    }

    /// Resolves a URI or path from a file in `base_dir`: `package://pkg/rel`, `package:///pkg/rel`,
    /// `file:///abs`, an absolute path, or a path relative to `base_dir`.
    pub fn resolve(&self, uri: &str, base_dir: &Path) -> Result<PathBuf, PackageError> {
        if let Some(rest) = uri.strip_prefix("package://") {
            let rest = rest.trim_start_matches('/');
            let (package, rel) = rest.split_once('/').unwrap_or((rest, ""));
            if Path::new(rel).components().any(|c| !matches!(c, std::path::Component::Normal(_) | std::path::Component::CurDir)) {
                return Err(PackageError::Escapes(uri.to_owned()));
            }
            return self.package_dir(uri, package).map(|d| d.join(rel));
        }
        if let Some(path) = uri.strip_prefix("file://") {
            return Ok(PathBuf::from(path));
        }
        if uri.contains("://") {
            return Err(PackageError::Scheme(uri.to_owned()));
        }
        let p = Path::new(uri);
        Ok(if p.is_absolute() { p.to_owned() } else { base_dir.join(p) })
    }

    fn package_dir(&self, uri: &str, package: &str) -> Result<PathBuf, PackageError> {
        let mut searched = Vec::new();
        if let Some((_, dir)) = self.map.iter().find(|(k, _)| k == package) {
            return Ok(dir.clone());
        }
        for dir in &self.ros_package_path {
            if dir.file_name().is_some_and(|n| n == package) && dir.is_dir() {
                return Ok(dir.clone());
            }
            let candidate = dir.join(package);
            if candidate.is_dir() {
                return Ok(candidate);
            }
            searched.push(candidate);
        }
        for prefix in &self.ament_prefix_path {
            let candidate = prefix.join("share").join(package);
            if candidate.is_dir() {
                return Ok(candidate);
            }
            searched.push(candidate);
        }
        Err(PackageError::UnknownPackage { uri: uri.to_owned(), package: package.to_owned(), searched })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn map_relative_and_errors() {
        let r = PackageResolver { map: vec![("my-pkg".into(), "/opt/my".into())], ..Default::default() };
        let base = Path::new("/robots/x");
        assert_eq!(r.resolve("package://my-pkg/meshes/a.stl", base).unwrap(), PathBuf::from("/opt/my/meshes/a.stl"));
        assert_eq!(r.resolve("package:///my-pkg/a.stl", base).unwrap(), PathBuf::from("/opt/my/a.stl"));
        assert_eq!(r.resolve("meshes/a.stl", base).unwrap(), PathBuf::from("/robots/x/meshes/a.stl"));
        assert_eq!(r.resolve("file:///abs/a.stl", base).unwrap(), PathBuf::from("/abs/a.stl"));
        let r2 =
            PackageResolver { ros_package_path: vec!["/nonexistent/ws".into()], ament_prefix_path: vec!["/nonexistent/prefix".into()], ..Default::default() };
        let e = r2.resolve("package://nope/a.stl", base).unwrap_err().to_string();
        assert!(
            e.contains("package://nope/a.stl") && e.contains("'nope'") && e.contains("/nonexistent/ws/nope") && e.contains("/nonexistent/prefix/share/nope"),
            "{e}"
        );
        assert!(r.resolve("http://x/a.stl", base).is_err());
        for escape in ["package://my-pkg/../../etc/passwd", "package://my-pkg//etc/passwd", "package://my-pkg/meshes/../../x.stl"] {
            assert_eq!(r.resolve(escape, base), Err(PackageError::Escapes(escape.into())));
        }
        assert_eq!(r.resolve("package://my-pkg/./meshes/a.stl", base).unwrap(), PathBuf::from("/opt/my/./meshes/a.stl"));
    }
}
