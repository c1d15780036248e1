//! A pass over a COLLADA document before mesh-loader 0.1.13 reads it. mesh-loader trusts the
//! counts, strides, offsets, ids and indices in the file: a `<p>` index past the vertices, an
//! accessor with stride 0 or 4,000,000,000, an `<input>` naming a source that does not exist each
//! panic inside it, `<triangles count="4000000000">` reserves 48 GB before reading one index, and
//! a non-empty `<Name_array>` in a mesh source loops forever. The defects, one reproducer each,
//! are in `docs/upstream/mesh-loader.md` and `docs/upstream/mesh-loader/repro_*.dae`.
//!
//! The pass parses the text with roxmltree (the parser mesh-loader uses; it does not recurse) and
//! replays what mesh-loader does with it, in the same order and with the same "the last one wins"
//! rules for repeated ids and elements: the reservations made while parsing (each must fit in the
//! text that is to fill it), then, for every geometry mesh-loader builds, every lookup, every
//! accessor slice and every index it reads. Nothing is copied: `<p>` lists are scanned twice
//! instead. [`check_xml`](super::xml_guard::check_xml) has already bounded the depth.
//!
//! Besides the panics it refuses two inputs mesh-loader reads wrongly without a word (a polygon of
//! fewer than 3 vertices in a `<polylist>`/`<polygons>`, after which every polygon is misread;
//! `<tristrips>`, read as fans) and one that costs time quadratic in the file: every primitive
//! copies its whole position, normal, texcoord and colour accessors, so 30,000 `<triangles>` over
//! one 30,000-vertex source (2.6 MB) take 4 s; past [`MAX_MESH_TRIANGLES`] triangles the file is
//! refused here, before mesh-loader allocates them.

mod build_check;
mod nodes;
mod primitive;
mod walk;

use self::nodes::elements;
use self::walk::Walk;
use roxmltree::Document;
use std::borrow::Cow;

/// Accessor elements mesh-loader may copy (summed over primitives) whatever the file's size.
const MIN_COPY_BUDGET: u64 = 1 << 24;
/// Accessor elements mesh-loader may copy per byte of the file. Real files copy each accessor
/// once per primitive that uses it: the 286 meshes of example-robot-data copy at most 0.15 per
/// byte (`romeo`'s, 334,160 copies for 2.2 MB) and 526,082 in all (the largest). At about 4 ns a
/// copy, a 1 GiB file may then take some 9 s; 30,000 primitives over one 30,000-vertex source
/// (2.6 MB, 900 million copies) are refused.
const COPIES_PER_BYTE: u64 = 2;
/// Longest attribute value quoted in an error.
const MAX_QUOTED: usize = 40;

/// Checks `bytes` (a `.dae` file) for what makes mesh-loader 0.1.13 panic, loop or allocate
/// without bound. `Err` is one line: the line of the file, the element, the attribute and its
/// value, and what is allowed. Files mesh-loader refuses with an error of its own may pass.
pub(crate) fn check_collada(bytes: &[u8]) -> Result<(), String> {
    let text = decode(bytes)?;
    let doc = Document::parse(&text).map_err(|e| format!("not well-formed XML: {e}"))?;
    let root = doc.root_element();
    if root.tag_name().name() != "COLLADA" {
        // mesh-loader refuses it before reading anything else.
        return Ok(());
    }
    let mut walk = Walk::default();
    for library in elements(root).filter(|n| n.tag_name().name() == "library_geometries") {
        for geometry in elements(library).filter(|n| n.tag_name().name() == "geometry") {
            walk.geometry(geometry)?;
        }
    }
    walk.check_build(bytes.len())
}

