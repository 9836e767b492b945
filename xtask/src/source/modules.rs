//! The module graph of each crate of the workspace: which modules a module's code names
//! (`use crate::a::…`, `use super::…`, `crate::a::f()` in code, a child module by name), and
//! the import circles between pairs of modules.
//!
//! A crate is one target: a package's `src/lib.rs`, `src/main.rs`, `src/bin/NAME.rs` or
//! `src/bin/NAME/main.rs`; its modules are found from the root through `mod NAME;`
//! declarations (and inline `mod NAME { … }`), as the compiler finds them. Test code
//! (`#[cfg(test)]`, `#[test]`) is left out. A path is resolved to the longest module prefix of
//! it: `crate::scenario::Scenario` names the module `scenario`.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::items::{in_spans, item_end, matching_brace, test_spans};
use super::lex::{lex, Token};

/// A module: its file and the modules its code names (module paths within the crate, `""`
/// for the crate root; never the module itself).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Module {
    pub file: PathBuf,
    pub imports: BTreeSet<String>,
}

/// The modules of one crate, by path (`"scenario::check"`; `""` is the root).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Crate {
    /// The package and, for a binary, its target: `host-sim`, `host-sim bin host-sim`.
    pub name: String,
    pub modules: BTreeMap<String, Module>,
}

impl Crate {
    /// The module graph: module → the modules it imports.
    pub fn graph(&self) -> BTreeMap<&str, &BTreeSet<String>> {
        self.modules
            .iter()
            .map(|(m, info)| (m.as_str(), &info.imports))
            .collect()
    }
}

/// Every crate (lib and binary targets) of the package in `package_dir`.
pub fn crates_of(package: &str, package_dir: &Path) -> Vec<Crate> {
    let src = package_dir.join("src");
    let mut roots: Vec<(String, PathBuf)> = Vec::new();
    if src.join("lib.rs").is_file() {
        roots.push((package.to_string(), src.join("lib.rs")));
    }
    if src.join("main.rs").is_file() {
        roots.push((format!("{package} bin {package}"), src.join("main.rs")));
    }
    let mut bins: Vec<PathBuf> = std::fs::read_dir(src.join("bin"))
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .collect();
    bins.sort();
    for p in bins {
        let stem = p.file_stem().map(|s| s.to_string_lossy().into_owned());
        let stem = stem.unwrap_or_default();
        if p.extension().is_some_and(|x| x == "rs") {
            roots.push((format!("{package} bin {stem}"), p));
        } else if p.join("main.rs").is_file() {
            roots.push((format!("{package} bin {stem}"), p.join("main.rs")));
        }
    }
    roots
        .into_iter()
        .map(|(name, root)| crate_of(name, &root))
        .collect()
}

/// One crate from its root file.
fn crate_of(name: String, root: &Path) -> Crate {
    let dir = root.parent().unwrap_or(Path::new(".")).to_path_buf();
    // First the module tree (names and files), then each module's imports, which need the
    // whole tree to find the longest module prefix of a path.
    let mut files: Vec<(String, PathBuf, PathBuf)> = vec![(String::new(), root.to_path_buf(), dir)];
    let mut lexed = BTreeMap::new();
    let mut tree: BTreeMap<String, PathBuf> = BTreeMap::new();
    while let Some((module, file, child_dir)) = files.pop() {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        let tokens = lex(&text).tokens;
        tree.insert(module.clone(), file.clone());
        for (m, d, decl) in module_declarations(&tokens, &module, &child_dir) {
            match decl {
                Decl::Inline => {
                    tree.insert(m, file.clone());
                }
                Decl::File => {
                    let own = d.join(last(&m));
                    let flat = d.join(format!("{}.rs", last(&m)));
                    let nested = own.join("mod.rs");
                    if flat.is_file() {
                        files.push((m, flat, own));
                    } else if nested.is_file() {
                        files.push((m, nested, own));
                    }
                }
            }
        }
        lexed.insert(module, tokens);
    }
    let known: BTreeSet<String> = tree.keys().cloned().collect();
    let mut modules: BTreeMap<String, Module> = tree
        .iter()
        .map(|(m, f)| {
            (
                m.clone(),
                Module {
                    file: f.clone(),
                    imports: BTreeSet::new(),
                },
            )
        })
        .collect();
    for (module, tokens) in &lexed {
        for (from, to) in imports(tokens, module, &known) {
            if from != to {
                if let Some(m) = modules.get_mut(&from) {
                    m.imports.insert(to);
                }
            }
        }
    }
    Crate { name, modules }
}

