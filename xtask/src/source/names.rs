//! What one module's code declares and names, read from its file's tokens outside test code:
//! the items it defines, its `use` declarations, the paths in its code and the words it uses.
//! [`super::modules`] resolves these against the whole crate.

use std::collections::{BTreeMap, BTreeSet};

use super::items::{in_spans, item_end, matching_brace, test_spans};
use super::lex::Token;

/// What kind of item a module defines under a name (a trait is imported for its methods,
/// whose calls do not spell its name).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ItemKind {
    Trait,
    Other,
}

/// One path of a `use` declaration: `use a::b::{c as d, e::*};` has two.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct UsePath {
    /// The path's segments as written (`super`, `crate`, `self` kept).
    pub segments: Vec<String>,
    /// The name it binds (the alias, or the last segment; `_` for `as _`); `None` for a glob.
    pub binds: Option<String>,
    /// `pub use` (any `pub(…)` too): a re-export.
    pub public: bool,
    /// At the module's top level (not inside a function body or block).
    pub top_level: bool,
    pub line: usize,
}

impl UsePath {
    /// The declaration as a reader would write it: `use super::Limits`, `use a::b as c`,
    /// `pub use a::*`.
    pub fn text(&self) -> String {
        let vis = if self.public { "pub " } else { "" };
        let path = self.segments.join("::");
        match &self.binds {
            None => format!("{vis}use {path}::*"),
            Some(b) if Some(b) != self.segments.last() => format!("{vis}use {path} as {b}"),
            Some(_) => format!("{vis}use {path}"),
        }
    }
}

/// A path in code (not in a `use`): `crate::a::f`, `super::X::new`, `child::g`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct CodePath {
    pub segments: Vec<String>,
    pub line: usize,
}

/// What one module declares and names.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Names {
    /// Items defined at the module's top level (not modules: those are the crate's tree).
    pub defines: BTreeMap<String, ItemKind>,
    pub uses: Vec<UsePath>,
    pub paths: Vec<CodePath>,
    /// Every word of its code outside `use` declarations (is an imported name used?).
    pub words: BTreeSet<String>,
}

/// The [`Names`] of the modules whose code is in one file: the file's own module `module` and
/// the inline modules (`mod m { … }`) in it, by module path. Test code is left out.
pub fn names_in_file(tokens: &[Token], module: &str) -> BTreeMap<String, Names> {
    let tests = test_spans(tokens);
    let mut out: BTreeMap<String, Names> = BTreeMap::new();
    out.insert(module.to_string(), Names::default());
    // Open scopes: (module, brace depth inside it, the token closing it).
    let mut scopes: Vec<(String, usize, usize)> = vec![(module.to_string(), 0, usize::MAX)];
    let mut i = 0;
    while i < tokens.len() {
        if in_spans(&tests, i) {
            i += 1;
            continue;
        }
        let t = &tokens[i];
        let Some((current, depth, close)) = scopes.last().cloned() else {
            break;
        };
        if i == close {
            scopes.pop();
            i += 1;
            continue;
        }
        let names = out.entry(current.clone()).or_default();
        if t.is_word("mod") && tokens.get(i + 2).is_some_and(|t| t.is_punct("{")) {
            if let Some(name) = tokens[i + 1].word() {
                let inner = join(&current, name);
                out.entry(inner.clone()).or_default();
                scopes.push((inner, 0, matching_brace(tokens, i + 2)));
                i += 3;
                continue;
            }
        }
        if t.is_punct("{") || t.is_punct("}") {
            if let Some(s) = scopes.last_mut() {
                s.1 = if t.is_punct("{") {
                    depth + 1
                } else {
                    depth.saturating_sub(1)
                };
            }
            i += 1;
            continue;
        }
        if t.is_word("use") {
            let end = item_end(tokens, i);
            names.uses.extend(use_paths(tokens, i, end, depth == 0));
            i = end;
            continue;
        }
        if let Some((path, end)) = code_path(tokens, i) {
            names.words.extend(path.segments.iter().cloned());
            names.paths.push(path);
            i = end;
            continue;
        }
        if let Some(w) = t.word() {
            names.words.insert(w.to_string());
            if depth == 0 {
                if let Some((name, kind)) = defined_item(tokens, i) {
                    names.defines.insert(name, kind);
                }
            }
        }
        i += 1;
    }
    out
}

