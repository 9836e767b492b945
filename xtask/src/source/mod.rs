//! The workspace's source rules, read from the files themselves (`cargo test -p xtask` checks
//! them, `xtask/tests/source_rules.rs`; docs/ci.md, Choices 86, 210 and 211). They
//! read every crate of the repository ([`crates`]): each target (library, binaries, examples,
//! benchmarks, build script) of every package. Test code is left out: `#[cfg(test)]` and
//! `#[test]` items, integration tests (`tests/`) and fuzz targets (`fuzz/`, which include the
//! tests' shared helpers); every `.rs` file must belong to some crate ([`unseen_rust_files`]).
//!
//! - **Long functions** ([`long_functions`]): a function outside test code longer than
//!   [`LONG_FN_LINES`] lines says why, in a line comment starting with [`LONG_MARKER`] among
//!   the comments and attributes directly above it (a straight-line state table, a closed form
//!   that reads best whole).
//! - **Import circles** ([`cycles::import_circles`]): no set of modules of a crate reach each
//!   other through their imports. A module depends on the module that defines what it names,
//!   through re-exports ([`modules`]), and on the folders it reaches into, not on its own
//!   ancestors ([`cycles::rule_graph`]); every strongly connected component of two or more
//!   modules is a circle, reported with the line behind each step.
//!
//! The files are read as tokens ([`lex`]), not parsed: braces, comments, strings and character
//! literals are told apart, which is all the rules need, and no parser crate is built for it.

pub mod cycles;
pub mod items;
pub mod lex;
pub mod modules;
pub mod names;
pub mod targets;

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

use cycles::Circle;
use modules::Crate;

/// The longest a function may be (lines from its `fn` keyword to its closing brace) without a
/// reason written beside it.
pub const LONG_FN_LINES: usize = 80;

/// How the reason for a long function starts: `// Long: <reason>` directly above the `fn`
/// (among its doc comment and attributes).
pub const LONG_MARKER: &str = "// Long:";

/// Every `.rs` file under `dir`, sorted; directories named `target` or starting with a dot
/// are not searched.
pub fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if p.is_dir() {
                if name != "target" && !name.starts_with('.') {
                    stack.push(p);
                }
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Every crate of every package under `root` (each target, test code included), with its
/// module graph.
pub fn all_crates(root: &Path) -> Result<Vec<Crate>, String> {
    Ok(targets::packages(root)?
        .iter()
        .flat_map(|(name, dir, manifest)| targets::targets(name, dir, manifest))
        .map(|t| modules::crate_of(t.crate_name(), t.kind, &t.root))
        .collect())
}

/// The crates the rules check: [`all_crates`] but integration tests and fuzz targets.
pub fn crates(root: &Path) -> Result<Vec<Crate>, String> {
    let mut all = all_crates(root)?;
    all.retain(|c| !c.kind.is_test_code());
    Ok(all)
}

/// Every import circle of the crates under `root`, its files relative to `root`.
pub fn circles(root: &Path) -> Result<Vec<Circle>, String> {
    let mut out: Vec<Circle> = crates(root)?
        .iter()
        .flat_map(cycles::import_circles)
        .collect();
    for step in out
        .iter_mut()
        .flat_map(|c| c.walk.iter_mut().chain(c.other_edges.iter_mut()))
    {
        if let Ok(rel) = step.site.file.strip_prefix(root) {
            step.site.file = rel.to_path_buf();
        }
    }
    Ok(out)
}

/// `.rs` files under `root` that no crate reads (as a module of any target, test modules and
/// integration tests included): a file the rules would never see.
pub fn unseen_rust_files(root: &Path) -> Result<Vec<PathBuf>, String> {
    let seen: BTreeSet<PathBuf> = all_crates(root)?.iter().flat_map(Crate::files).collect();
    Ok(rust_files(root)
        .into_iter()
        .filter(|f| !seen.contains(f))
        .map(|f| f.strip_prefix(root).unwrap_or(&f).to_path_buf())
        .collect())
}

/// Every function longer than [`LONG_FN_LINES`] in the files of the crates the rules check
/// (each file once, test-only module files left out), with its file relative to `root`.
pub fn workspace_long_functions(root: &Path) -> Result<Vec<(PathBuf, LongFn)>, String> {
    let files: BTreeSet<PathBuf> = crates(root)?
        .iter()
        .flat_map(|c| c.modules.values().map(|m| m.file.clone()))
        .collect();
    let mut out = Vec::new();
    for file in files {
        let text =
            std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
        let rel = file.strip_prefix(root).unwrap_or(&file).to_path_buf();
        out.extend(long_functions(&text).into_iter().map(|f| (rel.clone(), f)));
    }
    Ok(out)
}

/// A function outside test code longer than [`LONG_FN_LINES`].
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LongFn {
    pub name: String,
    /// Line of its `fn` keyword.
    pub line: usize,
    pub lines: usize,
    /// Its [`LONG_MARKER`] comment says why, if it has one.
    pub reason: Option<String>,
}

/// The functions of a file longer than [`LONG_FN_LINES`], with their reasons.
pub fn long_functions(text: &str) -> Vec<LongFn> {
    let lexed = lex::lex(text);
    let tokens = &lexed.tokens;
    items::functions(tokens)
        .into_iter()
        .filter(|f| f.lines > LONG_FN_LINES)
        .map(|f| {
            let fn_line = tokens[f.fn_token].line;
            // The header: lines after the previous item's last token, before the `fn` line.
            let after = f.first_token.checked_sub(1).map_or(0, |p| tokens[p].line);
            let reason = lexed
                .comments
                .iter()
                .filter(|c| c.line > after && c.line < fn_line)
                .find_map(|c| c.text.strip_prefix(LONG_MARKER))
                .map(|r| r.trim().to_string())
                .filter(|r| !r.is_empty());
            LongFn {
                name: f.name,
                line: fn_line,
                lines: f.lines,
                reason,
            }
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn body(n: usize) -> String {
        "    x();\n".repeat(n)
    }

    #[test]
    fn a_long_function_needs_its_reason_directly_above() {
        let src = format!(
            "fn short() {{\n{}}}\n\
             /// Doc.\n// Long: a state table.\n#[inline]\npub fn explained() {{\n{}}}\n\
             // Long: not this one's.\nfn other() {{}}\nfn unexplained() {{\n{}}}\n\
             // Long:\nfn empty_reason() {{\n{}}}\n",
            body(LONG_FN_LINES - 2),
            body(LONG_FN_LINES),
            body(LONG_FN_LINES),
            body(LONG_FN_LINES),
        );
        let got: Vec<(String, usize, Option<String>)> = long_functions(&src)
            .into_iter()
            .map(|f| (f.name, f.lines, f.reason))
            .collect();
        assert_eq!(
            got,
            [
                ("explained", LONG_FN_LINES + 2, Some("a state table.")),
                ("unexplained", LONG_FN_LINES + 2, None),
                ("empty_reason", LONG_FN_LINES + 2, None),
            ]
            .map(|(n, l, r)| (n.to_string(), l, r.map(str::to_string)))
        );
    }
}
