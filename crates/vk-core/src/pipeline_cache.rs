//! The pipeline cache kept on disk between runs: one file per device in a cache directory
//! (by default the user's, `$XDG_CACHE_HOME/tessera/pipelines` or `~/.cache/tessera/pipelines`),
//! read when a device is made and written back, atomically, when it is dropped.
//!
//! A file is handed to `vkCreatePipelineCache` only when its header (Vulkan's
//! `VkPipelineCacheHeaderVersionOne`: header size, header version, vendor id, device id and
//! the driver's `pipelineCacheUUID`) matches the device: data of another device or driver
//! version, a truncated file or one of another format is left out (and overwritten at the next
//! save) instead of being trusted to the driver. Each device (vendor, device id, UUID) has its
//! own file name, so two GPUs or two driver versions do not overwrite each other's cache.
//!
//! Writes go to a temporary file in the same directory, then rename over the old one: a run
//! killed mid-write or two runs saving at once leave a whole file, never a torn one. Nothing
//! is written when the cache holds what was read.
//!
//! `TESSERA_PIPELINE_CACHE=off` (or `0`) in the environment turns the disk cache off for every
//! program (the CLI, the window, the C ABI); the CLI's `--no-pipeline-cache` and the C ABI's
//! descriptor fields do the same per run.
use std::path::{Path, PathBuf};

/// The environment variable that turns the on-disk cache off (`off` or `0`).
pub const ENV: &str = "TESSERA_PIPELINE_CACHE";

/// Bytes of `VkPipelineCacheHeaderVersionOne`.
const HEADER_BYTES: usize = 32;

/// Which device and driver a cache file belongs to: the fields of the spec's cache header.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CacheIdentity {
    pub vendor_id: u32,
    pub device_id: u32,
    pub pipeline_cache_uuid: [u8; 16],
}

impl CacheIdentity {
    /// The file of this device in `dir`.
    pub fn file_in(&self, dir: &Path) -> PathBuf {
        let uuid: String = self
            .pipeline_cache_uuid
            .iter()
            .map(|b| format!("{b:02x}"))
            .collect();
        dir.join(format!(
            "{:04x}-{:04x}-{uuid}.bin",
            self.vendor_id, self.device_id
        ))
    }
}

/// Why a cache file's data was not used.
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum HeaderMismatch {
    #[error("{len} bytes, shorter than the 32-byte header")]
    Short { len: usize },
    #[error("header size {size} (expected at least 32 and at most the file's {len} bytes)")]
    HeaderSize { size: u32, len: usize },
    #[error("header version {version} (expected 1, VK_PIPELINE_CACHE_HEADER_VERSION_ONE)")]
    Version { version: u32 },
    #[error("vendor {found:#06x}, device {found_device:#06x} (this device is {vendor:#06x}, {device:#06x})")]
    Device {
        found: u32,
        found_device: u32,
        vendor: u32,
        device: u32,
    },
    #[error("pipelineCacheUUID of another driver build")]
    Uuid,
}

fn word(data: &[u8], at: usize) -> u32 {
    let mut w = [0u8; 4];
    w.copy_from_slice(&data[at..at + 4]);
    u32::from_le_bytes(w)
}

/// Checks `data`'s `VkPipelineCacheHeaderVersionOne` against `id` (little-endian, as every
/// device Tessera runs on stores it).
pub fn check_header(data: &[u8], id: &CacheIdentity) -> Result<(), HeaderMismatch> {
    if data.len() < HEADER_BYTES {
        return Err(HeaderMismatch::Short { len: data.len() });
    }
    let size = word(data, 0);
    if (size as usize) < HEADER_BYTES || size as usize > data.len() {
        return Err(HeaderMismatch::HeaderSize {
            size,
            len: data.len(),
        });
    }
    let version = word(data, 4);
    if version != 1 {
        return Err(HeaderMismatch::Version { version });
    }
    let (vendor, device) = (word(data, 8), word(data, 12));
    if (vendor, device) != (id.vendor_id, id.device_id) {
        return Err(HeaderMismatch::Device {
            found: vendor,
            found_device: device,
            vendor: id.vendor_id,
            device: id.device_id,
        });
    }
    if data[16..32] != id.pipeline_cache_uuid {
        return Err(HeaderMismatch::Uuid);
    }
    Ok(())
}

/// False when [`ENV`] turns the on-disk cache off (`off`, `0`, `no`, `false`).
pub fn allowed_by_env() -> bool {
    let Some(v) = std::env::var_os(ENV) else {
        return true;
    };
    match v.to_str().map(str::to_ascii_lowercase).as_deref() {
        Some("off" | "0" | "no" | "false") => false,
        Some("on" | "1" | "yes" | "true" | "") => true,
        _ => {
            log::warn!("{ENV}={v:?}: expected off or on; keeping the cache on");
            true
        }
    }
}