/// The paths of the `use` declaration whose keyword is at `i` and that ends (exclusive) at
/// `end`.
fn use_paths(tokens: &[Token], i: usize, end: usize, top_level: bool) -> Vec<UsePath> {
    let mut paths = Vec::new();
    use_tree(&tokens[i + 1..end], &mut Vec::new(), &mut paths);
    let public = is_public(tokens, i);
    paths
        .into_iter()
        .map(|(segments, binds)| UsePath {
            segments,
            binds,
            public,
            top_level,
            line: tokens[i].line,
        })
        .collect()
}

/// The path in code that starts at `i`, if one does (a word followed by `::`, not after
/// another `::` or a `$`), and the index after it.
fn code_path(tokens: &[Token], i: usize) -> Option<(CodePath, usize)> {
    let first = tokens[i].word()?;
    let starts_path = tokens.get(i + 1).is_some_and(|n| n.is_punct("::"))
        && !(i > 0 && (tokens[i - 1].is_punct("::") || tokens[i - 1].is_punct("$")));
    if !starts_path {
        return None;
    }
    let mut segments = vec![first.to_string()];
    let mut j = i + 1;
    while tokens.get(j).is_some_and(|t| t.is_punct("::")) {
        match tokens.get(j + 1).and_then(Token::word) {
            Some(w) => segments.push(w.to_string()),
            None => break,
        }
        j += 2;
    }
    let line = tokens[i].line;
    Some((CodePath { segments, line }, j))
}

/// `module::child`, or `child` at the root (`""`).
pub fn join(parent: &str, child: &str) -> String {
    if parent.is_empty() {
        child.to_string()
    } else {
        format!("{parent}::{child}")
    }
}

/// True if the `use` at `i` is `pub` or `pub(…)`.
fn is_public(tokens: &[Token], i: usize) -> bool {
    match i.checked_sub(1).map(|p| &tokens[p]) {
        Some(t) if t.is_word("pub") => true,
        Some(t) if t.is_punct(")") => (0..i - 1)
            .rev()
            .find(|&j| tokens[j].is_punct("("))
            .is_some_and(|open| open > 0 && tokens[open - 1].is_word("pub")),
        _ => false,
    }
}

/// The item the keyword at `i` defines at a module's top level, if it does: `fn f`,
/// `struct S`, `enum E`, `union U`, `trait T`, `type A`, `const C`, `static S`,
/// `macro_rules! m`.
fn defined_item(tokens: &[Token], i: usize) -> Option<(String, ItemKind)> {
    let t = &tokens[i];
    let next = tokens.get(i + 1)?;
    let kind = if t.is_word("trait") {
        ItemKind::Trait
    } else {
        ItemKind::Other
    };
    let name = if ["fn", "struct", "enum", "trait", "type"]
        .iter()
        .any(|k| t.is_word(k))
        || (t.is_word("union") && tokens.get(i + 2).is_some_and(|n| !n.is_punct("(")))
    {
        next.word()?
    } else if t.is_word("const") || t.is_word("static") {
        // Not `const fn`, `const unsafe fn`, `const _` or a `const { … }` block.
        let name = if next.is_word("mut") {
            tokens.get(i + 2)?.word()?
        } else {
            next.word()?
        };
        if ["fn", "unsafe", "async", "extern", "_"].contains(&name) {
            return None;
        }
        name
    } else if t.is_word("macro_rules") && next.is_punct("!") {
        tokens.get(i + 2)?.word()?
    } else {
        return None;
    };
    // `impl Trait for X` and `dyn Trait` are not definitions; a keyword after `::` is a path.
    if i > 0 && tokens[i - 1].is_punct("::") {
        return None;
    }
    Some((name.to_string(), kind))
}

