//! Atomic file replacement, for every file gyrocal writes (exported Verilog,
//! reports, results, figures).

/// Write `bytes` to `path` through a uniquely named temporary file beside
/// it, flushed to disk and renamed over `path`: a reader sees the old file
/// or the whole new one, never a part, and a failed write leaves nothing
/// behind. Permissions are those `File::create` would give (0666 less the
/// umask), not tempfile's private 0600.
pub fn write_atomically(path: &std::path::Path, bytes: impl AsRef<[u8]>) -> std::io::Result<()> {
    use std::io::Write;
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d,
        _ => std::path::Path::new("."),
    };
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let prefix = format!(".{name}.");
    let mut builder = tempfile::Builder::new();
    builder.prefix(&prefix).suffix(".tmp");
    #[cfg(unix)]
    {
        use std::os::unix::fs::PermissionsExt;
        builder.permissions(std::fs::Permissions::from_mode(0o666));
    }
    let mut tmp = builder.tempfile_in(dir)?;
    tmp.write_all(bytes.as_ref())?;
    tmp.as_file().sync_all()?;
    tmp.persist(path).map_err(|e| e.error)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn replaces_the_whole_file_and_leaves_no_temporary() {
        let dir = crate::ScratchDir::new("atomic").unwrap();
        let path = dir.path().join("report.md");
        write_atomically(&path, "first version, longer than the second").unwrap();
        write_atomically(&path, "second").unwrap();
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "second");
        let names: Vec<_> = std::fs::read_dir(dir.path())
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, vec![std::ffi::OsString::from("report.md")]);
    }

    #[test]
    fn a_failed_write_leaves_nothing() {
        let dir = crate::ScratchDir::new("atomic").unwrap();
        let missing = dir.path().join("no-such-folder").join("f.md");
        assert!(write_atomically(&missing, "x").is_err());
        assert!(!missing.exists());
    }
}
