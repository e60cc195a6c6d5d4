//! The module house (issue 65): no import cycle between source files in the library or in any
//! tool, and no function over 80 lines in `src/` or `tools/`. Read from the code as text: every
//! `use` tree and every `crate::` / `super::` / `self::` path outside comments and strings,
//! resolved to the file that defines the item (re-exports followed). A child that uses what its
//! own parent module file defines is allowed (the parent declares the child; that is not a
//! loop). The negative controls plant a cycle and a long function in a tree of their own.
//!
//! No cycle and no long function is allowed. `MODULE_HOUSE_EXPLAIN=1` prints the edges of
//! every cycle.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Longest function allowed, in lines from its `fn` line to its closing brace.
const MAX_FUNCTION_LINES: usize = 80;

/// One source file: its module path inside its crate and its text with comments and string
/// contents blanked (newlines kept).
struct SourceFile {
    path: PathBuf,
    module: Vec<String>,
    code: String,
}

/// A crate read from its root: every module file reached by `mod` declarations.
struct CrateTree {
    files: Vec<SourceFile>,
    /// Module path -> index into `files`.
    by_module: BTreeMap<Vec<String>, usize>,
}

/// Blanks comments, string and char literals (keeping newlines), so the scanners below see
/// only code.
fn strip(text: &str) -> String {
    let b = text.as_bytes();
    let mut out = Vec::with_capacity(b.len());
    let mut i = 0;
    let blank = |c: u8| if c == b'\n' { b'\n' } else { b' ' };
    while i < b.len() {
        let c = b[i];
        if c == b'/' && b.get(i + 1) == Some(&b'/') {
            while i < b.len() && b[i] != b'\n' {
                out.push(b' ');
                i += 1;
            }
        } else if c == b'/' && b.get(i + 1) == Some(&b'*') {
            let mut depth = 0;
            while i < b.len() {
                if b[i] == b'/' && b.get(i + 1) == Some(&b'*') {
                    depth += 1;
                    out.extend([b' ', b' ']);
                    i += 2;
                } else if b[i] == b'*' && b.get(i + 1) == Some(&b'/') {
                    depth -= 1;
                    out.extend([b' ', b' ']);
                    i += 2;
                    if depth == 0 {
                        break;
                    }
                } else {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
        } else if c == b'r'
            && (b.get(i + 1) == Some(&b'"') || b.get(i + 1) == Some(&b'#'))
            && (i == 0 || !(b[i - 1].is_ascii_alphanumeric() || b[i - 1] == b'_'))
        {
            let hashes = b[i + 1..].iter().take_while(|&&h| h == b'#').count();
            if b.get(i + 1 + hashes) != Some(&b'"') {
                out.push(c);
                i += 1;
                continue;
            }
            let close: Vec<u8> = std::iter::once(b'"')
                .chain(std::iter::repeat_n(b'#', hashes))
                .collect();
            out.push(b' ');
            i += 2 + hashes;
            out.extend(std::iter::repeat_n(b' ', 1 + hashes));
            while i < b.len() && !b[i..].starts_with(&close) {
                out.push(blank(b[i]));
                i += 1;
            }
            out.extend(std::iter::repeat_n(b' ', close.len()));
            i += close.len();
        } else if c == b'"' {
            out.push(b' ');
            i += 1;
            while i < b.len() && b[i] != b'"' {
                if b[i] == b'\\' {
                    out.push(b' ');
                    i += 1;
                }
                if i < b.len() {
                    out.push(blank(b[i]));
                    i += 1;
                }
            }
            out.push(b' ');
            i += 1;
        } else if c == b'\'' && (b.get(i + 2) == Some(&b'\'') || b.get(i + 1) == Some(&b'\\')) {
            // A char literal (a lifetime has no closing quote two bytes on).
            out.push(b' ');
            i += 1;
            while i < b.len() && b[i] != b'\'' {
                if b[i] == b'\\' {
                    out.push(b' ');
                    i += 1;
                }
                out.push(b' ');
                i += 1;
            }
            out.push(b' ');
            i += 1;
        } else {
            out.push(c);
            i += 1;
        }
    }
    out.truncate(b.len());
    String::from_utf8_lossy(&out).into_owned()
}

fn is_ident(c: char) -> bool {
    c.is_ascii_alphanumeric() || c == '_'
}

/// Words and punctuation of blanked code, each with its line (1-based).
fn tokens(code: &str) -> Vec<(String, usize)> {
    let mut out = Vec::new();
    let mut line = 1;
    let chars: Vec<char> = code.chars().collect();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        if c == '\n' {
            line += 1;
            i += 1;
        } else if c.is_whitespace() {
            i += 1;
        } else if is_ident(c) {
            let start = i;
            while i < chars.len() && is_ident(chars[i]) {
                i += 1;
            }
            out.push((chars[start..i].iter().collect(), line));
        } else if c == ':' && chars.get(i + 1) == Some(&':') {
            out.push(("::".to_string(), line));
            i += 2;
        } else {
            out.push((c.to_string(), line));
            i += 1;
        }
    }
    out
}

/// The file a `mod name;` in `file` (module path `module`) loads, by Rust's rules.
fn child_file(file: &Path, name: &str, path_attr: Option<&str>) -> PathBuf {
    let dir = file.parent().unwrap();
    if let Some(p) = path_attr {
        return dir.join(p);
    }
    let stem = file.file_stem().unwrap().to_str().unwrap();
    let base = if matches!(stem, "mod" | "lib" | "main") || is_crate_root(file) {
        dir.to_path_buf()
    } else {
        dir.join(stem)
    };
    let flat = base.join(format!("{name}.rs"));
    if flat.exists() {
        flat
    } else {
        base.join(name).join("mod.rs")
    }
}

thread_local! {
    static ROOTS: std::cell::RefCell<BTreeSet<PathBuf>> = const { std::cell::RefCell::new(BTreeSet::new()) };
}

fn is_crate_root(file: &Path) -> bool {
    ROOTS.with(|r| r.borrow().contains(file))
}

impl CrateTree {
    /// Reads the crate whose root file is `root`.
    fn read(root: &Path) -> CrateTree {
        ROOTS.with(|r| r.borrow_mut().insert(root.to_path_buf()));
        let mut tree = CrateTree {
            files: Vec::new(),
            by_module: BTreeMap::new(),
        };
        let mut todo = vec![(root.to_path_buf(), Vec::<String>::new())];
        while let Some((path, module)) = todo.pop() {
            let text = std::fs::read_to_string(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()));
            let code = strip(&text);
            let toks = tokens(&code);
            for (i, (t, _)) in toks.iter().enumerate() {
                // `mod name;` (not `mod name {`): a file of its own.
                if t == "mod" && toks.get(i + 2).map(|x| x.0.as_str()) == Some(";") {
                    let name = &toks[i + 1].0;
                    let attr = path_attribute(&text, toks[i].1);
                    let file = child_file(&path, name, attr.as_deref());
                    let mut m = module.clone();
                    m.push(name.clone());
                    todo.push((file, m));
                }
            }
            tree.by_module.insert(module.clone(), tree.files.len());
            tree.files.push(SourceFile { path, module, code });
        }
        tree
    }
}

