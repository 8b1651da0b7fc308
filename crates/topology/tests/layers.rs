//! The crate's layering (its crate documentation): `error` at the bottom, then `rules/`,
//! `mesh/`, `refine/`, `limit/` and `patches/`, each importing only what is below it.
//!
//! Reads the sources and fails if a module names a module of a higher layer (`crate::…` or a
//! `super::…` that climbs to the crate root), names the crate root's re-exports instead of a
//! real path, or if the modules of the layers import each other in a cycle. It also fails if
//! a folder under `src/` is not a layer listed here, or if the crate documentation does not
//! name every layer, so the layering cannot rot silently.
use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, bottom first: `error` is a module file, the others are folders.
const LAYERS: [&str; 6] = ["error", "rules", "mesh", "refine", "limit", "patches"];

fn src() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The source with comments (doc comments included), string and character literals blanked
/// out, line breaks kept: what is left is code, whose paths are imports.
fn code_only(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    let blank = |out: &mut String, s: &[u8]| {
        for &c in s {
            out.push(if c == b'\n' { '\n' } else { ' ' });
        }
    };
    while i < b.len() {
        let rest = &b[i..];
        if rest.starts_with(b"//") {
            let end = rest.iter().position(|&c| c == b'\n').unwrap_or(rest.len());
            blank(&mut out, &rest[..end]);
            i += end;
        } else if rest.starts_with(b"/*") {
            let end = text[i + 2..].find("*/").map_or(rest.len(), |e| e + 4);
            blank(&mut out, &rest[..end]);
            i += end;
        } else if rest.starts_with(b"r#\"") || rest.starts_with(b"r\"") {
            let hashes = rest[1..].iter().take_while(|&&c| c == b'#').count();
            let close = format!("\"{}", "#".repeat(hashes));
            let body = 2 + hashes;
            let end = text[i + body..]
                .find(&close)
                .map_or(rest.len(), |e| body + e + close.len());
            blank(&mut out, &rest[..end]);
            i += end;
        } else if rest[0] == b'"' {
            let mut j = 1;
            while j < rest.len() && rest[j] != b'"' {
                j += if rest[j] == b'\\' { 2 } else { 1 };
            }
            let end = (j + 1).min(rest.len());
            blank(&mut out, &rest[..end]);
            i += end;
        } else if rest[0] == b'\'' && rest.len() > 2 && (rest[1] == b'\\' || rest[2] == b'\'') {
            // A character literal (`'a'`, `'\n'`, `'\''`); a lifetime has no closing quote.
            // After a backslash the escaped character is skipped, then the closing quote.
            let from = if rest[1] == b'\\' { 3 } else { 2 };
            let end = rest[from.min(rest.len())..]
                .iter()
                .position(|&c| c == b'\'')
                .map_or(1, |e| e + from + 1);
            blank(&mut out, &rest[..end]);
            i += end;
        } else {
            let len = text[i..].chars().next().unwrap().len_utf8();
            out.push_str(&text[i..i + len]);
            i += len;
        }
    }
    out
}

fn ident_at(s: &str) -> &str {
    let end = s
        .find(|c: char| !(c.is_ascii_alphanumeric() || c == '_'))
        .unwrap_or(s.len());
    &s[..end]
}

/// The paths that follow `prefix::` in `code`, one per named item: `crate::a::b` gives
/// `[a, b]`, and `crate::{a::b, c}` gives `[a, b]` and `[c]`. Each comes with its line.
fn paths_after(code: &str, prefix: &str) -> Vec<(usize, Vec<String>)> {
    let mut out = Vec::new();
    let needle = format!("{prefix}::");
    let mut from = 0;
    while let Some(at) = code[from..].find(&needle) {
        let start = from + at;
        from = start + needle.len();
        let before = code[..start].chars().next_back();
        if before.is_some_and(|c| c.is_ascii_alphanumeric() || c == '_' || c == '$') {
            continue; // `pub(crate)`, `$crate`, `my_crate::` are no paths from this crate.
        }
        let line = code[..start].matches('\n').count() + 1;
        collect(&code[from..], Vec::new(), line, &mut out);
    }
    out
}

