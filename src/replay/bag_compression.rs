//! rosbag2's compression undone while reading: `ros2 bag record --compression-mode message|file
//! --compression-format zstd` (rosbag2_compression's zstd plugin, the only one rosbag2 ships).
//!
//! - **Message mode** stores each message's serialized bytes as one zstd frame (`ZSTD_compress`,
//!   which declares the content size) in place of the payload; the storage itself is a plain MCAP
//!   or sqlite3 file. Each payload is decoded by a streaming decoder that stops one byte past the
//!   limit, so a frame that claims (or produces) more than [`super::MAX_RECORD_BYTES`] is an
//!   error, never an allocation of that size.
//! - **File mode** compresses each closed storage file whole, as `<file>.zstd`, and lists that
//!   name in `relative_file_paths`. Neither MCAP nor SQLite can be read from a compressed stream,
//!   so each file is decompressed into a folder of its own under the temporary folder (removed
//!   when the reader is dropped, or when opening fails), bounded by [`MAX_FILE_BYTES`] in all and
//!   by the free space there, whichever is less.

use std::fs::File;
use std::io::{BufReader, Read, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicUsize, Ordering};

/// At most this many decompressed bytes, over all files of a file-compressed bag (16 GiB): a bag
/// larger than that is better decompressed once by hand than on every replay.
pub(crate) const MAX_FILE_BYTES: u64 = 16 << 30;

/// The zstd frame magic number (little endian on disk).
const ZSTD_MAGIC: [u8; 4] = [0x28, 0xb5, 0x2f, 0xfd];

/// How a bag's files and messages are compressed (`compression_mode` in metadata.yaml).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub(super) enum Compression {
    /// Stored as recorded.
    None,
    /// Each message payload is a zstd frame.
    Message,
    /// Each storage file is one zstd stream.
    File,
}

/// A metadata.yaml string field: `Ok(None)` when absent or null.
fn string_field<'a>(info: &'a serde_yaml_ng::Value, key: &str) -> Result<Option<&'a str>, String> {
    match info.get(key) {
        None | Some(serde_yaml_ng::Value::Null) => Ok(None),
        Some(v) => v.as_str().map(Some).ok_or_else(|| format!("{key} must be a string (it is {v:?})")),
    }
}

/// The compression metadata.yaml declares. rosbag2 writes `compression_mode` as `""`, `NONE`,
/// `FILE` or `MESSAGE` and reads it case-blind; `compression_format` names the plugin, `zstd`.
pub(super) fn compression_from_metadata(info: &serde_yaml_ng::Value) -> Result<Compression, String> {
    let mode = string_field(info, "compression_mode")?.unwrap_or("");
    let mode = match mode.to_ascii_uppercase().as_str() {
        "" | "NONE" => return Ok(Compression::None),
        "MESSAGE" => Compression::Message,
        "FILE" => Compression::File,
        _ => return Err(format!("compression_mode '{mode}' is not supported (expected none, file or message)")),
    };
    match string_field(info, "compression_format")? {
        Some(f) if f.eq_ignore_ascii_case("zstd") => Ok(mode),
        Some(f) => Err(format!("compression_format '{f}' is not supported (this reader decompresses zstd only)")),
        None => Err("compression_mode is set but compression_format is missing (expected zstd)".into()),
    }
}

/// Whether a payload starts like a zstd frame (a CDR payload starts with its encapsulation
/// header, `00 00`/`00 01`: the two cannot be confused).
pub(super) fn looks_like_zstd(data: &[u8]) -> bool {
    data.starts_with(&ZSTD_MAGIC)
}

/// A decompression context for [`decompress_message`], reused across the messages of a bag: a
/// fresh decoder per 200-byte payload (a joint state) took 40 us here, a reused context 0.6 us,
/// against 13.4 us for all the rest of replay's work per state on the bundled workcell
/// (docs/benchmarks.md, "Replay rate").
pub(super) type MessageContext = zstd::zstd_safe::DCtx<'static>;

/// A new [`MessageContext`].
pub(super) fn message_context() -> Result<MessageContext, String> {
    zstd::zstd_safe::DCtx::try_create().ok_or_else(|| "cannot allocate a zstd decompression context".to_owned())
}

