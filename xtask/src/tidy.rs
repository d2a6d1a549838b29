//! Tidy checks of the workspace, run by `cargo test` (rust-analyzer's
//! `xtask/src/tidy.rs`): the layering table, workspace lints, module docs,
//! manifest conventions, library purity and fixture provenance.

use std::fs;
use std::path::{Path, PathBuf};

/// The crate layering (docs/architecture.md, "Architecture Invariant"):
/// each workspace crate with the internal crates it may depend on, in any
/// dependency section (normal, dev, build).
const ALLOWED: &[(&str, &[&str])] = &[
    // layer 0: no internal dependencies, and neither knows the other
    ("levelset", &[]),
    ("sph-harmonics", &[]),
    // layer 1
    ("morph-dna", &["levelset", "sph-harmonics"]),
    // layer 2
    ("cloner", &["morph-dna", "levelset", "sph-harmonics"]),
    // the packers: seed 004's 2D front (with the gradings every packer
    // uses) and seed 001's particle-in-contact solvers at the bottom, the 3D
    // sphere front on both, the grain packer on the sphere front
    ("packer-quadtree", &[]),
    ("packer-contact", &[]),
    (
        "packer-spheres",
        &["packer-quadtree", "packer-contact", "levelset"],
    ),
    (
        "packer-grains",
        &["packer-spheres", "packer-quadtree", "levelset"],
    ),
    // layer 3: the specimen pipeline on the cloner and the packers
    (
        "specimen",
        &[
            "levelset",
            "sph-harmonics",
            "morph-dna",
            "cloner",
            "packer-quadtree",
            "packer-spheres",
            "packer-grains",
        ],
    ),
    // layer 4
    (
        "validate",
        &[
            "levelset",
            "sph-harmonics",
            "morph-dna",
            "cloner",
            "packer-quadtree",
            "packer-contact",
            "packer-spheres",
            "packer-grains",
            "specimen",
        ],
    ),
    // layer 5
    (
        "xtask",
        &[
            "levelset",
            "sph-harmonics",
            "morph-dna",
            "cloner",
            "packer-quadtree",
            "packer-contact",
            "packer-spheres",
            "packer-grains",
            "specimen",
            "validate",
        ],
    ),
];

/// Library crates: no file I/O, environment, clock or printing in `src/`.
const LIBRARIES: &[&str] = &[
    "levelset",
    "sph-harmonics",
    "morph-dna",
    "cloner",
    "packer-quadtree",
    "packer-contact",
    "packer-spheres",
    "packer-grains",
    "specimen",
    "validate",
];

fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask sits in the workspace root")
        .to_path_buf()
}

fn crate_dir(name: &str) -> PathBuf {
    if name == "xtask" {
        root().join("xtask")
    } else {
        root().join("crates").join(name)
    }
}

fn read(path: &Path) -> String {
    fs::read_to_string(path).unwrap_or_else(|e| panic!("reading {}: {e}", path.display()))
}

/// A dependency line of a manifest: (section, package name, line).
#[derive(Debug)]
struct Dep {
    section: String,
    name: String,
    line: String,
}

/// Minimal TOML reading, enough for our manifests: the dependency names of
/// `[dependencies]`, `[dev-dependencies]`, `[build-dependencies]` and their
/// target-specific forms, and `[dependencies.NAME]` tables.
fn dependencies(manifest: &str) -> Vec<Dep> {
    let mut deps = Vec::new();
    let mut section = String::new();
    for raw in manifest.lines() {
        let line = raw.split('#').next().unwrap_or("").trim();
        if line.is_empty() {
            continue;
        }
        if line.starts_with('[') {
            section = line.trim_matches(|c| c == '[' || c == ']').to_owned();
            // [dependencies.foo] style (also [target.'cfg(..)'.dev-dependencies.foo])
            let pieces: Vec<&str> = section.split('.').collect();
            let kind = pieces.iter().position(|p| {
                matches!(
                    *p,
                    "dependencies" | "dev-dependencies" | "build-dependencies"
                )
            });
            if let Some(name) = kind.and_then(|i| pieces.get(i + 1)) {
                deps.push(Dep {
                    section: section.clone(),
                    name: name.trim_matches('"').to_owned(),
                    line: line.to_owned(),
                });
            }
            continue;
        }
        let is_dep_section = ["dependencies", "dev-dependencies", "build-dependencies"]
            .iter()
            .any(|k| section == *k || section.ends_with(&format!(".{k}")));
        if is_dep_section && let Some((key, _)) = line.split_once('=') {
            let name = key.trim().split('.').next().unwrap_or("");
            deps.push(Dep {
                section: section.clone(),
                name: name.trim_matches('"').to_owned(),
                line: line.to_owned(),
            });
        }
    }
    deps
}