/// Reads one path (or `{…}` group of paths) at the start of `s`, after the segments `head`.
fn collect(s: &str, head: Vec<String>, line: usize, out: &mut Vec<(usize, Vec<String>)>) {
    let s = s.trim_start();
    if let Some(group) = s.strip_prefix('{') {
        let mut depth = 0;
        let mut item_start = 0;
        for (k, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    collect(&group[item_start..k], head.clone(), line, out);
                    return;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    collect(&group[item_start..k], head.clone(), line, out);
                    item_start = k + 1;
                }
                _ => {}
            }
        }
        return;
    }
    let name = ident_at(s);
    if name.is_empty() {
        if !head.is_empty() {
            out.push((line, head));
        }
        return;
    }
    let mut path = head;
    path.push(name.to_string());
    match s[name.len()..].trim_start().strip_prefix("::") {
        Some(rest) => collect(rest, path, line, out),
        None => out.push((line, path)),
    }
}

/// A module of a layer, as the cycle check sees it: the layer and its first-level module
/// (`limit/eval.rs` and `limit/eval/…` are `("limit", "eval")`; a layer's `mod.rs` is
/// `(layer, "")`; `error.rs` is `("error", "")`).
type Unit = (String, String);

fn unit_of_file(rel: &Path) -> Option<Unit> {
    let parts: Vec<String> = rel
        .iter()
        .map(|p| p.to_string_lossy().trim_end_matches(".rs").to_string())
        .collect();
    match parts.as_slice() {
        [file] if file == "lib" => None,
        [file] => Some((file.clone(), String::new())),
        [layer, m, ..] if m == "mod" => Some((layer.clone(), String::new())),
        [layer, m, ..] => Some((layer.clone(), m.clone())),
        [] => None,
    }
}

/// What a path names, as a unit: `crate::limit::eval::X` is `("limit", "eval")`, and
/// `crate::limit::X` is `("limit", "")` (the layer's own `mod.rs`) unless `X` is a module
/// file of the layer.
fn unit_of_path(path: &[String], modules: &BTreeSet<Unit>) -> Unit {
    let layer = path[0].clone();
    match path.get(1) {
        Some(m) if modules.contains(&(layer.clone(), m.clone())) => (layer, m.clone()),
        _ => (layer, String::new()),
    }
}

fn rank(layer: &str) -> Option<usize> {
    LAYERS.iter().position(|l| *l == layer)
}

#[test]
fn every_folder_is_a_layer_and_the_crate_doc_names_it() {
    let lib = std::fs::read_to_string(src().join("lib.rs")).unwrap();
    let doc: String = lib
        .lines()
        .filter_map(|l| l.strip_prefix("//!"))
        .collect::<Vec<_>>()
        .join("\n");
    let mut missing = Vec::new();
    for entry in std::fs::read_dir(src()).unwrap() {
        let path = entry.unwrap().path();
        let name = path.file_stem().unwrap().to_string_lossy().to_string();
        if path.is_dir() {
            if rank(&name).is_none() {
                missing.push(format!("src/{name}/ is in no layer of tests/layers.rs"));
            }
        } else if name != "lib" && rank(&name).is_none() {
            missing.push(format!(
                "src/{name}.rs is in no layer (a module belongs in a folder)"
            ));
        }
    }
    for layer in LAYERS {
        let named = if layer == "error" {
            "`error`".to_string()
        } else {
            format!("`{layer}/`")
        };
        if !doc.contains(&named) {
            missing.push(format!("the crate documentation does not name {named}"));
        }
        if !lib.contains(&format!("pub mod {layer};")) {
            missing.push(format!("lib.rs does not declare `pub mod {layer};`"));
        }
    }
    assert!(missing.is_empty(), "{}", missing.join("\n"));
}

