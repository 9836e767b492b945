//! A Rust source file as tokens with line numbers: enough for the source rules (brace
//! matching, `fn` items, paths), not a parser. Comments and the contents of string and
//! character literals never become tokens, so a brace or a `crate::` inside them is not seen;
//! line comments are kept apart with their lines (the long-function rule reads its marker from
//! them).

/// What a token is.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Kind {
    /// An identifier, keyword or number (`fn`, `crate`, `foo`, `0x1F`, `r#type` as `type`).
    Word(String),
    /// One punctuation character; `::` is one token.
    Punct(&'static str),
    /// A string, byte string, raw string or character literal (its text is not kept).
    Literal,
    /// A lifetime or loop label (`'a`).
    Lifetime,
}

/// One token and the line (1-based) it starts on.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Token {
    pub kind: Kind,
    pub line: usize,
}

impl Token {
    /// True if this token is the word `w`.
    pub fn is_word(&self, w: &str) -> bool {
        matches!(&self.kind, Kind::Word(x) if x == w)
    }

    /// True if this token is the punctuation `p`.
    pub fn is_punct(&self, p: &str) -> bool {
        matches!(self.kind, Kind::Punct(x) if x == p)
    }

    /// The word, if this token is one.
    pub fn word(&self) -> Option<&str> {
        match &self.kind {
            Kind::Word(w) => Some(w),
            _ => None,
        }
    }
}

/// A `//` comment (doc comments included) and its line.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct LineComment {
    pub line: usize,
    /// From the `//` to the end of the line.
    pub text: String,
}

/// A lexed file.
#[derive(Clone, Debug, Default)]
pub struct Lexed {
    pub tokens: Vec<Token>,
    pub comments: Vec<LineComment>,
    /// The source text of each string literal token (quotes and prefix included, escapes not
    /// processed), by token index: `#[path = "…"]` names a module's file with one.
    pub strings: std::collections::BTreeMap<usize, String>,
}

impl Lexed {
    /// The contents of the plain string literal at token `i` (`"src/x.rs"` gives `src/x.rs`).
    pub fn string(&self, i: usize) -> Option<&str> {
        self.strings.get(&i)?.strip_prefix('"')?.strip_suffix('"')
    }
}

const PUNCT: &str = "{}()[]<>;,.:#!?&|*+-/=%^@~$";

/// Splits `src` into tokens and line comments. Unterminated literals or comments end at the end
/// of the file (the compiler would refuse the file; the rules need not).
pub fn lex(src: &str) -> Lexed {
    let chars: Vec<char> = src.chars().collect();
    let mut out = Lexed::default();
    let mut line = 1;
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        let start_line = line;
        if c == '\n' {
            line += 1;
            i += 1;
        } else if c.is_whitespace() {
            i += 1;
        } else if c == '/' && next == Some('/') {
            let end = chars[i..]
                .iter()
                .position(|&c| c == '\n')
                .map_or(chars.len(), |n| i + n);
            out.comments.push(LineComment {
                line,
                text: chars[i..end].iter().collect(),
            });
            i = end;
        } else if c == '/' && next == Some('*') {
            i = block_comment_end(&chars, i, &mut line);
        } else if let Some(end) = string_end(&chars, i, &mut line) {
            out.strings
                .insert(out.tokens.len(), chars[i..end].iter().collect());
            out.tokens.push(token(Kind::Literal, start_line));
            i = end;
        } else if c == '\'' {
            let (kind, end) = quote(&chars, i);
            out.tokens.push(token(kind, start_line));
            i = end;
        } else if c == '_' || c.is_alphanumeric() {
            let mut end = i;
            while end < chars.len() && (chars[end] == '_' || chars[end].is_alphanumeric()) {
                end += 1;
            }
            let mut word: String = chars[i..end].iter().collect();
            // A raw identifier: `r#type` is the word `type`.
            if word == "r" && next == Some('#') && chars.get(i + 2).is_some_and(|c| is_ident(*c)) {
                end = i + 2;
                while end < chars.len() && is_ident(chars[end]) {
                    end += 1;
                }
                word = chars[i + 2..end].iter().collect();
            }
            out.tokens.push(token(Kind::Word(word), start_line));
            i = end;
        } else if c == ':' && next == Some(':') {
            out.tokens.push(token(Kind::Punct("::"), start_line));
            i += 2;
        } else {
            let p = PUNCT
                .find(c)
                .map_or("?", |at| &PUNCT[at..at + c.len_utf8()]);
            out.tokens.push(token(Kind::Punct(p), start_line));
            i += 1;
        }
    }
    out
}

fn token(kind: Kind, line: usize) -> Token {
    Token { kind, line }
}

fn is_ident(c: char) -> bool {
    c == '_' || c.is_alphanumeric()
}

/// The index after the (nested) block comment that starts at `i`.
fn block_comment_end(chars: &[char], mut i: usize, line: &mut usize) -> usize {
    let mut depth = 0;
    while i < chars.len() {
        match (chars[i], chars.get(i + 1)) {
            ('/', Some('*')) => {
                depth += 1;
                i += 2;
            }
            ('*', Some('/')) => {
                depth -= 1;
                i += 2;
                if depth == 0 {
                    return i;
                }
            }
            (c, _) => {
                if c == '\n' {
                    *line += 1;
                }
                i += 1;
            }
        }
    }
    i
}

