//! Reading and writing gradient meshes: the native JSON format, the authors' OFF, OBJ, and
//! mesh gradients from SVG.
//!
//! The native format is specified in `docs/format.md`. Every reader reports errors with the line
//! they occur on, and refuses input beyond its [`Limits`] (the `_with_limits` functions; the others use
//! [`Limits::DEFAULT`]) before allocating for it.

pub mod json;
pub mod obj;
pub mod off;
pub mod pdf;
pub mod svg;

use std::fs;
use std::io::{Read, Write};
use std::path::Path;
use std::sync::atomic::{AtomicU64, Ordering};

use crate::error::{Error, ErrorKind, Location};
use crate::mesh::{Document, GradientMesh};
use crate::size_limits::Limits;

/// The largest input accepted by default, in bytes (256 MiB): [`Limits::input_bytes`].
pub const MAX_INPUT_BYTES: u64 = Limits::DEFAULT.input_bytes;

/// The most control points one mesh may have by default: [`Limits::points`].
pub const MAX_POINTS: u64 = Limits::DEFAULT.points;

/// The most faces one mesh may have by default: [`Limits::faces`].
pub const MAX_FACES: u64 = Limits::DEFAULT.faces;

/// A file format, known by its extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Format {
    /// The native JSON format (`.json`), read and written.
    Json,
    /// The paper authors' extended OFF (`.off`), read only.
    Off,
    /// Wavefront OBJ polygon meshes (`.obj`), read; refined meshes are written.
    Obj,
    /// SVG mesh gradients (`.svg`), read: one layer per shape filled with a mesh gradient.
    Svg,
}

impl Format {
    /// Every format.
    pub const ALL: [Format; 4] = [Format::Json, Format::Off, Format::Obj, Format::Svg];

    /// The format of a path, from its extension (case-insensitive).
    pub fn from_path(path: &Path) -> Option<Format> {
        Format::from_extension(path.extension()?.to_str()?)
    }

    /// The format with extension `ext` (without the dot, case-insensitive).
    pub fn from_extension(ext: &str) -> Option<Format> {
        Format::ALL
            .into_iter()
            .find(|f| f.extension().eq_ignore_ascii_case(ext))
    }

    /// The usual extension, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Json => "json",
            Format::Off => "off",
            Format::Obj => "obj",
            Format::Svg => "svg",
        }
    }
}

/// Reads a document from text in the given format, within the default [`Limits`]. OFF and OBJ
/// files give one unnamed layer.
pub fn read_str(text: &str, format: Format) -> Result<Document, Error> {
    read_str_with_limits(text, format, &Limits::DEFAULT)
}

/// Reads a document from text in the given format, refusing input beyond `limits` (input bytes,
/// points, faces and corners per mesh, JSON nesting). OFF and OBJ files give one unnamed layer.
pub fn read_str_with_limits(
    text: &str,
    format: Format,
    limits: &Limits,
) -> Result<Document, Error> {
    match format {
        Format::Json => json::read_document_with_limits(text, limits),
        Format::Off => off::read_off_with_limits(text, limits).map(single_layer),
        Format::Obj => obj::read_obj_with_limits(text, limits).map(single_layer),
        Format::Svg => svg::read_document_with_limits(text, crate::ColourSpace::Lab, limits)
            .map(|read| read.document),
    }
}

/// Reads a document from a file within the default [`Limits`], choosing the format by the
/// extension. OFF and OBJ files give one layer named after the file stem. Every error is located
/// in the file.
pub fn read_path(path: &Path) -> Result<Document, Error> {
    read_path_with_limits(path, &Limits::DEFAULT)
}

/// Reads a document from a file as [`read_path`] does, refusing input beyond `limits`. A file
/// larger than [`Limits::input_bytes`] is refused before it is read.
pub fn read_path_with_limits(path: &Path, limits: &Limits) -> Result<Document, Error> {
    read_path_unlocated(path, limits).map_err(|e| e.in_file(path))
}

