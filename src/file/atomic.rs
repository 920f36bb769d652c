//! Output files that appear whole or not at all.
//!
//! Every writer of the crate goes through [`write_atomic`]: the bytes go to a
//! temporary file beside the target, named `.NAME.tetrefine-PID.tmp`, which
//! is renamed onto `NAME` once it is complete and synced.
//!
//! Several files can be made one unit with an [`OutputSet`]: while a set is
//! open, [`write_atomic`] leaves each finished temporary file in place and
//! records it; [`OutputSet::commit`] renames them all (only when every write
//! succeeded), and dropping an uncommitted set removes them. Writing the same
//! target twice in one set is refused. A TetGen `.node/.ele/.face/.edge`
//! output is written as one set (`io::tetgen::write`).
//!
//! Temporary files are registered while they exist; [`install_signal_cleanup`]
//! makes SIGINT, SIGTERM and SIGHUP remove them before the process dies. A
//! process killed by SIGKILL cannot clean up: the next write to the same
//! directory removes the `.NAME.tetrefine-PID.tmp` files of processes that
//! no longer run (see [`remove_stale_temporaries`]).

use super::IoError;
use std::cell::RefCell;
use std::ffi::CString;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, AtomicPtr, Ordering};

/// The marker in every temporary file name: `.NAME.tetrefine-PID.tmp`.
pub const TEMP_MARKER: &str = ".tetrefine-";

/// Slots for the temporary files the signal handler removes; more files
/// than this at once are still removed by the normal paths.
const SLOTS: usize = 256;

#[allow(clippy::declare_interior_mutable_const)] // only used to fill the array
const EMPTY: AtomicPtr<libc::c_char> = AtomicPtr::new(std::ptr::null_mut());
static REGISTRY: [AtomicPtr<libc::c_char>; SLOTS] = [EMPTY; SLOTS];

/// Registers `path` for removal by the signal handler; returns its slot.
fn register(path: &Path) -> Option<usize> {
    use std::os::unix::ffi::OsStrExt;
    let c = CString::new(path.as_os_str().as_bytes()).ok()?;
    let ptr = c.into_raw();
    for (i, slot) in REGISTRY.iter().enumerate() {
        if slot
            .compare_exchange(
                std::ptr::null_mut(),
                ptr,
                Ordering::SeqCst,
                Ordering::SeqCst,
            )
            .is_ok()
        {
            return Some(i);
        }
    }
    // SAFETY: `ptr` came from `CString::into_raw` above and was not stored.
    drop(unsafe { CString::from_raw(ptr) });
    None
}

/// Forgets slot `i` (the file was renamed or removed).
fn unregister(i: Option<usize>) {
    if let Some(i) = i {
        let p = REGISTRY[i].swap(std::ptr::null_mut(), Ordering::SeqCst);
        if !p.is_null() {
            // SAFETY: every non-null slot holds a pointer from `CString::into_raw`,
            // and the swap took it out, so it is freed once.
            drop(unsafe { CString::from_raw(p) });
        }
    }
}

extern "C" fn on_signal(sig: libc::c_int) {
    for slot in REGISTRY.iter() {
        let p = slot.swap(std::ptr::null_mut(), Ordering::SeqCst);
        if !p.is_null() {
            // SAFETY: `p` is a NUL-terminated path from `CString::into_raw`;
            // unlink is async-signal-safe. The memory is leaked: the process ends.
            unsafe {
                libc::unlink(p);
            }
        }
    }
    // SAFETY: restoring the default action and re-raising are
    // async-signal-safe; the process then dies of the signal as it would have.
    unsafe {
        libc::signal(sig, libc::SIG_DFL);
        libc::raise(sig);
    }
}

static INSTALLED: AtomicBool = AtomicBool::new(false);

