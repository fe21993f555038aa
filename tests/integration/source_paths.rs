//! No path of the build checkout reaches the library or the binary: the
//! crate's directory (`env!("CARGO_MANIFEST_DIR")`) appears in `src/` only
//! in test module files (`tests.rs`, `NAME_tests.rs`), where it finds the
//! checkout's test data, and every test module is declared under
//! `#[cfg(test)]`, so none of them is compiled into what is installed.

use std::path::{Path, PathBuf};

const MANIFEST_DIR: &str = concat!("CARGO_", "MANIFEST_DIR");

/// Whether `file` is a test module file.
fn is_test_file(file: &Path) -> bool {
    file.file_name()
        .and_then(|n| n.to_str())
        .is_some_and(|n| n == "tests.rs" || n.ends_with("_tests.rs"))
}

/// The lines (1-based) of `text`, a file that is not a test module file,
/// that name the crate's directory, or declare a module `tests` without
/// `#[cfg(test)]` among the attributes just above it.
fn faults(text: &str) -> Vec<usize> {
    let lines: Vec<&str> = text.lines().collect();
    let mut found = Vec::new();
    for (i, line) in lines.iter().enumerate() {
        if line.contains(MANIFEST_DIR) {
            found.push(i + 1);
        }
        let t = line.trim_start();
        if t.starts_with("mod tests;") || t.starts_with("mod tests {") {
            let gated = lines[..i]
                .iter()
                .rev()
                .take_while(|l| l.trim_start().starts_with("#["))
                .any(|l| l.trim() == "#[cfg(test)]");
            if !gated {
                found.push(i + 1);
            }
        }
    }
    found
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
fn the_checkout_s_path_is_named_only_in_test_module_files() {
    // The check itself: a use in a module's own file is found, in a test
    // block of it too; an ungated test module is found; a gated one is
    // not.
    let use_it = format!("env!(\"{MANIFEST_DIR}\")");
    let in_code = format!("fn f() {{ {use_it}; }}\n");
    let in_block = format!("fn f() {{}}\n#[cfg(test)]\nmod tests {{\n    {use_it};\n}}\n");
    assert_eq!(faults(&in_code), vec![1]);
    assert_eq!(faults(&in_block), vec![4]);
    assert_eq!(faults("#[path = \"a_tests.rs\"]\nmod tests;\n"), vec![2]);
    assert!(faults("#[cfg(test)]\n#[path = \"a_tests.rs\"]\nmod tests;\n").is_empty());
    assert!(is_test_file(Path::new("src/a/b_tests.rs")) && !is_test_file(Path::new("src/b.rs")));

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
    for file in files.iter().filter(|f| !is_test_file(f)) {
        let text = std::fs::read_to_string(file).unwrap();
        for line in faults(&text) {
            found.push(format!("{}:{line}", file.display()));
        }
    }
    assert!(
        found.is_empty(),
        "the checkout's path outside test module files, or a test module \
         not under #[cfg(test)]: {found:?}"
    );
}
