//! The module graph of each crate: which modules a module's code depends on, each edge with
//! the line that makes it.
//!
//! A crate is one target ([`super::targets`]); its modules are found from the root through
//! `mod NAME;` declarations (with their `#[path = "…"]`) and inline `mod NAME { … }`, as the
//! compiler finds them. Test code (`#[cfg(test)]`, `#[test]`) is left out; the files of
//! test-only modules are kept apart ([`Crate::test_files`]).
//!
//! An edge goes from a module to the module that **defines** what it names: a path is
//! resolved to its longest module prefix, then the item named there is looked up in that
//! module's namespace, following its `use` declarations (a `pub use` re-export, or a private
//! `use` that its children reach through `super::`) and glob imports to the module that
//! defines the item. So `use super::Limits` in `trajectory::error`, where `trajectory`
//! re-exports `Limits` from `trajectory::paths::waypoints`, is an edge to
//! `trajectory::paths::waypoints`, not to the parent. A `use` is an edge only if the module's
//! own code uses the name it binds (or it privately imports a trait, for its methods): a
//! re-export that only passes a name on is not a dependency of the module that writes it.
//! Items of other crates are not edges.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use super::items::{in_spans, matching_brace, test_spans};
use super::lex::{lex, Lexed, Token};
use super::names::{join, names_in_file, ItemKind, Names};
use super::targets::Kind;

/// Where an edge comes from: the file and line of the `use` or path, and its text.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Site {
    pub file: PathBuf,
    pub line: usize,
    /// `use super::Limits (re-exported by trajectory)`, `crate::sim::fly`.
    pub text: String,
}

/// A module: its file and the modules its code depends on (module paths within the crate,
/// `""` for the crate root; never the module itself), each with the first line that does.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Module {
    pub file: PathBuf,
    pub imports: BTreeSet<String>,
    pub sites: BTreeMap<String, Site>,
}

/// The modules of one crate, by path (`"scenario::check"`; `""` is the root).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Crate {
    /// The package and, for any other target than its library, the target:
    /// `host-sim`, `host-sim bin host-sim`, `firmware build` ([`super::targets::Target`]).
    pub name: String,
    pub kind: Kind,
    pub modules: BTreeMap<String, Module>,
    /// The files of modules declared only under test code (`#[cfg(test)] mod tests;`).
    pub test_files: BTreeSet<PathBuf>,
}

impl Crate {
    /// The module graph: module → the modules it imports.
    pub fn graph(&self) -> BTreeMap<&str, &BTreeSet<String>> {
        self.modules
            .iter()
            .map(|(m, info)| (m.as_str(), &info.imports))
            .collect()
    }

    /// Every file of the crate, test-only module files included.
    pub fn files(&self) -> BTreeSet<PathBuf> {
        let mut out: BTreeSet<PathBuf> = self.modules.values().map(|m| m.file.clone()).collect();
        out.extend(self.test_files.iter().cloned());
        out
    }
}

/// One crate from its root file.
pub fn crate_of(name: String, kind: Kind, root: &Path) -> Crate {
    let (tree, test_files, lexed) = module_tree(root);
    let mut names: BTreeMap<String, Names> = BTreeMap::new();
    for (module, lexed) in &lexed {
        names.extend(names_in_file(&lexed.tokens, module));
    }
    let known: BTreeSet<String> = tree.keys().cloned().collect();
    let resolver = Resolver {
        known: &known,
        names: &names,
    };
    let mut modules: BTreeMap<String, Module> = tree
        .iter()
        .map(|(m, f)| {
            let module = Module {
                file: f.clone(),
                ..Module::default()
            };
            (m.clone(), module)
        })
        .collect();
    for (module, own) in &names {
        let Some(m) = modules.get_mut(module) else {
            continue;
        };
        for (to, line, text) in resolver.edges(module, own) {
            if to != *module && m.imports.insert(to.clone()) {
                let file = m.file.clone();
                m.sites.insert(to, Site { file, line, text });
            }
        }
    }
    Crate {
        name,
        kind,
        modules,
        test_files,
    }
}

/// A crate's modules and their files, the files of its test-only modules, and each
/// module file's tokens (by the module the file holds).
type Tree = (
    BTreeMap<String, PathBuf>,
    BTreeSet<PathBuf>,
    BTreeMap<String, Lexed>,
);

