//! Rules the sources keep, checked on the files themselves:
//!
//! - **The repository speaks to its readers:** no code, comment, test, shader or document
//!   refers to a work session or a tracker issue by its number — a reader cannot look those
//!   up; history lives in commit messages.
//! - **No technique module imports another's:** a technique folder under
//!   `crates/tess/src/techniques/` (one that declares a registry entry) reaches shared
//!   machinery (`planned_patches`, `face_patches`, `shared`, `windows`, the crate's modules),
//!   never another technique's folder, so each can be read, changed and removed alone.
use std::fs;
use std::path::{Path, PathBuf};

const ROOT: &str = env!("CARGO_MANIFEST_DIR");

/// The folders whose files are checked for history references, and the extensions read.
const SOURCE_DIRS: [&str; 6] = ["crates", "tests", "glsl", "docs", "tools", "examples"];
const EXTENSIONS: [&str; 12] = [
    "rs", "md", "glsl", "comp", "vert", "frag", "tesc", "tese", "toml", "sh", "py", "h",
];

fn files_under(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        let name = entry.file_name();
        if name == "target" || name.to_string_lossy().starts_with('.') {
            continue;
        }
        if path.is_dir() {
            files_under(&path, out);
        } else if path
            .extension()
            .is_some_and(|e| EXTENSIONS.iter().any(|x| e == *x))
        {
            out.push(path);
        }
    }
}

/// `word` followed by an optional plural `s`, then spaces, `#` or `-`, then a digit,
/// case-insensitive (the cases are in [`history_reference_spots_what_it_should`]).
fn history_reference(line: &str, word: &str) -> bool {
    let lower = line.to_ascii_lowercase();
    let mut from = 0;
    while let Some(at) = lower[from..].find(word) {
        let start = from + at;
        let before_ok = start == 0 || !lower.as_bytes()[start - 1].is_ascii_alphanumeric();
        let rest = lower[start + word.len()..].trim_start_matches('s');
        let rest = rest.trim_start_matches([' ', '#', '-']);
        if before_ok && rest.starts_with(|c: char| c.is_ascii_digit()) {
            return true;
        }
        from = start + word.len();
    }
    false
}

#[test]
fn history_reference_spots_what_it_should() {
    // Built at run time, so this file holds no reference itself.
    let hits = [
        ("Session", " 18", ""),
        ("(issue", " 12", "'s list)"),
        ("issues", " 3", " and 4"),
        ("issue", " #7", ""),
        ("the issue", "-11", " frame"),
    ];
    for (head, number, tail) in hits {
        let hit = format!("{head}{number}{tail}");
        let word = if head.to_lowercase().contains("session") {
            "session"
        } else {
            "issue"
        };
        assert!(history_reference(&hit, word), "{hit}");
    }
    for miss in [
        "the session's device",
        "GitHub issue tracker",
        concat!("tiss", "ue 3"),
        "issue a",
    ] {
        assert!(
            !history_reference(miss, "session") && !history_reference(miss, "issue"),
            "{miss}"
        );
    }
}

#[test]
fn no_file_refers_to_a_session_or_issue_by_number() {
    let mut files = Vec::new();
    for dir in SOURCE_DIRS {
        files_under(&Path::new(ROOT).join(dir), &mut files);
    }
    files.push(Path::new(ROOT).join("README.md"));
    assert!(files.len() > 100, "found only {} files", files.len());
    let mut hits = Vec::new();
    for file in &files {
        let Ok(text) = fs::read_to_string(file) else {
            continue;
        };
        for (i, line) in text.lines().enumerate() {
            if history_reference(line, "session") || history_reference(line, "issue") {
                hits.push(format!("{}:{}: {}", file.display(), i + 1, line.trim()));
            }
        }
    }
    assert!(hits.is_empty(), "history references:\n{}", hits.join("\n"));
}

/// The technique folders: those with a file declaring a registry entry.
fn technique_folders(techniques: &Path) -> Vec<String> {
    let mut folders = Vec::new();
    for entry in fs::read_dir(techniques)
        .expect("techniques folder")
        .flatten()
    {
        let mut files = Vec::new();
        files_under(&entry.path(), &mut files);
        let declares = files.iter().any(|f| {
            fs::read_to_string(f).is_ok_and(|t| t.contains(": TechniqueInfo = TechniqueInfo {"))
        });
        if entry.path().is_dir() && declares {
            folders.push(entry.file_name().to_string_lossy().into_owned());
        }
    }
    folders.sort();
    folders
}

#[test]
fn no_technique_module_imports_another() {
    let techniques = Path::new(ROOT).join("crates/tess/src/techniques");
    let folders = technique_folders(&techniques);
    for expected in [
        "adaptive", "acc", "bft", "cpu", "flat", "gregory", "phong", "pn",
    ] {
        assert!(
            folders.iter().any(|f| f == expected),
            "{expected} in {folders:?}"
        );
    }
    assert!(
        !folders.iter().any(|f| f == "planned_patches"),
        "{folders:?}"
    );
    let mut hits = Vec::new();
    for folder in &folders {
        let mut files = Vec::new();
        files_under(&techniques.join(folder), &mut files);
        for file in files {
            let text = fs::read_to_string(&file).expect("source");
            for other in folders.iter().filter(|o| *o != folder) {
                for path in [
                    format!("techniques::{other}"),
                    format!("super::{other}"),
                    format!("super::super::{other}"),
                ] {
                    let used = text.lines().any(|l| {
                        !l.trim_start().starts_with("//")
                            && l.contains(&path)
                            && !l[l.find(&path).unwrap() + path.len()..]
                                .starts_with(|c: char| c.is_alphanumeric() || c == '_')
                    });
                    if used {
                        hits.push(format!("{} uses {path}", file.display()));
                    }
                }
            }
        }
    }
    assert!(hits.is_empty(), "{}", hits.join("\n"));
}
