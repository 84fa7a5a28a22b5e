//! The import graph of a crate's sources, read from the text: which file of `src/`
//! uses which.
//!
//! Each `.rs` file is a module (`src/a/b.rs` and `src/a/b/mod.rs` are `a::b`; `lib.rs`
//! is the library's root, `main.rs` the binary's, whose modules live in `cli/`). After
//! comments, strings and `#[cfg(test)]` modules are removed, a file *uses* a module when
//! it names a path into it:
//! - in a `use` statement (trees such as `use crate::a::{b, c::{d, e as f}}` expanded);
//! - inline, as `crate::…`, `super::…`, `self::…`, `focal::…` (the library, from the
//!   binary), a child module's name, or a module brought in by a `use`.
//!
//! A path goes to the longest module prefix that is a file; a name that module binds by
//! a `use` (a re-export `pub use x::Item`, or a private import its children reach
//! through `super::`) is followed to where the item comes from, so using an item
//! through a folder's `mod.rs` is an edge to the file that defines it, not to the
//! facade. A `pub use` is not an edge of its own unless the file's code also names the
//! item. Edges into the crate roots are kept (the plugin groups live there).

use std::collections::{BTreeMap, BTreeSet, HashMap};

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
}

/// A `use` item: whether it is `pub`, where it points and the name it binds.
struct UseItem {
    public: bool,
    path: Module,
    name: String,
}

impl Graph {
    /// The graph of `sources` (path relative to `src/`, text).
    pub fn of(sources: &[(String, String)]) -> Graph {
        let mut graph = Graph::default();
        let mut texts = BTreeMap::new();
        for (rel, text) in sources {
            let Some(module) = module_of(rel) else { continue };
            graph.files.insert(module.clone(), rel.clone());
            texts.insert(module, code_only(text));
        }
        let mut uses: BTreeMap<Module, Vec<UseItem>> = BTreeMap::new();
        let mut bindings: HashMap<Module, HashMap<String, Module>> = HashMap::new();
        for (module, text) in &texts {
            let mut items = Vec::new();
            for s in use_statements(text) {
                for (p, alias) in expand(&text[s.tree.clone()]) {
                    let (Some(name), Some(path)) = (alias.or_else(|| p.last().cloned()), graph.absolute(module, &p)) else { continue };
                    items.push(UseItem { public: s.public, path, name });
                }
            }
            for u in items.iter().filter(|u| u.name != "*") {
                bindings.entry(module.clone()).or_default().insert(u.name.clone(), u.path.clone());
            }
            uses.insert(module.clone(), items);
        }
        for (module, text) in &texts {
            let body = without_use_statements(text);
            let mut found: Vec<(Module, String)> = Vec::new();
            // Modules bound by a `use`, for inline paths through them.
            let mut bound: HashMap<&str, &Module> = HashMap::new();
            for u in &uses[module] {
                if u.public && !mentions(&body, &u.name) {
                    continue;
                }
                found.push((u.path.clone(), u.path.path.join("::")));
                if graph.files.contains_key(&u.path) {
                    bound.insert(&u.name, &u.path);
                }
            }
            for path in inline_paths(&body) {
                let abs = graph.absolute(module, &path).or_else(|| {
                    let m = bound.get(path[0].as_str())?;
                    Some(Module { bin: m.bin, path: [m.path.clone(), path[1..].to_vec()].concat() })
                });
                if let Some(abs) = abs {
                    found.push((abs, path.join("::")));
                }
            }
            let mut edges: Vec<Edge> = Vec::new();
            for (abs, via) in found {
                let Some(to) = graph.resolve(abs, &bindings) else { continue };
                if &to != module && !edges.iter().any(|e| e.to == to) {
                    edges.push(Edge { to, via });
                }
            }
            graph.edges.insert(module.clone(), edges);
        }
        graph
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

/// Whether `word` occurs in `text` as a whole identifier.
fn mentions(text: &str, word: &str) -> bool {
    text.match_indices(word).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + word.len()..].chars().next();
        !before.is_some_and(is_ident) && !after.is_some_and(is_ident)
    })
}