/// The `#[path = "..."]` just above line `line` of `text`, if any.
fn path_attribute(text: &str, line: usize) -> Option<String> {
    let above = text.lines().nth(line.checked_sub(2)?)?.trim();
    let rest = above.strip_prefix("#[path = \"")?;
    Some(rest.split('"').next()?.to_string())
}

/// Expands a `use` tree starting at token `i` (after `use`) into full paths; returns the
/// paths and the index after the closing `;`.
fn use_paths(toks: &[(String, usize)], mut i: usize) -> (Vec<Vec<String>>, usize) {
    fn tree(
        toks: &[(String, usize)],
        i: &mut usize,
        prefix: &[String],
        out: &mut Vec<Vec<String>>,
    ) {
        let mut path = prefix.to_vec();
        while *i < toks.len() {
            let t = toks[*i].0.as_str();
            match t {
                "::" => *i += 1,
                "{" => {
                    *i += 1;
                    loop {
                        tree(toks, i, &path, out);
                        match toks.get(*i).map(|x| x.0.as_str()) {
                            Some(",") => *i += 1,
                            Some("}") => {
                                *i += 1;
                                break;
                            }
                            _ => break,
                        }
                        if toks.get(*i).map(|x| x.0.as_str()) == Some("}") {
                            *i += 1;
                            break;
                        }
                    }
                    return;
                }
                "," | "}" | ";" => {
                    out.push(path);
                    return;
                }
                "as" => {
                    // The name the item is known by here: kept as a last `as:` segment.
                    if let Some(alias) = toks.get(*i + 1) {
                        path.push(format!("as:{}", alias.0));
                    }
                    *i += 2;
                }
                "*" => {
                    path.push("*".into());
                    *i += 1;
                }
                _ => {
                    path.push(t.to_string());
                    *i += 1;
                }
            }
        }
        out.push(path);
    }
    let mut out = Vec::new();
    tree(toks, &mut i, &[], &mut out);
    while i < toks.len() && toks[i].0 != ";" {
        i += 1;
    }
    (out, i + 1)
}

