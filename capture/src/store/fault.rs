//! Storage with injected faults, for tests of the store and of whatever
//! drives it: a process killed after a number of operations
//! ([`CrashingStorage`]) and a disk that fills ([`QuotaStorage`]).
//!
//! Both wrap another [`Storage`] (normally [`super::FsStorage`]) and leave
//! on it exactly what a real fault would, so a fresh store over the real
//! file system can resume from it.

use super::storage::Storage;
use std::fmt;
use std::io;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Mutex, PoisonError};

/// The mutating operations, for naming where a crash struck.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Operation {
    /// [`Storage::create_dir_all`].
    CreateDir,
    /// [`Storage::write_new`].
    WriteNew,
    /// [`Storage::sync_file`].
    SyncFile,
    /// [`Storage::sync_dir`].
    SyncDir,
    /// [`Storage::rename`].
    Rename,
    /// [`Storage::append`].
    Append,
    /// [`Storage::truncate`].
    Truncate,
    /// [`Storage::remove`].
    Remove,
    /// [`Storage::remove_dir`].
    RemoveDir,
}

impl fmt::Display for Operation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let name = match self {
            Operation::CreateDir => "create directory",
            Operation::WriteNew => "write",
            Operation::SyncFile => "fsync file",
            Operation::SyncDir => "fsync directory",
            Operation::Rename => "rename",
            Operation::Append => "append",
            Operation::Truncate => "truncate",
            Operation::Remove => "remove",
            Operation::RemoveDir => "remove directory",
        };
        f.write_str(name)
    }
}

/// Where a [`CrashingStorage`] crashed: the operation it was about to do,
/// on which file.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CrashPoint {
    /// The operation cut short.
    pub operation: Operation,
    /// Its file (the source, for a rename).
    pub path: PathBuf,
}

/// A storage whose process "dies" at its `n`-th mutating operation
/// (counting from 1): that operation is not done, except that a
/// [`Storage::write_new`] or [`Storage::append`] writes the first half of
/// its bytes (a torn write); from then on every operation, reading ones
/// included, fails with an error naming the crash.
#[derive(Debug)]
pub struct CrashingStorage<S> {
    inner: S,
    left: AtomicU64,
    crashed: Mutex<Option<CrashPoint>>,
}

impl<S: Storage> CrashingStorage<S> {
    /// Crash at the `n`-th mutating operation (`n` ≥ 1; 0 crashes at once).
    pub fn new(inner: S, n: u64) -> Self {
        Self {
            inner,
            left: AtomicU64::new(n),
            crashed: Mutex::new(None),
        }
    }

    /// Where it crashed, if it has.
    pub fn crash_point(&self) -> Option<CrashPoint> {
        self.crashed.lock().unwrap_or_else(PoisonError::into_inner).clone()
    }

    fn dead(&self) -> io::Result<()> {
        match self.crash_point() {
            Some(p) => Err(io::Error::other(format!(
                "simulated crash (killed at {} of {})",
                p.operation,
                p.path.display()
            ))),
            None => Ok(()),
        }
    }

    /// Count one mutating operation; `Ok(true)` if it is the fatal one.
    fn step(&self, operation: Operation, path: &Path) -> io::Result<bool> {
        self.dead()?;
        let left = self.left.load(Ordering::SeqCst);
        if left <= 1 {
            *self.crashed.lock().unwrap_or_else(PoisonError::into_inner) = Some(CrashPoint {
                operation,
                path: path.to_path_buf(),
            });
            return Ok(true);
        }
        self.left.store(left - 1, Ordering::SeqCst);
        Ok(false)
    }

    fn run(&self, operation: Operation, path: &Path, op: impl FnOnce() -> io::Result<()>) -> io::Result<()> {
        if self.step(operation, path)? {
            return self.dead();
        }
        op()
    }
}

impl<S: Storage> Storage for CrashingStorage<S> {
    fn create_dir_all(&self, dir: &Path) -> io::Result<()> {
        self.run(Operation::CreateDir, dir, || self.inner.create_dir_all(dir))
    }

