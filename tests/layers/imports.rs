//! The import graph of a crate's sources, read from the text: which file of `src/`
//! uses which.
//!
//! Each `.rs` file is a module (`src/a/b.rs` and `src/a/b/mod.rs` are `a::b`; `lib.rs`
//! is the library's root, `main.rs` the binary's, whose modules live in `cli/`). After
//! comments, strings and `#[cfg(test)]` modules are removed, a file *uses* a module when
//! it names a path into it:
//! - in a `use` statement (trees such as `use crate::a::{b, c::{d, e as f}}` expanded);
//! - inline, as `crate::…`, `super::…`, `self::…`, `focal::…` (the library, from the
//!   binary), a child module's name, or a module brought in by a `use` (also in a later
//!   `use`: `use crate::lens; use lens::stack::Screen;`);
//! - as a glob (`use x::*`): the module itself, and what it binds that the code names;
//! - as the type of an inherent `impl` block (a method added to a type elsewhere is a
//!   dependency no path shows where the method is called: such impls are listed, so a
//!   check can keep them in their type's folder).
//!
//! Inline modules (`mod name { … }`) resolve `super` and `self` from their own path.
//! A path goes to the longest module prefix that is a file; a name that module binds by
//! a `use` (a re-export `pub use x::Item`, or a private import its children reach
//! through `super::`) is followed to where the item comes from, so using an item
//! through a folder's `mod.rs` is an edge to the file that defines it, not to the
//! facade. A `pub use` is an edge of its own only when the file's code also names the
//! item or it reaches into another folder (re-exporting what sits above is knowing it).
//! Edges into the crate roots are kept (the plugin groups live there). Visibility paths
//! (`pub(in crate::a)`) name no dependency.

use std::collections::{BTreeMap, BTreeSet, HashMap};

use super::source::{
    code_only, expand, inherent_impls, inline_paths, mentions, scopes, use_statements, without_use_statements, without_visibility_paths,
};

/// A module: the crate it belongs to and its path in it (`[]` is the root).
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Module {
    pub bin: bool,
    pub path: Vec<String>,
}

impl Module {
    /// The top folder of `src/` it lives in (`lib.rs` or `main.rs` for the roots).
    pub fn folder(&self) -> String {
        match (self.bin, self.path.first()) {
            (_, Some(first)) => first.clone(),
            (false, None) => "lib.rs".into(),
            (true, None) => "main.rs".into(),
        }
    }
}

/// One file's edge to another, with the path that made it (for messages).
#[derive(Clone, Debug)]
pub struct Edge {
    pub to: Module,
    pub via: String,
}

/// The files of a crate and what each uses.
#[derive(Debug, Default)]
pub struct Graph {
    /// Module → its file, relative to `src/`.
    pub files: BTreeMap<Module, String>,
    pub edges: BTreeMap<Module, Vec<Edge>>,
    /// Inherent `impl` blocks of a type another folder defines: the file, the type's
    /// file, the impl as written.
    pub foreign_impls: Vec<(Module, Module, String)>,
}

/// A `use` item: whether it is `pub`, where it points and the name it binds (`*` for a
/// glob, whose `path` is then the module it reads).
struct UseItem {
    public: bool,
    path: Module,
    name: String,
}

/// One module's text: a file's own, or an inline module's, with its uses.
struct Part {
    file: Module,
    scope: Module,
    body: String,
    uses: Vec<UseItem>,
}

impl Graph {
    /// The graph of `sources` (path relative to `src/`, text). Files declared as test
    /// modules (`#[cfg(test)] mod tests;`) and everything under them are left out.
    pub fn of(sources: &[(String, String)]) -> Graph {
        let mut graph = Graph::default();
        let mut texts = BTreeMap::new();
        let mut test_modules = Vec::new();
        for (rel, text) in sources {
            let Some(module) = module_of(rel) else { continue };
            let (code, tests) = code_only(text);
            test_modules.extend(tests.iter().map(|t| child(&module, t)));
            graph.files.insert(module.clone(), rel.clone());
            texts.insert(module, code);
        }
        let is_test = |m: &Module| test_modules.iter().any(|t| t.bin == m.bin && m.path.starts_with(&t.path));
        graph.files.retain(|m, _| !is_test(m));
        texts.retain(|m, _| !is_test(m));
        let mut parts = Vec::new();
        let mut bindings: HashMap<Module, HashMap<String, Module>> = HashMap::new();
        for (file, text) in &texts {
            for scope in scopes(text) {
                let module = Module { bin: file.bin, path: [file.path.clone(), scope.below].concat() };
                let uses = graph.use_items(&module, &scope.text);
                for u in uses.iter().filter(|u| u.name != "*") {
                    bindings.entry(module.clone()).or_default().insert(u.name.clone(), u.path.clone());
                }
                let body = without_visibility_paths(&without_use_statements(&scope.text));
                parts.push(Part { file: file.clone(), scope: module, body, uses });
            }
        }
        let mut edges: BTreeMap<Module, Vec<Edge>> = graph.files.keys().map(|m| (m.clone(), Vec::new())).collect();
        let mut foreign_impls = Vec::new();
        for part in &parts {
            let out = edges.entry(part.file.clone()).or_default();
            for (abs, via, impl_of) in graph.named_paths(part, &bindings) {
                let Some(to) = graph.resolve(abs, &bindings) else { continue };
                if impl_of && to.folder() != part.file.folder() {
                    foreign_impls.push((part.file.clone(), to.clone(), via.clone()));
                }
                if to != part.file && !out.iter().any(|e| e.to == to) {
                    out.push(Edge { to, via });
                }
            }
        }
        graph.edges = edges;
        graph.foreign_impls = foreign_impls;
        graph
    }