/// A reference found in a file: the module it is written in and the path as written.
struct Reference {
    scope: Vec<String>,
    path: Vec<String>,
    /// The name a `use ... as name` gives the item.
    alias: Option<String>,
    is_use: bool,
    is_pub_use: bool,
}

/// Every `use` path and every `crate::`/`super::`/`self::` path of a file, with the inline
/// module each sits in.
fn references(file: &SourceFile) -> Vec<Reference> {
    let toks = tokens(&file.code);
    let mut out = Vec::new();
    let mut scope = file.module.clone();
    let mut inline: Vec<(usize, usize)> = Vec::new(); // (depth opened at, names pushed)
    let mut depth = 0usize;
    let mut i = 0;
    while i < toks.len() {
        let t = toks[i].0.as_str();
        match t {
            "{" => depth += 1,
            "}" => {
                depth -= 1;
                if inline.last().map(|x| x.0) == Some(depth) {
                    inline.pop();
                    scope.pop();
                }
            }
            "mod" if toks.get(i + 2).map(|x| x.0.as_str()) == Some("{") => {
                scope.push(toks[i + 1].0.clone());
                inline.push((depth, 1));
                depth += 1;
                i += 3;
                continue;
            }
            "use" => {
                let is_pub = i > 0 && (toks[i - 1].0 == "pub" || toks[i - 1].0 == ")");
                let (paths, next) = use_paths(&toks, i + 1);
                for mut path in paths {
                    let alias = path
                        .last()
                        .and_then(|l| l.strip_prefix("as:"))
                        .map(String::from);
                    if alias.is_some() {
                        path.pop();
                    }
                    out.push(Reference {
                        scope: scope.clone(),
                        path,
                        alias,
                        is_use: true,
                        is_pub_use: is_pub,
                    });
                }
                i = next;
                continue;
            }
            "crate" | "super" | "self"
                if toks.get(i + 1).map(|x| x.0.as_str()) == Some("::")
                    && (i == 0 || toks[i - 1].0 != "::") =>
            {
                let mut path = vec![t.to_string()];
                let mut j = i + 1;
                while toks.get(j).map(|x| x.0.as_str()) == Some("::")
                    && toks.get(j + 1).is_some_and(|x| x.0.chars().all(is_ident))
                {
                    path.push(toks[j + 1].0.clone());
                    j += 2;
                }
                out.push(Reference {
                    scope: scope.clone(),
                    path,
                    alias: None,
                    is_use: false,
                    is_pub_use: false,
                });
                i = j;
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    out
}

impl CrateTree {
    /// The absolute path a reference names, or `None` for another crate's.
    fn absolute(&self, r: &Reference) -> Option<Vec<String>> {
        let mut segs = r.path.iter();
        let first = segs.clone().next()?.as_str();
        let mut base: Vec<String> = match first {
            "crate" => {
                segs.next();
                Vec::new()
            }
            "self" | "super" => {
                let mut b = r.scope.clone();
                while let Some(s) = segs.clone().next() {
                    match s.as_str() {
                        "self" => {}
                        "super" => {
                            b.pop();
                        }
                        _ => break,
                    }
                    segs.next();
                }
                b
            }
            name if r.is_use => {
                // 2018 paths: a child module of the scope.
                let mut child = r.scope.clone();
                child.push(name.to_string());
                if !self.by_module.contains_key(&child) {
                    return None;
                }
                r.scope.clone()
            }
            _ => return None,
        };
        base.extend(segs.filter(|s| *s != "self").cloned());
        Some(base)
    }

    /// The file defining what `path` names: the deepest module file on it, then through that
    /// file's `pub use` re-exports of the next name.
    fn target(&self, path: &[String], hops: usize) -> Option<usize> {
        let mut k = path.len();
        while !self.by_module.contains_key(&path[..k]) {
            k -= 1;
        }
        let file = self.by_module[&path[..k]];
        let Some(item) = path.get(k) else {
            return Some(file);
        };
        if hops > 8 {
            return Some(file);
        }
        for r in references(&self.files[file]) {
            if !r.is_pub_use || r.scope != self.files[file].module {
                continue;
            }
            let last = r.path.last().map(String::as_str);
            let known_as = r.alias.as_deref().or(last);
            if known_as != Some(item.as_str()) && last != Some("*") {
                continue;
            }
            let Some(mut next) = self.absolute(&r) else {
                continue;
            };
            if last == Some("*") {
                next.pop();
                next.push(item.clone());
            }
            if next.starts_with(&path[..k]) && next.len() <= k {
                continue;
            }
            match self.target(&next, hops + 1) {
                Some(t) if last != Some("*") || t != file => return Some(t),
                _ => {}
            }
        }
        Some(file)
    }

    /// File -> files it takes from, each with the first path that takes it; edges to the
    /// file's own ancestors' module files dropped.
    fn edges(&self) -> Vec<BTreeMap<usize, String>> {
        let mut edges = vec![BTreeMap::new(); self.files.len()];
        for (f, file) in self.files.iter().enumerate() {
            for r in references(file) {
                let Some(abs) = self.absolute(&r) else {
                    continue;
                };
                let Some(t) = self.target(&abs, 0) else {
                    continue;
                };
                let own_ancestor = file.module.starts_with(&self.files[t].module);
                if t != f && !own_ancestor {
                    edges[f].entry(t).or_insert_with(|| r.path.join("::"));
                }
            }
        }
        edges
    }

    /// The edges inside one cycle, a line each, for the failure message.
    fn explain(&self, cycle: &str, root_dir: &Path) -> String {
        let members: BTreeSet<&str> = cycle.split(' ').collect();
        let edges = self.edges();
        let mut lines = Vec::new();
        for (f, out) in edges.iter().enumerate() {
            let from = rel(&self.files[f].path, root_dir);
            if !members.contains(from.as_str()) {
                continue;
            }
            for (t, why) in out {
                let to = rel(&self.files[*t].path, root_dir);
                if members.contains(to.as_str()) {
                    lines.push(format!("    {from} -> {to} ({why})"));
                }
            }
        }
        lines.join("\n")
    }

    /// The strongly connected groups of two or more files (Tarjan), each as sorted paths.
    fn cycles(&self, root_dir: &Path) -> Vec<String> {
        let edges = self
            .edges()
            .into_iter()
            .map(|e| e.into_keys().collect())
            .collect();
        let mut t = Tarjan::new(edges);
        for v in 0..self.files.len() {
            if t.index[v] == usize::MAX {
                t.visit(v);
            }
        }
        let mut out: Vec<String> = t
            .groups
            .into_iter()
            .filter(|g| g.len() > 1)
            .map(|g| {
                let mut names: Vec<String> = g
                    .iter()
                    .map(|&f| rel(&self.files[f].path, root_dir))
                    .collect();
                names.sort();
                names.join(" ")
            })
            .collect();
        out.sort();
        out
    }
}

/// Tarjan's strongly connected components over file edges.
struct Tarjan {
    edges: Vec<BTreeSet<usize>>,
    index: Vec<usize>,
    low: Vec<usize>,
    on_stack: Vec<bool>,
    stack: Vec<usize>,
    next: usize,
    groups: Vec<Vec<usize>>,
}

impl Tarjan {
    fn new(edges: Vec<BTreeSet<usize>>) -> Tarjan {
        let n = edges.len();
        Tarjan {
            edges,
            index: vec![usize::MAX; n],
            low: vec![0; n],
            on_stack: vec![false; n],
            stack: Vec::new(),
            next: 0,
            groups: Vec::new(),
        }
    }

    fn visit(&mut self, v: usize) {
        self.index[v] = self.next;
        self.low[v] = self.next;
        self.next += 1;
        self.stack.push(v);
        self.on_stack[v] = true;
        for w in self.edges[v].clone() {
            if self.index[w] == usize::MAX {
                self.visit(w);
                self.low[v] = self.low[v].min(self.low[w]);
            } else if self.on_stack[w] {
                self.low[v] = self.low[v].min(self.index[w]);
            }
        }
        if self.low[v] == self.index[v] {
            let mut group = Vec::new();
            while let Some(w) = self.stack.pop() {
                self.on_stack[w] = false;
                group.push(w);
                if w == v {
                    break;
                }
            }
            self.groups.push(group);
        }
    }
}

/// The renderer's layers: `render/core/` takes nothing from the rest of `render/`, and a
/// feature under `render/features/<name>/` takes only from `core` and its own folder.
fn layer_violations(tree: &CrateTree, root_dir: &Path) -> Vec<String> {
    let mut out = Vec::new();
    for (f, targets) in tree.edges().iter().enumerate() {
        let from = rel(&tree.files[f].path, root_dir);
        for (t, why) in targets {
            let to = rel(&tree.files[*t].path, root_dir);
            if !to.starts_with("src/render/") || to.starts_with("src/render/core/") {
                continue;
            }
            let feature = |p: &str| {
                p.strip_prefix("src/render/features/")
                    .map(|rest| rest.split('/').next().unwrap_or("").to_string())
            };
            let allowed = if from.starts_with("src/render/core/") {
                false
            } else if let Some(own) = feature(&from) {
                feature(&to).is_some_and(|f| f == own)
            } else {
                true
            };
            if !allowed {
                out.push(format!("{from} takes from {to} ({why})"));
            }
        }
    }
    out.sort();
    out
}

fn rel(path: &Path, root: &Path) -> String {
    path.strip_prefix(root)
        .unwrap_or(path)
        .to_string_lossy()
        .replace('\\', "/")
}

/// Functions over `max` lines in blanked code: (name, first line, lines).
fn long_functions(code: &str, max: usize) -> Vec<(String, usize, usize)> {
    let toks = tokens(code);
    let mut out = Vec::new();
    for i in 0..toks.len() {
        if toks[i].0 != "fn" || !toks.get(i + 1).is_some_and(|t| t.0.chars().all(is_ident)) {
            continue;
        }
        // The body's `{` is the first one outside parentheses/angle brackets' nesting; a `;`
        // first means a declaration without a body.
        let mut j = i + 2;
        let mut paren = 0i32;
        while j < toks.len() {
            match toks[j].0.as_str() {
                "(" | "[" => paren += 1,
                ")" | "]" => paren -= 1,
                ";" if paren == 0 => break,
                "{" if paren == 0 => break,
                _ => {}
            }
            j += 1;
        }
        if toks.get(j).map(|t| t.0.as_str()) != Some("{") {
            continue;
        }
        let mut depth = 0;
        let mut k = j;
        while k < toks.len() {
            match toks[k].0.as_str() {
                "{" => depth += 1,
                "}" => {
                    depth -= 1;
                    if depth == 0 {
                        break;
                    }
                }
                _ => {}
            }
            k += 1;
        }
        let (start, end) = (toks[i].1, toks[k.min(toks.len() - 1)].1);
        if end - start + 1 > max {
            out.push((toks[i + 1].0.clone(), start, end - start + 1));
        }
    }
    out
}

/// Every crate root of this package and its tools: the library and each binary and example.
fn crate_roots(root: &Path) -> Vec<PathBuf> {
    let mut roots = vec![
        root.join("src/lib.rs"),
        root.join("tools/bevy_hair/src/lib.rs"),
    ];
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    for line in manifest.lines() {
        if let Some(p) = line.trim().strip_prefix("path = \"") {
            let p = p.trim_end_matches('"');
            if p.ends_with(".rs") {
                roots.push(root.join(p));
            }
        }
    }
    for dir in ["tools/bevy_hair/examples"] {
        for e in std::fs::read_dir(root.join(dir)).unwrap() {
            let p = e.unwrap().path();
            if p.extension().is_some_and(|x| x == "rs") {
                roots.push(p);
            }
        }
    }
    roots.sort();
    roots.dedup();
    roots
}

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for e in std::fs::read_dir(dir).unwrap() {
        let p = e.unwrap().path();
        if p.is_dir() {
            if !p.ends_with("target") {
                rust_files(&p, out);
            }
        } else if p.extension().is_some_and(|x| x == "rs") {
            out.push(p);
        }
    }
}

fn check_against(found: &[String], known: &[&str], what: &str) -> Vec<String> {
    let known: BTreeSet<&str> = known.iter().copied().collect();
    let found_set: BTreeSet<&str> = found.iter().map(String::as_str).collect();
    let mut problems = Vec::new();
    for f in &found_set {
        if !known.contains(f) {
            problems.push(format!("new {what}: {f}"));
        }
    }
    for k in &known {
        if !found_set.contains(k) {
            problems.push(format!("gone (take it off the list): {what} {k}"));
        }
    }
    problems
}

#[test]
fn the_module_graph_has_no_cycles_and_no_function_is_over_80_lines() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut cycles = Vec::new();
    let mut explained = BTreeMap::new();
    let mut layers = Vec::new();
    for crate_root in crate_roots(root) {
        let tree = CrateTree::read(&crate_root);
        layers.extend(layer_violations(&tree, root));
        for c in tree.cycles(root) {
            explained.insert(c.clone(), tree.explain(&c, root));
            if std::env::var_os("MODULE_HOUSE_EXPLAIN").is_some() {
                eprintln!("cycle:\n{}", tree.explain(&c, root));
            }
            cycles.push(c);
        }
    }
    cycles.sort();
    cycles.dedup();
    let mut long = Vec::new();
    let mut files = Vec::new();
    rust_files(&root.join("src"), &mut files);
    rust_files(&root.join("tools"), &mut files);
    files.sort();
    for f in files {
        let code = strip(&std::fs::read_to_string(&f).unwrap());
        for (name, _, _) in long_functions(&code, MAX_FUNCTION_LINES) {
            long.push(format!("{}::{name}", rel(&f, root)));
        }
    }
    let mut sources = Vec::new();
    rust_files(&root.join("src"), &mut sources);
    let sources: BTreeSet<String> = sources.iter().map(|f| rel(f, &root.join("src"))).collect();
    let chapter = std::fs::read_to_string(root.join("src/guide/layout.md")).unwrap();
    let mut problems = check_against(&cycles, &[], "cycle");
    problems.extend(layout_problems(&chapter, &sources));
    problems.extend(layers.into_iter().map(|l| format!("layer: {l}")));
    for p in problems.iter_mut() {
        if let Some(why) = p.strip_prefix("new cycle: ").and_then(|c| explained.get(c)) {
            *p = format!("{p}\n{why}");
        }
    }
    problems.extend(check_against(&long, &[], "function over 80 lines"));
    eprintln!(
        "{} cycles, {} functions over {MAX_FUNCTION_LINES} lines",
        cycles.len(),
        long.len()
    );
    assert!(problems.is_empty(), "{}", problems.join("\n"));
}

/// What the layout chapter gets wrong: files it does not name and names that are not files.
/// Its headings name folders (`### \`render/core/\``, `### \`src/\`` for the root) and its
/// bullets the files in them (`- \`shared.rs\`: ...`).
fn layout_problems(chapter: &str, files: &BTreeSet<String>) -> Vec<String> {
    let mut named = BTreeSet::new();
    let mut folder: Option<String> = None;
    for line in chapter.lines() {
        if let Some(h) = line.strip_prefix("### `") {
            let dir = h.split('`').next().unwrap_or("");
            folder = Some(if dir == "src/" {
                String::new()
            } else {
                dir.to_string()
            });
        } else if let (Some(b), Some(dir)) = (line.strip_prefix("- `"), &folder) {
            let file = b.split('`').next().unwrap_or("");
            if file.ends_with(".rs") {
                named.insert(format!("{dir}{file}"));
            }
        }
    }
    let mut out: Vec<String> = files
        .difference(&named)
        .map(|f| format!("layout chapter does not name src/{f}"))
        .collect();
    out.extend(
        named
            .difference(files)
            .map(|f| format!("layout chapter names src/{f}, which does not exist")),
    );
    out
}

/// A tree of its own under the target folder, written file by file.
fn planted(name: &str, files: &[(&str, &str)]) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    let _ = std::fs::remove_dir_all(&dir);
    for (p, text) in files {
        let path = dir.join(p);
        std::fs::create_dir_all(path.parent().unwrap()).unwrap();
        std::fs::write(path, text).unwrap();
    }
    dir
}

