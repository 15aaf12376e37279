//! The kernel's modules import only the ones below them, as ARCHITECTURE.md's layer diagram lists
//! them: the diagram is read from ARCHITECTURE.md ("The layers of the kernel"), and every
//! `crate::<module>` path in the kernel's code (comments and test modules aside) must name a
//! module listed below the one it appears in. A module that imports one above it, an import
//! circle, or a module missing from the diagram fails the test with its file and line.

#![allow(clippy::unwrap_used, clippy::expect_used, clippy::panic, clippy::indexing_slicing)]

use std::collections::HashMap;
use std::path::{Path, PathBuf};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("..")
}

/// The modules of the diagram, top first: the names at the start of its second column
/// (`pair/`, `form_factor.rs`, `real.rs, math.rs`); continuation lines are skipped.
fn diagram_order() -> Vec<String> {
    let text = std::fs::read_to_string(workspace().join("ARCHITECTURE.md")).unwrap();
    let start = text.find("## The layers of the kernel").expect("ARCHITECTURE.md: no layer section");
    let rest = &text[start..];
    let open = rest.find("```text\n").expect("no diagram") + "```text\n".len();
    let close = open + rest[open..].find("```").expect("unterminated diagram");
    let mut order = Vec::new();
    for line in rest[open..close].lines() {
        // Column 2 starts at byte 16; the layer name, if any, is in column 1.
        let Some(cell) = line.get(16..) else { continue };
        let cell = cell.trim_start();
        if cell.is_empty() || line.starts_with("                                  ") {
            continue;
        }
        // "real.rs, math.rs  the float trait": the names up to the first double space.
        let head = cell.split("  ").next().unwrap_or_default();
        for name in head.split(", ") {
            let module = name.trim_end_matches(".rs").trim_end_matches('/');
            assert!(
                module.chars().all(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || c == '_'),
                "unexpected name {name:?} in the diagram line {line:?}"
            );
            order.push(module.to_string());
        }
    }
    order
}

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

#[test]
fn kernel_modules_import_only_the_layers_below() {
    let order = diagram_order();
    let rank: HashMap<&str, usize> = order.iter().enumerate().map(|(i, m)| (m.as_str(), i)).collect();
    assert!(rank.len() > 15, "the diagram lists too few modules: {order:?}");
    let src = workspace().join("pdm-kernel/src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut problems = Vec::new();
    for file in files {
        let rel = file.strip_prefix(&src).unwrap().to_string_lossy().replace('\\', "/");
        let top = rel.split('/').next().unwrap().trim_end_matches(".rs").to_string();
        // The crate root and the guide (documentation only) link everything; test files are not
        // part of the layering.
        if top == "lib" || top == "guide" || rel.ends_with("tests.rs") {
            continue;
        }
        let Some(&own) = rank.get(top.as_str()) else {
            problems.push(format!("{rel}: module `{top}` is not in ARCHITECTURE.md's layer diagram"));
            continue;
        };
        let text = std::fs::read_to_string(&file).unwrap();
        // A file's unit tests (`#[cfg(test)] mod tests { … }` at its end) may reach anything.
        let code = match text.find("#[cfg(test)]\nmod tests {") {
            Some(k) => &text[..k],
            None => &text,
        };
        for (n, line) in code.lines().enumerate() {
            let code_part = line.split("//").next().unwrap_or_default();
            let mut rest = code_part;
            while let Some(k) = rest.find("crate::") {
                rest = &rest[k + "crate::".len()..];
                for target in module_names(rest) {
                    if target == top {
                        continue;
                    }
                    if target.starts_with(|c: char| c.is_ascii_uppercase()) {
                        problems.push(format!("{rel}:{}: `crate::{target}` hides its module: name it", n + 1));
                        continue;
                    }
                    match rank.get(target.as_str()) {
                        None => problems.push(format!("{rel}:{}: `crate::{target}` is not in the diagram", n + 1)),
                        Some(&r) if r < own => {
                            problems.push(format!("{rel}:{}: `{top}` imports `{target}`, which is above it", n + 1));
                        }
                        Some(_) => {}
                    }
                }
            }
        }
    }
    assert!(problems.is_empty(), "layering broken:\n{}", problems.join("\n"));
}

/// The modules a path after `crate::` names: its first word, or for a group `{a::x, b, c::{…}}`
/// the first word of each element (a group that continues on the next lines is read as far as
/// this line goes).
fn module_names(rest: &str) -> Vec<String> {
    let word =
        |s: &str| -> String { s.trim_start().chars().take_while(|c| c.is_ascii_alphanumeric() || *c == '_').collect() };
    let Some(group) = rest.strip_prefix('{') else {
        return vec![word(rest)].into_iter().filter(|w| !w.is_empty()).collect();
    };
    let (mut names, mut depth, mut start) = (Vec::new(), 0usize, 0usize);
    for (i, ch) in group.char_indices() {
        match ch {
            '{' => depth += 1,
            '}' if depth == 0 => {
                names.push(word(&group[start..i]));
                break;
            }
            '}' => depth -= 1,
            ',' if depth == 0 => {
                names.push(word(&group[start..i]));
                start = i + 1;
            }
            _ => {}
        }
    }
    names.retain(|w| !w.is_empty());
    names
}

#[test]
fn module_names_reads_paths_and_groups() {
    assert_eq!(module_names("pair::route(a)"), vec!["pair"]);
    assert_eq!(module_names("{sum::exchange, pair::{a, b}, real::Real};"), vec!["sum", "pair", "real"]);
}
