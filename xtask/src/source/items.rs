//! Items in a token stream: matching braces, attributes, test code and `fn` items.

use std::ops::Range;

use super::lex::{Kind, Token};

/// The index of the `}` that closes the `{` at `open` (the last token if it is never closed).
pub fn matching_brace(tokens: &[Token], open: usize) -> usize {
    let mut depth = 0usize;
    for (i, t) in tokens.iter().enumerate().skip(open) {
        if t.is_punct("{") {
            depth += 1;
        } else if t.is_punct("}") {
            depth -= 1;
            if depth == 0 {
                return i;
            }
        }
    }
    tokens.len().saturating_sub(1)
}

/// The end (exclusive) of the attribute `#[…]` or `#![…]` that starts at `i`, if one does.
fn attribute_end(tokens: &[Token], i: usize) -> Option<usize> {
    if !tokens.get(i)?.is_punct("#") {
        return None;
    }
    let mut j = i + 1;
    if tokens.get(j)?.is_punct("!") {
        j += 1;
    }
    if !tokens.get(j)?.is_punct("[") {
        return None;
    }
    let mut depth = 0usize;
    for (k, t) in tokens.iter().enumerate().skip(j) {
        if t.is_punct("[") {
            depth += 1;
        } else if t.is_punct("]") {
            depth -= 1;
            if depth == 0 {
                return Some(k + 1);
            }
        }
    }
    None
}

/// True if the attribute in `tokens` (`#[…]`) marks test code: `#[test]`, or a `cfg` that
/// names `test` and has no `not` (`#[cfg(test)]`, `#[cfg(all(test, …))]`).
fn is_test_attribute(attr: &[Token]) -> bool {
    let words: Vec<&str> = attr.iter().filter_map(Token::word).collect();
    words == ["test"]
        || (words.first() == Some(&"cfg") && words.contains(&"test") && !words.contains(&"not"))
}

/// The end (exclusive) of the item that starts at `i` (after its attributes): its `;` or the
/// `}` closing its first brace at bracket depth 0 (`mod m { … }`, `fn f() -> [u8; 2] { … }`).
pub fn item_end(tokens: &[Token], i: usize) -> usize {
    let mut depth = 0i32;
    for (k, t) in tokens.iter().enumerate().skip(i) {
        match t.kind {
            Kind::Punct("(" | "[") => depth += 1,
            Kind::Punct(")" | "]") => depth -= 1,
            Kind::Punct(";") if depth == 0 => return k + 1,
            Kind::Punct("{") if depth == 0 => return matching_brace(tokens, k) + 1,
            _ => {}
        }
    }
    tokens.len()
}

/// Token ranges of test code: each item carrying a test attribute (its attributes included),
/// or the whole file under an inner `#![cfg(test)]`.
pub fn test_spans(tokens: &[Token]) -> Vec<Range<usize>> {
    let mut spans = Vec::new();
    let mut i = 0;
    while i < tokens.len() {
        let Some(end) = attribute_end(tokens, i) else {
            i += 1;
            continue;
        };
        if !is_test_attribute(&tokens[i..end]) {
            i = end;
            continue;
        }
        if tokens[i + 1].is_punct("!") {
            #[allow(clippy::single_range_in_vec_init, reason = "one span: the whole file")]
            return vec![0..tokens.len()];
        }
        // Further attributes of the same item, then the item.
        let mut start = end;
        while let Some(e) = attribute_end(tokens, start) {
            start = e;
        }
        let stop = item_end(tokens, start);
        spans.push(i..stop);
        i = stop;
    }
    spans
}

/// True if token `i` lies in one of `spans`.
pub fn in_spans(spans: &[Range<usize>], i: usize) -> bool {
    spans.iter().any(|s| s.contains(&i))
}

/// A `fn` item with a body.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct FnItem {
    pub name: String,
    /// Index of the `fn` token.
    pub fn_token: usize,
    /// Index of the item's first token (its first attribute or qualifier such as `pub`).
    pub first_token: usize,
    /// Lines from the `fn` keyword's line to the closing brace's, both included.
    pub lines: usize,
}

