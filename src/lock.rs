//! Advisory OS file locks that keep two oceanbench processes apart: one per results folder
//! (two runs must not write one results.json) and one per core (two runs measuring on the same
//! core make every number of both meaningless). The OS drops a lock when its holder exits or
//! crashes, so a stale lock file never blocks anyone; the file holds the holder's pid and
//! command line only to name it.

use std::fs::{File, OpenOptions, TryLockError};
use std::io::{Read, Seek, Write};
use std::os::unix::fs::MetadataExt;
use std::path::{Path, PathBuf};
use std::time::Duration;

/// The environment variable that overrides where the per-core lock files live (tests give each
/// run its own directory).
pub const DIR_ENV: &str = "OCEANBENCH_LOCK_DIR";

/// The name of the lock file inside a results folder.
pub const OUT_FILE: &str = ".oceanbench.lock";

/// How often a waiting run tries a held lock again.
const POLL: Duration = Duration::from_millis(100);

/// A held lock; dropping it removes the lock file and releases the lock.
#[derive(Debug)]
pub struct Lock {
    file: File,
    path: PathBuf,
}

impl Drop for Lock {
    fn drop(&mut self) {
        // Removed while still held: a process that opened the old file finds, once it gets
        // the lock, that the path no longer names it, and opens the new one (see `try_take`).
        let _ = std::fs::remove_file(&self.path);
        let _ = self.file.unlock();
    }
}

/// Why a lock was not taken.
#[derive(Debug, thiserror::Error)]
pub enum LockError {
    /// Another process holds it.
    #[error("{} is held by {holder}", path.display())]
    Held {
        /// The lock file.
        path: PathBuf,
        /// The holder as its lock file names it (`pid N: command line`).
        holder: String,
    },
    /// The lock file could not be opened or locked.
    #[error("{}: {source}", path.display())]
    Io {
        /// The lock file.
        path: PathBuf,
        /// The failure.
        source: std::io::Error,
    },
}

/// Where the per-core lock files live: `$OCEANBENCH_LOCK_DIR`, else `$XDG_RUNTIME_DIR/oceanbench`,
/// else `oceanbench-<uid>` in the temp directory, so every user of the machine shares them.
pub fn dir() -> PathBuf {
    // SAFETY: getuid has no preconditions and cannot fail.
    let uid = unsafe { libc::getuid() };
    dir_from(
        std::env::var_os(DIR_ENV),
        std::env::var_os("XDG_RUNTIME_DIR"),
        &std::env::temp_dir(),
        uid,
    )
}

/// [`dir`] from the two variables, the temp directory and the user id; an empty variable counts
/// as unset (a login without a runtime directory may export it empty).
fn dir_from(
    lock_dir: Option<std::ffi::OsString>,
    runtime_dir: Option<std::ffi::OsString>,
    temp: &Path,
    uid: u32,
) -> PathBuf {
    if let Some(d) = lock_dir.filter(|d| !d.is_empty()) {
        return PathBuf::from(d);
    }
    if let Some(d) = runtime_dir.filter(|d| !d.is_empty()) {
        return PathBuf::from(d).join("oceanbench");
    }
    temp.join(format!("oceanbench-{uid}"))
}

/// The lock file of one core.
pub fn core_file(core: usize) -> PathBuf {
    dir().join(format!("core-{core}.lock"))
}

/// Takes the lock of the results folder `out` (which must exist), or says who holds it.
pub fn out_dir(out: &Path) -> Result<Lock, LockError> {
    try_take(&out.join(OUT_FILE))
}

/// Takes the lock of every core in `cores`, in ascending order so two runs never hold one each
/// of the other's. A held core is waited for when `wait` is set (`on_wait` is told once, with the
/// error naming the holder, and `stop` ends the wait with that error), else refused at once.
pub fn cores(
    cores: &[usize],
    wait: bool,
    mut on_wait: impl FnMut(&LockError),
    stop: impl Fn() -> bool,
) -> Result<Vec<Lock>, LockError> {
    let mut sorted = cores.to_vec();
    sorted.sort_unstable();
    sorted.dedup();
    let dir = dir();
    std::fs::create_dir_all(&dir).map_err(|source| LockError::Io {
        path: dir.clone(),
        source,
    })?;
    let mut told = false;
    let mut held = Vec::new();
    for core in sorted {
        let path = core_file(core);
        loop {
            match try_take(&path) {
                Ok(lock) => {
                    held.push(lock);
                    break;
                }
                Err(e @ LockError::Held { .. }) if wait && !stop() => {
                    if !told {
                        on_wait(&e);
                        told = true;
                    }
                    std::thread::sleep(POLL);
                }
                Err(e) => return Err(e),
            }
        }
    }
    Ok(held)
}

