//! Reading Rust source as text for the import graph: comments, strings and test code
//! blanked; `use` statements and their trees; paths written in code; inline modules;
//! inherent `impl` blocks.

/// Whether `word` occurs in `text` as a whole identifier.
pub fn mentions(text: &str, word: &str) -> bool {
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
/// removed, and the names of the test modules it declares in files of their own
/// (`#[cfg(test)] mod tests;`).
pub fn code_only(text: &str) -> (String, Vec<String>) {
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

/// Removes each `#[cfg(test)]` item (after any further attributes): a `mod … { … }`
/// block, a `mod …;` declaration (its name is returned: that file is test code), a `use
/// …;` statement, or any other item up to its block or semicolon.
fn remove_test_items(text: &str) -> (String, Vec<String>) {
    let mut out = String::new();
    let mut test_files = Vec::new();
    let mut rest = text;
    while let Some(at) = rest.find("#[cfg(test)]") {
        out.push_str(&rest[..at]);
        let mut item = &rest[at + "#[cfg(test)]".len()..];
        // Further attributes of the same item.
        loop {
            let t = item.trim_start();
            if t.starts_with("#[") {
                match matching_bracket(t, 1) {
                    Some(close) => item = &t[close + 1..],
                    None => break,
                }
            } else {
                item = t;
                break;
            }
        }
        let words: Vec<&str> = item.split_whitespace().take(3).collect();
        let is_mod = words.first() == Some(&"mod") || (words.first().is_some_and(|w| w.starts_with("pub")) && words.get(1) == Some(&"mod"));
        let end = match (item.find('{'), item.find(';')) {
            (Some(open), semi) if semi.is_none_or(|s| open < s) => matching_brace(item, open).map(|e| e + 1),
            (_, Some(semi)) => {
                if is_mod {
                    let name = item[..semi].split_whitespace().last().unwrap_or_default();
                    test_files.push(name.to_string());
                }
                Some(semi + 1)
            }
            _ => None,
        };
        rest = &item[end.unwrap_or(item.len())..];
    }
    out.push_str(rest);
    (out, test_files)
}

/// The index of the `]` closing the `[` at byte `open` of `text`.
fn matching_bracket(text: &str, open: usize) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in text[open..].char_indices() {
        match c {
            '[' => depth += 1,
            ']' => {
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
pub struct UseStatement {
    pub public: bool,
    pub tree: std::ops::Range<usize>,
    pub whole: std::ops::Range<usize>,
}

/// Every `use` statement of a text (without comments and strings).
pub fn use_statements(text: &str) -> Vec<UseStatement> {
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
pub fn without_use_statements(text: &str) -> String {
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
pub fn inline_paths(text: &str) -> Vec<Vec<String>> {
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

/// A module written inline in a file (`mod name { … }`, not a test module): its path
/// below the file's module and its text; the file's own text has it blanked.
pub struct Scope {
    pub below: Vec<String>,
    pub text: String,
}

/// The file's own text and each inline module's, nested ones with their full path.
pub fn scopes(text: &str) -> Vec<Scope> {
    let mut out = Vec::new();
    split_scopes(text, &[], &mut out);
    out
}

fn split_scopes(text: &str, below: &[String], out: &mut Vec<Scope>) {
    let mut own = String::with_capacity(text.len());
    let mut rest = text;
    while let Some((start, name, open)) = next_inline_module(rest) {
        let Some(close) = matching_brace(rest, open) else { break };
        own.push_str(&rest[..start]);
        own.push_str(&" ".repeat(close + 1 - start));
        split_scopes(&rest[open + 1..close], &[below.to_vec(), vec![name]].concat(), out);
        rest = &rest[close + 1..];
    }
    own.push_str(rest);
    out.push(Scope { below: below.to_vec(), text: own });
}

/// The first `mod name {` of a text: where it starts, the name, where its brace is.
fn next_inline_module(text: &str) -> Option<(usize, String, usize)> {
    for (i, _) in text.match_indices("mod ") {
        if text[..i].chars().next_back().is_some_and(is_ident) {
            continue;
        }
        let after = &text[i + 4..];
        let name: String = after.trim_start().chars().take_while(|c| is_ident(*c)).collect();
        let tail = after.trim_start()[name.len()..].trim_start();
        if !name.is_empty() && tail.starts_with('{') {
            let open = text.len() - tail.len();
            return Some((i, name, open));
        }
    }
    None
}

/// The type paths of inherent `impl` blocks (`impl Type {`, `impl<T> a::b::Type<T> {`);
/// trait impls (`impl Trait for Type`) are left out.
pub fn inherent_impls(text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for (i, _) in text.match_indices("impl") {
        let before = text[..i].chars().next_back();
        let after = text[i + 4..].chars().next();
        if before.is_some_and(|c| is_ident(c) || c == ':') || !after.is_some_and(|c| c.is_whitespace() || c == '<') {
            continue;
        }
        // An item starts its line (`-> impl Trait` and `x: impl Trait` are types).
        let line = &text[text[..i].rfind('\n').map_or(0, |n| n + 1)..i];
        if !line.trim().is_empty() && line.trim() != "unsafe" {
            continue;
        }
        let Some(open) = text[i..].find(['{', ';']).map(|o| i + o) else { continue };
        let mut header = text[i + 4..open].trim();
        if header.starts_with('<') {
            let Some(end) = matching_angle(header) else { continue };
            header = header[end + 1..].trim_start();
        }
        let header = header.split(" where").next().unwrap_or(header);
        if header.split_whitespace().any(|w| w == "for") {
            continue;
        }
        let path: String = header.chars().take_while(|c| is_ident(*c) || *c == ':').collect();
        let path = segments(&path);
        if !path.is_empty() {
            out.push(path);
        }
    }
    out
}

fn matching_angle(text: &str) -> Option<usize> {
    let mut depth = 0;
    for (i, c) in text.char_indices() {
        match c {
            '<' => depth += 1,
            '>' => {
                depth -= 1;
                if depth == 0 {
                    return Some(i);
                }
            }
            _ => {}
        }
    }
    None
}

/// The text without visibility paths (`pub(in crate::a)`), which name no dependency.
pub fn without_visibility_paths(text: &str) -> String {
    let mut out = text.to_string();
    while let Some(at) = out.find("pub(in ") {
        let Some(close) = out[at..].find(')') else { break };
        out.replace_range(at..at + close + 1, "pub");
    }
    out
}