/// The module tree from the root file: every module and its file, as the compiler finds it.
fn module_tree(root: &Path) -> Tree {
    let dir = root.parent().unwrap_or(Path::new(".")).to_path_buf();
    // (module, file, its children's directory, declared under test code).
    let mut files: Vec<(String, PathBuf, PathBuf, bool)> =
        vec![(String::new(), root.to_path_buf(), dir, false)];
    let mut lexed = BTreeMap::new();
    let mut tree: BTreeMap<String, PathBuf> = BTreeMap::new();
    let mut test_files = BTreeSet::new();
    while let Some((module, file, child_dir, test)) = files.pop() {
        let Ok(text) = std::fs::read_to_string(&file) else {
            continue;
        };
        let l = lex(&text);
        let file_dir = file.parent().unwrap_or(Path::new(".")).to_path_buf();
        for decl in module_declarations(&l, &module, &child_dir) {
            let test = test || decl.test;
            match decl.file {
                None if test => {}
                None => {
                    tree.insert(decl.module, file.clone());
                }
                Some(DeclFile::Path(p)) => {
                    let own = file_dir.clone();
                    files.push((decl.module, normalize(&file_dir.join(p)), own, test));
                }
                Some(DeclFile::Default(d)) => {
                    let name = last(&decl.module).to_string();
                    let own = d.join(&name);
                    let flat = d.join(format!("{name}.rs"));
                    let nested = own.join("mod.rs");
                    if flat.is_file() {
                        files.push((decl.module, flat, own, test));
                    } else if nested.is_file() {
                        files.push((decl.module, nested, own, test));
                    }
                }
            }
        }
        if test {
            test_files.insert(file);
        } else {
            tree.insert(module.clone(), file);
            lexed.insert(module, l);
        }
    }
    (tree, test_files, lexed)
}

/// `a/b/../c` as `a/c` (a `#[path]` that climbs out of its folder), without touching the disk.
fn normalize(path: &Path) -> PathBuf {
    let mut out = PathBuf::new();
    for c in path.components() {
        match c {
            std::path::Component::ParentDir if out.file_name().is_some() => {
                out.pop();
            }
            std::path::Component::CurDir => {}
            c => out.push(c),
        }
    }
    out
}

fn last(module: &str) -> &str {
    module.rsplit("::").next().unwrap_or(module)
}

fn parent(module: &str) -> String {
    module
        .rsplit_once("::")
        .map_or(String::new(), |(p, _)| p.to_string())
}

/// Where a declared module's file is.
enum DeclFile {
    /// `#[path = "…"] mod name;`: this path, relative to the declaring file's directory.
    Path(String),
    /// `mod name;`: `name.rs` or `name/mod.rs` in this directory.
    Default(PathBuf),
}

/// A `mod` declaration: the module, its file (`None` for an inline `mod name { … }`), and
/// whether it is under test code.
struct Decl {
    module: String,
    file: Option<DeclFile>,
    test: bool,
}

/// The `mod` declarations of a file, with where each declared module's file is.
fn module_declarations(lexed: &Lexed, module: &str, dir: &Path) -> Vec<Decl> {
    let tokens = &lexed.tokens;
    let tests = test_spans(tokens);
    let mut out = Vec::new();
    // Inline modules open a scope: (module path, its children's directory, closing brace).
    let mut scopes: Vec<(String, PathBuf, usize)> =
        vec![(module.to_string(), dir.to_path_buf(), usize::MAX)];
    for (i, t) in tokens.iter().enumerate() {
        while scopes.len() > 1 && scopes.last().is_some_and(|s| i > s.2) {
            scopes.pop();
        }
        if !t.is_word("mod") {
            continue;
        }
        let Some(name) = tokens.get(i + 1).and_then(Token::word) else {
            continue;
        };
        let (current, current_dir, _) = scopes.last().cloned().unwrap_or_default();
        let m = join(&current, name);
        let test = in_spans(&tests, i);
        match tokens.get(i + 2) {
            Some(t) if t.is_punct(";") => {
                let file = match path_attribute(lexed, i) {
                    Some(p) => DeclFile::Path(p),
                    None => DeclFile::Default(current_dir),
                };
                out.push(Decl {
                    module: m,
                    file: Some(file),
                    test,
                });
            }
            Some(t) if t.is_punct("{") => {
                let close = matching_brace(tokens, i + 2);
                out.push(Decl {
                    module: m.clone(),
                    file: None,
                    test,
                });
                scopes.push((m, current_dir.join(name), close));
            }
            _ => {}
        }
    }
    out
}

/// The `#[path = "…"]` among the attributes and qualifiers before the `mod` at `i`.
fn path_attribute(lexed: &Lexed, i: usize) -> Option<String> {
    let tokens = &lexed.tokens;
    let mut k = i;
    // Back over `pub`, `pub(crate)` and attributes: stop at the previous item's end.
    while k > 0 {
        k -= 1;
        let t = &tokens[k];
        if t.is_punct(";") || t.is_punct("}") || t.is_punct("{") {
            return None;
        }
        if t.is_word("path")
            && tokens.get(k + 1).is_some_and(|t| t.is_punct("="))
            && k > 0
            && tokens[k - 1].is_punct("[")
        {
            return lexed.string(k + 2).map(str::to_string);
        }
    }
    None
}

