//! The type stubs (chatterspice.pyi) name every function and class the
//! extension module adds: a function registered without a stub would be
//! invisible to type checkers, and mypy's stubtest (run by the Python
//! tests) only checks the names the stubs have.

use std::path::Path;

fn read(path: &str) -> String {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    std::fs::read_to_string(root.join(path)).unwrap_or_else(|e| panic!("{path}: {e}"))
}

/// (Rust name, Python name) of the `#[pyfunction]`s in `source`: the
/// Python name is the `name = "…"` of their `#[pyo3(...)]`, else the Rust
/// name.
fn functions(source: &str) -> Vec<(String, String)> {
    let lines: Vec<&str> = source.lines().map(str::trim).collect();
    let mut names = Vec::new();
    for (k, line) in lines.iter().enumerate() {
        if *line != "#[pyfunction]" {
            continue;
        }
        let attribute = lines[k + 1..]
            .iter()
            .take_while(|l| !l.starts_with("fn ") && !l.starts_with("pub fn "))
            .find_map(|l| l.split("name = \"").nth(1))
            .and_then(|rest| rest.split('"').next());
        let rust = lines[k + 1..]
            .iter()
            .find_map(|l| l.strip_prefix("fn ").or_else(|| l.strip_prefix("pub fn ")))
            .and_then(|rest| rest.split(['(', '<']).next());
        if let Some(rust) = rust {
            names.push((rust.to_owned(), attribute.unwrap_or(rust).to_owned()));
        }
    }
    names
}

/// The last path segment of what each `prefix…end` line of `lib` names,
/// e.g. `py_run` of `m.add_function(wrap_pyfunction!(verdicts::py_run, m)?)?;`.
fn registered<'a>(lib: &'a str, prefix: &str, end: char) -> Vec<&'a str> {
    lib.lines()
        .filter_map(|l| l.trim().strip_prefix(prefix))
        .filter_map(|rest| rest.split(end).next())
        .map(|path| path.rsplit("::").next().unwrap_or(path))
        .collect()
}

#[test]
fn every_function_and_class_the_module_adds_has_a_stub() {
    let stubs = read("chatterspice.pyi");
    let lib = read("src/lib.rs");
    let mut sources = String::new();
    for entry in std::fs::read_dir(Path::new(env!("CARGO_MANIFEST_DIR")).join("src")).unwrap() {
        let path = entry.unwrap().path();
        if path.extension().is_some_and(|e| e == "rs") {
            sources.push_str(&std::fs::read_to_string(&path).unwrap());
        }
    }
    let all = functions(&sources);
    // The functions the module adds (`m.add_function(wrap_pyfunction!(x, m)`).
    let added = registered(&lib, "m.add_function(wrap_pyfunction!(", ',');
    assert!(added.len() >= 10, "{added:?}");
    for rust in &added {
        let (_, name) = all
            .iter()
            .find(|(r, _)| r == rust)
            .unwrap_or_else(|| panic!("{rust}: no #[pyfunction] found"));
        assert!(
            stubs.contains(&format!("\ndef {name}(")),
            "chatterspice.pyi has no `def {name}(`"
        );
    }
    let classes = registered(&lib, "m.add_class::<", '>');
    assert!(classes.len() >= 5, "{classes:?}");
    for class in classes {
        assert!(
            stubs.contains(&format!("\nclass {class}")),
            "chatterspice.pyi has no `class {class}`"
        );
    }
}

#[test]
fn function_names_are_read_from_their_attribute() {
    let source = "#[pyfunction]\n#[pyo3(name = \"run\", signature = (path))]\nfn py_run(\n\
                  x\n#[pyfunction]\nfn plain<'py>(\n";
    let pairs = functions(source);
    assert_eq!(
        pairs,
        [
            ("py_run".to_owned(), "run".to_owned()),
            ("plain".to_owned(), "plain".to_owned())
        ]
    );
}
