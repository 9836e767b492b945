//! The static call graph of a linked Thumb-2 ELF: every function symbol, the direct calls and
//! tail calls its code makes ([`crate::thumb`]), and what is reachable from a root.
//!
//! Code is read between the Arm ELF mapping symbols: `$t` starts Thumb code, `$d` starts data
//! (literal pools inside a function), so constants are never decoded as instructions. A branch
//! that leaves its function is a tail call; one that stays is control flow. Calls through a
//! register or memory cannot be followed: they are counted per function, so a report can say
//! where the graph is incomplete.

use std::collections::{BTreeMap, VecDeque};

use object::{Object, ObjectSection, ObjectSymbol, SectionKind, SymbolKind};

use crate::thumb::{self, Transfer};

/// One function of the image.
#[derive(Clone, Debug)]
pub struct Function {
    /// Demangled, without the hash (`controller_core::math::phase`), or the symbol as it is.
    pub name: String,
    pub addr: u64,
    pub size: u64,
    /// Direct calls and tail calls to other functions: (address of the instruction, callee).
    pub calls: Vec<(u64, usize)>,
    /// Addresses of the calls and branches through a register or memory.
    pub indirect: Vec<u64>,
}

/// Every function of an image and its direct calls.
pub struct CallGraph {
    pub functions: Vec<Function>,
}

/// How `target` was reached from the root: the chain of functions and the call site in each.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Route {
    /// (function, address of the call it makes to the next), root first, the target last
    /// (with address 0).
    pub hops: Vec<(usize, u64)>,
}

impl CallGraph {
    /// Builds the graph from the bytes of an ELF file.
    pub fn parse(bytes: &[u8]) -> Result<CallGraph, String> {
        let file = object::File::parse(bytes).map_err(|e| format!("not an ELF file: {e}"))?;
        // Function symbols (Thumb: the address has bit 0 set) and mapping symbols, per section.
        let mut functions = Vec::new();
        let mut data_marks: BTreeMap<u64, bool> = BTreeMap::new(); // address → is data
        for sym in file.symbols() {
            let name = sym.name().unwrap_or("");
            let addr = sym.address() & !1;
            if name == "$d" || name.starts_with("$d.") {
                data_marks.insert(addr, true);
            } else if name == "$t" || name.starts_with("$t.") {
                data_marks.insert(addr, false);
            } else if sym.kind() == SymbolKind::Text && sym.size() > 0 {
                functions.push(Function {
                    name: demangle(name),
                    addr,
                    size: sym.size(),
                    calls: Vec::new(),
                    indirect: Vec::new(),
                });
            }
        }
        functions.sort_by_key(|f| f.addr);
        functions.dedup_by_key(|f| f.addr);
        let code: Vec<_> = file
            .sections()
            .filter(|s| s.kind() == SectionKind::Text)
            .filter_map(|s| Some((s.address(), s.data().ok()?)))
            .collect();
        let bytes_at = |addr: u64, len: u64| {
            code.iter().find_map(|&(base, data)| {
                let start = addr.checked_sub(base)? as usize;
                data.get(start..start + len as usize)
            })
        };
        let mut graph = CallGraph { functions };
        for i in 0..graph.functions.len() {
            let (start, end) = (
                graph.functions[i].addr,
                graph.functions[i].addr + graph.functions[i].size,
            );
            for (lo, hi) in code_runs(&data_marks, start, end) {
                let Some(bytes) = bytes_at(lo, hi - lo) else {
                    continue;
                };
                for (at, t) in thumb::transfers(bytes, lo) {
                    match t {
                        Transfer::Call(target) => {
                            if let Some(j) = graph.function_at(target) {
                                graph.functions[i].calls.push((at, j));
                            }
                        }
                        Transfer::Jump(target) if !(start..end).contains(&target) => {
                            if let Some(j) = graph.function_at(target) {
                                graph.functions[i].calls.push((at, j));
                            }
                        }
                        Transfer::Jump(_) => {}
                        Transfer::Indirect => graph.functions[i].indirect.push(at),
                    }
                }
            }
        }
        Ok(graph)
    }