/// What a path or a name resolves to.
#[derive(Clone, Debug, PartialEq, Eq)]
enum Found {
    /// An item (or module) of this module of the crate.
    Module(String),
    /// Something of another crate (`std`, `nalgebra`), perhaps re-exported by the crate.
    External,
    /// Nothing the scan can see (a local item, a macro-made one).
    Unknown,
}

/// How deep re-exports are followed before giving up (a crate does not chain this many).
const MAX_HOPS: usize = 16;

/// Resolves paths against a crate's modules and their names.
struct Resolver<'a> {
    known: &'a BTreeSet<String>,
    names: &'a BTreeMap<String, Names>,
}

impl Resolver<'_> {
    /// The edges of module `module` with names `own`: (to, line, text).
    fn edges(&self, module: &str, own: &Names) -> Vec<(String, usize, String)> {
        let mut out = Vec::new();
        for u in &own.uses {
            let Some(binds) = &u.binds else {
                // A glob: an edge to the module that defines each name its code uses.
                let Found::Module(from) = self.resolve(&u.segments, module, 0) else {
                    continue;
                };
                for w in &own.words {
                    if let Found::Module(to) = self.lookup(&from, w, 0) {
                        let via = (to != from).then_some(from.as_str());
                        out.push((to.clone(), u.line, with_via(u.text(), via)));
                    }
                }
                continue;
            };
            let (found, via) = self.resolve_via(&u.segments, module);
            let Found::Module(to) = found else { continue };
            let trait_import = !u.public
                && u.segments
                    .last()
                    .is_some_and(|n| self.kind_in(&to, n) == Some(ItemKind::Trait));
            if own.words.contains(binds) || binds == "_" || trait_import {
                out.push((to, u.line, with_via(u.text(), via.as_deref())));
            }
        }
        for p in &own.paths {
            let (found, via) = self.resolve_via(&p.segments, module);
            if let Found::Module(to) = found {
                let text = with_via(p.segments.join("::"), via.as_deref());
                out.push((to, p.line, text));
            }
        }
        out
    }

    fn kind_in(&self, module: &str, name: &str) -> Option<ItemKind> {
        self.names.get(module)?.defines.get(name).copied()
    }

    /// Resolves `path` in `current`, and the module whose namespace passed it on if that is
    /// not the one that defines it (`trajectory` for `super::Limits`).
    fn resolve_via(&self, path: &[String], current: &str) -> (Found, Option<String>) {
        let found = self.resolve(path, current, 0);
        let prefix = self.module_prefix(path, current);
        let via = match (&found, prefix) {
            (Found::Module(to), Some((m, _))) if *to != m => Some(m),
            _ => None,
        };
        (found, via)
    }

    /// What `path`, written in module `current`, names.
    fn resolve(&self, path: &[String], current: &str, hops: usize) -> Found {
        if hops > MAX_HOPS {
            return Found::Unknown;
        }
        if let Some(bound) = self.bound_by_use(path, current) {
            // The path starts with a name a `use` of this module binds: follow that `use`.
            let mut full = bound.segments.clone();
            full.extend(path[1..].iter().cloned());
            return self.resolve(&full, current, hops + 1);
        }
        let Some((module, rest)) = self.module_prefix(path, current) else {
            return Found::External;
        };
        match rest.first() {
            None => Found::Module(module),
            Some(name) => match self.lookup(&module, name, hops + 1) {
                Found::Unknown => Found::Module(module),
                found => found,
            },
        }
    }

    /// The longest prefix of `path` (written in `current`) that is a module of the crate,
    /// and the segments after it; `None` for a path that does not start at a module of the
    /// crate (`std::fmt`, a local type).
    fn module_prefix<'p>(
        &self,
        path: &'p [String],
        current: &str,
    ) -> Option<(String, &'p [String])> {
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
            first if self.known.contains(&join(current, first)) => (current.to_string(), path),
            _ => return None,
        };
        let mut found = base.clone();
        let mut used = 0;
        for (k, seg) in rest.iter().enumerate() {
            base = join(&base, seg);
            if self.known.contains(&base) {
                found = base.clone();
                used = k + 1;
            } else {
                break;
            }
        }
        Some((found, &rest[used..]))
    }

    /// The top-level `use` of `current` that binds the first segment of `path`, if the path
    /// does not start at a module already (`paths::circle::f` after `use super::paths;`).
    fn bound_by_use(&self, path: &[String], current: &str) -> Option<&super::names::UsePath> {
        let first = path.first()?;
        if ["crate", "self", "super"].contains(&first.as_str())
            || self.known.contains(&join(current, first))
        {
            return None;
        }
        self.names
            .get(current)?
            .uses
            .iter()
            .find(|u| u.top_level && u.binds.as_ref() == Some(first) && u.segments[0] != *first)
    }

    /// The module that defines `name` as seen from module `module`'s namespace: its own item,
    /// a child module, or where a `use` or glob of it takes the name from.
    fn lookup(&self, module: &str, name: &str, hops: usize) -> Found {
        if hops > MAX_HOPS {
            return Found::Unknown;
        }
        let child = join(module, name);
        if self.known.contains(&child) {
            return Found::Module(child);
        }
        let Some(names) = self.names.get(module) else {
            return Found::Unknown;
        };
        if names.defines.contains_key(name) {
            return Found::Module(module.to_string());
        }
        let top = names.uses.iter().filter(|u| u.top_level);
        if let Some(u) = top.clone().find(|u| u.binds.as_deref() == Some(name)) {
            return self.resolve(&u.segments, module, hops + 1);
        }
        for glob in top.filter(|u| u.binds.is_none()) {
            if let Found::Module(from) = self.resolve(&glob.segments, module, hops + 1) {
                if let found @ Found::Module(_) = self.lookup(&from, name, hops + 1) {
                    return found;
                }
            }
        }
        Found::Unknown
    }
}