    /// The `use` items of one module's text, made absolute; a path that starts with a
    /// name an earlier item binds (`use crate::lens; use lens::stack::Screen;`) goes
    /// through it.
    fn use_items(&self, module: &Module, text: &str) -> Vec<UseItem> {
        let raw: Vec<(bool, Vec<String>, Option<String>)> = use_statements(text)
            .into_iter()
            .flat_map(|s| expand(&text[s.tree.clone()]).into_iter().map(move |(p, a)| (s.public, p, a)))
            .collect();
        let mut items: Vec<UseItem> = Vec::new();
        let mut done = vec![false; raw.len()];
        for _ in 0..4 {
            for (k, (public, p, alias)) in raw.iter().enumerate() {
                if done[k] {
                    continue;
                }
                let through = || {
                    let m = &items.iter().find(|u| u.name == p[0] && u.name != "*")?.path;
                    Some(Module { bin: m.bin, path: [m.path.clone(), p[1..].to_vec()].concat() })
                };
                let Some(mut path) = self.absolute(module, p).or_else(through) else { continue };
                let glob = p.last().is_some_and(|l| l == "*");
                if glob {
                    path.path.pop();
                }
                let name = if glob { "*".to_string() } else { alias.clone().unwrap_or_else(|| p.last().cloned().unwrap_or_default()) };
                items.push(UseItem { public: *public, path, name });
                done[k] = true;
            }
        }
        items
    }

    /// Every path one module's code names, with how it was written and whether it is the
    /// type of an inherent `impl`: its uses (a `pub use` only when the code names the
    /// item or it reaches into another folder; a glob as its module and the names the
    /// code takes from it), its inline paths, and its impls' types.
    fn named_paths(&self, part: &Part, bindings: &HashMap<Module, HashMap<String, Module>>) -> Vec<(Module, String, bool)> {
        let body = &part.body;
        let mut found: Vec<(Module, String, bool)> = Vec::new();
        let mut bound: HashMap<&str, &Module> = HashMap::new();
        for u in &part.uses {
            if u.name == "*" {
                found.push((u.path.clone(), format!("{}::*", u.path.path.join("::")), false));
                let file = self.resolve(u.path.clone(), bindings);
                for (name, target) in file.as_ref().and_then(|f| bindings.get(f)).into_iter().flatten() {
                    if mentions(body, name) {
                        found.push((target.clone(), format!("{}::* ({name})", u.path.path.join("::")), false));
                    }
                }
                continue;
            }
            let elsewhere = self.resolve(u.path.clone(), bindings).is_some_and(|t| t.folder() != part.file.folder());
            if u.public && !mentions(body, &u.name) && !elsewhere {
                continue;
            }
            found.push((u.path.clone(), u.path.path.join("::"), false));
            if self.files.contains_key(&u.path) {
                bound.insert(&u.name, &u.path);
            }
        }
        let through_bound = |path: &[String]| {
            let m = bound.get(path[0].as_str())?;
            Some(Module { bin: m.bin, path: [m.path.clone(), path[1..].to_vec()].concat() })
        };
        for path in inline_paths(body) {
            if let Some(abs) = self.absolute(&part.scope, &path).or_else(|| through_bound(&path)) {
                found.push((abs, path.join("::"), false));
            }
        }
        for path in inherent_impls(body) {
            let abs = match path.as_slice() {
                [name] => part.uses.iter().find(|u| &u.name == name).map(|u| u.path.clone()),
                _ => self.absolute(&part.scope, &path).or_else(|| through_bound(&path)),
            };
            if let Some(abs) = abs {
                found.push((abs, format!("impl {}", path.join("::")), true));
            }
        }
        found
    }

