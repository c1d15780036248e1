//! Bounds on the files and numbers that come in from outside, in one place, so the docs
//! (`docs/reference.md`, "Input bounds") and the errors quote the same figures. (The sequences of
//! a decoded message are bounded where it is decoded, in `msgs`.)
//!
//! A bound is there so that one hostile or careless input (a 2 GB description, a mesh that is a
//! link to `/dev/zero`, an XML tree 20,000 deep, a cylinder of radius 1e300) gets a one-line
//! error instead of taking the node down: memory, stack and the numeric core all have limits.
//!
//! Public: the bounds a front door applies itself ([`LENGTH_RANGE`] with [`is_length`], the state
//! line's [`MAX_STATE_LINE_BYTES`], a request's [`MAX_TRAJECTORY_SUBINTERVALS`]), the way it opens
//! an input file ([`open_regular`], [`InputFileError`]) and writes a number into an error
//! ([`show_number`]). The rest serves the library's own readers.

use std::fs::File;
use std::io::Read;
use std::path::{Path, PathBuf};

/// URDF files, `robot_description` and SRDF text.
pub(crate) const MAX_DESCRIPTION_BYTES: u64 = 16 << 20;
/// The parameters YAML.
pub(crate) const MAX_PARAMS_BYTES: u64 = 1 << 20;
/// Mesh files (STL, OBJ, COLLADA).
pub(crate) const MAX_MESH_BYTES: u64 = 1 << 30;
/// Triangles of one mesh file.
pub(crate) const MAX_MESH_TRIANGLES: usize = 20_000_000;
/// A line of a `check --states` file.
pub const MAX_STATE_LINE_BYTES: u64 = 16 << 20;
/// Nesting of XML elements (URDF, SRDF, COLLADA). Real files stay under 20; the parsers recurse.
pub(crate) const MAX_XML_DEPTH: usize = 256;
/// Shortest and longest accepted size (metres): primitive dimensions, thickness. Past 1e4 m the
/// support functions' products leave the range where an f64 still tells a contact apart.
pub const LENGTH_RANGE: [f64; 2] = [1e-6, 1e4];
/// Largest accepted coordinate (metres) of a position: origins, mesh vertices after scaling,
/// prismatic travel, transforms.
pub(crate) const MAX_COORDINATE: f64 = 1e5;
/// Longest list of names quoted in one error line; the rest are counted.
pub(crate) const MAX_NAMES_IN_ERROR: usize = 8;
/// Motion-check sub-intervals one `check_trajectory` request may spend in all (about 100 s of a
/// worker's time on the bundled workcell).
pub const MAX_TRAJECTORY_SUBINTERVALS: u64 = 1 << 22;

/// A file that cannot be read within the bounds.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum InputFileError {
    /// `open` or `read` failed. (The I/O error is part of the message, not a `source`: printed
    /// as a chain it would repeat itself.)
    #[error("{what} {path}: {error}")]
    Io {
        /// What the file was for ("URDF file", "mesh file", ...).
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// Why.
        error: std::io::Error,
    },
    /// A FIFO, a device, a socket or a directory.
    #[error("{what} {path}: is a {kind}, not a regular file")]
    NotRegular {
        /// What the file was for.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// What it is.
        kind: &'static str,
    },
    /// Larger than allowed.
    #[error("{what} {path}: {size} bytes, more than the {limit} allowed")]
    TooLarge {
        /// What the file was for.
        what: &'static str,
        /// The file.
        path: PathBuf,
        /// Its size.
        size: u64,
        /// The bound.
        limit: u64,
    },
}

fn kind_of(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        let t = meta.file_type();
        if t.is_fifo() {
            return "named pipe";
        }
        if t.is_char_device() || t.is_block_device() {
            return "device";
        }
        if t.is_socket() {
            return "socket";
        }
    }
    if meta.is_dir() {
        "directory"
    } else {
        "special file"
    }
}