/// The layering violations of one manifest, as "from -> to" messages.
fn layering_violations(krate: &str, manifest: &str) -> Vec<String> {
    let internal: Vec<&str> = ALLOWED.iter().map(|(n, _)| *n).collect();
    let allowed = ALLOWED
        .iter()
        .find(|(n, _)| *n == krate)
        .map(|(_, a)| *a)
        .unwrap_or(&[]);
    dependencies(manifest)
        .into_iter()
        .filter(|d| internal.contains(&d.name.as_str()) && !allowed.contains(&d.name.as_str()))
        .map(|d| {
            format!(
                "forbidden dependency edge {krate} -> {} (in [{}]; {krate} may depend on: {})",
                d.name,
                d.section,
                if allowed.is_empty() {
                    "no internal crate".to_owned()
                } else {
                    allowed.join(", ")
                }
            )
        })
        .collect()
}

fn workspace_crates() -> Vec<String> {
    let mut names: Vec<String> = fs::read_dir(root().join("crates"))
        .expect("crates/ exists")
        .flatten()
        .filter(|e| e.path().join("Cargo.toml").exists())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .collect();
    names.push("xtask".to_owned());
    names.sort();
    names
}

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let Ok(entries) = fs::read_dir(dir) else {
        return;
    };
    for entry in entries.flatten() {
        let path = entry.path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

#[test]
fn every_crate_is_in_the_layering_table() {
    let listed: Vec<&str> = ALLOWED.iter().map(|(n, _)| *n).collect();
    for name in workspace_crates() {
        assert!(
            listed.contains(&name.as_str()),
            "crate {name} is not in tidy.rs ALLOWED: add it with its layer (and to docs/architecture.md)"
        );
    }
    for name in listed {
        assert!(
            crate_dir(name).join("Cargo.toml").exists(),
            "ALLOWED names {name}, which does not exist"
        );
    }
}

#[test]
fn layering_is_respected() {
    let mut violations = Vec::new();
    for name in workspace_crates() {
        let manifest = read(&crate_dir(&name).join("Cargo.toml"));
        violations.extend(layering_violations(&name, &manifest));
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}

#[test]
fn layering_check_names_the_forbidden_edge() {
    let manifest = "[package]\nname = \"levelset\"\n\n[dependencies]\nnalgebra.workspace = true\nsph-harmonics = { workspace = true }\n\n[dev-dependencies.morph-dna]\nworkspace = true\n";
    let v = layering_violations("levelset", manifest);
    assert_eq!(v.len(), 2, "{v:?}");
    assert!(
        v[0].starts_with("forbidden dependency edge levelset -> sph-harmonics"),
        "{}",
        v[0]
    );
    assert!(
        v[1].starts_with("forbidden dependency edge levelset -> morph-dna"),
        "{}",
        v[1]
    );
    assert!(
        layering_violations("cloner", "[dependencies]\nmorph-dna.workspace = true\n").is_empty()
    );
}

#[test]
fn every_crate_inherits_workspace_lints_and_package_fields() {
    for name in workspace_crates() {
        let manifest = read(&crate_dir(&name).join("Cargo.toml"));
        let compact: String = manifest
            .lines()
            .map(str::trim)
            .collect::<Vec<_>>()
            .join("\n");
        assert!(
            compact.contains("[lints]\nworkspace = true"),
            "{name}: add `[lints] workspace = true`"
        );
        assert!(
            compact.contains("version = \"0.0.0\""),
            "{name}: internal crates are version 0.0.0"
        );
        assert!(
            compact.contains("publish = false"),
            "{name}: internal crates are publish = false"
        );
        assert!(
            compact.contains(&format!("name = \"{name}\"")),
            "{name}: folder name = package name"
        );
        for field in ["edition.workspace = true", "rust-version.workspace = true"] {
            assert!(compact.contains(field), "{name}: missing `{field}`");
        }
    }
}

#[test]
fn every_dependency_version_lives_in_the_workspace() {
    for name in workspace_crates() {
        let manifest = read(&crate_dir(&name).join("Cargo.toml"));
        for dep in dependencies(&manifest) {
            let ok = dep.line.contains("workspace = true")
                || dep.line.contains(".workspace=true")
                || dep.line.starts_with('[');
            assert!(
                ok,
                "{name}: `{}` must use `workspace = true` (versions live in the root Cargo.toml)",
                dep.line
            );
        }
    }
}

#[test]
fn every_module_has_a_doc_comment() {
    let mut missing = Vec::new();
    for name in workspace_crates() {
        let dir = crate_dir(&name);
        let mut files = Vec::new();
        for sub in ["src", "benches", "tests", "examples"] {
            rust_files(&dir.join(sub), &mut files);
        }
        if dir.join("build.rs").exists() {
            files.push(dir.join("build.rs"));
        }
        for file in files {
            let text = read(&file);
            let first = text
                .lines()
                .map(str::trim)
                .find(|l| !l.is_empty())
                .unwrap_or("");
            if !first.starts_with("//!") {
                missing.push(
                    file.strip_prefix(root())
                        .unwrap_or(&file)
                        .display()
                        .to_string(),
                );
            }
        }
    }
    assert!(
        missing.is_empty(),
        "modules without a `//!` doc:\n{}",
        missing.join("\n")
    );
}

#[test]
fn libraries_touch_no_files_environment_clock_or_stdout() {
    let banned = [
        "std::fs",
        "File::open",
        "File::create",
        "std::env::var",
        "env::var(",
        "Instant::now",
        "SystemTime::now",
        "println!",
        "eprintln!",
        "print!(",
        "stdout()",
    ];
    let mut hits = Vec::new();
    for name in LIBRARIES {
        let mut files = Vec::new();
        rust_files(&crate_dir(name).join("src"), &mut files);
        for file in files {
            // unit-test files may print their seeds
            if file.file_name().is_some_and(|f| f == "tests.rs")
                || file.components().any(|c| c.as_os_str() == "tests")
            {
                continue;
            }
            // inline `#[cfg(test)] mod tests` sit at the end of a file: tests
            // may print their seeds, so scanning stops there
            for (i, line) in read(&file)
                .lines()
                .enumerate()
                .take_while(|(_, l)| l.trim() != "#[cfg(test)]")
            {
                let code = line.split("//").next().unwrap_or("");
                for b in banned {
                    if code.contains(b) {
                        hits.push(format!(
                            "{}:{}: {b}",
                            file.strip_prefix(root()).unwrap_or(&file).display(),
                            i + 1
                        ));
                    }
                }
            }
        }
    }
    assert!(
        hits.is_empty(),
        "library code must not do I/O, read the environment or the clock, or print:\n{}",
        hits.join("\n")
    );
}

#[test]
fn every_fixture_folder_has_a_readme() {
    let fixtures = root().join("fixtures");
    let mut missing = Vec::new();
    for entry in fs::read_dir(&fixtures).expect("fixtures/ exists").flatten() {
        if entry.path().is_dir() && !entry.path().join("README.md").exists() {
            missing.push(entry.file_name().to_string_lossy().into_owned());
        }
    }
    assert!(
        fixtures.join("README.md").exists(),
        "fixtures/README.md is missing"
    );
    assert!(
        missing.is_empty(),
        "fixture folders without README.md: {missing:?}"
    );
}

#[test]
fn readme_test_command_is_what_ci_runs() {
    let readme = read(&root().join("README.md"));
    let ci = read(&root().join(".ci/run"));
    let command = "cargo test --workspace";
    assert!(
        readme.contains(command),
        "README.md must name the test command `{command}`"
    );
    assert!(
        ci.contains(command),
        ".ci/run must run the README's test command `{command}`"
    );
}

mod lengths;

/// Non-test source files of every crate (`src/` of the libraries and xtask).
fn source_files() -> Vec<PathBuf> {
    let mut files = Vec::new();
    for name in workspace_crates() {
        rust_files(&crate_dir(&name).join("src"), &mut files);
    }
    files.retain(|f| !lengths::is_test_file(f.strip_prefix(root()).unwrap_or(f)));
    files.sort();
    files
}

#[test]
fn no_long_functions_or_files() {
    let mut long = Vec::new();
    for file in source_files() {
        let rel = file
            .strip_prefix(root())
            .unwrap_or(&file)
            .display()
            .to_string();
        let (fns, lines) = lengths::measure(&read(&file));
        if lines > lengths::MAX_FILE_LINES {
            long.push(format!(
                "{rel}: {lines} non-test lines (limit {})",
                lengths::MAX_FILE_LINES
            ));
        }
        for f in fns.iter().filter(|f| f.lines > lengths::MAX_FN_LINES) {
            long.push(format!(
                "{rel}:{}: fn {} is {} lines (limit {})",
                f.line,
                f.name,
                f.lines,
                lengths::MAX_FN_LINES
            ));
        }
    }
    assert!(
        long.is_empty(),
        "split these along their stages or concepts (house style, \"Library first\"):\n{}",
        long.join("\n")
    );
}

#[test]
fn lengths_skip_comments_strings_and_tests() {
    let src = "//! doc\nfn short() {\n    let s = \"}}}\";\n    let c = '}';\n    let r = r#\"{\"#;\n    // }\n    /* { /* } */ */\n}\nfn lifetime<'a>(x: &'a str) -> &'a str {\n    x\n}\ntrait T {\n    fn decl(&self);\n}\n#[cfg(test)]\nmod tests {\n    fn in_test() {\n    }\n}\n";
    let (fns, lines) = lengths::measure(src);
    let got: Vec<(&str, usize, usize)> = fns
        .iter()
        .map(|f| (f.name.as_str(), f.line, f.lines))
        .collect();
    assert_eq!(got, vec![("short", 2, 7), ("lifetime", 9, 3)]);
    assert_eq!(lines, 14);
    let long = format!("fn big() {{\n{}}}\n", "    x();\n".repeat(200));
    let (fns, _) = lengths::measure(&long);
    assert_eq!(fns[0].lines, 202);
}

/// The source file of module path `segments` under `src` (`a::b` → `src/a/b.rs` or
/// `src/a/b/mod.rs`), trying the longest prefix that is a module file.
fn module_file(src: &Path, segments: &[&str]) -> Option<PathBuf> {
    (1..=segments.len()).rev().find_map(|n| {
        let rel: PathBuf = segments[..n].iter().collect();
        [
            src.join(&rel).with_extension("rs"),
            src.join(&rel).join("mod.rs"),
        ]
        .into_iter()
        .find(|p| p.exists())
    })
}

#[test]
fn error_types_form_no_module_cycle() {
    // A library's `error.rs` may name types of other modules (a rejection
    // count, a dtype), but those modules must not use the error type back:
    // such a type sits in the wrong file (issue 29).
    let mut cycles = Vec::new();
    for name in LIBRARIES {
        let src = crate_dir(name).join("src");
        let error = read(&src.join("error.rs"));
        let code = lengths::blank(&error);
        for at in code
            .match_indices("crate::")
            .map(|(i, _)| i + "crate::".len())
        {
            let path: Vec<&str> = code[at..]
                .split(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
                .next()
                .unwrap_or("")
                .split("::")
                .filter(|s| s.chars().next().is_some_and(char::is_lowercase))
                .collect();
            if path.is_empty() || path[0] == "error" {
                continue;
            }
            if let Some(file) = module_file(&src, &path) {
                let text = lengths::blank(&read(&file));
                if text.contains("crate::error") || text.contains("crate::{Error") {
                    cycles.push(format!(
                        "{name}: error.rs uses {} and {} uses the error type",
                        path.join("::"),
                        file.strip_prefix(root()).unwrap_or(&file).display()
                    ));
                }
            }
        }
    }
    cycles.sort();
    cycles.dedup();
    assert!(cycles.is_empty(), "{}", cycles.join("\n"));
}
