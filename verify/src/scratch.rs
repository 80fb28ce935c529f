//! A private, uniquely named scratch folder per verification run.
//!
//! Tests run in parallel (threads of one process, and several processes), so
//! every run gets its own folder under the system temp folder, named after the
//! process id, a process-wide counter and the time. The folder is removed when
//! the value is dropped, unless `GYROCAL_KEEP_SCRATCH` is set to `1`.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicU64, Ordering};

static COUNTER: AtomicU64 = AtomicU64::new(0);

/// A folder that exists for the lifetime of this value.
#[derive(Debug)]
pub struct ScratchDir {
    path: PathBuf,
}

impl ScratchDir {
    /// Create a new, empty folder `gyrocal-<tag>-<pid>-<n>-<nanos>` in the
    /// system temp folder.
    pub fn new(tag: &str) -> std::io::Result<Self> {
        Self::new_in(&std::env::temp_dir(), tag)
    }

    /// The same in `base` (the place-and-route flow uses `/var/tmp`: the
    /// YoWASP tools run sandboxed and cannot see a private `/tmp`).
    pub fn new_in(base: &Path, tag: &str) -> std::io::Result<Self> {
        loop {
            let n = COUNTER.fetch_add(1, Ordering::Relaxed);
            let nanos = std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map_or(0, |d| d.subsec_nanos());
            let path = base.join(format!("gyrocal-{tag}-{}-{n}-{nanos}", std::process::id()));
            match std::fs::create_dir(&path) {
                Ok(()) => return Ok(Self { path }),
                Err(e) if e.kind() == std::io::ErrorKind::AlreadyExists => continue,
                Err(e) => return Err(e),
            }
        }
    }

    /// The folder.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Whether folders are kept after use (`GYROCAL_KEEP_SCRATCH=1`).
    pub fn keep_requested() -> bool {
        std::env::var("GYROCAL_KEEP_SCRATCH").is_ok_and(|v| v == "1")
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        if Self::keep_requested() {
            eprintln!("gyrocal: kept scratch folder {}", self.path.display());
        } else {
            let _ = std::fs::remove_dir_all(&self.path);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn folders_are_unique_and_removed() {
        let a = ScratchDir::new("t").unwrap();
        let b = ScratchDir::new("t").unwrap();
        assert_ne!(a.path(), b.path());
        assert!(a.path().is_dir());
        let p = a.path().to_owned();
        std::fs::write(p.join("f"), "x").unwrap();
        drop(a);
        if !ScratchDir::keep_requested() {
            assert!(!p.exists());
        }
    }
}
