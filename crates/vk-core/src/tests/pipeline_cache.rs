//! The pipeline cache on disk, on a real device.
use super::*;

/// The pipeline cache file: written at device drop under the device's own name with a header
/// that matches it, and a file of another device in its place is left out and replaced.
#[test]
fn pipeline_cache_files_carry_this_devices_header() {
    let instance = Instance::new(&InstanceDesc {
        app_name: "vk-core-tests".into(),
        validation: Validation::Synchronization,
        surface_extensions: vec![],
    })
    .unwrap();
    let dir = std::env::temp_dir().join(format!("vk-core-pipelines-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    let desc = DeviceDesc {
        pipeline_cache_dir: Some(dir.clone()),
        ..DeviceDesc::default()
    };
    let open = || {
        let device = Device::new(&instance, &desc, &[]).unwrap();
        let f = Fixture::new(&device);
        drop(f);
        let file = device.pipeline_cache_file().unwrap().to_path_buf();
        let id = crate::pipeline_cache::CacheIdentity {
            vendor_id: device.info.vendor_id,
            device_id: device.info.device_id,
            pipeline_cache_uuid: device.info.pipeline_cache_uuid,
        };
        drop(device);
        (file, id)
    };
    let (file, id) = open();
    let data = std::fs::read(&file).unwrap();
    assert_eq!(crate::pipeline_cache::check_header(&data, &id), Ok(()));
    // Another device's data under this name (a copied cache directory): replaced at drop.
    let mut foreign = data.clone();
    foreign[12] ^= 0xff;
    std::fs::write(&file, &foreign).unwrap();
    let (again, _) = open();
    assert_eq!(again, file);
    let data = std::fs::read(&file).unwrap();
    assert_eq!(crate::pipeline_cache::check_header(&data, &id), Ok(()));
    assert_eq!(instance.messages().error_count(), 0);
    let _ = std::fs::remove_dir_all(&dir);
}