fn read_path_unlocated(path: &Path, limits: &Limits) -> Result<Document, Error> {
    if is_pdf_path(path) {
        return read_pdf_document(path, limits);
    }
    let format = Format::from_path(path).ok_or_else(|| {
        let found = match path.extension() {
            Some(ext) => format!("the extension \".{}\"", ext.to_string_lossy()),
            None => "no extension".to_string(),
        };
        Error::new(ErrorKind::UnsupportedFormat(format!(
            "cannot tell the format from {found}: expected .json, .off, .obj, .svg, .pdf or .ai"
        )))
    })?;
    let text = read_text(path, limits.input_bytes)?;
    let mut doc = read_str_with_limits(&text, format, limits)?;
    if matches!(format, Format::Off | Format::Obj) {
        if let Some(stem) = path.file_stem() {
            for layer in &mut doc.layers {
                layer.name = Some(stem.to_string_lossy().into_owned());
            }
        }
    }
    Ok(doc)
}

#[cfg(feature = "pdf-read")]
fn read_pdf_document(path: &Path, limits: &Limits) -> Result<Document, Error> {
    pdf::read_path_with_limits(path, 1, limits).map(|read| read.document)
}

/// Without the `pdf-read` feature a PDF file is refused, naming the feature.
#[cfg(not(feature = "pdf-read"))]
fn read_pdf_document(_path: &Path, _limits: &Limits) -> Result<Document, Error> {
    Err(Error::new(ErrorKind::UnsupportedFormat(
        "reading PDF and Illustrator files needs gradmesh built with its feature pdf-read".into(),
    )))
}

/// Whether `path` names a PDF file by its extension: `.pdf`, or `.ai` (Illustrator files
/// saved with PDF compatibility), case-insensitive. Such files are read by [`pdf`], page 1
/// by [`read_path`].
pub fn is_pdf_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| e.eq_ignore_ascii_case("pdf") || e.eq_ignore_ascii_case("ai"))
}

/// Reads a whole UTF-8 file, refusing one larger than `max_bytes`.
fn read_text(path: &Path, max_bytes: u64) -> Result<String, Error> {
    let bytes = read_bytes(path, max_bytes)?;
    String::from_utf8(bytes).map_err(|e| {
        let valid = &e.as_bytes()[..e.utf8_error().valid_up_to()];
        let line = 1 + valid.iter().filter(|&&b| b == b'\n').count();
        Error {
            location: Location::default().at_line(line),
            kind: ErrorKind::Syntax("the file is not UTF-8 text".into()),
        }
    })
}

/// Reads a whole file, refusing one larger than `max_bytes`.
pub(crate) fn read_bytes(path: &Path, max_bytes: u64) -> Result<Vec<u8>, Error> {
    let io = |e: std::io::Error| Error::new(ErrorKind::Io(format!("cannot read the file: {e}")));
    let file = fs::File::open(path).map_err(io)?;
    let metadata = file.metadata().map_err(io)?;
    if metadata.is_dir() {
        return Err(Error::new(ErrorKind::Io(
            "cannot read the file: it is a directory".into(),
        )));
    }
    let declared = metadata.len();
    check_size(declared, max_bytes)?;
    // Files that are not regular (pipes, devices) report no useful size: read them up to the
    // limit.
    let mut bytes = Vec::with_capacity((declared as usize).min(1 << 26));
    // One byte more than the limit, in case the file grew since its size was read.
    file.take(max_bytes.saturating_add(1))
        .read_to_end(&mut bytes)
        .map_err(io)?;
    check_size(bytes.len() as u64, max_bytes)?;
    Ok(bytes)
}

/// Refuses an input of `len` bytes above `max_bytes`.
pub(crate) fn check_size(len: u64, max_bytes: u64) -> Result<(), Error> {
    if len > max_bytes {
        return Err(ErrorKind::LimitExceeded {
            what: "the input size in bytes".into(),
            found: len,
            limit: max_bytes,
        }
        .into());
    }
    Ok(())
}