    /// `path` as written in `module`, made absolute (`None` for paths into other crates).
    fn absolute(&self, module: &Module, path: &[String]) -> Option<Module> {
        let (head, rest) = path.split_first()?;
        let (bin, path) = match head.as_str() {
            "crate" => (module.bin, rest.to_vec()),
            "focal" if module.bin => (false, rest.to_vec()),
            "self" => (module.bin, [module.path.clone(), rest.to_vec()].concat()),
            "super" => {
                let mut base = module.path.clone();
                let mut rest = path;
                while let Some((h, tail)) = rest.split_first()
                    && h == "super"
                {
                    base.pop()?;
                    rest = tail;
                }
                (module.bin, [base, rest.to_vec()].concat())
            }
            _ if self.files.contains_key(&child(module, head)) => (module.bin, [module.path.clone(), path.to_vec()].concat()),
            _ => return None,
        };
        Some(Module { bin, path })
    }

    /// The file a path ends in, following the names modules bind by `use`.
    fn resolve(&self, m: Module, bindings: &HashMap<Module, HashMap<String, Module>>) -> Option<Module> {
        let mut m = m;
        for _ in 0..16 {
            let (prefix, rest) = (0..=m.path.len()).rev().find_map(|i| {
                let p = Module { bin: m.bin, path: m.path[..i].to_vec() };
                self.files.contains_key(&p).then(|| (p, m.path[i..].to_vec()))
            })?;
            match rest.first().and_then(|name| bindings.get(&prefix)?.get(name)) {
                Some(target) => m = Module { bin: target.bin, path: [target.path.clone(), rest[1..].to_vec()].concat() },
                None => return Some(prefix),
            }
        }
        None
    }

    /// Groups of files that use each other (strongly connected, more than one file).
    pub fn cycles(&self) -> Vec<Vec<Module>> {
        let nodes: Vec<&Module> = self.files.keys().collect();
        let index_of: HashMap<&Module, usize> = nodes.iter().enumerate().map(|(i, m)| (*m, i)).collect();
        let next: Vec<Vec<usize>> =
            nodes.iter().map(|m| self.edges.get(*m).into_iter().flatten().filter_map(|e| index_of.get(&e.to).copied()).collect()).collect();
        strongly_connected(&next).into_iter().filter(|c| c.len() > 1).map(|c| c.into_iter().map(|i| nodes[i].clone()).collect()).collect()
    }

    /// The file of a module, for messages.
    pub fn file(&self, m: &Module) -> &str {
        self.files.get(m).map_or("?", String::as_str)
    }
}

fn child(m: &Module, name: &str) -> Module {
    Module { bin: m.bin, path: [m.path.clone(), vec![name.to_string()]].concat() }
}

/// The module of a file path relative to `src/`.
fn module_of(rel: &str) -> Option<Module> {
    let stem = rel.strip_suffix(".rs")?;
    let mut path: Vec<String> = stem.split('/').map(String::from).collect();
    if path.last().is_some_and(|s| s == "mod") {
        path.pop();
    }
    match path.as_slice() {
        [root] if root == "lib" => Some(Module { bin: false, path: vec![] }),
        [root] if root == "main" => Some(Module { bin: true, path: vec![] }),
        [first, ..] if first == "cli" => Some(Module { bin: true, path }),
        _ => Some(Module { bin: false, path }),
    }
}

/// Tarjan's strongly connected components of a graph given by successor lists.
fn strongly_connected(next: &[Vec<usize>]) -> Vec<Vec<usize>> {
    struct State<'a> {
        next: &'a [Vec<usize>],
        index: Vec<Option<usize>>,
        low: Vec<usize>,
        stack: Vec<usize>,
        on_stack: Vec<bool>,
        counter: usize,
        out: Vec<Vec<usize>>,
    }
    fn visit(s: &mut State, v: usize) {
        s.index[v] = Some(s.counter);
        s.low[v] = s.counter;
        s.counter += 1;
        s.stack.push(v);
        s.on_stack[v] = true;
        for k in 0..s.next[v].len() {
            let w = s.next[v][k];
            match s.index[w] {
                None => {
                    visit(s, w);
                    s.low[v] = s.low[v].min(s.low[w]);
                }
                Some(iw) if s.on_stack[w] => s.low[v] = s.low[v].min(iw),
                Some(_) => {}
            }
        }
        if Some(s.low[v]) == s.index[v] {
            let mut comp = Vec::new();
            while let Some(w) = s.stack.pop() {
                s.on_stack[w] = false;
                comp.push(w);
                if w == v {
                    break;
                }
            }
            comp.sort_unstable();
            s.out.push(comp);
        }
    }
    let n = next.len();
    let mut s =
        State { next, index: vec![None; n], low: vec![0; n], stack: Vec::new(), on_stack: vec![false; n], counter: 0, out: Vec::new() };
    for v in 0..n {
        if s.index[v].is_none() {
            visit(&mut s, v);
        }
    }
    s.out
}

/// The folders each folder uses (for the layer picture and messages).
pub fn folder_edges(graph: &Graph) -> BTreeMap<String, BTreeSet<String>> {
    let mut out: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for (from, edges) in &graph.edges {
        for e in edges {
            if from.folder() != e.to.folder() {
                out.entry(from.folder()).or_default().insert(e.to.folder());
            }
        }
    }
    out
}
