//! The workspace's source rules, read from the files themselves (`cargo test -p xtask` checks
//! them, `xtask/tests/source_rules.rs`; docs/ci.md#the-source-rules):
//!
//! - **Long functions** ([`long_functions`]): a function outside test code longer than
//!   [`LONG_FN_LINES`] lines says why, in a line comment starting with [`LONG_MARKER`] among
//!   the comments and attributes directly above it (a straight-line state table, a closed form
//!   that reads best whole).
//! - **Import circles** ([`modules::import_circles`]): no two modules of a crate import each
//!   other; the module graph itself is [`modules::Crate::graph`], for further rules.
//!
//! The files are read as tokens ([`lex`]), not parsed: braces, comments, strings and character
//! literals are told apart, which is all the rules need, and no parser crate is built for it.

pub mod items;
pub mod lex;
pub mod modules;

use std::path::{Path, PathBuf};

/// The longest a function may be (lines from its `fn` keyword to its closing brace) without a
/// reason written beside it.
pub const LONG_FN_LINES: usize = 80;

/// How the reason for a long function starts: `// Long: <reason>` directly above the `fn`
/// (among its doc comment and attributes).
pub const LONG_MARKER: &str = "// Long:";

/// The workspace's members: (package name, directory), from the root `Cargo.toml`.
pub fn members(root: &Path) -> Result<Vec<(String, PathBuf)>, String> {
    let read = |p: &Path| -> Result<toml::Table, String> {
        let text = std::fs::read_to_string(p).map_err(|e| format!("{}: {e}", p.display()))?;
        text.parse().map_err(|e| format!("{}: {e}", p.display()))
    };
    let manifest = read(&root.join("Cargo.toml"))?;
    let members = manifest
        .get("workspace")
        .and_then(|w| w.get("members"))
        .and_then(|m| m.as_array())
        .ok_or("Cargo.toml: no [workspace] members")?;
    let mut out = Vec::new();
    for m in members {
        let dir = root.join(m.as_str().ok_or("a workspace member is not a string")?);
        let package = read(&dir.join("Cargo.toml"))?;
        let name = package
            .get("package")
            .and_then(|p| p.get("name"))
            .and_then(|n| n.as_str())
            .ok_or_else(|| format!("{}: no package name", dir.display()))?;
        out.push((name.to_string(), dir));
    }
    Ok(out)
}

/// Every `.rs` file under `dir`, sorted.
pub fn rust_files(dir: &Path) -> Vec<PathBuf> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).into_iter().flatten().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p);
            } else if p.extension().is_some_and(|x| x == "rs") {
                out.push(p);
            }
        }
    }
    out.sort();
    out
}

/// Every crate (lib and binary targets) of every workspace member, with its module graph.
pub fn crates(root: &Path) -> Result<Vec<modules::Crate>, String> {
    Ok(members(root)?
        .iter()
        .flat_map(|(name, dir)| modules::crates_of(name, dir))
        .collect())
}

/// Every function longer than [`LONG_FN_LINES`] in the `src/` trees of the workspace's members,
/// with its file relative to `root`.
pub fn workspace_long_functions(root: &Path) -> Result<Vec<(PathBuf, LongFn)>, String> {
    let mut out = Vec::new();
    for (_, dir) in members(root)? {
        for file in rust_files(&dir.join("src")) {
            let text =
                std::fs::read_to_string(&file).map_err(|e| format!("{}: {e}", file.display()))?;
            let rel = file.strip_prefix(root).unwrap_or(&file).to_path_buf();
            out.extend(long_functions(&text).into_iter().map(|f| (rel.clone(), f)));
        }
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