/// Makes SIGINT, SIGTERM and SIGHUP remove the temporary files of this
/// process before it dies of the signal (the exit status stays the signal's).
pub fn install_signal_cleanup() {
    if INSTALLED.swap(true, Ordering::SeqCst) {
        return;
    }
    for sig in [libc::SIGINT, libc::SIGTERM, libc::SIGHUP] {
        // SAFETY: `on_signal` only performs async-signal-safe calls.
        unsafe {
            libc::signal(
                sig,
                on_signal as extern "C" fn(libc::c_int) as libc::sighandler_t,
            );
        }
    }
}

/// The temporary name for `path` in this process.
pub fn temporary_path(path: &Path) -> PathBuf {
    let (dir, name) = dir_and_name(path);
    dir.join(format!(".{name}{TEMP_MARKER}{}.tmp", std::process::id()))
}

fn dir_and_name(path: &Path) -> (PathBuf, String) {
    let dir = path
        .parent()
        .filter(|p| !p.as_os_str().is_empty())
        .unwrap_or(Path::new("."))
        .to_path_buf();
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "out".into());
    (dir, name)
}

/// Whether process `pid` is alive (`/proc/PID` exists, or `kill(pid, 0)`
/// does not say "no such process").
fn alive(pid: u32) -> bool {
    if Path::new("/proc/self").exists() {
        return Path::new(&format!("/proc/{pid}")).exists();
    }
    // SAFETY: signal 0 only checks that the process exists.
    let r = unsafe { libc::kill(pid as libc::pid_t, 0) };
    r == 0 || std::io::Error::last_os_error().raw_os_error() != Some(libc::ESRCH)
}

/// Removes the temporary files `.NAME.tetrefine-PID.tmp` of `path` left by
/// processes that no longer run (a SIGKILL, a power cut); returns how many.
/// Only this naming scheme is touched.
pub fn remove_stale_temporaries(path: &Path) -> usize {
    let (dir, name) = dir_and_name(path);
    let prefix = format!(".{name}{TEMP_MARKER}");
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return 0;
    };
    let mut removed = 0;
    for e in entries.flatten() {
        let f = e.file_name();
        let Some(f) = f.to_str() else { continue };
        let Some(pid) = f
            .strip_prefix(&prefix)
            .and_then(|r| r.strip_suffix(".tmp"))
            .and_then(|p| p.parse::<u32>().ok())
        else {
            continue;
        };
        if pid != std::process::id() && !alive(pid) && std::fs::remove_file(e.path()).is_ok() {
            removed += 1;
        }
    }
    removed
}

/// One staged file of an open [`OutputSet`].
struct Staged {
    tmp: PathBuf,
    target: PathBuf,
    slot: Option<usize>,
}

thread_local! {
    /// The open set of this thread, if any (per thread, so that tests
    /// running side by side do not share one).
    static OPEN_SET: RefCell<Option<Vec<Staged>>> = const { RefCell::new(None) };
    /// Removals handed over by joined sets, for the owner's commit.
    static PENDING_REMOVALS: RefCell<Vec<PathBuf>> = const { RefCell::new(Vec::new()) };
}

fn with_set<R>(f: impl FnOnce(&mut Option<Vec<Staged>>) -> R) -> R {
    OPEN_SET.with(|s| f(&mut s.borrow_mut()))
}

/// All outputs written while it is open appear together at
/// [`OutputSet::commit`], or not at all (see the module documentation).
#[derive(Debug)]
pub struct OutputSet {
    /// Whether this value opened the set (a nested one only joins it).
    owner: bool,
    /// Files to remove at commit (stale members of a multi-file output).
    remove_at_commit: Vec<PathBuf>,
}

impl OutputSet {
    /// Opens a set; if one is open already, joins it (its owner commits).
    pub fn begin() -> OutputSet {
        let owner = with_set(|g| {
            let owner = g.is_none();
            if owner {
                *g = Some(Vec::new());
            }
            owner
        });
        OutputSet {
            owner,
            remove_at_commit: Vec::new(),
        }
    }

    /// Removes `path` at commit if nothing in the set writes it (the `.edge`
    /// of an old TetGen output when the new one has none, say).
    pub fn remove_at_commit(&mut self, path: PathBuf) {
        self.remove_at_commit.push(path);
    }

