//! The book in docs/ holds together with the code that cites it:
//!
//! - docs/SUMMARY.md lists every page of docs/ and every entry of it is a page;
//! - the register (docs/decisions.md) has one row per Choice, numbered 1 to its last without a
//!   gap or a duplicate, each current row pointing at a section that explains it;
//! - every `Choice N` cited in the code, the READMEs or the docs is a row of the register, and
//!   the pages cite no superseded Choice;
//! - every citation of a page (`docs/<page>.md`, `docs/<page>.md#<anchor>`) and every link
//!   between markdown files resolves, anchors included;
//! - nothing cites the design document the book replaced, or a bare `§N` section number.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The workspace root.
fn root() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .parent()
        .expect("xtask sits in the workspace")
        .to_path_buf()
}

fn read(path: &Path) -> String {
    std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The text files that can cite the docs: sources, manifests, scripts, deployment files and
/// markdown, outside build output and version control.
fn cited_files() -> Vec<PathBuf> {
    const EXTENSIONS: [&str; 8] = ["rs", "md", "toml", "sh", "yaml", "yml", "sbatch", "in"];
    let mut out = Vec::new();
    let mut stack = vec![root()];
    while let Some(dir) = stack.pop() {
        let entries = std::fs::read_dir(&dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display()));
        for entry in entries {
            let path = entry.expect("a directory entry").path();
            let name = path.file_name().and_then(|n| n.to_str()).unwrap_or("");
            if path.is_dir() {
                let skip = ["target", "runs", "out", "corpus", "artifacts"].contains(&name)
                    || (name.starts_with('.') && name != ".cargo" && name != ".ci");
                if !skip {
                    stack.push(path);
                }
            } else if EXTENSIONS.iter().any(|e| name.ends_with(&format!(".{e}"))) {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

fn rel(path: &Path) -> String {
    path.strip_prefix(root())
        .unwrap_or(path)
        .display()
        .to_string()
}

/// A heading's anchor as GitHub makes it: lower case, letters, digits, `-` and `_` kept,
/// spaces turned into `-`, everything else dropped.
fn slug(heading: &str) -> String {
    heading
        .to_lowercase()
        .chars()
        .filter_map(|c| match c {
            ' ' => Some('-'),
            c if c.is_alphanumeric() || c == '-' || c == '_' => Some(c),
            _ => None,
        })
        .collect()
}

/// A markdown file's headings outside code fences: (level, anchor, line index), with GitHub's
/// `-1`, `-2` suffixes on repeated anchors.
fn headings(text: &str) -> Vec<(usize, String, usize)> {
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut fenced = false;
    let mut out = Vec::new();
    for (i, line) in text.lines().enumerate() {
        if line.trim_start().starts_with("```") {
            fenced = !fenced;
            continue;
        }
        let level = line.chars().take_while(|&c| c == '#').count();
        if fenced || level == 0 || !line[level..].starts_with(' ') {
            continue;
        }
        let base = slug(line[level..].trim());
        let n = seen.entry(base.clone()).or_insert(0);
        let anchor = if *n == 0 {
            base.clone()
        } else {
            format!("{base}-{n}")
        };
        *n += 1;
        out.push((level, anchor, i));
    }
    out
}

/// The text of the section under `anchor` (its heading to the next heading of the same or a
/// higher level), or `None` if the file has no such heading.
fn section(text: &str, anchor: &str) -> Option<String> {
    let hs = headings(text);
    let at = hs.iter().position(|(_, a, _)| a == anchor)?;
    let (level, _, start) = hs[at];
    let end = hs[at + 1..]
        .iter()
        .find(|(l, _, _)| *l <= level)
        .map_or(usize::MAX, |(_, _, i)| *i);
    Some(
        text.lines()
            .enumerate()
            .filter(|(i, _)| *i >= start && *i < end)
            .map(|(_, l)| l)
            .collect::<Vec<_>>()
            .join("\n"),
    )
}

/// The anchor characters of a citation after its `#`.
fn anchor_at(s: &str) -> &str {
    let end = s
        .char_indices()
        .find(|&(_, c)| !(c.is_alphanumeric() || c == '-' || c == '_'))
        .map_or(s.len(), |(i, _)| i);
    s[..end].trim_end_matches('-')
}

/// Every Choice number cited in `text`: `Choice N`, `Choices N–M`, `Choices N, M and K`
/// (any case, en dash or hyphen).
fn choices_cited(text: &str) -> Vec<(u32, usize)> {
    let lower = text.to_lowercase();
    let bytes = lower.as_bytes();
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(found) = lower[from..].find("choice") {
        let at = from + found;
        from = at + "choice".len();
        if at > 0 && (bytes[at - 1] as char).is_alphanumeric() {
            continue;
        }
        let mut rest = &lower[from..];
        rest = rest.strip_prefix('s').unwrap_or(rest);
        let Some(mut rest) = rest.strip_prefix(' ') else {
            continue;
        };
        let line = text[..at].matches('\n').count() + 1;
        // The previous number, and whether a dash joins it to the next one.
        let mut last: Option<u32> = None;
        let mut range = false;
        loop {
            let digits: String = rest.chars().take_while(|c| c.is_ascii_digit()).collect();
            let Ok(n) = digits.parse::<u32>() else { break };
            rest = &rest[digits.len()..];
            match last {
                Some(a) if range && a < n && n - a < 50 => {
                    out.extend((a + 1..=n).map(|k| (k, line)));
                }
                _ => out.push((n, line)),
            }
            last = Some(n);
            range = false;
            if let Some(r) = rest.strip_prefix('–').or_else(|| rest.strip_prefix('-')) {
                if r.starts_with(|c: char| c.is_ascii_digit()) {
                    range = true;
                    rest = r;
                    continue;
                }
            }
            let next = [", and ", " and ", ", "]
                .iter()
                .find_map(|sep| rest.strip_prefix(sep))
                .filter(|r| r.starts_with(|c: char| c.is_ascii_digit()));
            match next {
                Some(r) => rest = r,
                None => break,
            }
        }
    }
    out
}

#[derive(Debug, PartialEq)]
enum Status {
    Current,
    Superseded(u32),
    Unassigned,
}

struct Row {
    status: Status,
    /// `page.md#anchor` for a current row.
    page: Option<String>,
}

/// The register: its rows by number, and the numbers in the order they appear.
fn register() -> (BTreeMap<u32, Row>, Vec<u32>) {
    let text = read(&root().join("docs/decisions.md"));
    let mut rows = BTreeMap::new();
    let mut order = Vec::new();
    for line in text.lines() {
        let cells: Vec<&str> = line.split(" | ").map(str::trim).collect();
        let Some(n) = cells
            .first()
            .and_then(|c| c.strip_prefix("| "))
            .and_then(|c| c.parse::<u32>().ok())
        else {
            continue;
        };
        assert!(cells.len() >= 5, "register row {n} has not 5 cells: {line}");
        let status_cell = cells[cells.len() - 3];
        let page_cell = cells[cells.len() - 2];
        let status = match status_cell {
            "current" => Status::Current,
            "unassigned" => Status::Unassigned,
            s => Status::Superseded(
                s.strip_prefix("superseded by ")
                    .and_then(|n| n.parse().ok())
                    .unwrap_or_else(|| panic!("register row {n}: status {s:?}")),
            ),
        };
        let page = page_cell
            .split_once("](")
            .map(|(_, t)| t.trim_end_matches(')').to_string());
        order.push(n);
        rows.insert(n, Row { status, page });
    }
    (rows, order)
}

#[test]
fn the_register_numbers_every_choice_once_in_order() {
    let (rows, order) = register();
    let expected: Vec<u32> = (1..=order.len() as u32).collect();
    assert_eq!(
        order, expected,
        "docs/decisions.md: rows must be 1, 2, … without a gap or a duplicate"
    );
    assert!(rows.len() >= 180, "{} rows", rows.len());
}

#[test]
fn every_current_choice_is_explained_where_the_register_says() {
    let (rows, _) = register();
    let docs = root().join("docs");
    for (n, row) in &rows {
        match row.status {
            Status::Current => {
                let page = row
                    .page
                    .as_deref()
                    .unwrap_or_else(|| panic!("Choice {n} is current but names no page"));
                let (file, anchor) = page.split_once('#').unwrap_or((page, ""));
                let text = read(&docs.join(file));
                let body = if anchor.is_empty() {
                    text.clone()
                } else {
                    section(&text, anchor)
                        .unwrap_or_else(|| panic!("Choice {n}: no section {page}"))
                };
                assert!(
                    choices_cited(&body).iter().any(|(c, _)| c == n),
                    "Choice {n}: docs/{page} does not name it"
                );
            }
            Status::Superseded(by) => {
                assert!(row.page.is_none(), "superseded Choice {n} names a page");
                let by_row = rows
                    .get(&by)
                    .unwrap_or_else(|| panic!("Choice {n} superseded by {by}, no such row"));
                assert_ne!(by_row.status, Status::Unassigned, "Choice {n} → {by}");
            }
            Status::Unassigned => assert!(row.page.is_none(), "unassigned {n} names a page"),
        }
    }
}

#[test]
fn every_cited_choice_is_in_the_register_and_pages_cite_only_current_ones() {
    let (rows, _) = register();
    let mut bad = Vec::new();
    for path in cited_files() {
        let name = rel(&path);
        let text = read(&path);
        let page = name.starts_with("docs/") && name != "docs/decisions.md";
        for (n, line) in choices_cited(&text) {
            match rows.get(&n).map(|r| &r.status) {
                None | Some(Status::Unassigned) => {
                    bad.push(format!("{name}:{line}: Choice {n} has no register row"))
                }
                Some(Status::Superseded(by)) if page => bad.push(format!(
                    "{name}:{line}: Choice {n} is superseded by {by}: a page describes the design as it is"
                )),
                _ => {}
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

/// Every `docs/<page>.md[#anchor]` in `text`: (page file name, anchor, line).
fn page_citations(text: &str) -> Vec<(String, String, usize)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(found) = text[from..].find("docs/") {
        let at = from + found;
        from = at + "docs/".len();
        let before = text[..at].chars().next_back();
        if before.is_some_and(|c| c.is_alphanumeric() || "_-/.".contains(c)) {
            continue;
        }
        let rest = &text[from..];
        let stem: String = rest
            .chars()
            .take_while(|c| c.is_ascii_lowercase() || c.is_ascii_digit() || *c == '-' || *c == '_')
            .collect();
        let Some(after) = rest[stem.len()..].strip_prefix(".md") else {
            continue;
        };
        if stem.is_empty() || after.starts_with(|c: char| c.is_alphanumeric()) {
            continue;
        }
        let anchor = after.strip_prefix('#').map(anchor_at).unwrap_or("");
        let line = text[..at].matches('\n').count() + 1;
        out.push((format!("{stem}.md"), anchor.to_string(), line));
    }
    out
}

/// Every markdown link target `](target)` in `text`, with its line.
fn links(text: &str) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut from = 0;
    while let Some(found) = text[from..].find("](") {
        let at = from + found + 2;
        from = at;
        let Some(end) = text[at..].find(')') else {
            continue;
        };
        let target = &text[at..at + end];
        if target.contains(char::is_whitespace) || target.contains("://") {
            continue;
        }
        out.push((target.to_string(), text[..at].matches('\n').count() + 1));
    }
    out
}

/// `None` if `anchor` is empty or a heading of the markdown file `file`, else what is wrong.
fn anchor_problem(file: &Path, anchor: &str) -> Option<String> {
    if !file.is_file() {
        return Some(format!("no file {}", rel(file)));
    }
    if anchor.is_empty() {
        return None;
    }
    let text = read(file);
    let anchors: BTreeSet<String> = headings(&text).into_iter().map(|(_, a, _)| a).collect();
    (!anchors.contains(anchor)).then(|| format!("{} has no section #{anchor}", rel(file)))
}

#[test]
fn every_page_citation_and_markdown_link_resolves() {
    let docs = root().join("docs");
    let mut bad = Vec::new();
    for path in cited_files() {
        let name = rel(&path);
        let text = read(&path);
        for (page, anchor, line) in page_citations(&text) {
            if let Some(p) = anchor_problem(&docs.join(&page), &anchor) {
                bad.push(format!("{name}:{line}: docs/{page}#{anchor}: {p}"));
            }
        }
        if !name.ends_with(".md") {
            continue;
        }
        for (target, line) in links(&text) {
            let (file, anchor) = target.split_once('#').unwrap_or((&target, ""));
            let file = if file.is_empty() {
                path.clone()
            } else {
                path.parent().expect("a folder").join(file)
            };
            let problem = if file.extension().is_some_and(|e| e == "md") {
                anchor_problem(&file, anchor)
            } else {
                (!file.exists()).then(|| format!("no file {}", file.display()))
            };
            if let Some(p) = problem {
                bad.push(format!("{name}:{line}: ]({target}): {p}"));
            }
        }
    }
    assert!(bad.is_empty(), "{}", bad.join("\n"));
}

#[test]
fn nothing_cites_the_replaced_design_document_or_a_bare_section_number() {
    // The old citation forms: the design document's name, and `§N` (a standard's section,
    // `RFC 4231 §4.3`, is not ours).
    let old_doc = concat!("design", ".md");
    let mut bad = Vec::new();
    for path in cited_files() {
        let name = rel(&path);
        let text = read(&path);
        for (i, line) in text.lines().enumerate() {
            let bare_section = line.match_indices('§').any(|(at, _)| {
                let next = line[at + '§'.len_utf8()..].chars().next();
                next.is_some_and(|c| c.is_ascii_digit()) && !line[..at].contains("RFC ")
            });
            if line.contains(old_doc) || bare_section {
                bad.push(format!("{name}:{}: {}", i + 1, line.trim()));
            }
        }
    }
    assert!(
        bad.is_empty(),
        "cite docs/<page>.md[#section] instead (the lead's docs-refs script rewrites the old forms):\n{}",
        bad.join("\n")
    );
}

#[test]
fn the_summary_lists_every_page_and_only_pages() {
    let docs = root().join("docs");
    let summary = read(&docs.join("SUMMARY.md"));
    let listed: BTreeSet<String> = links(&summary)
        .into_iter()
        .map(|(t, _)| t.split('#').next().unwrap_or("").to_string())
        .filter(|t| t.ends_with(".md"))
        .collect();
    let pages: BTreeSet<String> = std::fs::read_dir(&docs)
        .expect("docs/")
        .map(|e| {
            e.expect("an entry")
                .file_name()
                .to_string_lossy()
                .into_owned()
        })
        .filter(|n| n.ends_with(".md") && n != "SUMMARY.md" && n != "README.md")
        .collect();
    assert_eq!(
        listed, pages,
        "docs/SUMMARY.md must list every page of docs/ and nothing else"
    );
    assert!(pages.contains("decisions.md"), "{pages:?}");
}

#[test]
fn the_readers_of_this_test_parse_what_the_book_writes() {
    assert_eq!(
        slug("`update`: fixed work and fail-safe"),
        "update-fixed-work-and-fail-safe"
    );
    assert_eq!(slug("The δ clamp"), "the-δ-clamp");
    assert_eq!(slug("Heading and K_d"), "heading-and-k_d");
    assert_eq!(slug("The preflight's contract"), "the-preflights-contract");
    let cited: Vec<u32> = choices_cited(
        "Choice 7; Choices 95–97, and choices 40, 45 and 77; Choices 162 and 170; **Choice 3:**",
    )
    .into_iter()
    .map(|(n, _)| n)
    .collect();
    assert_eq!(cited, [7, 95, 96, 97, 40, 45, 77, 162, 170, 3]);
    let c = page_citations("see docs/law.md#the-loop-rate-rule). and (docs/model.md) x/docs/y.md");
    assert_eq!(
        c,
        [
            ("law.md".into(), "the-loop-rate-rule".into(), 1),
            ("model.md".into(), String::new(), 1)
        ]
    );
    let text = "# A\n\n## B c\n\nChoice 1\n\n### D\n\nChoice 2\n\n## E\n\nChoice 3\n";
    let b = section(text, "b-c").expect("section b-c");
    assert!(b.contains("Choice 2") && !b.contains("Choice 3"), "{b}");
}