/// If a string literal starts at `i` (`"…"`, `b"…"`, `c"…"`, `r#"…"#`, `br"…"`, `cr"…"`), the
/// index after it. A character literal is not a string (see [`quote`]).
fn string_end(chars: &[char], i: usize, line: &mut usize) -> Option<usize> {
    // The prefix before the quote or the raw string's hashes.
    let mut j = i;
    while j < chars.len() && j < i + 2 && matches!(chars[j], 'b' | 'c' | 'r') {
        j += 1;
    }
    // The letters must not be the tail of a longer word (`cr` in `macro"…"` cannot happen, but
    // `abr"` would be the word `abr`): the caller only gets here at a token's start.
    let prefix: String = chars[i..j].iter().collect();
    let raw = prefix.ends_with('r');
    if !matches!(prefix.as_str(), "" | "b" | "c" | "r" | "br" | "cr") {
        return None;
    }
    if raw {
        let mut hashes = 0;
        while chars.get(j + hashes) == Some(&'#') {
            hashes += 1;
        }
        if chars.get(j + hashes) != Some(&'"') {
            return None;
        }
        let mut k = j + hashes + 1;
        while k < chars.len() {
            if chars[k] == '\n' {
                *line += 1;
            }
            if chars[k] == '"' && (1..=hashes).all(|h| chars.get(k + h) == Some(&'#')) {
                return Some(k + 1 + hashes);
            }
            k += 1;
        }
        return Some(k);
    }
    if chars.get(j) != Some(&'"') {
        return None;
    }
    let mut k = j + 1;
    while k < chars.len() {
        match chars[k] {
            '\\' => {
                if chars.get(k + 1) == Some(&'\n') {
                    *line += 1;
                }
                k += 2;
            }
            '"' => return Some(k + 1),
            c => {
                if c == '\n' {
                    *line += 1;
                }
                k += 1;
            }
        }
    }
    Some(k)
}

/// What starts at the quote at `i`: a character literal (`'a'`, `'\n'`, `'\u{1F}'`, `'''` is
/// not Rust) or a lifetime/label (`'a`, `'static`), and the index after it. A byte literal
/// `b'a'` reaches here as the word `b` then this quote.
fn quote(chars: &[char], i: usize) -> (Kind, usize) {
    match (chars.get(i + 1), chars.get(i + 2)) {
        // '\n', '\'', '\u{…}': to the closing quote after the escape.
        (Some('\\'), _) => {
            let mut k = i + 3;
            while k < chars.len() && chars[k] != '\'' {
                k += 1;
            }
            (Kind::Literal, k + 1)
        }
        // 'x'
        (Some(_), Some('\'')) => (Kind::Literal, i + 3),
        // 'label or 'lifetime
        _ => {
            let mut k = i + 1;
            while k < chars.len() && is_ident(chars[k]) {
                k += 1;
            }
            (Kind::Lifetime, k)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn words(src: &str) -> Vec<String> {
        lex(src)
            .tokens
            .iter()
            .map(|t| match &t.kind {
                Kind::Word(w) => w.clone(),
                Kind::Punct(p) => p.to_string(),
                Kind::Literal => "LIT".into(),
                Kind::Lifetime => "'".into(),
            })
            .collect()
    }

    #[test]
    fn braces_and_paths_inside_literals_and_comments_are_not_tokens() {
        let src = r##"fn f<'a>(x: &'a str) -> char { // } crate::x
            /* { /* nested } */ crate::y */
            let s = "}{ crate::z \" }";
            let r = r#"} " crate::w"#;
            let b = b'{'; let c = '}'; let q = '\''; let u = '\u{7B}';
            'outer: loop { break 'outer; }
            br"}"; c"}";
        }"##;
        let w = words(src);
        // The body's and the loop's braces only.
        assert_eq!(w.iter().filter(|t| *t == "{").count(), 2, "{w:?}");
        assert_eq!(w.iter().filter(|t| *t == "}").count(), 2, "{w:?}");
        assert!(!w.iter().any(|t| t == "crate"), "{w:?}");
        assert_eq!(
            w.iter().filter(|t| *t == "'").count(),
            4,
            "lifetimes and labels: {w:?}"
        );
    }

    #[test]
    fn lines_count_through_multi_line_literals_and_comments() {
        let l = lex("a\n/* x\ny */ b \"1\n2\" c\n// d\nr#\"\n\"# e");
        let lines: Vec<(String, usize)> = l
            .tokens
            .iter()
            .filter_map(|t| t.word().map(|w| (w.to_string(), t.line)))
            .collect();
        assert_eq!(
            lines,
            [("a", 1), ("b", 3), ("c", 4), ("e", 7)].map(|(w, n)| (w.to_string(), n))
        );
        assert_eq!(
            l.comments,
            [LineComment {
                line: 5,
                text: "// d".into()
            }]
        );
    }

    #[test]
    fn string_literals_keep_their_text() {
        let l = lex("#[path = \"a/b.rs\"] mod m; const R: &str = r#\"x\"#;");
        let at = |w: &str| l.tokens.iter().position(|t| t.is_word(w)).unwrap();
        assert_eq!(l.string(at("path") + 2), Some("a/b.rs"));
        assert_eq!(
            l.string(at("str") + 2),
            None,
            "a raw string is not a plain one"
        );
        assert_eq!(l.strings.len(), 2);
    }

    #[test]
    fn path_separators_and_raw_identifiers() {
        assert_eq!(
            words("use crate::a::{b, r#type};"),
            ["use", "crate", "::", "a", "::", "{", "b", ",", "type", "}", ";"]
        );
    }
}