    fn list(&self, dir: &Path) -> io::Result<Option<Vec<String>>> {
        self.dead()?;
        self.inner.list(dir)
    }

    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.dead()?;
        self.inner.read(path)
    }

    fn len(&self, path: &Path) -> io::Result<Option<u64>> {
        self.dead()?;
        self.inner.len(path)
    }

    fn write_new(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        if self.step(Operation::WriteNew, path)? {
            self.inner.write_new(path, &bytes[..bytes.len() / 2])?;
            return self.dead();
        }
        self.inner.write_new(path, bytes)
    }

    fn sync_file(&self, path: &Path) -> io::Result<()> {
        self.run(Operation::SyncFile, path, || self.inner.sync_file(path))
    }

    fn sync_dir(&self, dir: &Path) -> io::Result<()> {
        self.run(Operation::SyncDir, dir, || self.inner.sync_dir(dir))
    }

    fn rename(&self, from: &Path, to: &Path) -> io::Result<()> {
        self.run(Operation::Rename, from, || self.inner.rename(from, to))
    }

    fn append(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        if self.step(Operation::Append, path)? {
            self.inner.append(path, &bytes[..bytes.len() / 2])?;
            return self.dead();
        }
        self.inner.append(path, bytes)
    }

    fn truncate(&self, path: &Path, len: u64) -> io::Result<()> {
        self.run(Operation::Truncate, path, || self.inner.truncate(path, len))
    }

    fn remove(&self, path: &Path) -> io::Result<()> {
        self.run(Operation::Remove, path, || self.inner.remove(path))
    }

    fn remove_dir(&self, dir: &Path) -> io::Result<()> {
        self.run(Operation::RemoveDir, dir, || self.inner.remove_dir(dir))
    }
}

/// A storage with a byte quota: it counts the bytes of the files under a
/// root directory when opened, adds what is written, and takes off what
/// is truncated or removed. A write that would pass the quota writes what
/// fits and then fails with [`io::ErrorKind::StorageFull`], as a full disk
/// does.
#[derive(Debug)]
pub struct QuotaStorage<S> {
    inner: S,
    quota: AtomicU64,
    used: Mutex<u64>,
}

impl<S: Storage> QuotaStorage<S> {
    /// A quota of `quota_bytes` over `inner`, counting the files already
    /// under `root` (recursively; `root` may be absent).
    pub fn open(inner: S, root: &Path, quota_bytes: u64) -> io::Result<Self> {
        let used = tree_size(&inner, root)?;
        Ok(Self {
            inner,
            quota: AtomicU64::new(quota_bytes),
            used: Mutex::new(used),
        })
    }

    /// Bytes counted as used.
    pub fn used(&self) -> u64 {
        *self.used.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Change the quota (free space on the disk).
    pub fn set_quota(&self, quota_bytes: u64) {
        self.quota.store(quota_bytes, Ordering::SeqCst);
    }

    /// Write what fits of `bytes` with `op`, then fail if not all fitted.
    fn charge(&self, path: &Path, bytes: &[u8], op: impl FnOnce(&[u8]) -> io::Result<()>) -> io::Result<()> {
        let mut used = self.used.lock().unwrap_or_else(PoisonError::into_inner);
        let quota = self.quota.load(Ordering::SeqCst);
        let room = quota.saturating_sub(*used);
        let fits = usize::try_from(room).unwrap_or(usize::MAX).min(bytes.len());
        op(&bytes[..fits])?;
        *used += fits as u64;
        if fits < bytes.len() {
            return Err(io::Error::new(
                io::ErrorKind::StorageFull,
                format!(
                    "{}: quota of {quota} bytes reached ({} of {} bytes written)",
                    path.display(),
                    fits,
                    bytes.len()
                ),
            ));
        }
        Ok(())
    }

    fn release(&self, n: u64) {
        let mut used = self.used.lock().unwrap_or_else(PoisonError::into_inner);
        *used = used.saturating_sub(n);
    }
}

/// Total bytes of the files under `root` (0 if absent).
fn tree_size<S: Storage>(s: &S, root: &Path) -> io::Result<u64> {
    let Some(names) = s.list(root)? else {
        return Ok(0);
    };
    let mut total = 0;
    for name in names {
        let path = root.join(name);
        if path.is_dir() {
            total += tree_size(s, &path)?;
        } else {
            total += s.len(&path)?.unwrap_or(0);
        }
    }
    Ok(total)
}

impl<S: Storage> Storage for QuotaStorage<S> {
    fn create_dir_all(&self, dir: &Path) -> io::Result<()> {
        self.inner.create_dir_all(dir)
    }

