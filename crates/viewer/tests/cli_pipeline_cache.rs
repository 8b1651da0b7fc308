//! The pipeline cache of the CLI: kept in `$XDG_CACHE_HOME/tessera/pipelines` (one file per
//! device and driver build), and left alone with `--no-pipeline-cache` or
//! `TESSERA_PIPELINE_CACHE=off`.
mod common;
use common::tessera;

#[test]
fn render_keeps_its_pipeline_cache_in_the_users_cache_directory() {
    let root = std::env::temp_dir().join(format!("tessera-cli-cache-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let png = root.join("spot.png");
    std::fs::create_dir_all(&root).unwrap();
    let render = |home: &std::path::Path, extra: &[&str], env: &[(&str, &str)]| {
        let mut args = vec!["render", "-o", png.to_str().unwrap(), "--size", "64x48"];
        args.extend_from_slice(extra);
        let mut env = env.to_vec();
        let home = home.to_str().unwrap().to_owned();
        env.push(("XDG_CACHE_HOME", &home));
        let o = tessera(&args, &env);
        assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    };
    let files = |home: &std::path::Path| -> Vec<std::path::PathBuf> {
        std::fs::read_dir(home.join("tessera/pipelines"))
            .map(|d| d.map(|e| e.unwrap().path()).collect())
            .unwrap_or_default()
    };
    let on = root.join("on");
    render(&on, &[], &[]);
    let cached = files(&on);
    assert_eq!(cached.len(), 1, "{cached:?}");
    assert!(cached[0].extension().is_some_and(|e| e == "bin"));
    let first = std::fs::read(&cached[0]).unwrap();
    assert_eq!(u32::from_le_bytes(first[4..8].try_into().unwrap()), 1);
    // A warm run uses it and leaves one file.
    render(&on, &[], &[]);
    assert_eq!(files(&on).len(), 1);
    for (dir, extra, env) in [
        ("flag", &["--no-pipeline-cache"][..], &[][..]),
        ("env", &[][..], &[("TESSERA_PIPELINE_CACHE", "off")][..]),
    ] {
        let home = root.join(dir);
        render(&home, extra, env);
        assert!(files(&home).is_empty(), "{dir}: {:?}", files(&home));
    }
    let _ = std::fs::remove_dir_all(&root);
}