/// The paths a `use` tree names (its tokens after `use`, up to the `;`), each as segments
/// from its start with the name it binds (`None` for a glob): `crate::a::{b, c::{self, d as
/// e}, f::*}` gives `crate::a::b` (b), `crate::a::c` (c), `crate::a::c::d` (e), `crate::a::f`
/// (glob). Returns how many tokens it read.
pub fn use_tree(
    tokens: &[Token],
    prefix: &mut Vec<String>,
    out: &mut Vec<(Vec<String>, Option<String>)>,
) -> usize {
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
            out.push((prefix.clone(), None));
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
            let mut binds = prefix.last().cloned();
            if tokens.get(i).is_some_and(|t| t.is_word("as")) {
                binds = tokens.get(i + 1).and_then(Token::word).map(str::to_string);
                i += 2;
            }
            out.push((prefix.clone(), binds));
            break;
        } else {
            // `,`, `}` or `;`: the end of this tree.
            break;
        }
    }
    prefix.truncate(depth);
    i
}

#[cfg(test)]
mod tests {
    use super::super::lex::lex;
    use super::*;

    fn paths(src: &str) -> Vec<String> {
        let toks = lex(src).tokens;
        let mut out = Vec::new();
        use_tree(&toks[1..], &mut Vec::new(), &mut out);
        out.into_iter()
            .map(|(p, b)| format!("{} {}", p.join("::"), b.as_deref().unwrap_or("*")))
            .collect()
    }

    #[test]
    fn use_trees_flatten_to_their_paths_and_the_names_they_bind() {
        assert_eq!(
            paths("use crate::a::{b, c::{self, d as e}, f::*, g as _};"),
            [
                "crate::a::b b",
                "crate::a::c c",
                "crate::a::c::d e",
                "crate::a::f *",
                "crate::a::g _"
            ]
        );
        assert_eq!(paths("use super::super::x;"), ["super::super::x x"]);
        assert_eq!(paths("use std::fmt;"), ["std::fmt fmt"]);
    }

    #[test]
    fn a_file_gives_each_module_its_items_uses_paths_and_words() {
        let src = "\
pub use super::c::X; // crate::d::Y
pub(crate) use self::b::{Z as W};
pub trait T {}
const fn k() {}
static mut S: u8 = 0;
fn f() { use crate::e::E; crate::d::g(); b::h(); let s = \"crate::x\"; struct Inner; }
mod inline { pub struct Q; fn q() { super::f(); } }
#[cfg(test)]
mod tests { use crate::x::Z; struct Tested; }
";
        let got = names_in_file(&lex(src).tokens, "a");
        assert_eq!(got.keys().collect::<Vec<_>>(), ["a", "a::inline"]);
        let a = &got["a"];
        let defs: Vec<(&str, ItemKind)> = a.defines.iter().map(|(n, k)| (n.as_str(), *k)).collect();
        assert_eq!(
            defs,
            [
                ("S", ItemKind::Other),
                ("T", ItemKind::Trait),
                ("f", ItemKind::Other),
                ("k", ItemKind::Other)
            ]
        );
        let uses: Vec<(String, bool)> = a.uses.iter().map(|u| (u.text(), u.top_level)).collect();
        assert_eq!(
            uses,
            [
                ("pub use super::c::X".to_string(), true),
                ("pub use self::b::Z as W".to_string(), true),
                ("use crate::e::E".to_string(), false),
            ]
        );
        let code: Vec<String> = a.paths.iter().map(|p| p.segments.join("::")).collect();
        assert_eq!(code, ["crate::d::g", "b::h"]);
        assert!(a.words.contains("g") && !a.words.contains("X") && !a.words.contains("Tested"));
        let inline = &got["a::inline"];
        assert_eq!(inline.defines.keys().collect::<Vec<_>>(), ["Q", "q"]);
        assert_eq!(inline.paths[0].segments, ["super", "f"]);
    }
}
