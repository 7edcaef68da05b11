//! Where the store's bytes go: a small trait over the file operations the
//! store needs, so tests can inject faults (a disk that fills, a process
//! killed between two operations), and the real file system behind it.
//!
//! Every operation names its file by path. The store performs them in a
//! crash-safe order (temp file, fsync, rename, fsync of the directory;
//! then journal append, fsync); the trait only has to do each one.

use std::fs::{self, File, OpenOptions};
use std::io::{self, Write};
use std::path::{Path, PathBuf};

/// The file operations the session store uses.
///
/// Mutating operations are [`Storage::create_dir_all`],
/// [`Storage::write_new`], [`Storage::sync_file`], [`Storage::sync_dir`],
/// [`Storage::rename`], [`Storage::append`], [`Storage::truncate`],
/// [`Storage::remove`] and [`Storage::remove_dir`]; the rest only read.
pub trait Storage {
    /// Create a directory and its parents (no error if it exists).
    fn create_dir_all(&self, dir: &Path) -> io::Result<()>;

    /// Names of the entries in `dir` (files and directories), or `None` if
    /// `dir` does not exist.
    fn list(&self, dir: &Path) -> io::Result<Option<Vec<String>>>;

    /// The whole contents of a file.
    fn read(&self, path: &Path) -> io::Result<Vec<u8>>;

    /// A file's length in bytes, or `None` if it does not exist.
    fn len(&self, path: &Path) -> io::Result<Option<u64>>;

    /// Create (or truncate) `path` and write all of `bytes` to it.
    fn write_new(&self, path: &Path, bytes: &[u8]) -> io::Result<()>;

    /// Flush a file's data and metadata to the device (`fsync`).
    fn sync_file(&self, path: &Path) -> io::Result<()>;

    /// Flush a directory's entries to the device, so renames and removals
    /// in it survive a power cut.
    fn sync_dir(&self, dir: &Path) -> io::Result<()>;

    /// Rename `from` to `to`, replacing `to` (atomic on one file system).
    fn rename(&self, from: &Path, to: &Path) -> io::Result<()>;

    /// Append all of `bytes` to the end of an existing file, in one write
    /// call as far as the system allows.
    fn append(&self, path: &Path, bytes: &[u8]) -> io::Result<()>;

    /// Cut a file back to `len` bytes.
    fn truncate(&self, path: &Path, len: u64) -> io::Result<()>;

    /// Remove a file.
    fn remove(&self, path: &Path) -> io::Result<()>;

    /// Remove an empty directory (an error if it holds anything).
    fn remove_dir(&self, dir: &Path) -> io::Result<()>;
}

impl<S: Storage + ?Sized> Storage for &S {
    fn create_dir_all(&self, dir: &Path) -> io::Result<()> {
        (**self).create_dir_all(dir)
    }
    fn list(&self, dir: &Path) -> io::Result<Option<Vec<String>>> {
        (**self).list(dir)
    }
    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        (**self).read(path)
    }
    fn len(&self, path: &Path) -> io::Result<Option<u64>> {
        (**self).len(path)
    }
    fn write_new(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        (**self).write_new(path, bytes)
    }
    fn sync_file(&self, path: &Path) -> io::Result<()> {
        (**self).sync_file(path)
    }
    fn sync_dir(&self, dir: &Path) -> io::Result<()> {
        (**self).sync_dir(dir)
    }
    fn rename(&self, from: &Path, to: &Path) -> io::Result<()> {
        (**self).rename(from, to)
    }
    fn append(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        (**self).append(path, bytes)
    }
    fn truncate(&self, path: &Path, len: u64) -> io::Result<()> {
        (**self).truncate(path, len)
    }
    fn remove(&self, path: &Path) -> io::Result<()> {
        (**self).remove(path)
    }
    fn remove_dir(&self, dir: &Path) -> io::Result<()> {
        (**self).remove_dir(dir)
    }
}

/// Whether `name` is one of the store's temporary files (`.NAME.tmp`).
pub fn is_temp_name(name: &str) -> bool {
    name.starts_with('.') && name.ends_with(".tmp") && name.len() > ".tmp".len() + 1
}

/// A failed step of [`write_atomic`].
#[derive(Debug)]
pub struct AtomicWriteError {
    /// What was being done ("writing", "fsyncing", "renaming into place").
    pub action: &'static str,
    /// The file or directory it was done to.
    pub path: PathBuf,
    /// The error.
    pub source: io::Error,
}