/// Every `fn` item with a body outside test code, nested ones included. Trait method
/// declarations without a body, `fn` pointer types and `fn` in macro patterns are not items.
pub fn functions(tokens: &[Token]) -> Vec<FnItem> {
    let tests = test_spans(tokens);
    let mut out = Vec::new();
    for (k, t) in tokens.iter().enumerate() {
        if !t.is_word("fn") || in_spans(&tests, k) {
            continue;
        }
        let Some(name) = tokens.get(k + 1).and_then(Token::word) else {
            continue;
        };
        let mut depth = 0i32;
        let mut body = None;
        for (j, u) in tokens.iter().enumerate().skip(k + 2) {
            match u.kind {
                Kind::Punct("(" | "[") => depth += 1,
                Kind::Punct(")" | "]") => depth -= 1,
                Kind::Punct(";") if depth == 0 => break,
                Kind::Punct("{") if depth == 0 => {
                    body = Some(j);
                    break;
                }
                _ => {}
            }
        }
        let Some(open) = body else { continue };
        let close = matching_brace(tokens, open);
        out.push(FnItem {
            name: name.to_string(),
            fn_token: k,
            first_token: item_start(tokens, k),
            lines: tokens[close].line - t.line + 1,
        });
    }
    out
}

/// The first token of the item whose keyword is at `k`: back over its qualifiers (`pub`,
/// `pub(crate)`, `const`, `async`, `unsafe`, `extern "C"`, `default`) and attributes.
fn item_start(tokens: &[Token], k: usize) -> usize {
    let mut s = k;
    while s > 0 {
        let prev = &tokens[s - 1];
        if ["pub", "const", "async", "unsafe", "extern", "default"]
            .iter()
            .any(|w| prev.is_word(w))
            || (prev.kind == Kind::Literal
                && tokens
                    .get(s.wrapping_sub(2))
                    .is_some_and(|t| t.is_word("extern")))
        {
            s -= 1;
        } else if prev.is_punct(")") {
            // `pub(crate)`, `pub(super)`, `pub(in path)`.
            let Some(open) = (0..s - 1).rev().find(|&j| tokens[j].is_punct("(")) else {
                break;
            };
            if open == 0 || !tokens[open - 1].is_word("pub") {
                break;
            }
            s = open - 1;
        } else if prev.is_punct("]") {
            // An attribute: back to its `#`.
            let Some(hash) = (0..s - 1)
                .rev()
                .find(|&j| tokens[j].is_punct("#") && attribute_end(tokens, j) == Some(s))
            else {
                break;
            };
            s = hash;
        } else {
            break;
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::super::lex::lex;
    use super::*;

    #[test]
    fn functions_outside_tests_with_their_lines() {
        let src = "\
/// Doc.
#[inline]
pub(crate) fn a() -> [u8; 2] {
    [1, 2]
}
trait T { fn decl(&self); fn with_default(&self) {} }
type P = fn(u8) -> u8;
#[cfg(test)]
mod tests {
    fn helper() {}
}
#[test]
fn t() {}
const unsafe extern \"C\" fn b() { fn inner() {
} }
";
        let l = lex(src);
        let f = functions(&l.tokens);
        let got: Vec<(&str, usize, usize)> = f
            .iter()
            .map(|f| (f.name.as_str(), l.tokens[f.first_token].line, f.lines))
            .collect();
        assert_eq!(
            got,
            [
                ("a", 2, 3),
                ("with_default", 6, 1),
                ("b", 14, 2),
                ("inner", 14, 2)
            ]
        );
    }

    #[test]
    fn an_inner_cfg_test_makes_the_whole_file_test_code() {
        let l = lex("#![cfg(test)]\nfn a() {}\n");
        assert!(functions(&l.tokens).is_empty());
        // `cfg(not(test))` is not test code.
        let l = lex("#[cfg(not(test))]\nfn a() {}\n");
        assert_eq!(functions(&l.tokens).len(), 1);
    }
}