/// The user's cache directory for pipelines, or `None` when [`ENV`] turns the cache off or
/// neither `$XDG_CACHE_HOME` nor `$HOME` is set.
pub fn user_dir() -> Option<PathBuf> {
    if !allowed_by_env() {
        return None;
    }
    let base = std::env::var_os("XDG_CACHE_HOME")
        .filter(|d| !d.is_empty())
        .map(PathBuf::from)
        .or_else(|| std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".cache")))?;
    Some(base.join("tessera").join("pipelines"))
}

/// The data of `path` when its header matches `id`; empty (logged) otherwise.
pub fn load(path: &Path, id: &CacheIdentity) -> Vec<u8> {
    let data = match std::fs::read(path) {
        Ok(d) => d,
        Err(e) if e.kind() == std::io::ErrorKind::NotFound => return Vec::new(),
        Err(e) => {
            log::warn!("pipeline cache {} not read: {e}", path.display());
            return Vec::new();
        }
    };
    match check_header(&data, id) {
        Ok(()) => {
            log::info!(
                "pipeline cache: {} bytes from {}",
                data.len(),
                path.display()
            );
            data
        }
        Err(why) => {
            log::info!("pipeline cache {} left out: {why}", path.display());
            Vec::new()
        }
    }
}

/// Writes `data` to `path` through a temporary file in the same directory and a rename.
pub fn save(path: &Path, data: &[u8]) -> std::io::Result<()> {
    let dir = path.parent().unwrap_or(Path::new("."));
    std::fs::create_dir_all(dir)?;
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    static SAVES: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);
    let n = SAVES.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let tmp = dir.join(format!(".{name}.{}.{n}.tmp", std::process::id()));
    let written = std::fs::write(&tmp, data).and_then(|()| std::fs::rename(&tmp, path));
    if written.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    written
}

#[cfg(test)]
mod tests {
    use super::*;

    const ID: CacheIdentity = CacheIdentity {
        vendor_id: 0x10de,
        device_id: 0x2335,
        pipeline_cache_uuid: [7; 16],
    };

    fn header(size: u32, version: u32, vendor: u32, device: u32, uuid: [u8; 16]) -> Vec<u8> {
        let mut d = Vec::new();
        for w in [size, version, vendor, device] {
            d.extend_from_slice(&w.to_le_bytes());
        }
        d.extend_from_slice(&uuid);
        d.extend_from_slice(b"driver data");
        d
    }

    #[test]
    fn headers_of_another_device_driver_or_format_are_refused() {
        assert_eq!(
            check_header(&header(32, 1, 0x10de, 0x2335, [7; 16]), &ID),
            Ok(())
        );
        assert_eq!(
            check_header(&[0; 31], &ID),
            Err(HeaderMismatch::Short { len: 31 })
        );
        assert!(matches!(
            check_header(&header(16, 1, 0x10de, 0x2335, [7; 16]), &ID),
            Err(HeaderMismatch::HeaderSize { size: 16, .. })
        ));
        assert!(matches!(
            check_header(&header(4096, 1, 0x10de, 0x2335, [7; 16]), &ID),
            Err(HeaderMismatch::HeaderSize { size: 4096, .. })
        ));
        assert_eq!(
            check_header(&header(32, 2, 0x10de, 0x2335, [7; 16]), &ID),
            Err(HeaderMismatch::Version { version: 2 })
        );
        assert!(matches!(
            check_header(&header(32, 1, 0x1002, 0x2335, [7; 16]), &ID),
            Err(HeaderMismatch::Device { found: 0x1002, .. })
        ));
        assert!(matches!(
            check_header(&header(32, 1, 0x10de, 0x2330, [7; 16]), &ID),
            Err(HeaderMismatch::Device { .. })
        ));
        let mut uuid = [7; 16];
        uuid[15] = 8;
        assert_eq!(
            check_header(&header(32, 1, 0x10de, 0x2335, uuid), &ID),
            Err(HeaderMismatch::Uuid)
        );
    }

    #[test]
    fn files_are_named_per_device_and_saved_whole() {
        let dir = std::env::temp_dir().join(format!("vk-core-cache-{}", std::process::id()));
        let path = ID.file_in(&dir);
        assert_eq!(
            path.file_name().unwrap().to_str().unwrap(),
            "10de-2335-07070707070707070707070707070707.bin"
        );
        let good = header(32, 1, 0x10de, 0x2335, [7; 16]);
        save(&path, &good).unwrap();
        assert_eq!(load(&path, &ID), good);
        // A file of another device is read as empty, not handed to the driver.
        let other = CacheIdentity { device_id: 1, ..ID };
        assert!(load(&path, &other).is_empty());
        assert!(load(&dir.join("absent.bin"), &ID).is_empty());
        // Only the cache file is left: the temporary one was renamed over it.
        let names: Vec<_> = std::fs::read_dir(&dir).unwrap().collect();
        assert_eq!(names.len(), 1);
        let _ = std::fs::remove_dir_all(&dir);
    }
}
