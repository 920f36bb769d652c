//! Running TetGen in a forked child process, so that a TetGen that crashes
//! or never finishes cannot take the caller with it.
//!
//! The parent takes TetGen's global lock, forks, and lets go of the lock;
//! the child (which owns its copy of the lock) runs the work, writes the
//! bytes it returns into a pipe and ends with `_exit`. The parent reads the
//! pipe with `poll` until end of file or the deadline, kills the child with
//! `SIGKILL` at the deadline, and always reaps it with `waitpid`. The child
//! runs only the work given to it (TetGen over plain arrays and the
//! encoding of its output): no other thread exists in it, so it must not
//! take locks other threads of the parent may have held at the fork — it
//! uses neither Rust's standard streams nor rayon, and allocates with the C
//! library's `malloc`, which glibc makes safe after `fork`.
//!
//! The pattern is the classic one of POSIX `fork`/`pipe`/`waitpid` (see
//! W. R. Stevens, *Advanced Programming in the UNIX Environment*, ch. 8 and
//! 15) and of Python's `multiprocessing` "fork" start method.

use std::io;
use std::time::{Duration, Instant};

/// Why the child gave back no bytes.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum ChildError {
    /// The deadline passed; the child was killed.
    TimedOut,
    /// The child died by this signal.
    Signal(i32),
    /// The child could not be started, or ended without a result.
    Failed(String),
}

/// Signals whose handlers the child sets back to the default action: a
/// handler inherited from the parent (Python's `SIGINT` handler and
/// `faulthandler`, Rust's stack-overflow handler, a CLI's clean-up handler)
/// must not run in the child, which is to die of them plainly.
const DEFAULT_SIGNALS: [libc::c_int; 10] = [
    libc::SIGINT,
    libc::SIGTERM,
    libc::SIGHUP,
    libc::SIGQUIT,
    libc::SIGSEGV,
    libc::SIGBUS,
    libc::SIGFPE,
    libc::SIGILL,
    libc::SIGABRT,
    libc::SIGTRAP,
];

/// Exit status of a child whose work panicked.
const EXIT_PANIC: i32 = 101;
/// Exit status of a child that could not write its result.
const EXIT_WRITE: i32 = 102;
/// Exit status of a child whose parent was gone before it started.
const EXIT_ORPHAN: i32 = 103;

fn os_error(what: &str) -> ChildError {
    ChildError::Failed(format!(
        "could not run TetGen in a child process: {what}: {}",
        io::Error::last_os_error()
    ))
}

/// Closes a descriptor, ignoring errors (it is ours and open).
fn close(fd: libc::c_int) {
    // SAFETY: `fd` is a descriptor this module opened and closes once.
    unsafe { libc::close(fd) };
}

/// Writes all of `bytes` to `fd`, retrying on `EINTR`; false on any error.
fn write_all(fd: libc::c_int, mut bytes: &[u8]) -> bool {
    while !bytes.is_empty() {
        // SAFETY: `bytes` is valid for `bytes.len()` reads.
        let n = unsafe { libc::write(fd, bytes.as_ptr().cast(), bytes.len()) };
        if n < 0 {
            if io::Error::last_os_error().kind() == io::ErrorKind::Interrupted {
                continue;
            }
            return false;
        }
        bytes = &bytes[n as usize..];
    }
    true
}

/// Waits for `pid` to end, retrying on `EINTR`; its wait status, or `None`
/// when it cannot be waited for (someone else reaped it).
fn reap(pid: libc::pid_t) -> Option<libc::c_int> {
    loop {
        let mut status = 0;
        // SAFETY: `status` is a valid out-pointer; `pid` is our child.
        let r = unsafe { libc::waitpid(pid, &mut status, 0) };
        if r == pid {
            return Some(status);
        }
        if r < 0 && io::Error::last_os_error().kind() == io::ErrorKind::Interrupted {
            continue;
        }
        return None;
    }
}

/// Kills and reaps the child `pid`.
fn kill_and_reap(pid: libc::pid_t) {
    // SAFETY: `pid` is our child and not reaped yet, so the id cannot
    // belong to another process.
    unsafe { libc::kill(pid, libc::SIGKILL) };
    reap(pid);
}