#[test]
fn a_planted_cycle_is_found_and_a_child_using_its_parent_is_not_one() {
    let dir = planted(
        "planted_cycle",
        &[
            (
                "lib.rs",
                "pub mod a;\npub mod b;\npub mod c;\npub use c::Thing;\n",
            ),
            (
                "a.rs",
                "use crate::b::B; // crate::c::nothing\npub struct A;\n",
            ),
            (
                "b.rs",
                "pub struct B { x: crate::Thing }\nconst S: &str = \"crate::a::A\";\n",
            ),
            (
                "c/mod.rs",
                "pub mod inner;\npub struct Thing;\nfn f() -> super::a::A { todo!() }\n",
            ),
            ("c/inner.rs", "use super::Thing;\n"),
        ],
    );
    let tree = CrateTree::read(&dir.join("lib.rs"));
    assert_eq!(tree.cycles(&dir), vec!["a.rs b.rs c/mod.rs".to_string()]);

    // Without the back edge (c -> a) nothing loops, and c/inner.rs -> c/mod.rs is allowed.
    let dir = planted(
        "planted_no_cycle",
        &[
            (
                "lib.rs",
                "pub mod a;\npub mod b;\npub mod c;\npub use c::Thing;\n",
            ),
            ("a.rs", "use crate::b::B;\npub struct A;\n"),
            ("b.rs", "pub struct B { x: crate::Thing }\n"),
            (
                "c/mod.rs",
                "pub mod inner;\npub struct Thing;\nuse inner::I;\n",
            ),
            ("c/inner.rs", "use super::Thing;\npub struct I;\n"),
        ],
    );
    let tree = CrateTree::read(&dir.join("lib.rs"));
    assert!(tree.cycles(&dir).is_empty(), "{:?}", tree.cycles(&dir));
}