fn is_ident(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

/// The text with comments, string and char literals blanked and `#[cfg(test)]` items
/// (test modules, test-only `use`s) removed.
pub fn code_only(text: &str) -> String {
    let b: Vec<char> = text.chars().collect();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        let next = b.get(i + 1).copied();
        if c == '/' && next == Some('/') {
            while i < b.len() && b[i] != '\n' {
                i += 1;
            }
        } else if c == '/' && next == Some('*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == '/' && b.get(i + 1) == Some(&'*') {
                    depth += 1;
                    i += 2;
                } else if b[i] == '*' && b.get(i + 1) == Some(&'/') {
                    depth -= 1;
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    i += 1;
                }
            }
            out.push(' ');
        } else if (c == 'r' || c == 'b') && !out.chars().next_back().is_some_and(is_ident) && raw_string_at(&b, i).is_some() {
            i = raw_string_at(&b, i).unwrap_or(i + 1);
            out.push_str("\"\"");
        } else if c == '"' {
            i += 1;
            while i < b.len() && b[i] != '"' {
                i += if b[i] == '\\' { 2 } else { 1 };
            }
            i += 1;
            out.push_str("\"\"");
        } else if c == '\'' {
            // A char literal ('x', '\n', '\u{..}'); otherwise a lifetime.
            if next == Some('\\') {
                i += 2;
                while i < b.len() && b[i] != '\'' {
                    i += 1;
                }
                i += 1;
                out.push_str("' '");
            } else if b.get(i + 2) == Some(&'\'') {
                i += 3;
                out.push_str("' '");
            } else {
                out.push(c);
                i += 1;
            }
        } else {
            out.push(c);
            i += 1;
        }
    }
    remove_test_items(&out)
}

/// The end (exclusive) of a raw string literal starting at `i` (`r"…"`, `r#"…"#`,
/// `br"…"`), if one starts there.
fn raw_string_at(b: &[char], i: usize) -> Option<usize> {
    let mut j = i;
    if b[j] == 'b' {
        j += 1;
    }
    if b.get(j) != Some(&'r') {
        return None;
    }
    j += 1;
    let mut hashes = 0;
    while b.get(j) == Some(&'#') {
        hashes += 1;
        j += 1;
    }
    if b.get(j) != Some(&'"') {
        return None;
    }
    j += 1;
    while j < b.len() {
        if b[j] == '"' && (1..=hashes).all(|k| b.get(j + k) == Some(&'#')) {
            return Some(j + 1 + hashes);
        }
        j += 1;
    }
    Some(b.len())
}

/// Removes each `#[cfg(test)]` item: a `mod … { … }` block or a `use …;` statement.
fn remove_test_items(text: &str) -> String {
    let mut out = String::new();
    let mut rest = text;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let after = &rest[at + "#[cfg(test)]".len()..];
        let trimmed = after.trim_start();
        let skip = after.len() - trimmed.len();
        let end = if trimmed.starts_with("mod ") || trimmed.starts_with("pub mod ") {
            match (trimmed.find('{'), trimmed.find(';')) {
                (Some(open), semi) if semi.is_none_or(|s| open < s) => matching_brace(trimmed, open).map(|e| e + 1),
                (_, Some(semi)) => Some(semi + 1),
                _ => None,
            }
        } else if trimmed.starts_with("use ") {
            trimmed.find(';').map(|s| s + 1)
        } else {
            Some(0)
        };
        let end = end.unwrap_or(trimmed.len());
        rest = &after[skip + end..];
    }
    out.push_str(rest);
    out
}

fn matching_brace(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in text[open..].char_indices() {
        match c {
            '{' => depth += 1,
            '}' => {
                depth -= 1;
                if depth == 0 {
                    return Some(open + i);
                }
            }
            _ => {}
        }
    }
    None
}

/// A `use` statement: whether it is `pub` (any visibility), where its tree is in the
/// text, and where the whole statement is.
struct UseStatement {
    public: bool,
    tree: std::ops::Range<usize>,
    whole: std::ops::Range<usize>,
}