fn with_via(text: String, via: Option<&str>) -> String {
    match via {
        Some(m) => format!("{text} (through {})", display(m)),
        None => text,
    }
}

/// A module's name as the rules print it: the root is `crate`.
pub fn display(module: &str) -> &str {
    if module.is_empty() {
        "crate"
    } else {
        module
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crate from its files (`("lib.rs", "mod a; …")`), written under a directory of its
    /// own (`name`, one per test).
    fn krate(name: &str, files: &[(&str, &str)]) -> Crate {
        let dir = std::env::temp_dir().join(format!("xtask-modules-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for (f, text) in files {
            let p = dir.join(f);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(p, text).unwrap();
        }
        let c = crate_of("t".into(), Kind::Lib, &dir.join("lib.rs"));
        let _ = std::fs::remove_dir_all(&dir);
        c
    }

    fn edges(c: &Crate) -> Vec<String> {
        c.modules
            .iter()
            .flat_map(|(m, info)| {
                info.imports
                    .iter()
                    .map(move |to| format!("{} -> {}", display(m), display(to)))
            })
            .collect()
    }

    #[test]
    fn names_resolve_through_re_exports_to_the_module_that_defines_them() {
        let c = krate("re-exports", &[
            ("lib.rs", "mod t; mod u; mod v; mod w; pub use t::Limits; fn root() {}"),
            ("v.rs", "pub trait Tr { fn m(&self); }"),
            // A re-export its own code does not use: no edge.
            ("w.rs", "pub use crate::t::Limits;"),
            (
                "t/mod.rs",
                "mod limits; mod error; mod deep; pub use limits::Limits; use error::Error as E;\n\
                 pub fn f(e: E) {}",
            ),
            ("t/limits.rs", "pub struct Limits;"),
            (
                "t/error.rs",
                "use super::Limits;\npub struct Error(Limits);",
            ),
            ("t/deep.rs", "use super::*; fn g(_: Limits) {}"),
            // A path through the root's re-export, and a trait imported for its methods.
            (
                "u.rs",
                "pub use crate::t::Limits as L2; use crate::v::Tr;\n\
                 fn h() { let _ = crate::Limits; 1.m(); crate::root(); }",
            ),
        ]);
        assert_eq!(
            edges(&c),
            [
                "t -> t::error",
                "t::deep -> t::limits",
                "t::error -> t::limits",
                "u -> crate",
                "u -> t::limits",
                "u -> v",
            ]
        );
        let site = &c.modules["t::error"].sites["t::limits"];
        assert_eq!(
            (site.line, site.text.as_str()),
            (1, "use super::Limits (through t)")
        );
    }

    #[test]
    fn path_attributes_inline_modules_and_test_modules() {
        let c = krate("path", &[
            (
                "lib.rs",
                "#[path = \"other/x.rs\"]\npub mod x;\nmod i { pub fn f() { crate::x::g(); } }\n\
                 #[cfg(test)]\nmod tests;",
            ),
            ("other/x.rs", "pub fn g() {}"),
            ("tests.rs", "fn t() {}"),
        ]);
        assert_eq!(
            c.modules.keys().collect::<Vec<_>>(),
            ["", "i", "x"],
            "{c:?}"
        );
        assert!(c.modules["x"].file.ends_with("other/x.rs"));
        assert_eq!(edges(&c), ["i -> x"]);
        assert_eq!(c.test_files.len(), 1);
        assert!(c.test_files.iter().all(|f| f.ends_with("tests.rs")));
    }
}