/// Opens a regular file for reading, without blocking on a FIFO, after checking its type and size.
pub fn open_regular(path: &Path, what: &'static str, limit: u64) -> Result<(File, u64), InputFileError> {
    let io = |error| InputFileError::Io { what, path: path.to_owned(), error };
    let mut options = std::fs::OpenOptions::new();
    let _ = options.read(true);
    // Opening a FIFO for reading waits for a writer: open without blocking, then check the type
    // of what was opened (not of the path, which may change in between).
    #[cfg(unix)]
    {
        use std::os::unix::fs::OpenOptionsExt;
        let _ = options.custom_flags(libc::O_NONBLOCK);
    }
    let file = options.open(path).map_err(io)?;
    let meta = file.metadata().map_err(io)?;
    if !meta.is_file() {
        return Err(InputFileError::NotRegular { what, path: path.to_owned(), kind: kind_of(&meta) });
    }
    if meta.len() > limit {
        return Err(InputFileError::TooLarge { what, path: path.to_owned(), size: meta.len(), limit });
    }
    Ok((file, meta.len()))
}

/// Reads a whole regular file of at most `limit` bytes (a file that grows while read is cut at
/// `limit + 1` bytes and refused).
pub(crate) fn read_regular(path: &Path, what: &'static str, limit: u64) -> Result<Vec<u8>, InputFileError> {
    let (file, size) = open_regular(path, what, limit)?;
    let mut bytes = Vec::with_capacity(size as usize);
    let _ = file.take(limit + 1).read_to_end(&mut bytes).map_err(|error| InputFileError::Io { what, path: path.to_owned(), error })?;
    if bytes.len() as u64 > limit {
        return Err(InputFileError::TooLarge { what, path: path.to_owned(), size: bytes.len() as u64, limit });
    }
    Ok(bytes)
}

/// [`read_regular`] as UTF-8 text (a leading byte-order mark is dropped).
pub(crate) fn read_regular_text(path: &Path, what: &'static str, limit: u64) -> Result<String, InputFileError> {
    let bytes = read_regular(path, what, limit)?;
    let text = String::from_utf8(bytes).map_err(|e| InputFileError::Io {
        what,
        path: path.to_owned(),
        error: std::io::Error::new(std::io::ErrorKind::InvalidData, format!("not UTF-8 ({e})")),
    })?;
    Ok(match text.strip_prefix('\u{feff}') {
        Some(rest) => rest.to_owned(),
        None => text,
    })
}

/// The first line of a parser's message, trimmed and cut to 300 characters: some parsers append
/// a dump of their state (urdf-rs), and an error is one line.
pub(crate) fn first_line(message: &str) -> String {
    let line = message.lines().next().unwrap_or("").trim();
    match line.char_indices().nth(300) {
        Some((cut, _)) => format!("{}...", &line[..cut]),
        None => line.to_owned(),
    }
}

/// `names` joined with ", ", cut after [`MAX_NAMES_IN_ERROR`] with a count of the rest.
pub(crate) fn name_list<S: AsRef<str>>(names: &[S]) -> String {
    let shown: Vec<&str> = names.iter().take(MAX_NAMES_IN_ERROR).map(AsRef::as_ref).collect();
    let mut s = shown.join(", ");
    if names.len() > MAX_NAMES_IN_ERROR {
        s.push_str(&format!(" and {} more", names.len() - MAX_NAMES_IN_ERROR));
    }
    s
}