/// One message-compressed payload, decompressed; at most `limit` bytes.
pub(super) fn decompress_message(data: &[u8], limit: usize, context: &mut MessageContext) -> Result<Vec<u8>, String> {
    let declared = zstd::zstd_safe::get_frame_content_size(data).ok().flatten();
    if let Some(n) = declared.filter(|&n| n > limit as u64) {
        return Err(format!("decompresses to {n} bytes (its zstd frame says), more than this reader's limit of {limit} bytes per message"));
    }
    // (The context's session is reset first, whatever a failed message left in it.)
    let decoder = zstd::stream::read::Decoder::with_context(data, context);
    // The declared size is only a hint (a frame may lie): the decoder's output is bounded by take().
    let mut out = Vec::with_capacity(declared.map_or(0, |n| n as usize));
    let _ = decoder.take(limit as u64 + 1).read_to_end(&mut out).map_err(|e| format!("is not a valid zstd frame: {e}"))?;
    if out.len() > limit {
        return Err(format!("decompresses to more than this reader's limit of {limit} bytes per message"));
    }
    Ok(out)
}

/// A folder of decompressed bag files under the temporary folder, removed with its contents on drop.
#[derive(Debug)]
pub(super) struct Scratch {
    dir: PathBuf,
    /// Bytes decompressed into it so far (all files count against [`MAX_FILE_BYTES`]).
    written: u64,
}

