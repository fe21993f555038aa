//! No path of the build checkout reaches the library or the binary: the
//! crate's directory (`env!("CARGO_MANIFEST_DIR")`) appears in `src/` only
//! in test code, a file's `#[cfg(test)] mod tests` block (its last item)
//! or a test module file of its own (`tests.rs`), where it finds the
//! checkout's test data.

use std::path::{Path, PathBuf};

const MANIFEST_DIR: &str = concat!("CARGO_", "MANIFEST_DIR");

/// The lines (1-based) of `text` that name the crate's directory outside
/// its test block, the `#[cfg(test)]` that opens `mod tests {` and runs
/// to the end of the file.
fn outside_tests(text: &str) -> Vec<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let tests_start = lines
        .windows(2)
        .position(|w| w[0].trim() == "#[cfg(test)]" && w[1].trim_start().starts_with("mod tests {"))
        .unwrap_or(lines.len());
    lines[..tests_start]
        .iter()
        .enumerate()
        .filter(|(_, l)| l.contains(MANIFEST_DIR))
        .map(|(i, _)| i + 1)
        .collect()
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
fn the_checkout_s_path_is_named_only_in_test_code() {
    // The check itself: a use before the test block is found, one in it
    // is not.
    let use_it = format!("env!(\"{MANIFEST_DIR}\")");
    let bad = format!("fn f() {{ {use_it}; }}\n#[cfg(test)]\nmod tests {{\n}}\n");
    let good = format!("fn f() {{}}\n#[cfg(test)]\nmod tests {{\n    {use_it};\n}}\n");
    assert_eq!(outside_tests(&bad), vec![1]);
    assert!(outside_tests(&good).is_empty());

    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(
        files.len() > 50,
        "{} files under {}",
        files.len(),
        src.display()
    );
    let mut found = Vec::new();
    for file in files {
        if file.file_name().is_some_and(|n| n == "tests.rs") {
            continue;
        }
        let text = std::fs::read_to_string(&file).unwrap();
        for line in outside_tests(&text) {
            found.push(format!("{}:{line}", file.display()));
        }
    }
    assert!(
        found.is_empty(),
        "the checkout's path outside test code: {found:?}"
    );
}
