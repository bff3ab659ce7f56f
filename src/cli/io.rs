//! The only file access hypersynth has: reading an input (a path, or `-` for stdin) and
//! writing an output atomically, so that a failure never leaves a partial file behind.
//!
//! An atomic write goes through a temporary file in the target's directory, renamed over the
//! target once complete. So that the result looks like an ordinary write:
//! - a new file gets the permissions `open(2)` would give it (0666 minus the umask), and an
//!   existing file keeps its mode (the temporary file copies it before the rename);
//! - a symbolic link is followed: its final target is replaced, the link stays a link;
//! - errors never mention the temporary file, only their cause (the caller names the target);
//! - a target that is neither a regular file nor a directory (`/dev/null`, `/dev/stdout`, a
//!   named pipe) is written to directly, as a shell redirection would: renaming over it would
//!   replace the device with a regular file, and atomicity means nothing for a stream.
//!
//! Interruption: hypersynth installs no signal handler while it computes, so SIGINT, SIGTERM
//! and SIGHUP end it at once whatever the stage (nothing is written before the end). While a
//! temporary file exists ([`SignalGuard`], Unix), a handler removes it before letting the
//! signal end the process as it would have: an interrupted run leaves no file behind.

use std::io::{self, Read, Write};
use std::path::{Path, PathBuf};

/// Reads a whole text input; `-` means standard input.
pub fn read_input(path: &str) -> io::Result<String> {
    let mut text = String::new();
    if path == "-" {
        io::stdin().read_to_string(&mut text)?;
    } else {
        std::fs::File::open(path)?.read_to_string(&mut text)?;
    }
    Ok(text)
}

/// How many symbolic links are followed before giving up (Linux's own limit).
const MAX_SYMLINKS: usize = 40;

/// Writes `contents` to `path` through a temporary file in the same directory as the file that
/// will be replaced (the final target when `path` is a symbolic link), renamed over it only
/// once everything is written and flushed.
pub fn write_atomically(path: &Path, contents: &[u8]) -> io::Result<()> {
    let mut file = AtomicFile::create(path)?;
    file.write_all(contents)?;
    file.commit()
}

/// A file written as [`write_atomically`] writes one, for a writer that streams into it: the
/// temporary file exists (and a signal removes it) until [`AtomicFile::commit`] renames it over
/// the target; dropped uncommitted, it is removed. A signal removes up to [`GUARDED`] of them
/// (more at a time are only removed when dropped). Files nest: the first one made installs the
/// signal handler and restores the previous one when it goes, so it must outlive those made
/// after it (drop or commit them in reverse order).
pub struct AtomicFile {
    inner: Inner,
}

enum Inner {
    /// Not a regular file (a pipe, a terminal, `/dev/null`): written in place.
    Direct(std::fs::File),
    /// A regular file (or none yet): a temporary file, the target and its permissions.
    Temporary {
        file: io::BufWriter<tempfile::NamedTempFile>,
        target: PathBuf,
        existing_mode: Option<std::fs::Permissions>,
        guard: SignalGuard,
    },
}

impl AtomicFile {
    /// Starts the file that will replace `path`.
    pub fn create(path: &Path) -> io::Result<AtomicFile> {
        // `metadata` lets the kernel resolve the path, which also handles `/proc/self/fd`
        // links.
        if let Ok(metadata) = std::fs::metadata(path)
            && !metadata.is_file()
            && !metadata.is_dir()
        {
            let file = std::fs::OpenOptions::new().write(true).open(path)?;
            return Ok(AtomicFile {
                inner: Inner::Direct(file),
            });
        }
        let target = follow_symlinks(path)?;
        let directory = match target.parent() {
            Some(parent) if !parent.as_os_str().is_empty() => parent,
            _ => Path::new("."),
        };
        let existing_mode = match std::fs::metadata(&target) {
            Ok(metadata) => Some(metadata.permissions()),
            Err(e) if e.kind() == io::ErrorKind::NotFound => None,
            Err(e) => return Err(e),
        };
        let file = temporary_file(directory).map_err(without_temporary_path)?;
        let guard = SignalGuard::new(file.path());
        Ok(AtomicFile {
            inner: Inner::Temporary {
                file: io::BufWriter::new(file),
                target,
                existing_mode,
                guard,
            },
        })
    }

