//! Import circles: every strongly connected component of two or more modules of a crate's
//! dependency graph (Tarjan's algorithm), each shown as a closed walk through all its modules
//! with the line behind every step, so that a reader sees what to move to break it.
//!
//! The graph ([`rule_graph`]) is the module graph ([`super::modules`]: a module depends on the
//! module that defines what it names, through re-exports) with two readings of a folder:
//!
//! - a module that reaches into a folder from outside depends on the folder too: naming
//!   `trajectory::paths::waypoints` from `trajectory::kind` is an edge to
//!   `trajectory::paths::waypoints` and to `trajectory::paths`, every module that contains
//!   the one named up to the nearest that contains both (a folder's `mod.rs` is its front
//!   door, and its code is the folder's);
//! - a module's own ancestors are not edges: a child may use its parent's items, and a parent
//!   may use and re-export its children (docs/ci.md#the-source-rules, docs/ci.md, Choice 210).

use std::collections::{BTreeMap, BTreeSet, VecDeque};
use std::fmt;

use super::modules::{display, Crate, Site};

/// module → module it depends on → the line behind it.
pub type Graph = BTreeMap<String, BTreeMap<String, Site>>;

/// True if `a` is an ancestor of `b` (`scenario` of `scenario::check`); the root (`""`) is
/// everything's ancestor but its own.
pub fn is_ancestor(a: &str, b: &str) -> bool {
    a != b && (a.is_empty() || b.starts_with(&format!("{a}::")))
}

/// The graph the circle rule reads (see the module's doc): each module's edges but those to
/// its own ancestors, each also to the folders it reaches into.
pub fn rule_graph(krate: &Crate) -> Graph {
    let mut out = Graph::new();
    for (from, module) in &krate.modules {
        let edges = out.entry(from.clone()).or_default();
        for (to, site) in &module.sites {
            if is_ancestor(to, from) {
                continue;
            }
            edges.entry(to.clone()).or_insert_with(|| site.clone());
            // The folders that contain `to` but not `from`.
            let mut folder = to.as_str();
            while let Some((up, _)) = folder.rsplit_once("::") {
                folder = up;
                if is_ancestor(folder, from) || folder == from {
                    break;
                }
                let text = format!("{} (into {})", site.text, display(to));
                edges.entry(folder.to_string()).or_insert_with(|| Site {
                    text,
                    ..site.clone()
                });
            }
        }
    }
    out
}

/// One step of a circle: `from` depends on `to` because of `site`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Step {
    pub from: String,
    pub to: String,
    pub site: Site,
}

/// A set of modules of one crate that all reach each other through their imports.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Circle {
    pub krate: String,
    /// Its modules, sorted.
    pub modules: Vec<String>,
    /// A closed walk from the first module through every other and back.
    pub walk: Vec<Step>,
    /// The component's other edges (not on the walk): each is a circle of its own to break.
    pub other_edges: Vec<Step>,
}

impl fmt::Display for Circle {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let names: Vec<&str> = self.modules.iter().map(|m| display(m)).collect();
        writeln!(
            f,
            "{}: {} modules import each other: {}",
            self.krate,
            names.len(),
            names.join(", ")
        )?;
        for s in &self.walk {
            writeln!(f, "    {s}")?;
        }
        if !self.other_edges.is_empty() {
            writeln!(f, "  and inside it also:")?;
            for s in &self.other_edges {
                writeln!(f, "    {s}")?;
            }
        }
        Ok(())
    }
}

impl fmt::Display for Step {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} -> {}  ({}:{} `{}`)",
            display(&self.from),
            display(&self.to),
            self.site.file.display(),
            self.site.line,
            self.site.text
        )
    }
}

/// Every import circle of `krate`, sorted by their modules.
pub fn import_circles(krate: &Crate) -> Vec<Circle> {
    let graph = rule_graph(krate);
    let mut out: Vec<Circle> = components(&graph)
        .into_iter()
        .filter(|c| c.len() >= 2)
        .map(|modules| circle(&krate.name, &graph, modules))
        .collect();
    out.sort_by(|a, b| a.modules.cmp(&b.modules));
    out
}

