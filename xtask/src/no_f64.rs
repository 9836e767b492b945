//! No double-precision arithmetic on the control step, proven from the linked ELF: no
//! soft-float f64 routine (compiler-builtins' `__aeabi_d*`, `__adddf3`, `__extendsfdf2`, …)
//! may be reachable from `Controller::update` in the call graph of a flying image
//! (docs/numerics.md#no-f64-on-the-control-step-from-the-elf). The Cortex-M4F's FPU is single precision only, so every f64 operation
//! there is one of these calls; f64 bit operations (abs, negation, loads) need none and are not
//! arithmetic.
//!
//! For each routine found, the report names the chain of calls from `update` and, from the
//! ELF's DWARF, the functions inlined at the call site (with LTO most of the core is inlined
//! into `update`), e.g. `__aeabi_dmul ← libm::math::rem_pio2f ← libm::math::sinf ← …::Controller::update`.

use std::collections::BTreeMap;
use std::path::Path;

use firmware::image::Image;

use crate::callgraph::{CallGraph, InlineFrames};
use crate::images::{Built, Variant};
use xtask::ci::Ci;

/// Whether a soft-float f64 routine reachable from `update` fails the firmware CI: it does. The
/// trajectory's phases are integer arithmetic and the default math backend is the core's f32
/// kernels, so the flying images have none (docs/numerics.md#no-f64-on-the-control-step-from-the-elf).
pub const FATAL: bool = true;

/// The demangled name of the control step, the root of the check.
pub const ROOT: &str = "controller_core::controller::Controller::update";

/// Whether `name` (a symbol, or the last segment of a demangled path) is a soft-float routine
/// that does f64 arithmetic, comparison or conversion: the Arm EABI's `__aeabi_d…` (and
/// `__aeabi_f2d`, `__aeabi_i2d`, `__aeabi_ui2d`, `__aeabi_l2d`, `__aeabi_ul2d`), and the
/// generic libgcc/compiler-rt names with a `df` mode (`__adddf3`, `__fixdfsi`, `__floatundidf`,
/// `__extendsfdf2`, `__truncdfsf2`, `__gtdf2`, `__unorddf2`, …).
pub fn is_soft_f64(name: &str) -> bool {
    let name = name.rsplit("::").next().unwrap_or(name);
    if let Some(rest) = name.strip_prefix("__aeabi_") {
        return rest.starts_with('d') || matches!(rest, "f2d" | "i2d" | "ui2d" | "l2d" | "ul2d");
    }
    let Some(rest) = name.strip_prefix("__") else {
        return false;
    };
    // compiler-rt: an operation name, then the machine mode(s) `df` (f64), maybe `sf`/`si`/…,
    // then the operand count.
    rest.starts_with(|c: char| c.is_ascii_lowercase())
        && rest
            .trim_end_matches(|c: char| c.is_ascii_digit())
            .contains("df")
        && rest
            .chars()
            .all(|c| c.is_ascii_lowercase() || c.is_ascii_digit())
}

/// One reachable f64 routine: the shortest call chain from the root, and where it is called.
#[derive(Debug, PartialEq, Eq)]
pub struct Finding {
    pub routine: String,
    /// Function names from the root to the routine.
    pub chain: Vec<String>,
    /// Every reachable function that calls it directly, with the functions inlined at that
    /// call site (innermost first) when the ELF has DWARF.
    pub callers: Vec<String>,
}

/// What the check found in one image.
#[derive(Debug)]
pub struct Report {
    /// Functions reachable from the root (itself included).
    pub reachable: usize,
    /// Reachable f64 routines.
    pub findings: Vec<Finding>,
    /// Reachable functions with calls or branches through a register (not followed), with
    /// their count.
    pub indirect: Vec<(String, usize)>,
}

/// Runs the check on an ELF's bytes from the function named `root`.
pub fn check(bytes: &[u8], root: &str) -> Result<Report, String> {
    let graph = CallGraph::parse(bytes)?;
    let roots = graph.named(root);
    let &[root_fn] = &roots[..] else {
        return Err(format!(
            "expected one function named {root}, found {} (is it still #[inline(never)]?)",
            roots.len()
        ));
    };
    let reach = graph.reachable(root_fn);
    let frames = InlineFrames::new(bytes);
    let name = |i: usize| graph.functions[i].name.clone();
    let mut findings = Vec::new();
    for (&f, route) in &reach {
        if !is_soft_f64(&graph.functions[f].name) {
            continue;
        }
        let mut callers: BTreeMap<String, ()> = BTreeMap::new();
        for &g in reach.keys() {
            for &(at, callee) in &graph.functions[g].calls {
                if callee != f || is_soft_f64(&graph.functions[g].name) {
                    continue;
                }
                let site = match &frames {
                    Some(fr) => {
                        let chain = fr.at(at);
                        if chain.is_empty() {
                            name(g)
                        } else {
                            chain.join(" ← ")
                        }
                    }
                    None => name(g),
                };
                callers.insert(site, ());
            }
        }
        findings.push(Finding {
            routine: name(f),
            chain: route.hops.iter().map(|&(g, _)| name(g)).collect(),
            callers: callers.into_keys().collect(),
        });
    }
    let indirect = reach
        .keys()
        .filter(|&&f| !graph.functions[f].indirect.is_empty())
        .map(|&f| (name(f), graph.functions[f].indirect.len()))
        .collect();
    Ok(Report {
        reachable: reach.len(),
        findings,
        indirect,
    })
}