impl Scratch {
    /// A new, empty folder in `base` (the temporary folder, in use).
    pub(super) fn create(base: &Path) -> std::io::Result<Self> {
        static NEXT: AtomicUsize = AtomicUsize::new(0);
        loop {
            let dir = base.join(format!("thickness_collision_bag_{}_{}", std::process::id(), NEXT.fetch_add(1, Ordering::Relaxed)));
            // Private (0700): the temporary folder is shared, a recording need not be.
            match std::os::unix::fs::DirBuilderExt::mode(&mut std::fs::DirBuilder::new(), 0o700).create(&dir) {
                Ok(()) => return Ok(Scratch { dir, written: 0 }),
                // Left by an earlier process with the same id that was killed: try the next name.
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// Decompresses `src` (one zstd stream) into this folder; returns the decompressed file. At
    /// most `limit` bytes in all files, and never more than the folder's disk has free.
    pub(super) fn decompress(&mut self, src: &Path, limit: u64) -> Result<PathBuf, String> {
        let io = |what: &str, e: std::io::Error| format!("cannot {what}: {e}");
        let file = crate::limits::open_regular(src, "compressed bag file", u64::MAX).map(|(f, _)| f).map_err(|e| match e {
            crate::limits::InputFileError::Io { error, .. } => io("open it", error),
            other => other.to_string(),
        })?;
        let mut input = BufReader::with_capacity(64 << 10, file);
        let mut head = [0u8; 18]; // the longest zstd frame header
        let got = read_up_to(&mut input, &mut head).map_err(|e| io("read it", e))?;
        if !looks_like_zstd(&head[..got]) {
            return Err("is not a zstd file (no zstd magic number at its start)".into());
        }
        let free = free_space(&self.dir);
        let room = limit.saturating_sub(self.written).min(free.unwrap_or(u64::MAX));
        let why = || {
            let free_text = free.map_or(String::new(), |f| format!(", {f} bytes free in {}", self.dir.parent().unwrap_or(&self.dir).display()));
            format!(
                "this reader decompresses at most {} bytes (16 GiB in all, or the free space of the temporary folder, whichever is less{free_text}); decompress it by hand (`zstd -d {}`) and replay the decompressed file",
                limit.min(free.unwrap_or(u64::MAX)),
                src.display()
            )
        };
        if let Some(n) = zstd::zstd_safe::get_frame_content_size(&head[..got]).ok().flatten().filter(|&n| n > room) {
            return Err(format!("decompresses to {n} bytes (its zstd frame says): {}", why()));
        }
        let name = src.file_name().and_then(|n| n.to_str()).unwrap_or("bag");
        let dst = self.dir.join(name.strip_suffix(".zstd").unwrap_or(name));
        let mut out = File::create(&dst).map_err(|e| io(&format!("create {}", dst.display()), e))?;
        let decoder = zstd::stream::read::Decoder::new(std::io::Cursor::new(head[..got].to_vec()).chain(input)).map_err(|e| io("start a zstd decoder", e))?;
        let mut bounded = decoder.take(room.saturating_add(1));
        let mut buf = vec![0u8; 256 << 10];
        let mut n = 0u64;
        loop {
            let k = match bounded.read(&mut buf) {
                Ok(0) => break,
                Ok(k) => k,
                Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
                Err(e) => return Err(format!("is not a valid zstd file: {e}")),
            };
            n += k as u64;
            if n > room {
                return Err(format!("decompresses to more than {room} bytes: {}", why()));
            }
            out.write_all(&buf[..k]).map_err(|e| io(&format!("write {}", dst.display()), e))?;
        }
        self.written += n;
        Ok(dst)
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.dir);
    }
}

/// Reads until `buf` is full or the end of the input; returns the bytes read.
fn read_up_to(r: &mut impl Read, buf: &mut [u8]) -> std::io::Result<usize> {
    let mut got = 0;
    while got < buf.len() {
        match r.read(&mut buf[got..]) {
            Ok(0) => break,
            Ok(k) => got += k,
            Err(e) if e.kind() == std::io::ErrorKind::Interrupted => continue,
            Err(e) => return Err(e),
        }
    }
    Ok(got)
}

/// Bytes an unprivileged process may still write on the file system of `dir` (`statvfs`).
fn free_space(dir: &Path) -> Option<u64> {
    use std::os::unix::ffi::OsStrExt;
    let c = std::ffi::CString::new(dir.as_os_str().as_bytes()).ok()?;
    // SAFETY: statvfs writes only into the zeroed struct we own; the path is NUL-terminated.
    let mut s: libc::statvfs = unsafe { std::mem::zeroed() };
    if unsafe { libc::statvfs(c.as_ptr(), &mut s) } != 0 {
        return None;
    }
    #[allow(clippy::unnecessary_cast, clippy::useless_conversion)] // the field types differ by platform
    Some((s.f_bavail as u64).saturating_mul(s.f_frsize as u64))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn yaml(text: &str) -> serde_yaml_ng::Value {
        serde_yaml_ng::from_str(text).unwrap()
    }

    #[test]
    fn metadata_modes_and_formats() {
        for (text, want) in [
            ("version: 8", Compression::None),
            ("compression_mode: ''\ncompression_format: ''", Compression::None),
            ("compression_mode: NONE", Compression::None),
            ("compression_mode: MESSAGE\ncompression_format: zstd", Compression::Message),
            ("compression_mode: message\ncompression_format: zstd", Compression::Message),
            ("compression_mode: FILE\ncompression_format: zstd", Compression::File),
        ] {
            assert_eq!(compression_from_metadata(&yaml(text)), Ok(want), "{text}");
        }
        for (text, says) in [
            ("compression_mode: MESSAGE\ncompression_format: lz4", "compression_format 'lz4' is not supported (this reader decompresses zstd only)"),
            ("compression_mode: FILE", "compression_format is missing"),
            ("compression_mode: chunk\ncompression_format: zstd", "compression_mode 'chunk' is not supported (expected none, file or message)"),
            ("compression_mode: 3", "compression_mode must be a string"),
        ] {
            let e = compression_from_metadata(&yaml(text)).unwrap_err();
            assert!(e.contains(says), "{text}: {e}");
        }
    }

    #[test]
    fn message_payloads_are_bounded() {
        let payload: Vec<u8> = (0..5000u32).map(|i| (i * 7 % 251) as u8).collect();
        let frame = zstd::bulk::compress(&payload, 1).unwrap();
        assert!(looks_like_zstd(&frame) && !looks_like_zstd(&[0, 1, 0, 0]));
        let c = &mut message_context().unwrap();
        assert_eq!(decompress_message(&frame, 5000, c).unwrap(), payload);
        // Declared in the frame header: refused before decoding.
        let e = decompress_message(&frame, 4999, c).unwrap_err();
        assert!(e.contains("5000 bytes") && e.contains("limit of 4999 bytes"), "{e}");
        // Not declared (a streaming encoder): refused one byte past the limit.
        let mut streamed = Vec::new();
        {
            let mut w = zstd::stream::write::Encoder::new(&mut streamed, 1).unwrap();
            w.write_all(&payload).unwrap();
            let _ = w.finish().unwrap();
        }
        assert!(matches!(zstd::zstd_safe::get_frame_content_size(&streamed), Ok(None)));
        assert_eq!(decompress_message(&streamed, 5000, c).unwrap(), payload);
        let e = decompress_message(&streamed, 4999, c).unwrap_err();
        assert!(e.contains("more than this reader's limit of 4999 bytes"), "{e}");
        // A frame that claims 2^40 bytes: an error, not an allocation.
        let huge = zstd::bulk::compress(&vec![0u8; 1 << 20], 1).unwrap();
        assert!(decompress_message(&huge, 1000, c).is_err());
        // Frame header: single segment, an 8-byte content size of 2^40.
        let mut lying = vec![0x28, 0xb5, 0x2f, 0xfd, 0xe0];
        lying.extend_from_slice(&(1u64 << 40).to_le_bytes());
        let e = decompress_message(&lying, 1000, c).unwrap_err();
        assert!(e.contains("1099511627776 bytes"), "{e}");
        assert!(decompress_message(b"\x00\x01\x00\x00 plain CDR", 1000, c).unwrap_err().contains("not a valid zstd frame"));
        // The context, left mid-frame by the refusals, decodes the next payload.
        assert_eq!(decompress_message(&streamed, 5000, c).unwrap(), payload);
    }

    #[test]
    fn files_decompress_into_a_scratch_folder_that_goes_away() {
        let base = std::env::temp_dir().join(format!("tc_bag_compression_{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&base);
        std::fs::create_dir_all(&base).unwrap();
        let content: Vec<u8> = (0..300_000u32).map(|i| (i % 253) as u8).collect();
        let src = base.join("bag_0.mcap.zstd");
        std::fs::write(&src, zstd::bulk::compress(&content, 1).unwrap()).unwrap();
        let streamed = base.join("bag_1.db3.zstd");
        {
            let mut w = zstd::stream::write::Encoder::new(File::create(&streamed).unwrap(), 1).unwrap();
            w.write_all(&content).unwrap();
            let _ = w.finish().unwrap();
        }
        let scratch_dir;
        {
            let mut s = Scratch::create(&base).unwrap();
            scratch_dir = s.dir.clone();
            use std::os::unix::fs::PermissionsExt;
            assert_eq!(std::fs::metadata(&scratch_dir).unwrap().permissions().mode() & 0o777, 0o700);
            let a = s.decompress(&src, 1 << 30).unwrap();
            assert_eq!(a.file_name().unwrap(), "bag_0.mcap");
            assert_eq!(std::fs::read(&a).unwrap(), content);
            let b = s.decompress(&streamed, 1 << 30).unwrap();
            assert_eq!(b.file_name().unwrap(), "bag_1.db3");
            assert_eq!(std::fs::read(&b).unwrap(), content);
            assert_eq!(s.written, 600_000);
        }
        assert!(!scratch_dir.exists(), "removed on drop");

        let mut s = Scratch::create(&base).unwrap();
        // Declared size over the limit: refused before anything is written, with the way out.
        let e = s.decompress(&src, 299_999).unwrap_err();
        assert!(e.contains("300000 bytes") && e.contains("zstd -d") && e.contains("bag_0.mcap.zstd") && e.contains("16 GiB"), "{e}");
        // Undeclared: refused one byte past the limit (the partial file goes with the folder).
        let e = s.decompress(&streamed, 299_999).unwrap_err();
        assert!(e.contains("more than 299999 bytes") && e.contains("zstd -d"), "{e}");
        // The limit counts every file of the bag.
        let _ = s.decompress(&src, 400_000).unwrap();
        assert!(s.decompress(&streamed, 400_000).unwrap_err().contains("more than 100000 bytes"));
        let plain = base.join("plain.mcap.zstd");
        std::fs::write(&plain, b"\x89MCAP0\r\n not compressed").unwrap();
        assert!(s.decompress(&plain, 1 << 30).unwrap_err().contains("not a zstd file"));
        let cut = base.join("cut.mcap.zstd");
        let full = zstd::bulk::compress(&content, 1).unwrap();
        std::fs::write(&cut, &full[..full.len() / 2]).unwrap();
        assert!(s.decompress(&cut, 1 << 30).unwrap_err().contains("not a valid zstd file"));
        drop(s);
        assert!(free_space(&base).is_some_and(|f| f > 0));
        let _ = std::fs::remove_dir_all(&base);
    }
}