fn circle(krate: &str, graph: &Graph, modules: Vec<String>) -> Circle {
    let inside: BTreeSet<&str> = modules.iter().map(String::as_str).collect();
    let step = |from: &str, to: &str| Step {
        from: from.to_string(),
        to: to.to_string(),
        site: graph[from][to].clone(),
    };
    let next = |m: &str| -> Vec<&str> {
        graph[m]
            .keys()
            .map(String::as_str)
            .filter(|t| inside.contains(t))
            .collect()
    };
    // A closed walk: from the first module to each one not yet visited by a shortest path,
    // then back to the first.
    let mut walk = Vec::new();
    let mut seen: BTreeSet<&str> = BTreeSet::new();
    let start = modules[0].as_str();
    let mut at = start;
    seen.insert(at);
    for target in modules.iter().map(String::as_str).chain([start]) {
        if target != start && seen.contains(target) {
            continue;
        }
        if target == start && walk.is_empty() && modules.len() > 1 {
            continue;
        }
        for (a, b) in shortest_path(at, target, &next) {
            seen.insert(b);
            walk.push(step(a, b));
        }
        at = target;
    }
    let on_walk: BTreeSet<(&str, &str)> = walk
        .iter()
        .map(|s| (s.from.as_str(), s.to.as_str()))
        .collect();
    let mut other_edges = Vec::new();
    for m in &modules {
        for t in next(m) {
            if !on_walk.contains(&(m.as_str(), t)) {
                other_edges.push(step(m, t));
            }
        }
    }
    Circle {
        krate: krate.to_string(),
        modules: modules.clone(),
        walk,
        other_edges,
    }
}

/// The edges of a shortest path from `from` to `to` (`to` reachable), at least one edge.
fn shortest_path<'a>(
    from: &'a str,
    to: &'a str,
    next: &dyn Fn(&str) -> Vec<&'a str>,
) -> Vec<(&'a str, &'a str)> {
    let mut came: BTreeMap<&str, &str> = BTreeMap::new();
    let mut queue = VecDeque::from([from]);
    while let Some(m) = queue.pop_front() {
        for n in next(m) {
            if came.contains_key(n) {
                continue;
            }
            came.insert(n, m);
            if n == to {
                let mut path = vec![(m, n)];
                let mut at = m;
                while at != from {
                    let prev = came[at];
                    path.push((prev, at));
                    at = prev;
                }
                path.reverse();
                return path;
            }
            queue.push_back(n);
        }
    }
    Vec::new()
}

/// The strongly connected components of `graph` (Tarjan), each sorted.
pub fn components(graph: &Graph) -> Vec<Vec<String>> {
    struct State<'a> {
        graph: &'a Graph,
        index: BTreeMap<&'a str, usize>,
        low: BTreeMap<&'a str, usize>,
        stack: Vec<&'a str>,
        on_stack: BTreeSet<&'a str>,
        out: Vec<Vec<String>>,
    }
    fn visit<'a>(s: &mut State<'a>, v: &'a str) {
        let i = s.index.len();
        s.index.insert(v, i);
        s.low.insert(v, i);
        s.stack.push(v);
        s.on_stack.insert(v);
        let graph = s.graph;
        for w in graph.get(v).into_iter().flat_map(|ws| ws.keys()) {
            let Some((w, _)) = graph.get_key_value(w.as_str()) else {
                continue;
            };
            let w = w.as_str();
            if !s.index.contains_key(w) {
                visit(s, w);
                let low = s.low[v].min(s.low[w]);
                s.low.insert(v, low);
            } else if s.on_stack.contains(w) {
                let low = s.low[v].min(s.index[w]);
                s.low.insert(v, low);
            }
        }
        if s.low[v] == s.index[v] {
            let mut component = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack.remove(w);
                component.push(w.to_string());
                if w == v {
                    break;
                }
            }
            component.sort();
            s.out.push(component);
        }
    }
    let mut s = State {
        graph,
        index: BTreeMap::new(),
        low: BTreeMap::new(),
        stack: Vec::new(),
        on_stack: BTreeSet::new(),
        out: Vec::new(),
    };
    for v in graph.keys() {
        let v = v.as_str();
        if !s.index.contains_key(v) {
            visit(&mut s, v);
        }
    }
    s.out
}

#[cfg(test)]
mod tests {
    use super::super::modules::Module;
    use super::super::targets::Kind;
    use super::*;
    use std::path::PathBuf;

