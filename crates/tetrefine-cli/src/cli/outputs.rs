//! A command's outputs as one unit: every file is written to a temporary
//! file and renamed only when the command and its standard output both
//! succeeded ([`tetrefine::io::OutputSet`]); two outputs on one path are
//! refused before any work; a failed write to standard output (a full disk,
//! a closed descriptor, a reader that went away) makes the command fail.

use std::io::Write;
use std::path::Path;
use std::sync::Mutex;

/// The first failed write to standard output, if any.
static STDOUT_ERROR: Mutex<Option<String>> = Mutex::new(None);

/// Writes one line to standard output; a failure is remembered and fails
/// the command at its end ([`finish_stdout`]).
pub fn say_line(args: std::fmt::Arguments<'_>) {
    refuse_closed_stdout();
    let mut out = std::io::stdout().lock();
    if let Err(e) = out.write_fmt(args).and_then(|()| out.write_all(b"\n")) {
        record(e);
    }
}

/// Writes text to standard output as it is (see [`say_line`]).
pub fn say_text(text: &str) {
    refuse_closed_stdout();
    if let Err(e) = std::io::stdout().lock().write_all(text.as_bytes()) {
        record(e);
    }
}

/// Whether descriptor 1 was closed when the process started (`>&-`),
/// read by [`PROBE_STDOUT`] before Rust's runtime looks at it: `main`'s
/// prologue reopens a closed descriptor 0–2 on `/dev/null`, after which
/// every write "succeeds" and the output is lost without a word. Asking
/// afterwards cannot tell that from a caller's own `/dev/null` (Python's
/// `subprocess.DEVNULL` opens it read-write too), so the question is put
/// before `main`.
static STDOUT_CLOSED_AT_START: std::sync::atomic::AtomicBool =
    std::sync::atomic::AtomicBool::new(false);

/// Run by the dynamic loader with the other `.init_array` constructors,
/// before the C `main` that starts Rust's runtime.
#[cfg(target_os = "linux")]
#[used]
#[link_section = ".init_array"]
static PROBE_STDOUT: extern "C" fn() = {
    extern "C" fn probe() {
        // SAFETY: fcntl(F_GETFD) on a descriptor number only reads its
        // flags; it fails with EBADF when the descriptor is not open.
        if unsafe { libc::fcntl(1, libc::F_GETFD) } == -1 {
            STDOUT_CLOSED_AT_START.store(true, std::sync::atomic::Ordering::Relaxed);
        }
    }
    probe
};

/// Records an error if standard output was closed when the process started.
fn refuse_closed_stdout() {
    if STDOUT_CLOSED_AT_START.load(std::sync::atomic::Ordering::Relaxed) {
        record(std::io::Error::new(
            std::io::ErrorKind::BrokenPipe,
            "it was closed when the command started",
        ));
    }
}

fn record(e: std::io::Error) {
    let mut g = STDOUT_ERROR.lock().unwrap_or_else(|p| p.into_inner());
    if g.is_none() {
        *g = Some(e.to_string());
    }
}

/// Flushes standard output; `Err` if any write to it failed.
pub fn finish_stdout() -> super::CliResult {
    if let Err(e) = std::io::stdout().lock().flush() {
        record(e);
    }
    match STDOUT_ERROR
        .lock()
        .unwrap_or_else(|p| p.into_inner())
        .take()
    {
        Some(e) => Err(format!("cannot write to standard output: {e}")),
        None => Ok(()),
    }
}

/// Refuses two outputs on one file (`-o x --stats x`, or the same file by
/// two spellings), naming both options.
pub fn refuse_shared_paths(outputs: &[(&str, Option<&Path>)]) -> super::CliResult {
    let key = |p: &Path| {
        let dir = p
            .parent()
            .filter(|d| !d.as_os_str().is_empty())
            .unwrap_or(Path::new("."));
        (
            std::fs::canonicalize(dir).unwrap_or_else(|_| dir.to_path_buf()),
            p.file_name().map(|n| n.to_os_string()),
        )
    };
    let given: Vec<(&str, &Path)> = outputs
        .iter()
        .filter_map(|&(opt, p)| p.map(|p| (opt, p)))
        .collect();
    for (i, &(a, pa)) in given.iter().enumerate() {
        for &(b, pb) in &given[..i] {
            if pa == pb || key(pa) == key(pb) {
                return Err(format!(
                    "{b} and {a} both name {}: give each output its own file",
                    pa.display()
                ));
            }
        }
    }
    Ok(())
}