/// Refuses a count of `what` above `limit`.
pub(crate) fn check_count(what: &str, found: u64, limit: u64) -> Result<(), Error> {
    if found > limit {
        return Err(ErrorKind::LimitExceeded {
            what: what.into(),
            found,
            limit,
        }
        .into());
    }
    Ok(())
}

/// A syntax error at a line.
pub(crate) fn syntax_error(line: usize, message: impl Into<String>) -> Error {
    Error::syntax(&Location::default(), line, message)
}

/// A located error of another kind.
pub(crate) fn error_at(line: usize, kind: ErrorKind) -> Error {
    Error {
        location: Location::default().at_line(line),
        kind,
    }
}

fn single_layer(mesh: GradientMesh) -> Document {
    Document::new(vec![mesh])
}

/// Distinguishes the temporary files of one process.
static TEMP_COUNTER: AtomicU64 = AtomicU64::new(0);

/// Writes `bytes` to `path` atomically: into a new temporary file in the same directory, flushed
/// to disk, then renamed over `path`. If anything fails, the temporary file is removed and an
/// existing file at `path` is left as it was; a reader never sees a partly written file.
///
/// An existing file's permissions are kept. The error is located in `path`.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), Error> {
    write_atomic_streamed(path, |w| w.write_all(bytes))
}

