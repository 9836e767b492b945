//! The design's indexes stay true: docs/README.md and design.md's own table at its top name
//! every numbered section of docs/design.md (`## N. …`).

use std::path::Path;

fn read(rel: &str) -> String {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("..").join(rel);
    std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The numbers of design.md's `## N. …` sections.
fn sections(design: &str) -> Vec<u32> {
    design
        .lines()
        .filter_map(|l| l.strip_prefix("## "))
        .filter_map(|l| l.split_once(". ").and_then(|(n, _)| n.parse().ok()))
        .collect()
}

#[test]
fn both_indexes_name_every_section_of_the_design() {
    let design = read("docs/design.md");
    let index = read("docs/README.md");
    // design.md's table of sections: from its header to the first line that is not a row.
    let start = design
        .find("| § | topic | code |")
        .expect("design.md's table of sections");
    let table: Vec<&str> = design[start..]
        .lines()
        .take_while(|l| l.starts_with('|'))
        .collect();
    let numbers = sections(&design);
    assert!(numbers.len() >= 22, "{numbers:?}");
    for n in &numbers {
        assert!(
            index.contains(&format!("(§{n})")),
            "docs/README.md does not name §{n}"
        );
        assert!(
            table
                .iter()
                .any(|row| row.starts_with(&format!("| {n} | "))),
            "design.md's table of sections has no row for §{n}"
        );
    }
}