/// The text as mesh-loader decodes it (`utils::utf16::decode_string`): UTF-8, with or without a
/// byte-order mark, or UTF-16 with one.
fn decode(bytes: &[u8]) -> Result<Cow<'_, str>, String> {
    let utf16 = |rest: &[u8], be: bool| -> Result<Cow<'_, str>, String> {
        if !rest.len().is_multiple_of(2) {
            return Err("invalid UTF-16: odd number of bytes".to_owned());
        }
        let units = rest.chunks_exact(2).map(|c| if be { u16::from_be_bytes([c[0], c[1]]) } else { u16::from_le_bytes([c[0], c[1]]) });
        char::decode_utf16(units).collect::<Result<String, _>>().map(Cow::Owned).map_err(|e| format!("invalid UTF-16: {e}"))
    };
    if let Some(rest) = bytes.strip_prefix(&[0xEF, 0xBB, 0xBF]) {
        std::str::from_utf8(rest).map(Cow::Borrowed).map_err(|e| format!("invalid UTF-8: {e}"))
    } else if bytes.starts_with(&[0xFF, 0xFE, 0, 0]) || bytes.starts_with(&[0, 0, 0xFE, 0xFF]) {
        Err("UTF-32 text is not supported".to_owned())
    } else if let Some(rest) = bytes.strip_prefix(&[0xFE, 0xFF]) {
        utf16(rest, true)
    } else if let Some(rest) = bytes.strip_prefix(&[0xFF, 0xFE]) {
        utf16(rest, false)
    } else {
        std::str::from_utf8(bytes).map(Cow::Borrowed).map_err(|e| format!("invalid UTF-8: {e}"))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::path::{Path, PathBuf};

    fn repro_dir() -> PathBuf {
        Path::new(env!("CARGO_MANIFEST_DIR")).join("docs/upstream/mesh-loader")
    }

    fn load(bytes: &[u8]) -> Result<usize, String> {
        let r = std::panic::catch_unwind(|| mesh_loader::Loader::default().load_from_slice(bytes, "x.dae"));
        match r {
            Ok(Ok(scene)) => Ok(scene.meshes.iter().map(|m| m.faces.len()).sum()),
            Ok(Err(e)) => Err(e.to_string()),
            Err(_) => Err("panic".to_owned()),
        }
    }

    /// Every reproducer is refused with one line naming a line of the file and an element.
    #[test]
    fn every_reproducer_is_refused() {
        let mut n = 0;
        for entry in std::fs::read_dir(repro_dir()).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().and_then(|e| e.to_str()) != Some("dae") {
                continue;
            }
            let bytes = std::fs::read(&path).unwrap();
            let err = check_collada(&bytes).expect_err(&path.display().to_string());
            eprintln!("{}: {err}", path.display());
            assert!(err.starts_with("line ") && err.contains('<') && !err.contains('\n'), "{}: {err}", path.display());
            n += 1;
        }
        assert!(n >= 20, "{n} reproducers");
    }

    fn mesh(body: &str) -> String {
        let p3 = r##"<param type="float"/><param type="float"/><param type="float"/>"##;
        format!(
            r##"<COLLADA version="1.4.1"><library_geometries><geometry id="g"><mesh>
<source id="s"><float_array id="a" count="12">0 0 0 1 0 0 0 1 0 0 0 1</float_array><technique_common><accessor source="#a" count="4" stride="3">{p3}</accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#s"/></vertices>
{body}
</mesh></geometry></library_geometries></COLLADA>"##
        )
    }

    #[test]
    fn good_primitives_pass_and_load() {
        let vin = r##"<input semantic="VERTEX" source="#v" offset="0"/>"##;
        for body in [
            format!(r##"<triangles count="2">{vin}<p>0 1 2 0 2 3</p></triangles>"##),
            format!(r##"<polylist count="2">{vin}<vcount>3 4</vcount><p>0 1 2 0 1 2 3</p></polylist>"##),
            format!(r##"<polygons count="2">{vin}<p>0 1 2</p><p>0 1 2 3</p></polygons>"##),
            format!(r##"<trifans count="1">{vin}<p>0 1 2 3</p></trifans>"##),
            format!(r##"<lines count="2">{vin}<p>0 1 2 3</p></lines>"##),
            format!(r##"<triangles count="0">{vin}</triangles>"##),
            // A NORMAL input with an offset of its own.
            format!(r##"<triangles count="1">{vin}<input semantic="NORMAL" source="#s" offset="1"/><p>0 3 1 3 2 3</p></triangles>"##),
        ] {
            let text = mesh(&body);
            assert_eq!(check_collada(text.as_bytes()), Ok(()), "{body}");
            assert!(load(text.as_bytes()).is_ok(), "{body}");
        }
    }

    /// Hostile variants beyond the reproducer files: each refused; without the guard each panics.
    #[test]
    fn variants_are_refused_and_would_panic() {
        let vin = r##"<input semantic="VERTEX" source="#v" offset="0"/>"##;
        for body in [
            // A normal index past the normals (the positions are fine).
            format!(r##"<triangles count="1">{vin}<input semantic="NORMAL" source="#s" offset="1"/><p>0 0 1 4 2 0</p></triangles>"##),
            // A texcoord index past the texcoords (4 triples of source s).
            format!(r##"<triangles count="1">{vin}<input semantic="TEXCOORD" source="#s" offset="1"/><p>0 0 1 1 2 4</p></triangles>"##),
            // Polygons: an <input> after the first <p> widens the stride.
            format!(r##"<polygons count="1">{vin}<p>0 1 2</p><input semantic="TEXCOORD" source="#s" offset="1"/></polygons>"##),
            // A colour source that is not there.
            format!(r##"<triangles count="1">{vin}<input semantic="COLOR" source="#nothing" offset="0"/><p>0 1 2</p></triangles>"##),
        ] {
            let text = mesh(&body);
            let err = check_collada(text.as_bytes()).expect_err(&body);
            assert!(err.starts_with("line "), "{err}");
            assert_eq!(load(text.as_bytes()), Err("panic".to_owned()), "{body}");
        }
    }

    /// Many primitives over one large source: quadratic in mesh-loader, refused here.
    #[test]
    fn shared_source_copies_are_bounded() {
        let vertices = 20_000;
        let floats = vec!["0"; 3 * vertices].join(" ");
        let p3 = r##"<param type="float"/><param type="float"/><param type="float"/>"##;
        let prims = r##"<triangles count="0"><input semantic="VERTEX" source="#v" offset="0"/></triangles>"##.repeat(2_000);
        let text = format!(
            r##"<COLLADA version="1.4.1"><library_geometries><geometry id="g"><mesh><source id="s"><float_array id="a" count="{}">{floats}</float_array><technique_common><accessor source="#a" count="{vertices}" stride="3">{p3}</accessor></technique_common></source><vertices id="v"><input semantic="POSITION" source="#s"/></vertices>{prims}</mesh></geometry></library_geometries></COLLADA>"##,
            3 * vertices
        );
        let err = check_collada(text.as_bytes()).unwrap_err();
        assert!(err.contains("copy more than"), "{err}");
    }

    #[test]
    fn utf16_and_non_collada() {
        let text = mesh(r##"<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 9</p></triangles>"##);
        let mut utf16 = vec![0xFF, 0xFE];
        utf16.extend(text.encode_utf16().flat_map(u16::to_le_bytes));
        assert!(check_collada(&utf16).unwrap_err().contains("index 9"));
        assert_eq!(check_collada(b"<robot/>"), Ok(()));
        assert!(check_collada(b"<COLLADA").unwrap_err().starts_with("not well-formed XML"));
    }

    /// Every .dae mesh on this machine (the robots of example-robot-data in the project's venv,
    /// and config/) passes the guard and loads in mesh-loader. Skipped where the venv is absent.
    #[test]
    fn real_meshes_pass() {
        let mut files = Vec::new();
        let mut dirs: Vec<PathBuf> = vec![Path::new(env!("CARGO_MANIFEST_DIR")).join("config")];
        if let Ok(home) = std::env::var("HOME") {
            let lib = Path::new(&home).join(".cache/thickness_collision/venv/lib");
            for py in std::fs::read_dir(&lib).into_iter().flatten().flatten() {
                dirs.push(py.path().join("site-packages/cmeel.prefix/share/example-robot-data/robots"));
            }
        }
        while let Some(dir) = dirs.pop() {
            for entry in std::fs::read_dir(&dir).into_iter().flatten().flatten() {
                let path = entry.path();
                if path.is_dir() {
                    dirs.push(path);
                } else if path.extension().and_then(|e| e.to_str()).is_some_and(|e| e.eq_ignore_ascii_case("dae")) {
                    files.push(path);
                }
            }
        }
        for path in &files {
            let bytes = std::fs::read(path).unwrap();
            assert_eq!(check_collada(&bytes), Ok(()), "{}", path.display());
            assert!(load(&bytes).is_ok(), "{}", path.display());
        }
        eprintln!("{} real .dae files pass", files.len());
    }
}