#[test]
fn a_core_or_feature_that_takes_from_above_is_found() {
    let dir = planted(
        "planted_layers",
        &[
            ("src/lib.rs", "pub mod render;\n"),
            (
                "src/render/mod.rs",
                "pub mod core;\npub mod features;\npub mod renderer;\n",
            ),
            (
                "src/render/core/mod.rs",
                "pub struct Graph;\nfn f(_: crate::render::renderer::R) {}\n",
            ),
            ("src/render/features/mod.rs", "pub mod a;\npub mod b;\n"),
            (
                "src/render/features/a/mod.rs",
                "use crate::render::core::Graph;\nuse super::b::B;\n",
            ),
            ("src/render/features/b/mod.rs", "pub struct B;\n"),
            (
                "src/render/renderer.rs",
                "pub struct R;\nuse super::features::a;\n",
            ),
        ],
    );
    let tree = CrateTree::read(&dir.join("src/lib.rs"));
    assert_eq!(
        layer_violations(&tree, &dir),
        vec![
            "src/render/core/mod.rs takes from src/render/renderer.rs (crate::render::renderer::R)"
                .to_string(),
            "src/render/features/a/mod.rs takes from src/render/features/b/mod.rs (super::b::B)"
                .to_string(),
        ]
    );
}

#[test]
fn a_layout_chapter_that_misses_a_file_or_names_a_missing_one_is_refused() {
    let files: BTreeSet<String> = ["lib.rs", "render/mod.rs", "render/core/shared.rs"]
        .map(String::from)
        .into();
    let good = "### `src/`\n\n- `lib.rs`: root.\n\n### `render/`\n- `mod.rs`: x.\n### `render/core/`\n- `shared.rs`: y.\n";
    assert!(layout_problems(good, &files).is_empty());
    let missing = good.replace("- `shared.rs`: y.\n", "- `slots.rs`: y.\n");
    assert_eq!(
        layout_problems(&missing, &files),
        vec![
            "layout chapter does not name src/render/core/shared.rs".to_string(),
            "layout chapter names src/render/core/slots.rs, which does not exist".to_string(),
        ]
    );
}

#[test]
fn a_planted_long_function_is_found() {
    let body = "    let x = 1;\n".repeat(MAX_FUNCTION_LINES - 2);
    let code = strip(&format!(
        "fn short() {{}}\nfn long() {{\n{body}}}\nfn decl();\n"
    ));
    let found = long_functions(&code, MAX_FUNCTION_LINES);
    assert!(found.is_empty(), "{found:?}");
    let code = strip(&format!("fn long() {{\n{body}    let s = \"}}\";\n}}\n"));
    assert_eq!(
        long_functions(&code, MAX_FUNCTION_LINES),
        vec![("long".to_string(), 1, 81)]
    );
}
