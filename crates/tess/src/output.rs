//! Writing the files Tessera produces (images, OBJ, CSV, Markdown, plots, screenshots) so that
//! nothing is reported written that was not, and a failed write never leaves a truncated file
//! where a good one was.
//!
//! [`write_file`] writes into a temporary file beside the target (`.<name>.<pid>.tmp`),
//! flushes it, syncs it to the disk and renames it over the target: the rename is atomic, so
//! the target holds either its old contents or the new ones whole. Any error (a full disk, a
//! missing permission, a directory that cannot be made) is [`TessError::Write`], naming the
//! file and the operating system's reason; the temporary file is removed.
//!
//! A symbolic link is followed: the file it names is replaced, the link stays. A target that
//! exists and is not a regular file (a device such as `/dev/null` or `/dev/stdout`, a FIFO)
//! cannot be renamed over; it is written in place, flushed and checked. Missing parent
//! directories are created.
use crate::error::{Result, TessError};
use std::io::Write;
use std::path::{Path, PathBuf};

fn failed(path: &Path, error: std::io::Error) -> TessError {
    TessError::Write {
        path: path.display().to_string(),
        error,
    }
}

/// Writes `path` with `write` (see the module docs); `write` gets a buffered writer.
pub fn write_file(
    path: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> Result<()> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_dir() => {
            return Err(failed(
                path,
                std::io::Error::new(std::io::ErrorKind::IsADirectory, "is a directory"),
            ))
        }
        // A device or FIFO: written in place.
        Ok(m) if !m.is_file() => {
            let file = std::fs::OpenOptions::new()
                .write(true)
                .open(path)
                .map_err(|e| failed(path, e))?;
            let mut w = std::io::BufWriter::new(file);
            return write(&mut w)
                .and_then(|()| w.flush())
                .map_err(|e| failed(path, e));
        }
        _ => {}
    }
    // The file a link names is replaced, not the link.
    let target = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
    let dir = match target.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    std::fs::create_dir_all(&dir).map_err(|e| {
        failed(
            path,
            std::io::Error::new(e.kind(), format!("cannot create {}: {e}", dir.display())),
        )
    })?;
    let name = target
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_else(|| "output".into());
    let temp = dir.join(format!(".{name}.{}.tmp", std::process::id()));
    let result = write_temp(&temp, &target, write).and_then(|()| std::fs::rename(&temp, &target));
    if let Err(e) = result {
        let _ = std::fs::remove_file(&temp);
        return Err(failed(path, e));
    }
    Ok(())
}

/// Writes, flushes and syncs `temp`, with `target`'s permissions when it exists.
fn write_temp(
    temp: &Path,
    target: &Path,
    write: impl FnOnce(&mut dyn Write) -> std::io::Result<()>,
) -> std::io::Result<()> {
    let file = std::fs::OpenOptions::new()
        .write(true)
        .create(true)
        .truncate(true)
        .open(temp)?;
    if let Ok(m) = std::fs::metadata(target) {
        file.set_permissions(m.permissions())?;
    }
    let mut w = std::io::BufWriter::new(file);
    write(&mut w)?;
    w.flush()?;
    let file = w.into_inner().map_err(|e| e.into_error())?;
    file.sync_all()
}

/// [`write_file`] of bytes already made (an encoded image, a report's text).
pub fn write_bytes(path: &Path, bytes: &[u8]) -> Result<()> {
    write_file(path, |w| w.write_all(bytes))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A file `name` in test `test`'s own directory (tests run in parallel: one's temporary
    /// file must not show up in another's directory).
    fn scratch(test: &str, name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("tess-output-{}-{test}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    fn leftovers(dir: &Path) -> Vec<String> {
        std::fs::read_dir(dir)
            .unwrap()
            .filter_map(|e| {
                let n = e.ok()?.file_name().to_string_lossy().into_owned();
                n.ends_with(".tmp").then_some(n)
            })
            .collect()
    }

    /// A write that fails half way leaves the old file whole and no temporary file.
    #[test]
    fn a_failed_write_keeps_the_old_file() {
        let p = scratch("kept", "kept.txt");
        write_bytes(&p, b"the good contents\n").unwrap();
        let e = write_file(&p, |w| {
            w.write_all(b"half of the new")?;
            Err(std::io::Error::other("the disk filled up"))
        })
        .unwrap_err();
        assert!(matches!(e, TessError::Write { .. }));
        assert_eq!(
            e.to_string(),
            format!("cannot write {}: the disk filled up", p.display())
        );
        assert_eq!(std::fs::read(&p).unwrap(), b"the good contents\n");
        assert!(leftovers(p.parent().unwrap()).is_empty());
    }

    /// A link is followed (the file it names gets the contents; the link stays), missing
    /// directories are made, a directory as the target is refused.
    #[test]
    fn links_directories_and_new_paths() {
        let real = scratch("links", "real.txt");
        write_bytes(&real, b"old").unwrap();
        #[cfg(unix)]
        {
            let link = scratch("links", "link.txt");
            let _ = std::fs::remove_file(&link);
            std::os::unix::fs::symlink(&real, &link).unwrap();
            write_bytes(&link, b"new").unwrap();
            assert!(std::fs::symlink_metadata(&link)
                .unwrap()
                .file_type()
                .is_symlink());
            assert_eq!(std::fs::read(&real).unwrap(), b"new");
        }
        let deep = scratch("links", "made/for/it.txt");
        write_bytes(&deep, b"x").unwrap();
        assert_eq!(std::fs::read(&deep).unwrap(), b"x");
        let dir = scratch("links", "made");
        let e = write_bytes(&dir, b"x").unwrap_err().to_string();
        assert!(e.contains("is a directory"), "{e}");
    }

    /// A device is written in place and its errors are the write's: `/dev/full` refuses with
    /// ENOSPC, named; `/dev/null` takes anything.
    #[cfg(target_os = "linux")]
    #[test]
    fn devices_are_written_in_place_and_checked() {
        write_bytes(Path::new("/dev/null"), b"anything").unwrap();
        let e = write_bytes(Path::new("/dev/full"), &[0u8; 100_000])
            .unwrap_err()
            .to_string();
        assert!(
            e.starts_with("cannot write /dev/full: ") && e.contains("os error 28"),
            "{e}"
        );
    }
}
