//! Reading an input file whole, within a bound: every file Tessera reads (OBJ meshes, texture
//! and height maps, benchmark CSV) goes through [`read_regular_file`], so a device, a FIFO or a
//! directory given as input is refused before it is opened (opening a FIFO blocks until a
//! writer comes; reading `/dev/zero` never ends), and a file larger than its bound is refused
//! by its size before it is read.
//!
//! The errors are [`std::io::Error`]s whose text says what the path is or how large, and the
//! bound, so a caller's "cannot read FILE: ..." says it all.

use std::io::Read;
use std::path::Path;

/// The largest OBJ file [`load_obj`](crate::mesh::obj::load_obj) reads: 1 GiB (about 30 million vertices and faces
/// of plain text; parsing takes a few times the file's size in memory).
pub const MAX_OBJ_BYTES: u64 = 1 << 30;

/// `n` bytes in the largest binary unit that keeps it whole-ish: "1 GiB", "3.5 MiB", "812
/// bytes".
pub fn bytes_text(n: u64) -> String {
    const UNITS: [(&str, u64); 3] = [("GiB", 1 << 30), ("MiB", 1 << 20), ("KiB", 1 << 10)];
    for (unit, size) in UNITS {
        if n >= size {
            let x = n as f64 / size as f64;
            return if n.is_multiple_of(size) {
                format!("{} {unit}", n / size)
            } else {
                format!("{x:.1} {unit}")
            };
        }
    }
    format!("{n} bytes")
}

/// What a path that is not a regular file is, in words, or `None` for a regular file.
fn not_regular(file_type: std::fs::FileType) -> Option<&'static str> {
    if file_type.is_file() {
        return None;
    }
    if file_type.is_dir() {
        return Some("a directory");
    }
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt;
        if file_type.is_fifo() {
            return Some("a FIFO (named pipe)");
        }
        if file_type.is_char_device() {
            return Some("a character device");
        }
        if file_type.is_block_device() {
            return Some("a block device");
        }
        if file_type.is_socket() {
            return Some("a socket");
        }
    }
    Some("not a regular file")
}

fn invalid(text: String) -> std::io::Error {
    std::io::Error::new(std::io::ErrorKind::InvalidInput, text)
}

fn too_large(size: u64, max_bytes: u64, what: &str) -> std::io::Error {
    invalid(format!(
        "is {}, more than the {} {what} may have",
        bytes_text(size),
        bytes_text(max_bytes)
    ))
}

/// The checks of [`read_regular_file`] without reading: for a reader that opens the file itself
/// (the USD reader). Returns the file's metadata.
pub fn check_regular_file(
    path: &Path,
    max_bytes: u64,
    what: &str,
) -> std::io::Result<std::fs::Metadata> {
    let meta = std::fs::metadata(path)?;
    if let Some(kind) = not_regular(meta.file_type()) {
        return Err(invalid(format!("is {kind}, not a regular file")));
    }
    if meta.len() > max_bytes {
        return Err(too_large(meta.len(), max_bytes, what));
    }
    Ok(meta)
}

/// The whole of the regular file at `path` (symbolic links followed), at most `max_bytes`
/// long; `what` names the kind of input in the size error ("an OBJ file", "a texture").
///
/// Refused without opening it: a path that is a directory, FIFO, device or socket (said so:
/// "is a FIFO (named pipe), not a regular file"), and a file whose size exceeds the bound
/// ("is 3 GiB, more than the 1 GiB an OBJ file may have"). A file that grows past the bound
/// while it is read is refused too.
pub fn read_regular_file(path: &Path, max_bytes: u64, what: &str) -> std::io::Result<Vec<u8>> {
    let meta = check_regular_file(path, max_bytes, what)?;
    let too_large = |size: u64| too_large(size, max_bytes, what);
    let file = std::fs::File::open(path)?;
    // The path may have been replaced between the two looks; what was opened decides.
    if let Some(kind) = not_regular(file.metadata()?.file_type()) {
        return Err(invalid(format!("is {kind}, not a regular file")));
    }
    let mut bytes = Vec::with_capacity(meta.len() as usize);
    file.take(max_bytes + 1).read_to_end(&mut bytes)?;
    if bytes.len() as u64 > max_bytes {
        return Err(too_large(bytes.len() as u64));
    }
    Ok(bytes)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> std::path::PathBuf {
        let dir = std::env::temp_dir().join(format!("topology-input-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join(name)
    }

    #[test]
    fn sizes_read_as_people_write_them() {
        assert_eq!(bytes_text(812), "812 bytes");
        assert_eq!(bytes_text(1 << 30), "1 GiB");
        assert_eq!(bytes_text(3 << 29), "1.5 GiB");
        assert_eq!(bytes_text(64 << 20), "64 MiB");
    }

    #[test]
    fn regular_files_within_the_bound_are_read_whole() {
        let p = scratch("ten.txt");
        std::fs::write(&p, "0123456789").unwrap();
        assert_eq!(read_regular_file(&p, 10, "a test").unwrap(), b"0123456789");
        let e = read_regular_file(&p, 9, "a test file").unwrap_err();
        assert_eq!(
            e.to_string(),
            "is 10 bytes, more than the 9 bytes a test file may have"
        );
    }

    #[test]
    fn what_is_not_a_regular_file_is_refused_unopened() {
        let dir = scratch("a_directory");
        std::fs::create_dir_all(&dir).unwrap();
        let mut cases = vec![(dir, "is a directory, not a regular file")];
        #[cfg(unix)]
        {
            cases.push((
                "/dev/zero".into(),
                "is a character device, not a regular file",
            ));
            let fifo = scratch("fifo");
            let _ = std::fs::remove_file(&fifo);
            let made = std::process::Command::new("mkfifo")
                .arg(&fifo)
                .status()
                .is_ok_and(|s| s.success());
            if made {
                // Opening it would block until a writer came: refused by its type first.
                cases.push((fifo, "is a FIFO (named pipe), not a regular file"));
            }
        }
        for (path, said) in cases {
            let e = read_regular_file(&path, 1 << 20, "a test").unwrap_err();
            assert_eq!(e.to_string(), said, "{}", path.display());
        }
    }
}