    /// Flushes the file and renames it over the target.
    pub fn commit(self) -> io::Result<()> {
        let Inner::Temporary {
            file,
            target,
            existing_mode,
            guard,
        } = self.inner
        else {
            return Ok(());
        };
        let file = file
            .into_inner()
            .map_err(|e| without_temporary_path(e.into_error()))?;
        let written = (|| {
            if let Some(permissions) = existing_mode {
                file.as_file().set_permissions(permissions)?;
            }
            file.as_file().sync_all()
        })();
        written.map_err(without_temporary_path)?;
        file.persist(&target)
            .map_err(|e| without_temporary_path(e.error))?;
        // A signal from here on finds the file renamed: removing the temporary name fails
        // harmlessly.
        drop(guard);
        Ok(())
    }
}

impl Write for AtomicFile {
    fn write(&mut self, bytes: &[u8]) -> io::Result<usize> {
        match &mut self.inner {
            Inner::Direct(file) => file.write(bytes),
            Inner::Temporary { file, .. } => file.write(bytes).map_err(without_temporary_path),
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match &mut self.inner {
            Inner::Direct(file) => file.flush(),
            Inner::Temporary { file, .. } => file.flush().map_err(without_temporary_path),
        }
    }
}

/// While it lives, SIGINT, SIGTERM and SIGHUP (those not ignored) remove the temporary file
/// at `path` and then end the process as their default action does (the handler restores it
/// and raises the signal again). The path is a C string the handler reads through an atomic
/// pointer: removing a file and raising a signal are async-signal-safe, allocating is not.
#[cfg(unix)]
struct SignalGuard {
    path: *mut libc::c_char,
    previous: Vec<(libc::c_int, libc::sigaction)>,
}

/// How many temporary files a signal removes.
pub const GUARDED: usize = 4;

/// The temporary files to remove on a signal, or nulls.
#[cfg(unix)]
static TEMPORARY: [std::sync::atomic::AtomicPtr<libc::c_char>; GUARDED] =
    [const { std::sync::atomic::AtomicPtr::new(std::ptr::null_mut()) }; GUARDED];

#[cfg(unix)]
const SIGNALS: [libc::c_int; 3] = [libc::SIGINT, libc::SIGTERM, libc::SIGHUP];

#[cfg(unix)]
extern "C" fn remove_temporary_and_die(signal: libc::c_int) {
    use std::sync::atomic::Ordering;
    for slot in &TEMPORARY {
        let path = slot.swap(std::ptr::null_mut(), Ordering::SeqCst);
        // SAFETY: `path` is null or the C string a live guard leaked for this; `unlink` is
        // async-signal-safe.
        if !path.is_null() {
            unsafe { libc::unlink(path) };
        }
    }
    // SAFETY: `signal` and `raise` are async-signal-safe.
    unsafe {
        libc::signal(signal, libc::SIG_DFL);
        libc::raise(signal);
    }
}

#[cfg(unix)]
impl SignalGuard {
    fn new(path: &Path) -> SignalGuard {
        use std::os::unix::ffi::OsStrExt as _;
        use std::sync::atomic::Ordering;
        let path = std::ffi::CString::new(path.as_os_str().as_bytes())
            .map_or(std::ptr::null_mut(), std::ffi::CString::into_raw);
        // The first free slot; with none, the file is only removed when dropped.
        let slot = TEMPORARY.iter().position(|slot| {
            slot.compare_exchange(
                std::ptr::null_mut(),
                path,
                Ordering::SeqCst,
                Ordering::SeqCst,
            )
            .is_ok()
        });
        if slot.is_none() && !path.is_null() {
            // SAFETY: made by `CString::into_raw` just above and not shared.
            drop(unsafe { std::ffi::CString::from_raw(path) });
            return SignalGuard {
                path: std::ptr::null_mut(),
                previous: Vec::new(),
            };
        }
        let mut previous = Vec::new();
        for signal in SIGNALS {
            // SAFETY: plain sigaction calls with zeroed (then filled) structures.
            unsafe {
                let mut old: libc::sigaction = std::mem::zeroed();
                if libc::sigaction(signal, std::ptr::null(), &mut old) != 0
                    || old.sa_sigaction != libc::SIG_DFL
                {
                    continue; // ignored, or someone else's handler: leave it alone
                }
                let mut action: libc::sigaction = std::mem::zeroed();
                action.sa_sigaction = remove_temporary_and_die as *const () as usize;
                libc::sigemptyset(&mut action.sa_mask);
                if libc::sigaction(signal, &action, std::ptr::null_mut()) == 0 {
                    previous.push((signal, old));
                }
            }
        }
        SignalGuard { path, previous }
    }
}

#[cfg(unix)]
impl Drop for SignalGuard {
    fn drop(&mut self) {
        use std::sync::atomic::Ordering;
        for (signal, old) in &self.previous {
            // SAFETY: restores the action saved by `new`.
            unsafe {
                libc::sigaction(*signal, old, std::ptr::null_mut());
            }
        }
        // If a handler took the path, it is using it and ends the process: leave it be.
        let freed = !self.path.is_null()
            && TEMPORARY.iter().any(|slot| {
                slot.compare_exchange(
                    self.path,
                    std::ptr::null_mut(),
                    Ordering::SeqCst,
                    Ordering::SeqCst,
                )
                .is_ok()
            });
        if freed {
            // SAFETY: made by `CString::into_raw` in `new`, and no handler holds it now.
            drop(unsafe { std::ffi::CString::from_raw(self.path) });
        }
    }
}

#[cfg(not(unix))]
struct SignalGuard;

#[cfg(not(unix))]
impl SignalGuard {
    fn new(_path: &Path) -> SignalGuard {
        SignalGuard
    }
}

/// A temporary file created with the mode a new file would get (0666 minus the umask).
#[cfg(unix)]
fn temporary_file(directory: &Path) -> io::Result<tempfile::NamedTempFile> {
    use std::os::unix::fs::PermissionsExt as _;
    tempfile::Builder::new()
        .permissions(std::fs::Permissions::from_mode(0o666))
        .tempfile_in(directory)
}

#[cfg(not(unix))]
fn temporary_file(directory: &Path) -> io::Result<tempfile::NamedTempFile> {
    tempfile::NamedTempFile::new_in(directory)
}

/// The file a write to `path` must replace: `path` itself, or the final target of the chain
/// of symbolic links starting at it (which need not exist yet).
fn follow_symlinks(path: &Path) -> io::Result<PathBuf> {
    let mut current = path.to_path_buf();
    for _ in 0..MAX_SYMLINKS {
        match std::fs::symlink_metadata(&current) {
            Ok(metadata) if metadata.file_type().is_symlink() => {
                let link = std::fs::read_link(&current)?;
                current = match current.parent() {
                    Some(parent) if link.is_relative() => parent.join(link),
                    _ => link,
                };
            }
            Ok(_) => return Ok(current),
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(current),
            Err(e) => return Err(e),
        }
    }
    Err(io::Error::other("too many levels of symbolic links"))
}

/// `tempfile` adds the temporary file's path to its errors (`CAUSE at path "/dir/.tmpXYZ"`),
/// without keeping the cause reachable; the user never named that file, so keep the cause only.
fn without_temporary_path(error: io::Error) -> io::Error {
    if error.get_ref().is_none() {
        return error;
    }
    let message = error.to_string();
    match message.rfind(" at path ") {
        Some(end) => io::Error::new(error.kind(), &message[..end]),
        None => error,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atomic_write_replaces_the_whole_file() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        std::fs::write(&path, "old contents that are longer").unwrap();
        write_atomically(&path, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "new");
        // Only the target remains: the temporary file was renamed, not copied.
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[test]
    fn atomic_write_into_a_missing_directory_fails_without_output() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("missing").join("out.txt");
        let error = write_atomically(&path, b"x").unwrap_err();
        assert_eq!(error.kind(), io::ErrorKind::NotFound);
        assert_eq!(
            error.to_string(),
            io::Error::from_raw_os_error(2).to_string()
        );
        assert!(!path.exists());
    }

    #[cfg(unix)]
    #[test]
    fn an_existing_file_keeps_its_mode() {
        use std::os::unix::fs::PermissionsExt as _;
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("out.txt");
        for mode in [0o644, 0o640, 0o755] {
            std::fs::write(&path, "old").unwrap();
            std::fs::set_permissions(&path, std::fs::Permissions::from_mode(mode)).unwrap();
            write_atomically(&path, b"new").unwrap();
            let got = std::fs::metadata(&path).unwrap().permissions().mode() & 0o7777;
            assert_eq!(got, mode);
        }
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_is_followed_and_kept() {
        let dir = tempfile::tempdir().unwrap();
        let real = dir.path().join("real.txt");
        let link = dir.path().join("link.txt");
        let link_to_link = dir.path().join("link2.txt");
        std::fs::write(&real, "old").unwrap();
        std::os::unix::fs::symlink("real.txt", &link).unwrap();
        std::os::unix::fs::symlink(&link, &link_to_link).unwrap();
        write_atomically(&link_to_link, b"new").unwrap();
        assert_eq!(std::fs::read_to_string(&real).unwrap(), "new");
        assert!(
            std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        assert!(
            std::fs::symlink_metadata(&link_to_link)
                .unwrap()
                .file_type()
                .is_symlink()
        );
        // A dangling link is followed too: its target is created.
        let dangling = dir.path().join("dangling.txt");
        std::os::unix::fs::symlink("created.txt", &dangling).unwrap();
        write_atomically(&dangling, b"x").unwrap();
        assert_eq!(
            std::fs::read_to_string(dir.path().join("created.txt")).unwrap(),
            "x"
        );
    }

    #[cfg(unix)]
    #[test]
    fn a_named_pipe_is_written_to_and_stays_a_pipe() {
        use std::os::unix::fs::FileTypeExt as _;
        let dir = tempfile::tempdir().unwrap();
        let pipe = dir.path().join("pipe");
        match std::process::Command::new("mkfifo").arg(&pipe).status() {
            Ok(status) if status.success() => {}
            _ => {
                eprintln!("skipped: mkfifo is not available");
                return;
            }
        }
        // Holding both ends open keeps every open and read below from blocking.
        let mut held = std::fs::OpenOptions::new()
            .read(true)
            .write(true)
            .open(&pipe)
            .unwrap();
        write_atomically(&pipe, b"through the pipe").unwrap();
        let file_type = std::fs::symlink_metadata(&pipe).unwrap().file_type();
        assert!(file_type.is_fifo());
        let mut received = [0; 16];
        held.read_exact(&mut received).unwrap();
        assert_eq!(&received, b"through the pipe");
        assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 1);
    }

    #[cfg(unix)]
    #[test]
    fn a_symbolic_link_loop_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        let a = dir.path().join("a");
        std::os::unix::fs::symlink("b", &a).unwrap();
        std::os::unix::fs::symlink("a", dir.path().join("b")).unwrap();
        assert!(write_atomically(&a, b"x").is_err());
    }
}
