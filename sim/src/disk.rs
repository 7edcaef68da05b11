//! A storage area that fills up: a directory with a byte quota.
//!
//! Writes go to a temporary file in the directory and are renamed into
//! place only once complete and flushed ([`QuotaWriter::commit`]), as the
//! session store does. A write that would take the directory past its
//! quota fails with [`std::io::ErrorKind::StorageFull`] (the kind Linux
//! gives `ENOSPC`), the temporary file is removed, and nothing appears at
//! the final path; earlier files stay intact. The quota counts the sizes
//! of the files in the directory (not subdirectories) when it is opened,
//! plus every byte written through it since, less the temporary files
//! abandoned; bytes written around it are not seen.

use std::fs::File;
use std::io::{self, Write};
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex, PoisonError};

/// A directory with a byte quota.
#[derive(Debug, Clone)]
pub struct QuotaDir {
    root: PathBuf,
    quota: u64,
    used: Arc<Mutex<u64>>,
    temp_counter: Arc<AtomicU64>,
}

impl QuotaDir {
    /// A quota of `quota_bytes` on the existing directory `root`.
    pub fn open(root: &Path, quota_bytes: u64) -> io::Result<Self> {
        let mut used = 0;
        for entry in std::fs::read_dir(root)? {
            let meta = entry?.metadata()?;
            if meta.is_file() {
                used += meta.len();
            }
        }
        Ok(Self {
            root: root.to_path_buf(),
            quota: quota_bytes,
            used: Arc::new(Mutex::new(used)),
            temp_counter: Arc::new(AtomicU64::new(0)),
        })
    }

    /// The directory.
    pub fn root(&self) -> &Path {
        &self.root
    }

    /// Bytes in use (committed, or in temporary files being written).
    pub fn used(&self) -> u64 {
        *self.used.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Bytes left.
    pub fn free(&self) -> u64 {
        self.quota.saturating_sub(self.used())
    }

    /// Start writing the file `name` (a plain file name inside the
    /// directory): bytes go to a temporary file until
    /// [`QuotaWriter::commit`].
    pub fn create(&self, name: &str) -> io::Result<QuotaWriter> {
        let plain = Path::new(name).file_name().is_some_and(|f| f == name);
        if !plain {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{name:?} is not a plain file name"),
            ));
        }
        let n = self.temp_counter.fetch_add(1, Ordering::Relaxed);
        let temp = self.root.join(format!(".{name}.{n}.tmp"));
        let file = File::create(&temp)?;
        Ok(QuotaWriter {
            dir: self.clone(),
            file: Some(file),
            temp,
            target: self.root.join(name),
            written: 0,
        })
    }

    /// Write `bytes` to `name` whole or not at all.
    pub fn write_atomic(&self, name: &str, bytes: &[u8]) -> io::Result<()> {
        let mut w = self.create(name)?;
        w.write_all(bytes)?;
        w.commit()
    }

    fn reserve(&self, n: u64) -> io::Result<()> {
        let mut used = self.used.lock().unwrap_or_else(PoisonError::into_inner);
        if *used + n > self.quota {
            return Err(io::Error::new(
                io::ErrorKind::StorageFull,
                format!(
                    "{}: quota of {} bytes reached ({} used, {n} more asked for)",
                    self.root.display(),
                    self.quota,
                    *used
                ),
            ));
        }
        *used += n;
        Ok(())
    }

    fn release(&self, n: u64) {
        let mut used = self.used.lock().unwrap_or_else(PoisonError::into_inner);
        *used = used.saturating_sub(n);
    }
}

/// A file being written under a quota. Dropped without
/// [`QuotaWriter::commit`], it removes its temporary file.
#[derive(Debug)]
pub struct QuotaWriter {
    dir: QuotaDir,
    file: Option<File>,
    temp: PathBuf,
    target: PathBuf,
    written: u64,
}

impl QuotaWriter {
    /// Flush, sync and rename the file into place.
    pub fn commit(mut self) -> io::Result<()> {
        let Some(mut file) = self.file.take() else {
            return Err(io::Error::other("file already abandoned"));
        };
        file.flush()?;
        file.sync_all()?;
        drop(file);
        std::fs::rename(&self.temp, &self.target)?;
        // Committed: the bytes stay counted and the drop does nothing.
        self.written = 0;
        Ok(())
    }

    fn abandon(&mut self) {
        if self.file.take().is_some() {
            let _ = std::fs::remove_file(&self.temp);
            self.dir.release(self.written);
            self.written = 0;
        }
    }
}

impl Write for QuotaWriter {
    fn write(&mut self, buf: &[u8]) -> io::Result<usize> {
        if self.file.is_none() {
            return Err(io::Error::other("file abandoned after an error"));
        }
        if let Err(e) = self.dir.reserve(buf.len() as u64) {
            self.abandon();
            return Err(e);
        }
        let Some(file) = self.file.as_mut() else {
            return Err(io::Error::other("file abandoned after an error"));
        };
        match file.write_all(buf) {
            Ok(()) => {
                self.written += buf.len() as u64;
                Ok(buf.len())
            }
            Err(e) => {
                self.dir.release(buf.len() as u64);
                self.abandon();
                Err(e)
            }
        }
    }

    fn flush(&mut self) -> io::Result<()> {
        match self.file.as_mut() {
            Some(f) => f.flush(),
            None => Ok(()),
        }
    }
}

impl Drop for QuotaWriter {
    fn drop(&mut self) {
        self.abandon();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn quota_stops_a_write_cleanly() {
        let tmp = tempfile::tempdir().unwrap();
        std::fs::write(tmp.path().join("old.bin"), [7u8; 100]).unwrap();
        let disk = QuotaDir::open(tmp.path(), 1_000).unwrap();
        assert_eq!(disk.used(), 100);
        disk.write_atomic("a.bin", &[1u8; 600]).unwrap();
        assert_eq!(disk.free(), 300);
        // 400 bytes do not fit in the 300 left.
        let err = disk.write_atomic("b.bin", &[2u8; 400]).unwrap_err();
        assert_eq!(err.kind(), io::ErrorKind::StorageFull);
        assert!(!tmp.path().join("b.bin").exists());
        // Earlier files intact, no temporary file left, quota restored.
        assert_eq!(std::fs::read(tmp.path().join("a.bin")).unwrap(), vec![1u8; 600]);
        assert_eq!(std::fs::read(tmp.path().join("old.bin")).unwrap(), vec![7u8; 100]);
        let names: Vec<_> = std::fs::read_dir(tmp.path())
            .unwrap()
            .map(|e| e.unwrap().file_name().into_string().unwrap())
            .collect();
        assert_eq!(names.len(), 2, "{names:?}");
        assert_eq!(disk.used(), 700);
        // A write in chunks fails at the chunk that crosses the quota.
        let mut w = disk.create("c.bin").unwrap();
        w.write_all(&[3u8; 200]).unwrap();
        assert_eq!(w.write_all(&[3u8; 200]).unwrap_err().kind(), io::ErrorKind::StorageFull);
        drop(w);
        assert!(!tmp.path().join("c.bin").exists());
        assert_eq!(disk.used(), 700);
        // What fits still goes.
        disk.write_atomic("d.bin", &[4u8; 300]).unwrap();
        assert_eq!(disk.free(), 0);
        assert!(disk.create("../escape").is_err());
    }
}
