//! The modules of polar-render form a layering: no two of them import each other, directly
//! or in a loop (issue 15). Reads every `crate::` path in `src/*.rs` (use lines and paths in
//! code alike) and checks that the graph "module -> modules it names" is acyclic.

use std::collections::{BTreeMap, BTreeSet};
use std::path::Path;

/// Module name -> the modules its code names through `crate::`.
type Graph = BTreeMap<String, BTreeSet<String>>;

/// The source with `//` comments (and so doc comments) removed.
fn strip_comments(src: &str) -> String {
    src.lines()
        .map(|l| l.split_once("//").map_or(l, |(code, _)| code))
        .collect::<Vec<_>>()
        .join("\n")
}

/// The first path segment after every `crate::` in `src`, including each item of a
/// `crate::{a::X, b}` group.
fn crate_roots(src: &str) -> Vec<String> {
    let ident = |s: &str| -> String {
        s.trim_start()
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_')
            .collect()
    };
    let mut roots = Vec::new();
    for (i, _) in src.match_indices("crate::") {
        let rest = &src[i + "crate::".len()..];
        let Some(group) = rest.strip_prefix('{') else {
            roots.push(ident(rest));
            continue;
        };
        let (mut depth, mut item_start) = (0, 0);
        for (j, c) in group.char_indices() {
            match c {
                '{' => depth += 1,
                '}' if depth == 0 => {
                    roots.push(ident(&group[item_start..j]));
                    break;
                }
                '}' => depth -= 1,
                ',' if depth == 0 => {
                    roots.push(ident(&group[item_start..j]));
                    item_start = j + 1;
                }
                _ => {}
            }
        }
    }
    roots.retain(|r| !r.is_empty());
    roots
}

/// Items declared in the crate root itself (not re-exports): naming them adds no edge.
fn root_items(lib: &str) -> BTreeSet<String> {
    let kinds = ["enum ", "struct ", "fn ", "type ", "const ", "trait "];
    strip_comments(lib)
        .lines()
        .filter_map(|l| {
            let l = l.trim_start().trim_start_matches("pub ");
            kinds
                .iter()
                .find_map(|k| l.strip_prefix(k))
                .map(|rest| {
                    rest.chars()
                        .take_while(|c| c.is_alphanumeric() || *c == '_')
                })
                .map(String::from_iter)
        })
        .collect()
}

/// The module graph of `modules` (name -> source), or the `crate::` names that are
/// neither a module nor an item of the root `lib` (re-exports hide the real edge).
fn module_graph(lib: &str, modules: &BTreeMap<String, String>) -> Result<Graph, Vec<String>> {
    let items = root_items(lib);
    let mut graph = Graph::new();
    let mut hidden = Vec::new();
    for (name, src) in modules {
        let edges = graph.entry(name.clone()).or_default();
        for root in crate_roots(&strip_comments(src)) {
            if modules.contains_key(&root) {
                if root != *name {
                    edges.insert(root);
                }
            } else if !items.contains(&root) {
                hidden.push(format!(
                    "src/{name}.rs names crate::{root}: a re-export; name its module"
                ));
            }
        }
    }
    if hidden.is_empty() {
        Ok(graph)
    } else {
        Err(hidden)
    }
}

/// A loop of modules `[a, b, ..., a]` if the graph has one.
fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &Graph,
        done: &mut BTreeSet<String>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        if let Some(at) = stack.iter().position(|s| s == node) {
            let mut cycle = stack[at..].to_vec();
            cycle.push(node.to_owned());
            return Some(cycle);
        }
        if done.contains(node) {
            return None;
        }
        stack.push(node.to_owned());
        for next in graph.get(node).into_iter().flatten() {
            if let Some(c) = visit(next, graph, done, stack) {
                return Some(c);
            }
        }
        stack.pop();
        done.insert(node.to_owned());
        None
    }
    let mut done = BTreeSet::new();
    graph
        .keys()
        .find_map(|n| visit(n, graph, &mut done, &mut Vec::new()))
}

fn sources(dir: &Path) -> (String, BTreeMap<String, String>) {
    let mut lib = None;
    let mut modules = BTreeMap::new();
    for entry in std::fs::read_dir(dir).expect("read src/") {
        let path = entry.expect("read src/ entry").path();
        if path.extension().is_some_and(|e| e == "rs") {
            let name = path.file_stem().unwrap().to_string_lossy().into_owned();
            let text = std::fs::read_to_string(&path).expect("read a source file");
            if name == "lib" {
                lib = Some(text);
            } else {
                modules.insert(name, text);
            }
        }
    }
    (lib.expect("src/lib.rs"), modules)
}

#[test]
fn polar_render_modules_import_each_other_in_no_loop() {
    let (lib, modules) = sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src"));
    assert!(modules.len() > 5, "found only {:?}", modules.keys());
    let graph = module_graph(&lib, &modules).unwrap_or_else(|e| panic!("{}", e.join("\n")));
    assert!(
        graph["integrator"].contains("world"),
        "the parser misses edges: {graph:?}"
    );
    if let Some(cycle) = find_cycle(&graph) {
        panic!("module loop in polar-render: {}", cycle.join(" -> "));
    }
}

#[test]
fn the_checker_finds_a_loop_and_a_hidden_edge() {
    let lib = "pub enum Error {}\npub use b::Thing;";
    let modules = |a: &str, b: &str| {
        BTreeMap::from([
            ("a".to_owned(), a.to_owned()),
            ("b".to_owned(), b.to_owned()),
        ])
    };
    let looped = modules(
        "use crate::{Error, b::{X, Y}};",
        "fn f() { crate::a::g() } // crate::c",
    );
    let graph = module_graph(lib, &looped).unwrap();
    assert_eq!(
        find_cycle(&graph),
        Some(vec!["a".to_owned(), "b".to_owned(), "a".to_owned()])
    );
    let layered = modules("use crate::b::X;", "use crate::Error;");
    assert_eq!(find_cycle(&module_graph(lib, &layered).unwrap()), None);
    let hidden = modules("use crate::Thing;", "");
    assert!(module_graph(lib, &hidden).is_err());
}
