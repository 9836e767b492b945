//! The snapshots under `firmware/snapshots/`: the self-test's decoded defmt logs and the images'
//! sizes, and how a run is compared with them.

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::Path;

/// Flash and static RAM of every image (one line per image and backend).
pub const SIZES: &str = "firmware/snapshots/sizes.txt";

/// The self-test's decoded log with `backend` (`libm`, `micromath`).
pub fn selftest_log(backend: &str) -> String {
    format!("firmware/snapshots/selftest-{backend}.log")
}

/// Bytes of flash and static RAM.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct Sizes {
    pub flash: u64,
    pub ram: u64,
}

#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub struct SizeKey {
    pub bin: String,
    pub backend: String,
}

/// Reads `sizes.txt`: `<bin> <backend> flash=<bytes> ram=<bytes>` per line, `#` comments.
pub fn read_sizes(path: &Path) -> Result<BTreeMap<SizeKey, Sizes>, String> {
    let text =
        std::fs::read_to_string(path).map_err(|e| format!("reading {}: {e}", path.display()))?;
    let mut out = BTreeMap::new();
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let bad = || {
            format!(
                "{}:{}: expected `<bin> <backend> flash=N ram=N`, got `{line}`",
                path.display(),
                i + 1
            )
        };
        let f: Vec<&str> = line.split_whitespace().collect();
        let [bin, backend, flash, ram] = f[..] else {
            return Err(bad());
        };
        let num = |s: &str, key: &str| {
            s.strip_prefix(key)
                .and_then(|v| v.parse::<u64>().ok())
                .ok_or_else(bad)
        };
        out.insert(
            SizeKey {
                bin: bin.into(),
                backend: backend.into(),
            },
            Sizes {
                flash: num(flash, "flash=")?,
                ram: num(ram, "ram=")?,
            },
        );
    }
    Ok(out)
}

pub fn write_sizes(path: &Path, sizes: &BTreeMap<SizeKey, Sizes>) -> Result<(), String> {
    let mut text = String::from(
        "# Flash and static RAM (bytes) of each firmware image, from its ELF sections.\n\
         # Written by `cargo xtask images --bless`; CI fails on a change of more than 10 %.\n",
    );
    for (k, s) in sizes {
        writeln!(
            text,
            "{} {} flash={} ram={}",
            k.bin, k.backend, s.flash, s.ram
        )
        .ok();
    }
    std::fs::write(path, text).map_err(|e| format!("writing {}: {e}", path.display()))
}

/// A size is close to its snapshot within ±10 % (at least ±64 bytes, for tiny sections).
pub fn size_close(now: u64, snapshot: u64) -> bool {
    now.abs_diff(snapshot) <= (snapshot / 10).max(64)
}

/// A log line as it is compared: numbers on the lines that depend on the compiler
/// (instruction counts, stack depth) are masked; the budgets check those numbers.
pub fn normalise(log: &str) -> Vec<String> {
    log.lines()
        .map(|l| {
            if l.contains("instructions") || l.contains("stack high-water") {
                mask_digits(l)
            } else {
                l.to_string()
            }
        })
        .collect()
}

fn mask_digits(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut in_number = false;
    for c in line.chars() {
        if c.is_ascii_digit() {
            if !in_number {
                out.push('#');
            }
            in_number = true;
        } else {
            out.push(c);
            in_number = false;
        }
    }
    out
}

/// A line diff of `old` → `new` (longest common subsequence): `-` lines only in `old`, `+`
/// lines only in `new`, with their line numbers. Empty if they are equal.
pub fn diff(old: &[String], new: &[String]) -> Vec<String> {
    let (n, m) = (old.len(), new.len());
    // lcs[i][j]: length of the LCS of old[i..] and new[j..].
    let mut lcs = vec![vec![0usize; m + 1]; n + 1];
    for i in (0..n).rev() {
        for j in (0..m).rev() {
            lcs[i][j] = if old[i] == new[j] {
                lcs[i + 1][j + 1] + 1
            } else {
                lcs[i + 1][j].max(lcs[i][j + 1])
            };
        }
    }
    let (mut i, mut j, mut out) = (0, 0, Vec::new());
    while i < n || j < m {
        if i < n && j < m && old[i] == new[j] {
            i += 1;
            j += 1;
        } else if i < n && (j == m || lcs[i + 1][j] >= lcs[i][j + 1]) {
            out.push(format!("-{:>3}: {}", i + 1, old[i]));
            i += 1;
        } else {
            out.push(format!("+{:>3}: {}", j + 1, new[j]));
            j += 1;
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn lines(s: &[&str]) -> Vec<String> {
        s.iter().map(|l| l.to_string()).collect()
    }

    #[test]
    fn numbers_are_masked_only_on_compiler_dependent_lines() {
        let log = "INFO  update instructions: max=35320 mean=26200\n\
                   INFO  stack high-water mark: 8364 bytes\n\
                   INFO  golden vectors: 50 of 50 agree";
        assert_eq!(
            normalise(log),
            lines(&[
                "INFO  update instructions: max=# mean=#",
                "INFO  stack high-water mark: # bytes",
                "INFO  golden vectors: 50 of 50 agree",
            ])
        );
    }

    #[test]
    fn the_diff_shows_what_changed_where() {
        let old = lines(&["a", "b", "c", "d"]);
        let new = lines(&["a", "x", "c", "d", "e"]);
        assert_eq!(diff(&old, &new), ["-  2: b", "+  2: x", "+  5: e"]);
        assert!(diff(&old, &old).is_empty());
    }

    #[test]
    fn sizes_round_trip_and_a_ten_percent_jump_is_flagged() {
        let path = std::env::temp_dir().join(format!("xtask-sizes-{}.txt", std::process::id()));
        let mut m = BTreeMap::new();
        m.insert(
            SizeKey {
                bin: "firmware-qemu".into(),
                backend: "libm".into(),
            },
            Sizes {
                flash: 73060,
                ram: 20,
            },
        );
        write_sizes(&path, &m).unwrap();
        assert_eq!(read_sizes(&path).unwrap(), m);
        std::fs::remove_file(&path).unwrap();
        assert!(size_close(80_366, 73_060) && !size_close(80_367, 73_060));
        assert!(size_close(84, 20) && !size_close(85, 20));
    }
}
