//! The library's modules depend on each other only as ARCHITECTURE.md allows: the layers go
//! from the text primitives up to the pipeline, and never back. Each file's `crate::MODULE`
//! paths (outside comments) are checked against the table below; `mdp`, the generic MDP core
//! (the model, its solver, graph algorithms and DRN export), uses no game module at all.

use std::collections::BTreeSet;
use std::path::Path;

/// Each module with the modules it may use (besides itself), lowest layer first.
const ALLOWED: &[(&str, &[&str])] = &[
    ("position", &[]),
    ("limits", &[]),
    // `limits` (deadlines, memory budgets) is below everything that can be limited.
    ("stage", &["limits"]),
    ("bdd", &["limits"]),
    ("index", &[]),
    ("csr", &["index"]),
    ("diagnostic", &["position"]),
    ("ltl", &["diagnostic", "position"]),
    (
        "automata",
        &["bdd", "csr", "diagnostic", "index", "limits", "position"],
    ),
    (
        "translate",
        &["automata", "bdd", "csr", "limits", "ltl", "position"],
    ),
    // `stage` (the observer and its progress meter) is at the bottom: any stage may report.
    (
        "arena",
        &[
            "automata",
            "csr",
            "diagnostic",
            "index",
            "position",
            "stage",
        ],
    ),
    (
        "game",
        &[
            "arena", "automata", "csr", "index", "limits", "ltl", "position", "stage",
        ],
    ),
    // The generic MDP core: models, graph algorithms, the solver and DRN; it never sees a game.
    ("mdp", &["csr", "index", "limits", "stage"]),
    // Opportunistic synthesis on the hypergame (its tests build DFAs).
    (
        "opportunistic",
        &[
            "arena",
            "automata",
            "csr",
            "diagnostic",
            "game",
            "index",
            "limits",
            "mdp",
            "position",
            "stage",
        ],
    ),
    // The implicit engine: the readers' arenas and automata, the product's automaton tables
    // and the regions' types, the MDP's rules (levels, risk, adversary, presentation) and the
    // interval type of values.
    (
        "implicit",
        &["arena", "automata", "csr", "game", "mdp", "opportunistic"],
    ),
    // The certificate's checker: the file's reader and the adversary's rules, nothing of the
    // MDP's build, solver, policy or evaluation (see the test below).
    ("certificate", &["arena", "csr", "index", "opportunistic"]),
    // `stage`'s timings appear in JSON reports.
    (
        "report",
        &["arena", "automata", "game", "mdp", "opportunistic", "stage"],
    ),
    (
        "render",
        &["arena", "automata", "game", "mdp", "opportunistic"],
    ),
    // The explorer page: its data as plain values (decision tables and the exported
    // controller's tables) and the page; the pipeline computes the data.
    ("explorer", &["opportunistic", "render"]),
    (
        "pipeline",
        &[
            "arena",
            "automata",
            "certificate",
            "csr",
            "diagnostic",
            "explorer",
            "game",
            "implicit",
            "index",
            "limits",
            "ltl",
            "mdp",
            "position",
            "opportunistic",
            "render",
            "report",
            "stage",
            "translate",
        ],
    ),
    // The test helpers shared by the test binaries and the benchmarks (the `testing` feature).
    ("testing", &["automata", "game", "opportunistic", "render"]),
];

/// The modules `text` names as `crate::MODULE`, outside comments.
fn crate_paths(text: &str) -> BTreeSet<String> {
    let mut modules = BTreeSet::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap_or_default();
        for (at, _) in code.match_indices("crate::") {
            let rest = &code[at + "crate::".len()..];
            let name: String = rest
                .chars()
                .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
                .collect();
            let preceded_by_identifier = code[..at]
                .chars()
                .next_back()
                .is_some_and(|c| c.is_ascii_alphanumeric() || c == '_');
            if !name.is_empty() && !preceded_by_identifier {
                modules.insert(name);
            }
        }
    }
    modules
}

/// The top-level module a file of `src/` belongs to (`None` for `lib.rs`).
fn module_of(src: &Path, file: &Path) -> Option<String> {
    let relative = file.strip_prefix(src).expect("a file under src");
    let first = relative.components().next()?.as_os_str().to_str()?;
    let name = first.strip_suffix(".rs").unwrap_or(first);
    (name != "lib").then(|| name.to_string())
}

#[test]
fn the_scanner_finds_crate_paths_outside_comments_only() {
    let text = "use crate::game::Hypergame;\n\
                let x = crate::mdp::solve(); // crate::render is a comment\n\
                /// see [`crate::report`]\n\
                use mycrate::arena;\n";
    let found: Vec<String> = crate_paths(text).into_iter().collect();
    assert_eq!(found, ["game", "mdp"]);
}

#[test]
fn modules_depend_only_on_lower_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let files = crate::common::rust_files(&src);
    let mut violations = Vec::new();
    let mut seen = BTreeSet::new();
    for file in &files {
        let Some(module) = module_of(&src, file) else {
            continue;
        };
        let Some((_, allowed)) = ALLOWED.iter().find(|(name, _)| *name == module) else {
            violations.push(format!(
                "{}: module `{module}` is not in the table",
                file.display()
            ));
            continue;
        };
        seen.insert(module.clone());
        let text = std::fs::read_to_string(file).expect("a readable source file");
        for used in crate_paths(&text) {
            if used != module && !allowed.contains(&used.as_str()) {
                violations.push(format!("{}: `{module}` uses `{used}`", file.display()));
            }
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
    let listed: BTreeSet<String> = ALLOWED.iter().map(|(name, _)| name.to_string()).collect();
    assert_eq!(seen, listed, "every module of the table exists");
}

/// What a certificate's checker must not use (docs/semantics.md §9.4): the MDP core (its
/// solver among it), the MDP's build, the policy and the controller, the evaluation, the level
/// searches and the views they run on. Their results are what it checks.
const UNTRUSTED: &[&str] = &[
    "crate::mdp",
    "opportunistic::build",
    "opportunistic::controller",
    "opportunistic::evaluate",
    "opportunistic::levels",
    "opportunistic::simulate",
    "opportunistic::view",
];

#[test]
fn the_certificate_checker_uses_nothing_it_checks() {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/certificate");
    let files = crate::common::rust_files(&dir);
    assert!(!files.is_empty(), "the checker's files exist");
    let mut violations = Vec::new();
    for file in &files {
        let text = std::fs::read_to_string(file).expect("a readable source file");
        for (n, line) in text.lines().enumerate() {
            let code = line.split("//").next().unwrap_or_default();
            // `super::` paths stay inside the module; `crate::` paths are what is checked.
            if code.contains("opportunistic::{") {
                let message = "name the modules of `opportunistic` one path each";
                violations.push(format!("{}:{}: {message}", file.display(), n + 1));
            }
            for path in UNTRUSTED {
                if code.contains(path) {
                    violations.push(format!("{}:{}: {path}", file.display(), n + 1));
                }
            }
        }
    }
    assert!(violations.is_empty(), "{}", violations.join("\n"));
}
