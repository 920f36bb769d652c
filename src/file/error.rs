//! [`IoError`]: the one error type of the readers and writers. It names the
//! file and, for text, the 1-based line, and keeps what caused it (the
//! operating system's error, the mesh store's build error, a decoder's
//! message) as its [`std::error::Error::source`].

use std::fmt;
use std::path::{Path, PathBuf};
use std::sync::Arc;

/// A file that could not be read or written, with the place and the problem.
#[derive(Debug, Clone)]
pub struct IoError {
    /// The file.
    pub path: PathBuf,
    /// 1-based line, when the problem has one.
    pub line: Option<usize>,
    /// What went wrong.
    pub kind: IoErrorKind,
}

/// What went wrong with a file: [`IoError::kind`].
#[derive(Debug, Clone)]
#[non_exhaustive]
pub enum IoErrorKind {
    /// The operating system refused to open, read, write or rename it.
    Os {
        /// What was being done ("cannot write", …), or `None` for a failed open.
        doing: Option<&'static str>,
        /// The operating system's error.
        source: Arc<std::io::Error>,
    },
    /// The content is wrong: what is wrong, in one sentence.
    Invalid(String),
    /// The content was read, but what it describes is not valid (a mesh
    /// the store refuses, say): the error of the layer that refused it.
    Content(Arc<dyn std::error::Error + Send + Sync>),
    /// An external decoder (JSON, …) refused the content.
    Decode {
        /// What the decoder was reading ("invalid weights file", …).
        what: &'static str,
        /// The decoder's error.
        source: Arc<dyn std::error::Error + Send + Sync>,
    },
}

impl IoError {
    /// An error at a line of a file.
    pub fn at(path: &Path, line: usize, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line: Some(line),
            kind: IoErrorKind::Invalid(message.into()),
        }
    }

    /// An error about a whole file.
    pub fn file(path: &Path, message: impl Into<String>) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line: None,
            kind: IoErrorKind::Invalid(message.into()),
        }
    }

    /// The operating system's error `e` while `doing` something with `path`
    /// (`None`: opening or reading it).
    pub fn os(path: &Path, doing: Option<&'static str>, e: std::io::Error) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line: None,
            kind: IoErrorKind::Os {
                doing,
                source: Arc::new(e),
            },
        }
    }

    /// A higher layer refused what was read from `path` (at `line`, if
    /// known): the mesh store's build error, say, kept as the source.
    pub fn content(
        path: &Path,
        line: Option<usize>,
        e: impl std::error::Error + Send + Sync + 'static,
    ) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line,
            kind: IoErrorKind::Content(Arc::new(e)),
        }
    }

    /// A decoder's error at an optional line.
    pub fn decode(
        path: &Path,
        line: Option<usize>,
        what: &'static str,
        e: impl std::error::Error + Send + Sync + 'static,
    ) -> IoError {
        IoError {
            path: path.to_path_buf(),
            line,
            kind: IoErrorKind::Decode {
                what,
                source: Arc::new(e),
            },
        }
    }

    /// The problem in one sentence, without the file and line.
    pub fn message(&self) -> String {
        match &self.kind {
            IoErrorKind::Os { doing, source } => match doing {
                Some(d) => format!("{d}: {}", open_message(source)),
                None => open_message(source),
            },
            // One line, even when the message quotes a garbled file.
            IoErrorKind::Invalid(m) => m
                .chars()
                .map(|c| if c.is_control() { ' ' } else { c })
                .collect(),
            IoErrorKind::Content(e) => e.to_string(),
            IoErrorKind::Decode { what, source } => format!("{what}: {source}"),
        }
    }
}

impl fmt::Display for IoError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.path.display(), l, self.message()),
            None => write!(f, "{}: {}", self.path.display(), self.message()),
        }
    }
}

impl PartialEq for IoError {
    /// Same file, line and message (sources compare by their message).
    fn eq(&self, other: &IoError) -> bool {
        self.path == other.path && self.line == other.line && self.message() == other.message()
    }
}

impl std::error::Error for IoError {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match &self.kind {
            IoErrorKind::Os { source, .. } => Some(&**source),
            IoErrorKind::Content(e) => Some(&**e),
            IoErrorKind::Decode { source, .. } => Some(&**source),
            IoErrorKind::Invalid(_) => None,
        }
    }
}

/// A readable sentence for a failed open.
pub fn open_message(e: &std::io::Error) -> String {
    match e.kind() {
        std::io::ErrorKind::NotFound => "no such file".to_string(),
        std::io::ErrorKind::PermissionDenied => "permission denied".to_string(),
        _ => e.to_string(),
    }
}