/// Every `use` statement of a text (without comments and strings).
fn use_statements(text: &str) -> Vec<UseStatement> {
    let mut out = Vec::new();
    for (i, _) in text.match_indices("use") {
        let before = text[..i].chars().next_back();
        let after = text[i + 3..].chars().next();
        if before.is_some_and(|c| is_ident(c) || c == ':') || !after.is_some_and(char::is_whitespace) {
            continue;
        }
        let Some(end) = text[i..].find(';').map(|e| i + e) else { continue };
        let prefix = text[..i].trim_end();
        let line = &prefix[prefix.rfind('\n').map_or(0, |n| n + 1)..];
        let public = line.ends_with("pub") || (line.ends_with(')') && line.contains("pub("));
        out.push(UseStatement { public, tree: i + 3..end, whole: i..end + 1 });
    }
    out
}

/// The text with its `use` statements blanked.
fn without_use_statements(text: &str) -> String {
    let mut out = text.to_string();
    for s in use_statements(text).into_iter().rev() {
        out.replace_range(s.whole, " ");
    }
    out
}

/// The paths of a use tree, each with the alias it is bound to (`as`), if any.
pub fn expand(tree: &str) -> Vec<(Vec<String>, Option<String>)> {
    let tree: String = tree.split_whitespace().collect::<Vec<_>>().join(" ");
    let mut out = Vec::new();
    expand_into(&[], &tree, &mut out);
    out
}

fn expand_into(prefix: &[String], tree: &str, out: &mut Vec<(Vec<String>, Option<String>)>) {
    let mut depth = 0;
    let mut start = 0;
    let mut items = Vec::new();
    for (i, c) in tree.char_indices() {
        match c {
            '{' => depth += 1,
            '}' => depth -= 1,
            ',' if depth == 0 => {
                items.push(&tree[start..i]);
                start = i + 1;
            }
            _ => {}
        }
    }
    items.push(&tree[start..]);
    for item in items.into_iter().map(str::trim).filter(|s| !s.is_empty()) {
        if let (Some(open), Some(close)) = (item.find('{'), item.rfind('}')) {
            let head = segments(item[..open].trim_end_matches(|c: char| c == ':' || c.is_whitespace()));
            expand_into(&[prefix.to_vec(), head].concat(), &item[open + 1..close], out);
        } else {
            let (path, alias) = match item.split_once(" as ") {
                Some((p, a)) => (p, Some(a.trim().to_string())),
                None => (item, None),
            };
            let path = [prefix.to_vec(), segments(path)].concat();
            match path.last().map(String::as_str) {
                // `use a::b::{self}` binds `b`.
                Some("self") => out.push((path[..path.len() - 1].to_vec(), alias)),
                Some(_) => out.push((path, alias)),
                None => {}
            }
        }
    }
}

fn segments(path: &str) -> Vec<String> {
    path.split("::").map(str::trim).filter(|s| !s.is_empty()).map(String::from).collect()
}

/// Paths written in code: runs of identifiers joined by `::` (at least two segments),
/// not preceded by `::` themselves.
fn inline_paths(text: &str) -> Vec<Vec<String>> {
    let b: Vec<char> = text.chars().collect();
    let mut out = Vec::new();
    let mut i = 0;
    while i < b.len() {
        let starts = is_ident(b[i]) && !b[i].is_ascii_digit() && (i == 0 || !(is_ident(b[i - 1]) || b[i - 1] == ':'));
        if !starts {
            i += 1;
            continue;
        }
        let mut path = Vec::new();
        let mut j = i;
        loop {
            let s = j;
            while j < b.len() && is_ident(b[j]) {
                j += 1;
            }
            path.push(b[s..j].iter().collect::<String>());
            if b.get(j) == Some(&':') && b.get(j + 1) == Some(&':') && b.get(j + 2).is_some_and(|c| is_ident(*c)) {
                j += 2;
            } else {
                break;
            }
        }
        if path.len() > 1 {
            out.push(path);
        }
        i = j.max(i + 1);
    }
    out
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