/// The child's side: never returns.
fn child_main<L>(
    write_fd: libc::c_int,
    read_fd: libc::c_int,
    parent: libc::pid_t,
    lock: L,
    work: impl FnOnce(&L) -> Vec<u8>,
) -> ! {
    close(read_fd);
    #[cfg(target_os = "linux")]
    {
        // Die with the parent: a caller killed meanwhile leaves no TetGen
        // running on (the signal follows the forking thread, which waits
        // for this child until it ends).
        // SAFETY: prctl with PR_SET_PDEATHSIG takes a signal number.
        unsafe { libc::prctl(libc::PR_SET_PDEATHSIG, libc::SIGKILL) };
        // SAFETY: getppid has no preconditions.
        if unsafe { libc::getppid() } != parent {
            // SAFETY: `_exit` ends the child at once.
            unsafe { libc::_exit(EXIT_ORPHAN) };
        }
    }
    #[cfg(not(target_os = "linux"))]
    let _ = parent;
    for sig in DEFAULT_SIGNALS {
        // SAFETY: SIG_DFL is a valid disposition for each of these signals.
        unsafe { libc::signal(sig, libc::SIG_DFL) };
    }
    // SAFETY: an empty set is initialised by sigemptyset before use; the
    // child unblocks every signal (the forking thread may have blocked some).
    unsafe {
        let mut set: libc::sigset_t = std::mem::zeroed();
        libc::sigemptyset(&mut set);
        libc::pthread_sigmask(libc::SIG_SETMASK, &set, std::ptr::null_mut());
    }
    // TetGen prints with printf: to standard error, never into the
    // caller's standard output.
    // SAFETY: descriptors 1 and 2 are the child's own copies.
    unsafe { libc::dup2(2, 1) };
    let result = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&lock)));
    let code = match result {
        Ok(bytes) if write_all(write_fd, &bytes) => 0,
        Ok(_) => EXIT_WRITE,
        Err(_) => EXIT_PANIC,
    };
    // SAFETY: flushes C's buffers (TetGen's messages), then ends the child
    // without running the parent's atexit handlers or destructors.
    unsafe {
        libc::fflush(std::ptr::null_mut());
        libc::_exit(code)
    }
}

/// Runs `work` in a child process forked while `lock` is held (the child
/// gets its own copy of it; the parent drops its own right after the fork)
/// and returns the bytes `work` returned. With `time_limit`, a child still
/// running at the deadline is killed ([`ChildError::TimedOut`]).
pub(crate) fn run<L>(
    time_limit: Option<Duration>,
    lock: L,
    work: impl FnOnce(&L) -> Vec<u8>,
) -> Result<Vec<u8>, ChildError> {
    // A limit too far away to represent is no limit.
    let deadline = time_limit.and_then(|d| Instant::now().checked_add(d));
    let mut fds = [0 as libc::c_int; 2];
    // SAFETY: `fds` has room for the two descriptors pipe2 writes. With
    // O_CLOEXEC no program another thread starts inherits the write end
    // (which would hold end of file back).
    if unsafe { libc::pipe2(fds.as_mut_ptr(), libc::O_CLOEXEC) } != 0 {
        return Err(os_error("pipe"));
    }
    let [read_fd, write_fd] = fds;
    // SAFETY: getpid has no preconditions.
    let parent = unsafe { libc::getpid() };
    // SAFETY: fork has no preconditions; the child runs only `child_main`,
    // which keeps to what is safe after fork in a threaded process (see the
    // module's documentation) and ends with `_exit`.
    let pid = unsafe { libc::fork() };
    if pid < 0 {
        let e = os_error("fork");
        close(read_fd);
        close(write_fd);
        return Err(e);
    }
    if pid == 0 {
        child_main(write_fd, read_fd, parent, lock, work);
    }
    drop(lock);
    close(write_fd);
    let mut bytes = Vec::new();
    let mut chunk = vec![0u8; 1 << 20];
    loop {
        let timeout_ms: libc::c_int = match deadline {
            None => -1,
            Some(d) => {
                let left = d.saturating_duration_since(Instant::now());
                if left.is_zero() {
                    close(read_fd);
                    kill_and_reap(pid);
                    return Err(ChildError::TimedOut);
                }
                // Rounded up, so that poll does not return just before it.
                left.as_micros().div_ceil(1000).min(i32::MAX as u128) as libc::c_int
            }
        };
        let mut pfd = libc::pollfd {
            fd: read_fd,
            events: libc::POLLIN,
            revents: 0,
        };
        // SAFETY: `pfd` is one valid pollfd.
        let r = unsafe { libc::poll(&mut pfd, 1, timeout_ms) };
        if r < 0 {
            if io::Error::last_os_error().kind() == io::ErrorKind::Interrupted {
                continue;
            }
            let e = os_error("poll");
            close(read_fd);
            kill_and_reap(pid);
            return Err(e);
        }
        if r == 0 {
            continue; // the deadline is checked at the top
        }
        // SAFETY: `chunk` is valid for `chunk.len()` writes.
        let n = unsafe { libc::read(read_fd, chunk.as_mut_ptr().cast(), chunk.len()) };
        if n < 0 {
            if io::Error::last_os_error().kind() == io::ErrorKind::Interrupted {
                continue;
            }
            let e = os_error("read");
            close(read_fd);
            kill_and_reap(pid);
            return Err(e);
        }
        if n == 0 {
            break; // end of file: the child has ended (or is ending)
        }
        bytes.extend_from_slice(&chunk[..n as usize]);
    }
    close(read_fd);
    let Some(status) = reap(pid) else {
        return Err(ChildError::Failed(
            "TetGen's child process was reaped by someone else: its exit status is unknown".into(),
        ));
    };
    if libc::WIFSIGNALED(status) {
        return Err(ChildError::Signal(libc::WTERMSIG(status)));
    }
    match libc::WEXITSTATUS(status) {
        0 => Ok(bytes),
        EXIT_PANIC => Err(ChildError::Failed(
            "TetGen's child process panicked (a bug; please report it)".into(),
        )),
        EXIT_WRITE => Err(ChildError::Failed(
            "TetGen's child process could not send its result back".into(),
        )),
        code => Err(ChildError::Failed(format!(
            "TetGen's child process exited with status {code} without a result"
        ))),
    }
}