#[test]
fn layers_import_only_layers_below_them_without_cycles() {
    let root = src();
    let mut files = Vec::new();
    rust_files(&root, &mut files);
    files.sort();
    let units: Vec<(PathBuf, Unit)> = files
        .iter()
        .filter_map(|f| {
            let rel = f.strip_prefix(&root).unwrap().to_path_buf();
            unit_of_file(&rel).map(|u| (rel, u))
        })
        .collect();
    assert!(
        units.len() > 20,
        "the sources were not found under {root:?}"
    );
    let modules: BTreeSet<Unit> = units.iter().map(|(_, u)| u.clone()).collect();

    let mut wrong = Vec::new();
    let mut edges: BTreeMap<Unit, BTreeSet<Unit>> = BTreeMap::new();
    for (rel, unit) in &units {
        let text = std::fs::read_to_string(root.join(rel)).unwrap();
        let code = code_only(&text);
        let from = rank(&unit.0).unwrap_or_else(|| panic!("{rel:?} is in no layer"));
        let mut named = paths_after(&code, "crate");
        // A layer's `mod.rs` is a child of the crate root: `super::` there (outside nested
        // modules, which are indented) is a path from the root.
        if rel.ends_with("mod.rs") {
            for (line, path) in paths_after(&code, "super") {
                let text_line = code.lines().nth(line - 1).unwrap_or("");
                if !text_line.starts_with(' ') {
                    named.push((line, path));
                }
            }
        }
        for (line, path) in named {
            let Some(to) = rank(&path[0]) else {
                wrong.push(format!(
                    "{}:{line}: `crate::{}` is a re-export of the crate root; name its layer",
                    rel.display(),
                    path.join("::")
                ));
                continue;
            };
            if to > from {
                wrong.push(format!(
                    "{}:{line}: layer `{}` imports `crate::{}` of the higher layer `{}`",
                    rel.display(),
                    unit.0,
                    path.join("::"),
                    path[0]
                ));
            }
            let target = unit_of_path(&path, &modules);
            if target != *unit {
                edges.entry(unit.clone()).or_default().insert(target);
            }
        }
        // `super::x` from a module file of a layer names its sibling `x` in the same layer.
        if rel.components().count() == 2 && !rel.ends_with("mod.rs") {
            for (_, path) in paths_after(&code, "super") {
                let sibling = (unit.0.clone(), path[0].clone());
                if modules.contains(&sibling) && sibling != *unit {
                    edges.entry(unit.clone()).or_default().insert(sibling);
                }
            }
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
    assert!(
        edges.values().map(BTreeSet::len).sum::<usize>() > 20,
        "too few imports found: the path reader is broken"
    );

    // Depth-first search for a cycle among the modules.
    fn visit(
        u: &Unit,
        edges: &BTreeMap<Unit, BTreeSet<Unit>>,
        state: &mut BTreeMap<Unit, bool>,
        stack: &mut Vec<Unit>,
    ) -> Option<Vec<Unit>> {
        match state.get(u) {
            Some(true) => return None,
            Some(false) => {
                let at = stack.iter().position(|s| s == u).unwrap();
                let mut cycle = stack[at..].to_vec();
                cycle.push(u.clone());
                return Some(cycle);
            }
            None => {}
        }
        state.insert(u.clone(), false);
        stack.push(u.clone());
        for v in edges.get(u).into_iter().flatten() {
            if let Some(c) = visit(v, edges, state, stack) {
                return Some(c);
            }
        }
        stack.pop();
        state.insert(u.clone(), true);
        None
    }
    let mut state = BTreeMap::new();
    for u in edges.keys() {
        if let Some(cycle) = visit(u, &edges, &mut state, &mut Vec::new()) {
            let names: Vec<String> = cycle
                .iter()
                .map(|(l, m)| {
                    if m.is_empty() {
                        l.clone()
                    } else {
                        format!("{l}::{m}")
                    }
                })
                .collect();
            panic!(
                "modules import each other in a cycle: {}",
                names.join(" -> ")
            );
        }
    }
}

#[test]
fn the_path_reader_sees_groups_and_skips_comments_and_strings() {
    let code = code_only(
        "use crate::{a::{B, C}, d::E};\n// crate::x::Y\nlet s = \"crate::z\"; let c = '\"';\n\
         let q = '\\''; /* crate::w::V */ let r = r#\"crate::u\"#;\n\
         fn f<'a>(x: &'a crate::g::H) {}\npub(crate) fn k() {}\n",
    );
    let paths: Vec<Vec<String>> = paths_after(&code, "crate")
        .into_iter()
        .map(|p| p.1)
        .collect();
    let want: Vec<Vec<String>> = [&["a", "B"][..], &["a", "C"], &["d", "E"], &["g", "H"]]
        .iter()
        .map(|p| p.iter().map(|s| s.to_string()).collect())
        .collect();
    assert_eq!(paths, want);
}