    /// The function whose code contains `addr`.
    pub fn function_at(&self, addr: u64) -> Option<usize> {
        let i = self.functions.partition_point(|f| f.addr <= addr);
        let f = self.functions.get(i.checked_sub(1)?)?;
        (addr < f.addr + f.size).then_some(i - 1)
    }

    /// The functions named `name` (demangled, without the hash).
    pub fn named(&self, name: &str) -> Vec<usize> {
        (0..self.functions.len())
            .filter(|&i| self.functions[i].name == name)
            .collect()
    }

    /// Every function reachable from `root` (itself included), each with the shortest chain
    /// of calls that reaches it (breadth first).
    pub fn reachable(&self, root: usize) -> BTreeMap<usize, Route> {
        let mut parent: BTreeMap<usize, Option<(usize, u64)>> = BTreeMap::new();
        parent.insert(root, None);
        let mut queue = VecDeque::from([root]);
        while let Some(f) = queue.pop_front() {
            for &(at, g) in &self.functions[f].calls {
                if let std::collections::btree_map::Entry::Vacant(e) = parent.entry(g) {
                    e.insert(Some((f, at)));
                    queue.push_back(g);
                }
            }
        }
        parent
            .keys()
            .map(|&f| {
                let mut hops = vec![(f, 0)];
                let mut cur = f;
                while let Some(Some((p, at))) = parent.get(&cur) {
                    hops.push((*p, *at));
                    cur = *p;
                }
                hops.reverse();
                (f, Route { hops })
            })
            .collect()
    }
}

/// The runs of code in [start, end), between the `$d` (data) and `$t` (code) marks.
fn code_runs(marks: &BTreeMap<u64, bool>, start: u64, end: u64) -> Vec<(u64, u64)> {
    // Code at `start` unless a mark before or at it says data.
    let mut is_data = marks.range(..=start).next_back().is_some_and(|(_, &d)| d);
    let mut runs = Vec::new();
    let mut from = start;
    for (&at, &d) in marks.range(start + 1..end) {
        if d != is_data {
            if !is_data {
                runs.push((from, at));
            }
            from = at;
            is_data = d;
        }
    }
    if !is_data {
        runs.push((from, end));
    }
    runs
}

/// A symbol's demangled name without its hash; the symbol itself if it is not a Rust one.
pub fn demangle(symbol: &str) -> String {
    match rustc_demangle::try_demangle(symbol) {
        Ok(d) => format!("{d:#}"),
        Err(_) => symbol.to_string(),
    }
}

/// The chain of functions inlined at an address, outermost last, from the ELF's DWARF.
pub struct InlineFrames<'a> {
    ctx: addr2line::Context<addr2line::gimli::EndianSlice<'a, addr2line::gimli::LittleEndian>>,
}

impl<'a> InlineFrames<'a> {
    /// The DWARF of `bytes` (an ELF file); `None` if it has none.
    pub fn new(bytes: &'a [u8]) -> Option<InlineFrames<'a>> {
        use addr2line::gimli;
        let file = object::File::parse(bytes).ok()?;
        file.section_by_name(".debug_info")?;
        let dwarf = gimli::Dwarf::load(|id| -> Result<_, gimli::Error> {
            let data = file
                .section_by_name(id.name())
                .and_then(|s| s.data().ok())
                .unwrap_or(&[]);
            Ok(gimli::EndianSlice::new(data, gimli::LittleEndian))
        })
        .ok()?;
        let ctx = addr2line::Context::from_dwarf(dwarf).ok()?;
        Some(InlineFrames { ctx })
    }

    /// The functions whose code is at `addr`, innermost first (demangled, without hashes).
    pub fn at(&self, addr: u64) -> Vec<String> {
        let mut out = Vec::new();
        let Ok(mut frames) = self.ctx.find_frames(addr).skip_all_loads() else {
            return out;
        };
        while let Ok(Some(frame)) = frames.next() {
            if let Some(name) = frame.function.as_ref().and_then(|f| f.raw_name().ok()) {
                out.push(demangle(&name));
            }
        }
        out
    }
}