/// A number as a person would write it in an error: `1e300`, `1e-9`, `0.25`, `NaN`.
pub fn show_number(v: f64) -> String {
    if v != 0.0 && v.is_finite() && !(1e-3..1e6).contains(&v.abs()) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

/// Whether `v` is a size the core accepts ([`LENGTH_RANGE`]).
pub fn is_length(v: f64) -> bool {
    (LENGTH_RANGE[0]..=LENGTH_RANGE[1]).contains(&v)
}

/// Whether `v` is a coordinate the core accepts (finite, |v| ≤ [`MAX_COORDINATE`]).
pub(crate) fn is_coordinate(v: f64) -> bool {
    v.abs() <= MAX_COORDINATE
}

thread_local! {
    static CONTAINING: std::cell::Cell<bool> = const { std::cell::Cell::new(false) };
    static CONTAINED_PANIC: std::cell::RefCell<Option<String>> = const { std::cell::RefCell::new(None) };
}

/// Runs `f`, turning a panic inside it into `Err` with the panic's message and place, printed
/// nowhere. For code that is not ours and panics on malformed input (mesh-loader); a panic
/// anywhere else still goes to the hook that was installed before.
pub(crate) fn contain_panic<T>(f: impl FnOnce() -> T) -> Result<T, String> {
    static HOOK: std::sync::Once = std::sync::Once::new();
    HOOK.call_once(|| {
        let previous = std::panic::take_hook();
        std::panic::set_hook(Box::new(move |info| {
            if CONTAINING.with(|c| c.get()) {
                let message = info.payload().downcast_ref::<&str>().map(|s| s.to_string()).or_else(|| info.payload().downcast_ref::<String>().cloned());
                let place = info.location().map(|l| format!(" at {}:{}", l.file(), l.line())).unwrap_or_default();
                let text = format!("panicked{place}: {}", message.as_deref().unwrap_or("(no message)"));
                CONTAINED_PANIC.with(|p| *p.borrow_mut() = Some(text));
            } else {
                previous(info);
            }
        }));
    });
    let outer = CONTAINING.with(|c| c.replace(true));
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(f));
    CONTAINING.with(|c| c.set(outer));
    result.map_err(|_| CONTAINED_PANIC.with(|p| p.borrow_mut().take()).unwrap_or_else(|| "panicked".into()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn special_files_are_refused_without_blocking() {
        let e = read_regular(Path::new("/dev/zero"), "mesh file", MAX_MESH_BYTES).unwrap_err().to_string();
        assert!(e.contains("/dev/zero") && e.contains("device"), "{e}");
        let e = read_regular(Path::new("/"), "mesh file", MAX_MESH_BYTES).unwrap_err().to_string();
        assert!(e.contains("directory"), "{e}");
        let dir = std::env::temp_dir().join(format!("tc_limits_{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let fifo = dir.join("pipe.stl");
        let _ = std::fs::remove_file(&fifo);
        let c = std::ffi::CString::new(fifo.to_str().unwrap()).unwrap();
        assert_eq!(unsafe { libc::mkfifo(c.as_ptr(), 0o600) }, 0);
        let e = read_regular(&fifo, "mesh file", MAX_MESH_BYTES).unwrap_err().to_string();
        assert!(e.contains("named pipe"), "{e}");
        let big = dir.join("big.stl");
        let f = File::create(&big).unwrap();
        f.set_len(2 << 30).unwrap();
        let e = read_regular(&big, "mesh file", MAX_MESH_BYTES).unwrap_err().to_string();
        assert!(e.contains("2147483648 bytes") && e.contains("1073741824"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn name_lists_are_cut() {
        let names: Vec<String> = (0..100_000).map(|i| format!("link_{i}")).collect();
        let s = name_list(&names);
        assert!(s.len() < 200 && s.ends_with("and 99992 more"), "{s}");
        assert_eq!(name_list(&["a", "b"]), "a, b");
    }

    #[test]
    fn contained_panics_become_errors() {
        assert_eq!(contain_panic(|| 3), Ok(3));
        let e = contain_panic(|| -> u32 { panic!("index {} out of bounds", 7) }).unwrap_err();
        assert!(e.contains("index 7 out of bounds") && e.contains("limits.rs"), "{e}");
        let v: Vec<u8> = Vec::new();
        let e = contain_panic(|| v[usize::from(v.is_empty())]).unwrap_err();
        assert!(e.contains("out of bounds"), "{e}");
    }
}
