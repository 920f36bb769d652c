//! Files: the one error type of reading and writing ([`IoError`]: path,
//! line, what went wrong, and its source), whole-file reads with readable
//! errors, and atomic writes ([`write_atomic`], [`OutputSet`]). The lowest
//! layer of the crate: mesh formats, reports and the surface schemes all
//! write through [`write_atomic`], so a failed write never leaves a partial
//! file behind.

mod atomic;
mod error;

pub use atomic::{
    install_signal_cleanup, remove_stale_temporaries, temporary_path, write_atomic, OutputSet,
    TEMP_MARKER,
};
pub use error::{open_message, IoError, IoErrorKind};

use std::path::Path;

/// Reads the whole file, with a clear error that keeps the system's.
pub fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    std::fs::read(path).map_err(|e| IoError::os(path, None, e))
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