/// The name of a signal number (`11` → `SIGSEGV`).
pub(crate) fn signal_name(signal: i32) -> &'static str {
    match signal {
        libc::SIGSEGV => "SIGSEGV",
        libc::SIGABRT => "SIGABRT",
        libc::SIGBUS => "SIGBUS",
        libc::SIGFPE => "SIGFPE",
        libc::SIGILL => "SIGILL",
        libc::SIGKILL => "SIGKILL",
        libc::SIGTERM => "SIGTERM",
        libc::SIGINT => "SIGINT",
        libc::SIGHUP => "SIGHUP",
        libc::SIGQUIT => "SIGQUIT",
        libc::SIGTRAP => "SIGTRAP",
        libc::SIGSYS => "SIGSYS",
        libc::SIGXCPU => "SIGXCPU",
        libc::SIGXFSZ => "SIGXFSZ",
        libc::SIGPIPE => "SIGPIPE",
        _ => "an unnamed signal",
    }
}

/// Byte encoding of values sent from the child: little-endian, each array
/// preceded by its length as a `u64`.
pub(crate) mod wire {
    /// Appends `n` as 8 bytes.
    pub(crate) fn put_len(out: &mut Vec<u8>, n: usize) {
        out.extend_from_slice(&(n as u64).to_le_bytes());
    }

    /// Appends an array of `f64`.
    pub(crate) fn put_f64s(out: &mut Vec<u8>, v: &[f64]) {
        put_len(out, v.len());
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// Appends an array of `i32`.
    pub(crate) fn put_i32s(out: &mut Vec<u8>, v: &[i32]) {
        put_len(out, v.len());
        for x in v {
            out.extend_from_slice(&x.to_le_bytes());
        }
    }

    /// Reads what the `put_` functions wrote, refusing truncated input.
    pub(crate) struct Reader<'a>(pub(crate) &'a [u8]);

    impl Reader<'_> {
        fn take(&mut self, n: usize) -> Option<&[u8]> {
            if self.0.len() < n {
                return None;
            }
            let (a, b) = self.0.split_at(n);
            self.0 = b;
            Some(a)
        }

        /// One byte.
        pub(crate) fn u8(&mut self) -> Option<u8> {
            self.take(1).map(|b| b[0])
        }

        /// A length, checked against the bytes left (`size` bytes per item).
        pub(crate) fn len(&mut self, size: usize) -> Option<usize> {
            let n = u64::from_le_bytes(self.take(8)?.try_into().ok()?);
            let n = usize::try_from(n).ok()?;
            (n.checked_mul(size)? <= self.0.len()).then_some(n)
        }

        /// An array of `f64`.
        pub(crate) fn f64s(&mut self) -> Option<Vec<f64>> {
            let n = self.len(8)?;
            let b = self.take(8 * n)?;
            Some(
                b.chunks_exact(8)
                    .map(|c| f64::from_le_bytes(c.try_into().expect("8 bytes")))
                    .collect(),
            )
        }

        /// An array of `i32`.
        pub(crate) fn i32s(&mut self) -> Option<Vec<i32>> {
            let n = self.len(4)?;
            let b = self.take(4 * n)?;
            Some(
                b.chunks_exact(4)
                    .map(|c| i32::from_le_bytes(c.try_into().expect("4 bytes")))
                    .collect(),
            )
        }

        /// A UTF-8 string (stored as its bytes).
        pub(crate) fn string(&mut self) -> Option<String> {
            let n = self.len(1)?;
            String::from_utf8(self.take(n)?.to_vec()).ok()
        }

        /// Whether everything has been read.
        pub(crate) fn is_empty(&self) -> bool {
            self.0.is_empty()
        }
    }
}