/// As [`write_atomic`], for output produced piece by piece: `write` streams into the
/// temporary file (buffered), so a large output is never held in memory whole.
pub fn write_atomic_streamed(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<(), Error> {
    let fail = |what: &str, e: std::io::Error| {
        Error::new(ErrorKind::Io(format!("cannot {what}: {e}"))).in_file(path)
    };
    let name = path.file_name().ok_or_else(|| {
        Error::new(ErrorKind::Io("the output path names no file".into())).in_file(path)
    })?;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => Path::new("."),
    };
    // Clear errors for the usual mistakes, before anything is created.
    match fs::metadata(dir) {
        Ok(m) if m.is_dir() => {}
        Ok(_) => {
            return Err(Error::new(ErrorKind::Io(format!(
                "cannot write into {}: it is not a directory",
                dir.display()
            )))
            .in_file(path))
        }
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => {
            return Err(Error::new(ErrorKind::Io(format!(
                "the directory {} does not exist",
                dir.display()
            )))
            .in_file(path))
        }
        Err(e) => return Err(fail("read the directory", e)),
    }
    let existing = fs::metadata(path).ok();
    if existing.as_ref().is_some_and(|m| m.is_dir()) {
        return Err(
            Error::new(ErrorKind::Io("the output path is a directory".into())).in_file(path),
        );
    }
    let permissions = existing.map(|m| m.permissions());

    let (temp_path, mut file) = loop {
        let n = TEMP_COUNTER.fetch_add(1, Ordering::Relaxed);
        let temp_name = format!(".{}.tmp-{}-{n}", name.to_string_lossy(), std::process::id());
        let candidate = dir.join(temp_name);
        match fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&candidate)
        {
            Ok(f) => break (candidate, f),
            // Left over by a crashed run with the same process id: take the next name.
            Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists && n < 1 << 20 => continue,
            Err(e) => {
                return Err(fail(
                    &format!("create a temporary file in {}", dir.display()),
                    e,
                ))
            }
        }
    };
    let result = (|| {
        let mut buffered = std::io::BufWriter::with_capacity(1 << 16, &mut file);
        write(&mut buffered).map_err(|e| fail("write", e))?;
        buffered.flush().map_err(|e| fail("write", e))?;
        drop(buffered);
        if let Some(p) = permissions {
            file.set_permissions(p)
                .map_err(|e| fail("set permissions", e))?;
        }
        file.sync_all().map_err(|e| fail("flush to disk", e))?;
        drop(file);
        fs::rename(&temp_path, path).map_err(|e| fail("replace the file", e))
    })();
    if result.is_err() {
        let _ = fs::remove_file(&temp_path);
        return result;
    }
    // Make the rename itself durable where directories can be synced; best effort.
    if let Ok(d) = fs::File::open(dir) {
        let _ = d.sync_all();
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn formats_from_paths() {
        assert_eq!(Format::from_path(Path::new("a/b.json")), Some(Format::Json));
        assert_eq!(Format::from_path(Path::new("B.OFF")), Some(Format::Off));
        assert_eq!(Format::from_path(Path::new("x.Obj")), Some(Format::Obj));
        assert_eq!(Format::from_path(Path::new("x.SVG")), Some(Format::Svg));
        assert_eq!(Format::from_path(Path::new("x.png")), None);
        assert_eq!(Format::from_path(Path::new("json")), None);
    }

    #[test]
    fn unknown_extension_is_named() {
        let e = read_path(Path::new("/nonexistent/picture.png")).unwrap_err();
        let text = e.to_string();
        assert!(
            text.contains("\".png\"") && text.contains("picture.png"),
            "{text}"
        );
    }

    #[test]
    fn missing_file_is_located() {
        let e = read_path(Path::new("/nonexistent/picture.json")).unwrap_err();
        assert_eq!(
            e.location.file.as_deref(),
            Some(Path::new("/nonexistent/picture.json"))
        );
        assert!(matches!(e.kind, ErrorKind::Io(_)));
    }

    #[test]
    fn atomic_write_replaces_and_leaves_no_temporary() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.json");
        write_atomic(&path, b"first").unwrap();
        write_atomic(&path, b"second").unwrap();
        assert_eq!(fs::read(&path).unwrap(), b"second");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1);
    }

    #[test]
    fn failed_atomic_write_keeps_the_old_file() {
        let dir = tempfile::tempdir().unwrap();
        // A directory at the output path is refused before anything is written.
        let target = dir.path().join("taken");
        fs::create_dir(&target).unwrap();
        fs::write(target.join("inside"), b"keep").unwrap();
        let e = write_atomic(&target, b"new").unwrap_err();
        assert!(
            e.to_string().ends_with("the output path is a directory"),
            "{e}"
        );
        assert_eq!(fs::read(target.join("inside")).unwrap(), b"keep");
        let names: Vec<_> = fs::read_dir(dir.path()).unwrap().collect();
        assert_eq!(names.len(), 1, "the temporary file was not removed");
        // A directory that does not exist: nothing is created.
        let e = write_atomic(&dir.path().join("no/such/dir.json"), b"x").unwrap_err();
        assert!(e.to_string().contains("no/such does not exist"), "{e}");
        assert!(!dir.path().join("no").exists());
        // A file where the directory should be.
        fs::write(dir.path().join("file"), b"").unwrap();
        let e = write_atomic(&dir.path().join("file/out.json"), b"x").unwrap_err();
        assert!(e.to_string().contains("it is not a directory"), "{e}");
    }

    #[test]
    #[cfg(unix)]
    fn read_only_directory_is_a_clear_error_and_leaves_nothing() {
        use std::os::unix::fs::PermissionsExt;
        let dir = tempfile::tempdir().unwrap();
        let ro = dir.path().join("ro");
        fs::create_dir(&ro).unwrap();
        fs::write(ro.join("out.json"), b"old").unwrap();
        fs::set_permissions(&ro, fs::Permissions::from_mode(0o555)).unwrap();
        let result = write_atomic(&ro.join("out.json"), b"new");
        let names: Vec<_> = fs::read_dir(&ro)
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        let old = fs::read(ro.join("out.json")).unwrap();
        fs::set_permissions(&ro, fs::Permissions::from_mode(0o755)).unwrap();
        // Root may write anyway; otherwise the error names the directory and the old file stays.
        if let Err(e) = result {
            assert!(
                e.to_string().contains("cannot create a temporary file in"),
                "{e}"
            );
            assert_eq!(old, b"old");
            assert_eq!(names.len(), 1, "{names:?}");
        }
    }
}