/// The CI step: every built image, reported; a finding in a flying image (not the self-test)
/// fails the CI when [`FATAL`]. An image without the root, or whose root reaches nothing,
/// always fails: the check would prove nothing.
pub fn run(ci: &mut Ci, built: &Built) {
    ci.step(&format!(
        "no f64 on the control step: soft-float f64 routines reachable from {ROOT} ({})",
        if FATAL {
            "fatal"
        } else {
            "reported, not yet fatal: xtask/src/no_f64.rs FATAL"
        }
    ));
    for v in Variant::ALL {
        let Some(elf) = built.elf(v) else { continue };
        report_image(ci, v, elf);
    }
}

fn report_image(ci: &mut Ci, v: Variant, elf: &Path) {
    let label = v.label();
    let bytes = match std::fs::read(elf) {
        Ok(b) => b,
        Err(e) => {
            ci.fail(format!("{label}: reading {}: {e}", elf.display()));
            return;
        }
    };
    let report = match check(&bytes, ROOT) {
        Ok(r) => r,
        // A check that cannot find its root proves nothing: always a failure.
        Err(e) => {
            ci.fail(format!("{label}: no-f64 check: {e}"));
            return;
        }
    };
    if report.reachable < 2 {
        ci.fail(format!(
            "{label}: no-f64 check: {ROOT} reaches no other function; the call graph is broken"
        ));
    }
    let names: Vec<&str> = report.findings.iter().map(|f| f.routine.as_str()).collect();
    println!(
        "{label}: {} functions reachable from update; {} soft-float f64 routines{}{}",
        report.reachable,
        names.len(),
        if names.is_empty() { "" } else { ": " },
        names.join(", ")
    );
    // The routines the core's code calls, with where; those only other f64 routines call
    // (e.g. __aeabi_dadd → __adddf3) on one line.
    for f in report.findings.iter().filter(|f| !f.callers.is_empty()) {
        println!("  {} via {}", f.routine, f.chain.join(" → "));
        for c in &f.callers {
            println!("      called at {c}");
        }
    }
    let inner: Vec<&str> = report
        .findings
        .iter()
        .filter(|f| f.callers.is_empty())
        .map(|f| f.routine.as_str())
        .collect();
    if !inner.is_empty() {
        println!("  and, called only by those: {}", inner.join(", "));
    }
    for (f, n) in &report.indirect {
        println!("  not followed: {n} indirect call(s) or branch(es) in {f}");
    }
    if FATAL && v.image != Image::QemuSelftest && !report.findings.is_empty() {
        ci.fail(format!(
            "{label}: {} soft-float f64 routine(s) reachable from update: {} (see above)",
            names.len(),
            names.join(", ")
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use object::write::{Object, StandardSection, Symbol, SymbolSection};
    use object::{Architecture, BinaryFormat, Endianness, SymbolFlags, SymbolKind, SymbolScope};

    #[test]
    fn the_soft_float_f64_routines_are_recognised_and_nothing_else() {
        for name in [
            "__aeabi_dadd",
            "__aeabi_dcmpge",
            "__aeabi_d2f",
            "__aeabi_d2iz",
            "__aeabi_f2d",
            "__aeabi_ul2d",
            "__adddf3",
            "__extendsfdf2",
            "__truncdfsf2",
            "__fixdfsi",
            "__floatundidf",
            "__unorddf2",
            "compiler_builtins::float::div::__divdf3",
        ] {
            assert!(is_soft_f64(name), "{name}");
        }
        for name in [
            "__aeabi_fadd",
            "__aeabi_l2f",
            "__aeabi_uldivmod",
            "__aeabi_memcpy",
            "__mulsf3",
            "__floatundisf",
            "__fixsfdi",
            "__udivmoddi4",
            "__divdi3",
            "controller_core::math::phase",
            "libm::math::floor::floor",
        ] {
            assert!(!is_soft_f64(name), "{name}");
        }
    }

    /// A tiny Thumb ELF, assembled by hand (encodings worked out from ARM DDI 0403E §A7.7 and
    /// checked with `llvm-objdump -d --triple=thumbv7em`, LLVM 14):
    ///
    /// ```text
    /// 0x00 update:  bl a            f000 f80e  (+0x1c → 0x20)
    ///       0x04    bx lr           4770
    ///       0x06    nop             bf00
    ///       0x08    $d: f000 f82a   (would be `bl __aeabi_ddiv`: data, must be skipped)
    /// 0x20 a:       blx r3          4798       (indirect: reported, not followed)
    ///       0x22    b.w dadd        f000 b80d  (+0x1a → 0x40: a tail call)
    ///       0x26    b.n e           e023       (+0x46 → 0x70: a tail call)
    ///       0x28    bne 0x20        d1fa       (−0x0c: inside a, control flow)
    /// 0x30 c:       bl dmul         f000 f80e  (+0x1c → 0x50; c is not reachable)
    /// 0x40 __aeabi_dadd, 0x50 __aeabi_dmul, 0x60 __aeabi_ddiv, 0x80 __aeabi_f2d: bx lr
    /// 0x70 e:       bl f2d          f000 f806  (+0x0c → 0x80)
    /// ```
    fn fixture() -> Vec<u8> {
        let mut code = vec![0u8; 0x90];
        let mut put = |at: usize, halfwords: &[u16]| {
            for (i, h) in halfwords.iter().enumerate() {
                code[at + 2 * i..at + 2 * i + 2].copy_from_slice(&h.to_le_bytes());
            }
        };
        put(0x00, &[0xf000, 0xf80e, 0x4770, 0xbf00, 0xf000, 0xf82a]);
        put(0x20, &[0x4798, 0xf000, 0xb80d, 0xe023, 0xd1fa, 0x4770]);
        put(0x30, &[0xf000, 0xf80e, 0x4770]);
        for at in [0x40, 0x50, 0x60, 0x80] {
            put(at, &[0x4770]);
        }
        put(0x70, &[0xf000, 0xf806, 0x4770]);
        let mut obj = Object::new(BinaryFormat::Elf, Architecture::Arm, Endianness::Little);
        let text = obj.section_id(StandardSection::Text);
        obj.append_section_data(text, &code, 4);
        let mut sym = |name: &str, value: u64, size: u64, kind: SymbolKind| {
            obj.add_symbol(Symbol {
                name: name.as_bytes().to_vec(),
                value,
                size,
                kind,
                scope: SymbolScope::Compilation,
                weak: false,
                section: SymbolSection::Section(text),
                flags: SymbolFlags::None,
            });
        };
        // Thumb function symbols have bit 0 set.
        for (name, at, size) in [
            ("update", 0x00, 0x20),
            ("a", 0x20, 0x10),
            ("c", 0x30, 0x10),
            ("__aeabi_dadd", 0x40, 0x10),
            ("__aeabi_dmul", 0x50, 0x10),
            ("__aeabi_ddiv", 0x60, 0x10),
            ("e", 0x70, 0x10),
            ("__aeabi_f2d", 0x80, 0x10),
        ] {
            sym(name, at | 1, size, SymbolKind::Text);
            sym("$t", at, 0, SymbolKind::Label);
        }
        sym("$d", 0x08, 0, SymbolKind::Label);
        obj.write().expect("writing the fixture")
    }

    #[test]
    fn the_check_finds_what_update_reaches_through_calls_and_tail_calls_only() {
        let report = check(&fixture(), "update").expect("the fixture has its root");
        let found: Vec<(&str, Vec<&str>)> = report
            .findings
            .iter()
            .map(|f| {
                (
                    f.routine.as_str(),
                    f.chain.iter().map(String::as_str).collect(),
                )
            })
            .collect();
        assert_eq!(
            found,
            [
                ("__aeabi_dadd", vec!["update", "a", "__aeabi_dadd"]),
                ("__aeabi_f2d", vec!["update", "a", "e", "__aeabi_f2d"]),
            ]
        );
        // update, a, dadd, e, f2d; not c, dmul, or the ddiv that only data "calls".
        assert_eq!(report.reachable, 5);
        assert_eq!(report.indirect, [("a".to_string(), 1)]);
        assert_eq!(report.findings[0].callers, ["a"]);
        assert_eq!(report.findings[1].callers, ["e"]);
    }

    #[test]
    fn a_missing_root_is_an_error() {
        assert!(check(&fixture(), "controller_core::nothing").is_err());
    }
}