/// Write `bytes` to `dir/name` whole or not at all: to the temporary file
/// `dir/.name.tmp`, fsync it, rename it into place, fsync `dir`. On
/// failure it removes what it wrote (as far as the storage still allows),
/// so nothing is left at the final path.
pub fn write_atomic<S: Storage + ?Sized>(s: &S, dir: &Path, name: &str, bytes: &[u8]) -> Result<(), AtomicWriteError> {
    let temp = dir.join(format!(".{name}.tmp"));
    let target = dir.join(name);
    let fail = |action, path: &Path, source| AtomicWriteError {
        action,
        path: path.to_path_buf(),
        source,
    };
    let staged = s
        .write_new(&temp, bytes)
        .map_err(|e| fail("writing", &temp, e))
        .and_then(|()| s.sync_file(&temp).map_err(|e| fail("fsyncing", &temp, e)))
        .and_then(|()| {
            s.rename(&temp, &target)
                .map_err(|e| fail("renaming into place", &temp, e))
        });
    if let Err(e) = staged {
        let _ = s.remove(&temp);
        return Err(e);
    }
    if let Err(e) = s.sync_dir(dir) {
        let _ = s.remove(&target);
        return Err(fail("fsyncing directory", dir, e));
    }
    Ok(())
}

/// The real file system (the default storage).
#[derive(Debug, Clone, Copy, Default)]
pub struct FsStorage;

impl Storage for FsStorage {
    fn create_dir_all(&self, dir: &Path) -> io::Result<()> {
        fs::create_dir_all(dir)
    }

    fn list(&self, dir: &Path) -> io::Result<Option<Vec<String>>> {
        let entries = match fs::read_dir(dir) {
            Ok(e) => e,
            Err(e) if e.kind() == io::ErrorKind::NotFound => return Ok(None),
            Err(e) => return Err(e),
        };
        let mut names = Vec::new();
        for entry in entries {
            names.push(entry?.file_name().to_string_lossy().into_owned());
        }
        names.sort();
        Ok(Some(names))
    }

    fn read(&self, path: &Path) -> io::Result<Vec<u8>> {
        fs::read(path)
    }

    fn len(&self, path: &Path) -> io::Result<Option<u64>> {
        match fs::metadata(path) {
            Ok(m) => Ok(Some(m.len())),
            Err(e) if e.kind() == io::ErrorKind::NotFound => Ok(None),
            Err(e) => Err(e),
        }
    }

    fn write_new(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        let mut f = File::create(path)?;
        f.write_all(bytes)
    }

    fn sync_file(&self, path: &Path) -> io::Result<()> {
        // fsync applies to the inode, so a fresh descriptor flushes what
        // earlier ones wrote.
        OpenOptions::new().read(true).open(path)?.sync_all()
    }

    fn sync_dir(&self, dir: &Path) -> io::Result<()> {
        File::open(dir)?.sync_all()
    }

    fn rename(&self, from: &Path, to: &Path) -> io::Result<()> {
        fs::rename(from, to)
    }

    fn append(&self, path: &Path, bytes: &[u8]) -> io::Result<()> {
        let mut f = OpenOptions::new().append(true).open(path)?;
        f.write_all(bytes)
    }

    fn truncate(&self, path: &Path, len: u64) -> io::Result<()> {
        OpenOptions::new().write(true).open(path)?.set_len(len)
    }

    fn remove(&self, path: &Path) -> io::Result<()> {
        fs::remove_file(path)
    }

    fn remove_dir(&self, dir: &Path) -> io::Result<()> {
        fs::remove_dir(dir)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fs_storage_does_each_operation() {
        let tmp = tempfile::tempdir().unwrap();
        let s = FsStorage;
        let d = tmp.path().join("a/b");
        assert_eq!(s.list(&d).unwrap(), None);
        s.create_dir_all(&d).unwrap();
        let f = d.join("x");
        s.write_new(&f, b"hello").unwrap();
        s.sync_file(&f).unwrap();
        s.append(&f, b" world").unwrap();
        assert_eq!(s.read(&f).unwrap(), b"hello world");
        s.truncate(&f, 5).unwrap();
        assert_eq!(s.len(&f).unwrap(), Some(5));
        s.rename(&f, &d.join("y")).unwrap();
        s.sync_dir(&d).unwrap();
        assert_eq!(s.list(&d).unwrap(), Some(vec!["y".to_string()]));
        s.remove(&d.join("y")).unwrap();
        assert_eq!(s.len(&d.join("y")).unwrap(), None);
        assert!(s.append(&d.join("absent"), b"z").is_err());
    }
}
