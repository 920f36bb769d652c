//! Files: the one error type of reading and writing (path, line, message),
//! whole-file reads with readable errors, and atomic writes. The lowest
//! layer of the crate: mesh formats, reports and the surface schemes all
//! write through [`write_atomic`], so a failed write never leaves a partial
//! file behind.

use std::fmt;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// A file that could not be read or written, with the place and the problem.
#[derive(Debug, Clone, PartialEq)]
pub struct IoError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, when the problem has one.
    pub line: Option<usize>,
    /// What is wrong, in one sentence.
    pub message: String,
}

impl IoError {
    /// An error at a line of a file.
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line: Some(line),
            message: message.into(),
        }
    }

    /// An error about a whole file.
    pub fn file(path: &Path, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line: None,
            message: message.into(),
        }
    }
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.path.display(), l, self.message),
            None => write!(f, "{}: {}", self.path.display(), self.message),
        }
    }
}

impl std::error::Error for IoError {}

/// A readable sentence for a failed open.
pub fn open_message(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => e.to_string(),
    }
}

/// Reads the whole file, with a clear error.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    std::fs::read(path).map_err(|e| IoError::file(path, open_message(&e)))
}

/// The whole file as UTF-8 text, with a clear error.
pub fn read_text(path: &Path) -> Result<String, IoError> {
    let bytes = read_bytes(path)?;
    as_text(path, &bytes).map(str::to_owned)
}

/// The file as UTF-8 text, or a clear error for binary garbage.
pub fn as_text<'a>(path: &Path, bytes: &'a [u8]) -> Result<&'a str, IoError> {
    std::str::from_utf8(bytes).map_err(|e| {
        let line = bytes[..e.valid_up_to()]
            .iter()
            .filter(|&&c| c == b'\n')
            .count()
            + 1;
        IoError::at(
            path,
            line,
            "not a text file (invalid UTF-8): expected an ASCII mesh",
        )
    })
}

/// Writes through a temporary file beside `path` and renames it into place,
/// so that a failure (or a crash) never leaves a partial output file.
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), IoError> {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."));
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    let tmp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = (|| {
        let f = File::create(&tmp)?;
        let mut w = BufWriter::with_capacity(1 << 20, f);
        body(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()?;
        std::fs::rename(&tmp, path)
    })();
    result.map_err(|e| {
        let _ = std::fs::remove_file(&tmp);
        IoError::file(path, format!("cannot write: {}", open_message(&e)))
    })
}