fn last(module: &str) -> &str {
    module.rsplit("::").next().unwrap_or(module)
}

fn join(parent: &str, child: &str) -> String {
    if parent.is_empty() {
        child.to_string()
    } else {
        format!("{parent}::{child}")
    }
}

fn parent(module: &str) -> String {
    module
        .rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

enum Decl {
    /// `mod name;`: a file.
    File,
    /// `mod name { … }`: in this file.
    Inline,
}

/// The `mod` declarations of a file outside test code, with the directory where each
/// declared module's own children live.
fn module_declarations(tokens: &[Token], module: &str, dir: &Path) -> Vec<(String, PathBuf, Decl)> {
    let tests = test_spans(tokens);
    let mut out = Vec::new();
    // Inline modules open a scope: (module path, its children's directory, closing brace).
    let mut scopes: Vec<(String, PathBuf, usize)> =
        vec![(module.to_string(), dir.to_path_buf(), usize::MAX)];
    for (i, t) in tokens.iter().enumerate() {
        while scopes.len() > 1 && scopes.last().is_some_and(|s| i > s.2) {
            scopes.pop();
        }
        if !t.is_word("mod") || in_spans(&tests, i) {
            continue;
        }
        let Some(name) = tokens.get(i + 1).and_then(Token::word) else {
            continue;
        };
        let (current, current_dir, _) = scopes.last().cloned().unwrap_or_default();
        let m = join(&current, name);
        match tokens.get(i + 2) {
            Some(t) if t.is_punct(";") => out.push((m, current_dir, Decl::File)),
            Some(t) if t.is_punct("{") => {
                let close = matching_brace(tokens, i + 2);
                out.push((m.clone(), current_dir.clone(), Decl::Inline));
                scopes.push((m, current_dir.join(name), close));
            }
            _ => {}
        }
    }
    out
}

/// (module, module it names) for every path in a file's code outside test code.
fn imports(tokens: &[Token], module: &str, known: &BTreeSet<String>) -> Vec<(String, String)> {
    let tests = test_spans(tokens);
    let mut out = Vec::new();
    let mut scopes: Vec<(String, usize)> = vec![(module.to_string(), usize::MAX)];
    let mut i = 0;
    while i < tokens.len() {
        while scopes.len() > 1 && scopes.last().is_some_and(|s| i > s.1) {
            scopes.pop();
        }
        let current = scopes.last().map(|s| s.0.clone()).unwrap_or_default();
        if in_spans(&tests, i) {
            i += 1;
            continue;
        }
        let t = &tokens[i];
        if t.is_word("mod") && tokens.get(i + 2).is_some_and(|t| t.is_punct("{")) {
            if let Some(name) = tokens[i + 1].word() {
                scopes.push((join(&current, name), matching_brace(tokens, i + 2)));
            }
            i += 3;
            continue;
        }
        if t.is_word("use") {
            let end = item_end(tokens, i);
            let mut paths = Vec::new();
            use_tree(&tokens[i + 1..end], &mut Vec::new(), &mut paths);
            for p in paths {
                if let Some(to) = resolve(&p, &current, known) {
                    out.push((current.clone(), to));
                }
            }
            i = end;
            continue;
        }
        // A path in code: `crate::…`, `super::…`, `self::…`, or `child::…` at its start.
        let starts_path = tokens.get(i + 1).is_some_and(|n| n.is_punct("::"))
            && !(i > 0 && (tokens[i - 1].is_punct("::") || tokens[i - 1].is_punct("$")));
        if let (true, Some(first)) = (starts_path, t.word()) {
            let mut path = vec![first.to_string()];
            let mut j = i + 1;
            while tokens.get(j).is_some_and(|t| t.is_punct("::")) {
                match tokens.get(j + 1).and_then(Token::word) {
                    Some(w) => path.push(w.to_string()),
                    None => break,
                }
                j += 2;
            }
            if let Some(to) = resolve(&path, &current, known) {
                out.push((current.clone(), to));
            }
            i = j;
            continue;
        }
        i += 1;
    }
    out
}

/// The paths a `use` tree names (its tokens after `use`, up to the `;`), each as segments
/// from its start: `crate::a::{b, c::{self, d}}` gives `crate::a::b`, `crate::a::c`,
/// `crate::a::c::d`.
fn use_tree(tokens: &[Token], prefix: &mut Vec<String>, out: &mut Vec<Vec<String>>) -> usize {
    let depth = prefix.len();
    let mut i = 0;
    while i < tokens.len() {
        let t = &tokens[i];
        if t.is_punct("::") {
            i += 1;
        } else if t.is_punct("{") {
            // A group: each element is a tree with this prefix.
            i += 1;
            while i < tokens.len() && !tokens[i].is_punct("}") {
                if tokens[i].is_punct(",") {
                    i += 1;
                    continue;
                }
                // An element that is not a tree (nothing Rust accepts) is skipped.
                i += use_tree(&tokens[i..], prefix, out).max(1);
            }
            i += 1;
            break;
        } else if t.is_punct("*") {
            out.push(prefix.clone());
            i += 1;
            break;
        } else if let Some(w) = t.word() {
            if w == "self" && !prefix.is_empty() {
                // `a::{self, …}`: the module `a` itself.
            } else {
                prefix.push(w.to_string());
            }
            i += 1;
            if tokens.get(i).is_some_and(|t| t.is_punct("::")) {
                continue;
            }
            if tokens.get(i).is_some_and(|t| t.is_word("as")) {
                i += 2;
            }
            out.push(prefix.clone());
            break;
        } else {
            // `,`, `}` or `;`: the end of this tree.
            break;
        }
    }
    prefix.truncate(depth);
    i
}

/// The module a path names: its longest prefix that is a module of the crate, `None` for a
/// path outside the crate (another crate, `std`). `current` is the module the path is in.
fn resolve(path: &[String], current: &str, known: &BTreeSet<String>) -> Option<String> {
    let (mut base, rest) = match path.first()?.as_str() {
        "crate" => (String::new(), &path[1..]),
        "self" => (current.to_string(), &path[1..]),
        "super" => {
            let mut base = current.to_string();
            let mut n = 0;
            while path.get(n).is_some_and(|s| s == "super") {
                base = parent(&base);
                n += 1;
            }
            (base, &path[n..])
        }
        // A child module by name (2018 paths: `use check::invalid;` in `scenario`).
        first if known.contains(&join(current, first)) => (current.to_string(), path),
        _ => return None,
    };
    let mut found = base.clone();
    for seg in rest {
        base = join(&base, seg);
        if known.contains(&base) {
            found = base.clone();
        } else {
            break;
        }
    }
    Some(found)
}

/// True if `a` is an ancestor of `b` (`scenario` of `scenario::check`); the root (`""`) is
/// everything's ancestor.
pub fn is_ancestor(a: &str, b: &str) -> bool {
    a != b && (a.is_empty() || b.starts_with(&format!("{a}::")))
}

/// True if module `x`'s own code depends on module `y`: it names `y`, a module inside `y`
/// (`y::z`), or a module that contains `y` (`scenario` for `scenario::check`: a parent
/// re-exports and uses its children) other than one that contains `x` too (a module's own
/// parent, whose items its siblings also use, or the root).
fn depends(x: &str, xm: &Module, y: &str) -> bool {
    xm.imports
        .iter()
        .any(|m| m == y || is_ancestor(y, m) || (is_ancestor(m, y) && !is_ancestor(m, x)))
}

/// The pairs of modules of `krate` that import each other, each pair once, sorted. A module
/// depends on another when its own code names that module, a module inside it, or a module
/// that contains it other than one that contains the first module too (its parent's items are
/// its siblings' as well). A module and its own ancestor or descendant are never a pair: a
/// parent declares and re-exports its children, and children use their parent's items.
pub fn import_circles(krate: &Crate) -> Vec<(String, String)> {
    let mut out = Vec::new();
    for (a, ma) in &krate.modules {
        for (b, mb) in krate.modules.range::<String, _>((
            std::ops::Bound::Excluded(a.clone()),
            std::ops::Bound::Unbounded,
        )) {
            if is_ancestor(a, b) || is_ancestor(b, a) {
                continue;
            }
            if depends(a, ma, b) && depends(b, mb, a) {
                out.push((a.clone(), b.clone()));
            }
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paths(src: &str) -> Vec<String> {
        let toks = lex(src).tokens;
        let mut out = Vec::new();
        use_tree(&toks[1..], &mut Vec::new(), &mut out);
        out.into_iter().map(|p| p.join("::")).collect()
    }

    #[test]
    fn use_trees_flatten_to_their_paths() {
        assert_eq!(
            paths("use crate::a::{b, c::{self, d as e}, f::*};"),
            [
                "crate::a::b",
                "crate::a::c",
                "crate::a::c::d",
                "crate::a::f"
            ]
        );
        assert_eq!(paths("use super::super::x;"), ["super::super::x"]);
        assert_eq!(paths("use std::fmt;"), ["std::fmt"]);
    }

    fn known(ms: &[&str]) -> BTreeSet<String> {
        ms.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn paths_resolve_to_their_longest_module_prefix() {
        let k = known(&["", "a", "a::b", "c"]);
        let r = |p: &str, cur: &str| {
            let segs: Vec<String> = p.split("::").map(str::to_string).collect();
            resolve(&segs, cur, &k)
        };
        assert_eq!(r("crate::a::b::Item", "c").as_deref(), Some("a::b"));
        assert_eq!(r("crate::a::Item", "c").as_deref(), Some("a"));
        assert_eq!(r("crate::Item", "c").as_deref(), Some(""));
        assert_eq!(r("super::c::f", "a::b").as_deref(), Some("a"));
        assert_eq!(r("super::super::c::f", "a::b").as_deref(), Some("c"));
        assert_eq!(r("self::b::f", "a").as_deref(), Some("a::b"));
        assert_eq!(r("b::f", "a").as_deref(), Some("a::b"));
        assert_eq!(r("nalgebra::Vector6", "a"), None);
    }

    #[test]
    fn code_paths_and_use_lines_become_imports_but_not_comments_or_tests() {
        let k = known(&["", "a", "a::b", "c", "d"]);
        let src = "\
use super::c::X; // crate::d::Y
fn f() { crate::d::g(); b::h(); let s = \"crate::x\"; }
pub(crate) fn g() {}
#[cfg(test)]
mod tests { use crate::x::Z; }
";
        let got: BTreeSet<String> = imports(&lex(src).tokens, "a", &k)
            .into_iter()
            .map(|(_, to)| to)
            .collect();
        assert_eq!(got, known(&["a::b", "c", "d"]));
    }

    fn krate(edges: &[(&str, &[&str])]) -> Crate {
        Crate {
            name: "t".into(),
            modules: edges
                .iter()
                .map(|(m, to)| {
                    (
                        m.to_string(),
                        Module {
                            file: PathBuf::new(),
                            imports: known(to),
                        },
                    )
                })
                .collect(),
        }
    }

    #[test]
    fn circles_are_pairs_that_import_each_other_or_each_others_parents() {
        let c = krate(&[
            ("", &["a", "b", "s"]),
            ("a", &["b", ""]),
            ("b", &["a"]),
            // A parent and its child using each other is not a circle.
            ("s", &["s::p", "s::q"]),
            ("s::p", &["s", "s::q", "paper"]),
            ("s::q", &["s"]),
            // `paper` imports `s`, which holds `s::p`, which imports `paper`.
            ("paper", &["s"]),
            ("sil", &["s::q"]),
            // Siblings that use their parent's items are not a circle.
            ("s::r", &["s"]),
        ]);
        assert_eq!(
            import_circles(&c),
            [("a", "b"), ("paper", "s::p")].map(|(x, y)| (x.to_string(), y.to_string()))
        );
    }
}