    /// Renames every staged file onto its target. A joined (nested) set
    /// hands its removals to the owner's commit.
    pub fn commit(mut self) -> Result<(), IoError> {
        let removals = std::mem::take(&mut self.remove_at_commit);
        if !self.owner {
            // The owner commits; stale files are removed now only if the
            // owner stages nothing at their path.
            PENDING_REMOVALS.with(|p| p.borrow_mut().extend(removals));
            std::mem::forget(self);
            return Ok(());
        }
        let staged = with_set(|g| g.take()).unwrap_or_default();
        let mut removals = removals;
        removals.extend(PENDING_REMOVALS.with(|p| std::mem::take(&mut *p.borrow_mut())));
        std::mem::forget(self);
        let mut result = Ok(());
        let mut done = 0;
        for s in &staged {
            if let Err(e) = std::fs::rename(&s.tmp, &s.target) {
                result = Err(IoError::os(&s.target, Some("cannot write"), e));
                break;
            }
            unregister(s.slot);
            done += 1;
        }
        for s in &staged[done..] {
            let _ = std::fs::remove_file(&s.tmp);
            unregister(s.slot);
        }
        if result.is_ok() {
            for r in removals {
                if !staged.iter().any(|s| s.target == r) {
                    let _ = std::fs::remove_file(r);
                }
            }
        }
        result
    }

    /// The targets staged so far (for messages).
    pub fn targets() -> Vec<PathBuf> {
        with_set(|g| {
            g.as_ref()
                .map(|v| v.iter().map(|s| s.target.clone()).collect())
                .unwrap_or_default()
        })
    }
}

impl Drop for OutputSet {
    /// An uncommitted set removes every staged temporary file.
    fn drop(&mut self) {
        if !self.owner {
            return;
        }
        PENDING_REMOVALS.with(|p| p.borrow_mut().clear());
        if let Some(staged) = with_set(|g| g.take()) {
            for s in staged {
                let _ = std::fs::remove_file(&s.tmp);
                unregister(s.slot);
            }
        }
    }
}

/// The same file, whether named by a relative or an absolute path: the
/// canonical directory joined with the file name.
fn same_target(a: &Path, b: &Path) -> bool {
    let key = |p: &Path| {
        let (dir, name) = dir_and_name(p);
        (std::fs::canonicalize(&dir).unwrap_or(dir), name)
    };
    a == b || key(a) == key(b)
}

/// Writes through a temporary file beside `path` and renames it into place,
/// so that a failure (or a crash) never leaves a partial output file. Inside
/// an open [`OutputSet`] the rename waits for [`OutputSet::commit`].
pub fn write_atomic(
    path: &Path,
    body: impl FnOnce(&mut BufWriter<File>) -> std::io::Result<()>,
) -> Result<(), IoError> {
    if with_set(|g| {
        g.as_ref()
            .is_some_and(|v| v.iter().any(|s| same_target(&s.target, path)))
    }) {
        return Err(IoError::file(
            path,
            "is the target of two outputs of this command; give each output its own path",
        ));
    }
    remove_stale_temporaries(path);
    let tmp = temporary_path(path);
    let slot = register(&tmp);
    let result = (|| {
        let f = File::create(&tmp)?;
        let mut w = BufWriter::with_capacity(1 << 20, f);
        body(&mut w)?;
        w.flush()?;
        w.into_inner().map_err(|e| e.into_error())?.sync_all()
    })();
    if let Err(e) = result {
        let _ = std::fs::remove_file(&tmp);
        unregister(slot);
        return Err(IoError::os(path, Some("cannot write"), e));
    }
    let tmp = match with_set(|g| match g.as_mut() {
        Some(staged) => {
            staged.push(Staged {
                tmp,
                target: path.to_path_buf(),
                slot,
            });
            None
        }
        None => Some(tmp),
    }) {
        None => return Ok(()),
        Some(tmp) => tmp,
    };
    let r = std::fs::rename(&tmp, path);
    if r.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    unregister(slot);
    r.map_err(|e| IoError::os(path, Some("cannot write"), e))
}