    fn krate(edges: &[(&str, &[&str])]) -> Crate {
        let modules = edges
            .iter()
            .map(|(m, to)| {
                let file = PathBuf::from(format!("{m}.rs"));
                let sites = to
                    .iter()
                    .map(|t| {
                        let text = format!("use crate::{t}");
                        let site = Site {
                            file: file.clone(),
                            line: 1,
                            text,
                        };
                        (t.to_string(), site)
                    })
                    .collect();
                let module = Module {
                    file,
                    imports: to.iter().map(|t| t.to_string()).collect(),
                    sites,
                };
                (m.to_string(), module)
            })
            .collect();
        Crate {
            name: "t".into(),
            kind: Kind::Lib,
            modules,
            test_files: BTreeSet::new(),
        }
    }

    fn walk(c: &Circle) -> Vec<String> {
        c.walk
            .iter()
            .map(|s| format!("{}>{}", s.from, s.to))
            .collect()
    }

    #[test]
    fn every_component_of_two_or_more_modules_is_a_circle() {
        let c = krate(&[
            // A 3-cycle with no pair importing each other.
            ("runner", &["stats"]),
            ("stats", &["upload"]),
            ("upload", &["runner", "link"]),
            // A pair, and a chain into it that is not part of it.
            ("a", &["b"]),
            ("b", &["a"]),
            ("link", &["a"]),
            ("leaf", &[]),
        ]);
        let circles = import_circles(&c);
        let modules: Vec<Vec<&str>> = circles
            .iter()
            .map(|c| c.modules.iter().map(String::as_str).collect())
            .collect();
        assert_eq!(modules, [vec!["a", "b"], vec!["runner", "stats", "upload"]]);
        assert_eq!(
            walk(&circles[1]),
            ["runner>stats", "stats>upload", "upload>runner"]
        );
        assert!(circles[1].other_edges.is_empty());
        let text = circles[1].to_string();
        assert!(
            text.contains("upload -> runner  (upload.rs:1 `use crate::runner`)"),
            "{text}"
        );
    }

    #[test]
    fn reaching_into_a_folder_depends_on_it_but_a_parent_is_no_edge() {
        let c = krate(&[
            // The parent uses its children, and they use its items: no circle.
            ("t", &["t::kind", "t::paths"]),
            ("t::kind", &["t", "t::paths::waypoints"]),
            ("t::paths", &["t", "t::kind", "t::paths::waypoints"]),
            ("t::paths::waypoints", &["t", "t::paths"]),
        ]);
        let graph = rule_graph(&c);
        let edges = |m: &str| graph[m].keys().cloned().collect::<Vec<_>>();
        assert_eq!(edges("t"), ["t::kind", "t::paths"]);
        assert_eq!(edges("t::kind"), ["t::paths", "t::paths::waypoints"]);
        assert!(edges("t::paths::waypoints").is_empty());
        // `t::kind` reaches into the folder `t::paths`, whose front door uses `t::kind`.
        let circles = import_circles(&c);
        assert_eq!(circles.len(), 1);
        assert_eq!(walk(&circles[0]), ["t::kind>t::paths", "t::paths>t::kind"]);
        assert_eq!(
            circles[0].walk[0].site.text,
            "use crate::t::paths::waypoints (into t::paths::waypoints)"
        );
    }

    #[test]
    fn the_walk_visits_every_module_and_the_rest_is_listed() {
        // Two 2-cycles sharing `hub`: no simple cycle through all three.
        let c = krate(&[("hub", &["x", "y"]), ("x", &["hub"]), ("y", &["hub"])]);
        let circles = import_circles(&c);
        assert_eq!(circles.len(), 1);
        assert_eq!(walk(&circles[0]), ["hub>x", "x>hub", "hub>y", "y>hub"]);
        assert!(circles[0].other_edges.is_empty());
        // A shortcut edge off the walk is named.
        let c = krate(&[("a", &["b", "c"]), ("b", &["c"]), ("c", &["a"])]);
        let circles = import_circles(&c);
        assert_eq!(walk(&circles[0]), ["a>b", "b>c", "c>a"]);
        let others: Vec<String> = circles[0]
            .other_edges
            .iter()
            .map(|s| format!("{}>{}", s.from, s.to))
            .collect();
        assert_eq!(others, ["a>c"]);
    }
}