/// The holder of the lock file at `path`, if another live process holds it.
pub fn holder(path: &Path) -> Option<String> {
    let file = File::open(path).ok()?;
    match file.try_lock_shared() {
        Ok(()) => None,
        Err(TryLockError::WouldBlock) => {
            let holder = read_holder(file);
            let own = format!("pid {}:", std::process::id());
            (!holder.starts_with(&own)).then_some(holder)
        }
        Err(TryLockError::Error(_)) => None,
    }
}

fn try_take(path: &Path) -> Result<Lock, LockError> {
    let io = |source| LockError::Io {
        path: path.to_path_buf(),
        source,
    };
    // A holder may remove the file between our open and our lock, so the file we locked may no
    // longer be the one at `path`: open it again. Bounded, so that a file replaced over and
    // over (or a broken check) is an error within milliseconds, never a hang.
    for _ in 0..MAX_REOPENS {
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .create(true)
            .truncate(false)
            .open(path)
            .map_err(io)?;
        match file.try_lock() {
            Ok(()) => {}
            Err(TryLockError::WouldBlock) => {
                return Err(LockError::Held {
                    path: path.to_path_buf(),
                    holder: read_holder(file),
                })
            }
            Err(TryLockError::Error(e)) => return Err(io(e)),
        }
        if !same_file(&file, path) {
            continue;
        }
        file.set_len(0).map_err(io)?;
        file.rewind().map_err(io)?;
        file.write_all(whoami().as_bytes()).map_err(io)?;
        return Ok(Lock {
            file,
            path: path.to_path_buf(),
        });
    }
    Err(io(std::io::Error::other(format!(
        "the lock file was replaced {MAX_REOPENS} times while it was being taken"
    ))))
}

/// Times [`try_take`] opens a lock file again after finding the one it locked replaced.
const MAX_REOPENS: usize = 64;

/// Whether `path` still names the open `file` (its holder may have removed it meanwhile).
fn same_file(file: &File, path: &Path) -> bool {
    match (file.metadata(), std::fs::metadata(path)) {
        (Ok(a), Ok(b)) => a.dev() == b.dev() && a.ino() == b.ino(),
        _ => false,
    }
}

/// `pid N: command line` of this process.
fn whoami() -> String {
    let args: Vec<String> = std::env::args().collect();
    format!("pid {}: {}", std::process::id(), args.join(" "))
}

fn read_holder(mut file: File) -> String {
    let mut text = String::new();
    let _ = file.read_to_string(&mut text);
    let text = text.trim();
    if text.is_empty() {
        "another process (it has not written its pid yet)".into()
    } else {
        text.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::ffi::OsString;

    #[test]
    fn the_lock_dir_skips_empty_variables() {
        let tmp = Path::new("/tmp");
        let some = |s: &str| Some(OsString::from(s));
        assert_eq!(
            dir_from(some("/l"), some("/run/user/7"), tmp, 7),
            Path::new("/l")
        );
        assert_eq!(
            dir_from(some(""), some("/run/user/7"), tmp, 7),
            Path::new("/run/user/7/oceanbench")
        );
        assert_eq!(
            dir_from(None, some(""), tmp, 7),
            Path::new("/tmp/oceanbench-7")
        );
        assert_eq!(dir_from(None, None, tmp, 7), Path::new("/tmp/oceanbench-7"));
    }

    #[test]
    fn a_lock_file_removed_and_made_again_is_not_the_one_opened() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("core-0.lock");
        let old = File::create(&path).unwrap();
        assert!(same_file(&old, &path));
        // What a waiting run sees when the holder removed the file between its open and its
        // lock, and a third run made it again: same device, another inode.
        std::fs::remove_file(&path).unwrap();
        assert!(!same_file(&old, &path), "the path names nothing now");
        let new = File::create(&path).unwrap();
        assert!(!same_file(&old, &path), "the path names another file");
        assert!(same_file(&new, &path));
    }

    #[test]
    fn a_taker_that_opened_a_removed_lock_file_takes_the_new_one() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("core-0.lock");
        let first = try_take(&path).unwrap();
        let stale = File::open(&path).unwrap();
        drop(first);
        assert!(!path.exists(), "a dropped lock removes its file");
        let second = try_take(&path).unwrap();
        assert!(same_file(&second.file, &path));
        assert!(!same_file(&stale, &path));
        assert!(holder(&path).is_none(), "this process holds it");
    }
}