    fn list(&self, dir: &Path) -> io::Result<Option<Vec<String>>> {
        self.inner.list(dir)
    }

    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        self.inner.read(path)
    }

    fn len(&self, path: &Path) -> io::Result<Option<u64>> {
        self.inner.len(path)
    }

    fn write_new(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        // Overwriting a file frees its old bytes first.
        if let Some(old) = self.inner.len(path)? {
            self.release(old);
        }
        self.charge(path, bytes, |b| self.inner.write_new(path, b))
    }

    fn sync_file(&self, path: &Path) -> io::Result<()> {
        self.inner.sync_file(path)
    }

    fn sync_dir(&self, dir: &Path) -> io::Result<()> {
        self.inner.sync_dir(dir)
    }

    fn rename(&self, from: &Path, to: &Path) -> io::Result<()> {
        let replaced = self.inner.len(to)?;
        self.inner.rename(from, to)?;
        if let Some(old) = replaced {
            self.release(old);
        }
        Ok(())
    }

    fn append(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        self.charge(path, bytes, |b| self.inner.append(path, b))
    }

    fn truncate(&self, path: &Path, len: u64) -> io::Result<()> {
        let old = self.inner.len(path)?.unwrap_or(0);
        self.inner.truncate(path, len)?;
        self.release(old.saturating_sub(len));
        Ok(())
    }

    fn remove(&self, path: &Path) -> io::Result<()> {
        let old = self.inner.len(path)?.unwrap_or(0);
        self.inner.remove(path)?;
        self.release(old);
        Ok(())
    }

    fn remove_dir(&self, dir: &Path) -> io::Result<()> {
        self.inner.remove_dir(dir)
    }
}

#[cfg(test)]
mod tests {
    use super::super::FsStorage;
    use super::*;

    #[test]
    fn crash_tears_the_fatal_write_and_stops_everything_after() {
        let tmp = tempfile::tempdir().unwrap();
        let f = tmp.path().join("f");
        let s = CrashingStorage::new(FsStorage, 3);
        s.write_new(&f, b"0123").unwrap();
        s.sync_file(&f).unwrap();
        assert!(s.append(&f, b"abcdef").is_err());
        assert_eq!(
            s.crash_point(),
            Some(CrashPoint {
                operation: Operation::Append,
                path: f.clone()
            })
        );
        assert!(s.read(&f).is_err());
        assert!(s.remove(&f).is_err());
        assert_eq!(std::fs::read(&f).unwrap(), b"0123abc");
    }

    #[test]
    fn quota_writes_what_fits_then_reports_storage_full() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join("old"), [0u8; 40]).unwrap();
        let s = QuotaStorage::open(FsStorage, tmp.path(), 100).unwrap();
        assert_eq!(s.used(), 40);
        let f = tmp.path().join("f");
        s.write_new(&f, &[1u8; 50]).unwrap();
        let e = s.append(&f, &[2u8; 20]).unwrap_err();
        assert_eq!(e.kind(), io::ErrorKind::StorageFull);
        assert_eq!(std::fs::metadata(&f).unwrap().len(), 60);
        s.truncate(&f, 50).unwrap();
        assert_eq!(s.used(), 90);
        s.remove(&f).unwrap();
        assert_eq!(s.used(), 40);
        s.set_quota(1000);
        s.write_new(&f, &[3u8; 500]).unwrap();
    }
}
