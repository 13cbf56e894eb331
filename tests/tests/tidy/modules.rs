//! The module graph of a crate at every depth, drawn from its sources with `syn`.
//!
//! Each crate root (`src/lib.rs`, `src/main.rs`, `src/bin/*.rs`) is parsed with the modules it
//! declares (`mod x;` files and inline `mod x { … }` blocks, tests included). Every path a module's
//! own code names — `use` trees, paths in types, expressions and patterns, and `crate::`/`super::`
//! paths inside macro calls — is resolved to the module that *defines* the item: `crate::`,
//! `super::`, `self::` and names brought into scope by `use` (re-exports followed, globs looked
//! through). Names that resolve outside the crate (`std`, `trust_core`, locals) are skipped.
//!
//! A reference from module `a::b::c` to `a::d::e` is an edge between the siblings `a::b` and
//! `a::d` under their deepest common ancestor `a`; a reference between a module and one of its
//! ancestors is no edge (a parent declares and re-exports its children, and children use the
//! parent's types: the crate root is no node of the top-level graph either). So the rule "no
//! cycle" holds at every depth: among the top-level modules, among the children of each module.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use proc_macro2::{TokenStream, TokenTree};
use syn::visit::Visit;

/// One module of a crate.
#[derive(Debug, Default)]
struct Module {
    /// Its path from the crate root (empty for the root).
    path: Vec<String>,
    parent: Option<usize>,
    children: BTreeMap<String, usize>,
    /// Names of the items it defines (other than modules).
    items: BTreeSet<String>,
    /// Names a `use` brings into its scope, and the path each stands for.
    aliases: BTreeMap<String, Vec<String>>,
    /// Paths of its glob imports (`use x::*`).
    globs: Vec<Vec<String>>,
    /// Every path its own code names (the `use` targets included).
    refs: Vec<Vec<String>>,
}

/// The modules of one crate; index 0 is the root.
#[derive(Debug)]
pub struct Crate {
    modules: Vec<Module>,
}

/// What a path resolves to: a module, or an item defined in a module.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Target {
    Module(usize),
    Item(usize),
}

impl Target {
    fn module(self) -> usize {
        match self {
            Target::Module(m) | Target::Item(m) => m,
        }
    }
}

/// How deep alias chains are followed (a guard against `use` loops the compiler would reject).
const MAX_HOPS: usize = 32;

impl Crate {
    /// Parses the crate whose root file is `root` (and every module file it declares).
    ///
    /// # Panics
    /// On a file that does not parse or a `mod x;` whose file is missing.
    pub fn parse(root: &Path) -> Crate {
        let mut krate = Crate {
            modules: vec![Module::default()],
        };
        let file = parse_file(root);
        // A crate root owns its directory: `mod x;` is `x.rs` or `x/mod.rs` beside it.
        let dir = root
            .parent()
            .expect("a crate root has a folder")
            .to_path_buf();
        krate.fill(0, &file.items, &dir);
        krate
    }

    /// Records the items of module `m`, whose child module files live in `dir`.
    fn fill(&mut self, m: usize, items: &[syn::Item], dir: &Path) {
        let mut scope = Scope::default();
        for item in items {
            match item {
                syn::Item::Mod(md) => {
                    let name = md.ident.to_string();
                    let child = self.modules.len();
                    let mut path = self.modules[m].path.clone();
                    path.push(name.clone());
                    self.modules.push(Module {
                        path,
                        parent: Some(m),
                        ..Module::default()
                    });
                    self.modules[m].children.insert(name.clone(), child);
                    match &md.content {
                        Some((_, inner)) => self.fill(child, inner, &dir.join(&name)),
                        None => {
                            let (file, child_dir) = module_file(dir, &name, &md.attrs);
                            let parsed = parse_file(&file);
                            self.fill(child, &parsed.items, &child_dir);
                        }
                    }
                    // The attributes of `mod x;` and its visibility are this module's code.
                    for a in &md.attrs {
                        scope.visit_attribute(a);
                    }
                }
                other => {
                    if let Some(name) = item_name(other) {
                        self.modules[m].items.insert(name);
                    }
                    scope.visit_item(other);
                }
            }
        }
        let module = &mut self.modules[m];
        module.items.extend(scope.items);
        module.aliases.extend(scope.aliases);
        module.globs.extend(scope.globs);
        module.refs.extend(scope.refs);
    }

    /// The module `n` levels above `m` (`None` above the root).
    fn up(&self, m: usize, n: usize) -> Option<usize> {
        let mut at = m;
        for _ in 0..n {
            at = self.modules[at].parent?;
        }
        Some(at)
    }

    /// Resolves `name` as it is seen inside module `m` (its children, its items, its `use`s, its
    /// globs); `None` for a name from outside the crate (or a local).
    fn lookup(&self, m: usize, name: &str, hops: usize) -> Option<Target> {
        if hops > MAX_HOPS {
            return None;
        }
        let module = &self.modules[m];
        if let Some(&c) = module.children.get(name) {
            return Some(Target::Module(c));
        }
        if module.items.contains(name) {
            return Some(Target::Item(m));
        }
        if let Some(path) = module.aliases.get(name) {
            return self.resolve(m, path, hops + 1);
        }
        for glob in &module.globs {
            if let Some(Target::Module(g)) = self.resolve(m, glob, hops + 1)
                && g != m
                && let Some(t) = self.lookup(g, name, hops + 1)
            {
                return Some(t);
            }
        }
        None
    }

    /// Resolves `path` as written in module `m`.
    fn resolve(&self, m: usize, path: &[String], hops: usize) -> Option<Target> {
        let (first, rest) = path.split_first()?;
        let mut at = match first.as_str() {
            "crate" | "$crate" => Target::Module(0),
            "self" => Target::Module(m),
            "super" => Target::Module(self.up(m, 1)?),
            "Self" => return None,
            name => self.lookup(m, name, hops)?,
        };
        for seg in rest {
            let Target::Module(x) = at else { break };
            at = match seg.as_str() {
                "super" => Target::Module(self.up(x, 1)?),
                "self" => Target::Module(x),
                // A name the module does not define or import (a macro's item, a variant of a
                // glob-imported enum): the module is the best guess of where it lives.
                name => self.lookup(x, name, hops).unwrap_or(Target::Item(x)),
            };
        }
        Some(at)
    }

    /// Every module of the crate by its path (`a::b`; the root is `crate`).
    fn name(&self, m: usize) -> String {
        if self.modules[m].path.is_empty() {
            "crate".into()
        } else {
            self.modules[m].path.join("::")
        }
    }

    /// The edges between modules: `(from, to)` by path, for every reference that resolves into
    /// another module of the crate, each with the first path that makes it (as written).
    pub fn references(&self) -> BTreeMap<(Vec<String>, Vec<String>), String> {
        let mut out = BTreeMap::new();
        for (m, module) in self.modules.iter().enumerate() {
            for r in &module.refs {
                if let Some(t) = self.resolve(m, r, 0) {
                    let to = t.module();
                    if to != m {
                        out.entry((module.path.clone(), self.modules[to].path.clone()))
                            .or_insert_with(|| r.join("::"));
                    }
                }
            }
        }
        out
    }

    /// The graph of sibling modules at every depth, by parent (`crate` for the top level): for
    /// each module that has children, the edges between them (a reference from inside one
    /// child's subtree to inside another's).
    pub fn sibling_graphs(&self) -> BTreeMap<String, Level> {
        let mut levels: BTreeMap<String, Level> = BTreeMap::new();
        for (m, module) in self.modules.iter().enumerate() {
            if !module.children.is_empty() {
                let level = levels.entry(self.name(m)).or_default();
                for c in module.children.keys() {
                    level.graph.entry(c.clone()).or_default();
                }
            }
        }
        for ((from, to), written) in self.references() {
            let common = from.iter().zip(&to).take_while(|(a, b)| a == b).count();
            if common == from.len() || common == to.len() {
                continue; // a module and its ancestor
            }
            let parent = if common == 0 {
                "crate".to_string()
            } else {
                from[..common].join("::")
            };
            let level = levels
                .get_mut(&parent)
                .expect("a parent of two modules has children");
            let (a, b) = (from[common].clone(), to[common].clone());
            level
                .graph
                .get_mut(&a)
                .expect("a child is a node")
                .insert(b.clone());
            level
                .why
                .entry((a, b))
                .or_insert_with(|| format!("`{}` names `{written}`", from.join("::")));
        }
        levels
    }
}

/// The modules under one parent and their references to each other.
#[derive(Debug, Default)]
pub struct Level {
    /// Edges between the children.
    pub graph: Graph,
    /// For each edge, the first reference that makes it.
    pub why: BTreeMap<(String, String), String>,
}

/// A directed graph of names.
pub type Graph = BTreeMap<String, BTreeSet<String>>;

/// The module cycles of a crate at every depth, each written `a::b -> a::c -> a::b`: one cycle
/// for each group of siblings that reach each other (a strongly connected component).
pub fn module_cycles(krate: &Crate) -> Vec<String> {
    let mut out = Vec::new();
    for (parent, level) in krate.sibling_graphs() {
        let prefix = if parent == "crate" {
            String::new()
        } else {
            format!("{parent}::")
        };
        for (cycle, component) in cycles(&level.graph) {
            let name = |c: &String| format!("{prefix}{c}");
            let mut line = cycle.iter().map(name).collect::<Vec<_>>().join(" -> ");
            if component.len() + 1 > cycle.len() {
                let all: Vec<String> = component.iter().map(name).collect();
                line += &format!(" (all of {} reach each other)", all.join(", "));
            }
            for pair in cycle.windows(2) {
                let why = &level.why[&(pair[0].clone(), pair[1].clone())];
                line += &format!("\n    {} -> {}: {why}", name(&pair[0]), name(&pair[1]));
            }
            out.push(line);
        }
    }
    out
}

/// One cycle through each strongly connected component of `graph` with more than one node, and
/// the component.
pub fn cycles(graph: &Graph) -> Vec<(Vec<String>, BTreeSet<String>)> {
    let reach = |from: &str| -> BTreeSet<String> {
        let mut seen = BTreeSet::new();
        let mut todo = vec![from.to_string()];
        while let Some(u) = todo.pop() {
            for v in graph.get(&u).into_iter().flatten() {
                if seen.insert(v.clone()) {
                    todo.push(v.clone());
                }
            }
        }
        seen
    };
    let reached: BTreeMap<&String, BTreeSet<String>> =
        graph.keys().map(|u| (u, reach(u))).collect();
    let mut done = BTreeSet::new();
    let mut out = Vec::new();
    for u in graph.keys() {
        if done.contains(u) || !reached[u].contains(u) {
            continue;
        }
        let component: BTreeSet<String> = graph
            .keys()
            .filter(|v| reached[u].contains(*v) && reached[*v].contains(u))
            .cloned()
            .collect();
        let sub: Graph = component
            .iter()
            .map(|v| {
                let next = graph[v].intersection(&component).cloned().collect();
                (v.clone(), next)
            })
            .collect();
        let cycle = find_cycle(&sub).expect("a component of more than one node has a cycle");
        done.extend(component.iter().cloned());
        out.push((cycle, component));
    }
    out
}

/// A cycle of `graph`, if any (depth-first search), as the nodes along it with the first
/// repeated at the end.
pub fn find_cycle(graph: &Graph) -> Option<Vec<String>> {
    fn visit(
        u: &str,
        graph: &Graph,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(u.to_string(), 1);
        stack.push(u.to_string());
        for v in graph.get(u).into_iter().flatten() {
            match state.get(v) {
                Some(1) => {
                    let at = stack.iter().position(|s| s == v).expect("on stack");
                    let mut cycle = stack[at..].to_vec();
                    cycle.push(v.clone());
                    return Some(cycle);
                }
                Some(_) => {}
                None => {
                    if let Some(c) = visit(v, graph, state, stack) {
                        return Some(c);
                    }
                }
            }
        }
        stack.pop();
        state.insert(u.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for u in graph.keys() {
        if !state.contains_key(u)
            && let Some(c) = visit(u, graph, &mut state, &mut Vec::new())
        {
            return Some(c);
        }
    }
    None
}

/// The crate roots of a package in `dir`: `src/lib.rs`, `src/main.rs` and `src/bin/*.rs`.
pub fn crate_roots(dir: &Path) -> Vec<PathBuf> {
    let src = dir.join("src");
    let mut roots: Vec<PathBuf> = ["lib.rs", "main.rs"]
        .iter()
        .map(|f| src.join(f))
        .filter(|p| p.is_file())
        .collect();
    let mut bins: Vec<PathBuf> = std::fs::read_dir(src.join("bin"))
        .into_iter()
        .flatten()
        .flatten()
        .map(|e| e.path())
        .map(|p| if p.is_dir() { p.join("main.rs") } else { p })
        .filter(|p| p.is_file() && p.extension().is_some_and(|x| x == "rs"))
        .collect();
    bins.sort();
    roots.extend(bins);
    roots
}

fn parse_file(path: &Path) -> syn::File {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    syn::parse_file(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// The file of `mod name;` declared in a module whose child files live in `dir`, and the folder
/// of that file's own children.
fn module_file(dir: &Path, name: &str, attrs: &[syn::Attribute]) -> (PathBuf, PathBuf) {
    for a in attrs {
        if a.path().is_ident("path")
            && let syn::Meta::NameValue(nv) = &a.meta
            && let syn::Expr::Lit(syn::ExprLit {
                lit: syn::Lit::Str(s),
                ..
            }) = &nv.value
        {
            let file = dir.join(s.value());
            let child_dir = file.parent().expect("a file has a folder").to_path_buf();
            return (file, child_dir);
        }
    }
    let flat = dir.join(format!("{name}.rs"));
    if flat.is_file() {
        return (flat, dir.join(name));
    }
    let nested = dir.join(name).join("mod.rs");
    assert!(
        nested.is_file(),
        "mod {name}: neither {} nor {}",
        flat.display(),
        nested.display()
    );
    (nested, dir.join(name))
}

/// The name an item defines, if it is one that paths can name.
fn item_name(item: &syn::Item) -> Option<String> {
    let ident = match item {
        syn::Item::Const(i) => &i.ident,
        syn::Item::Enum(i) => &i.ident,
        syn::Item::Fn(i) => &i.sig.ident,
        syn::Item::Static(i) => &i.ident,
        syn::Item::Struct(i) => &i.ident,
        syn::Item::Trait(i) => &i.ident,
        syn::Item::TraitAlias(i) => &i.ident,
        syn::Item::Type(i) => &i.ident,
        syn::Item::Union(i) => &i.ident,
        syn::Item::Macro(i) => i.ident.as_ref()?,
        _ => return None,
    };
    Some(ident.to_string())
}

/// What one module's own code (its items, not its child modules) names.
#[derive(Default)]
struct Scope {
    /// Items defined inside function bodies and other nested places.
    items: BTreeSet<String>,
    aliases: BTreeMap<String, Vec<String>>,
    globs: Vec<Vec<String>>,
    refs: Vec<Vec<String>>,
}

impl Scope {
    fn use_tree(&mut self, prefix: &mut Vec<String>, tree: &syn::UseTree) {
        match tree {
            syn::UseTree::Path(p) => {
                prefix.push(p.ident.to_string());
                self.use_tree(prefix, &p.tree);
                prefix.pop();
            }
            syn::UseTree::Name(n) => {
                let name = n.ident.to_string();
                let (alias, path) = if name == "self" {
                    (prefix.last().cloned(), prefix.clone())
                } else {
                    let mut path = prefix.clone();
                    path.push(name.clone());
                    (Some(name), path)
                };
                if let Some(alias) = alias {
                    self.aliases.insert(alias, path.clone());
                }
                self.refs.push(path);
            }
            syn::UseTree::Rename(r) => {
                let mut path = prefix.clone();
                if r.ident != "self" {
                    path.push(r.ident.to_string());
                }
                if r.rename != "_" {
                    self.aliases.insert(r.rename.to_string(), path.clone());
                }
                self.refs.push(path);
            }
            syn::UseTree::Glob(_) => {
                self.globs.push(prefix.clone());
                self.refs.push(prefix.clone());
            }
            syn::UseTree::Group(g) => {
                for t in &g.items {
                    self.use_tree(prefix, t);
                }
            }
        }
    }

    /// The paths written inside a macro call's tokens: `a::b::c` runs of identifiers (`$crate`
    /// as `crate`).
    fn macro_tokens(&mut self, tokens: TokenStream) {
        let flat = flatten(tokens);
        let mut i = 0;
        while i < flat.len() {
            let start = match &flat[i] {
                Tok::Ident(s) => Some(s.clone()),
                Tok::Dollar if matches!(flat.get(i + 1), Some(Tok::Ident(s)) if s == "crate") => {
                    i += 1;
                    Some("$crate".into())
                }
                _ => None,
            };
            let Some(first) = start else {
                i += 1;
                continue;
            };
            let mut path = vec![first];
            i += 1;
            while let (Some(Tok::PathSep), Some(Tok::Ident(s))) = (flat.get(i), flat.get(i + 1)) {
                path.push(s.clone());
                i += 2;
            }
            self.refs.push(path);
        }
    }
}

/// A token of a macro call, flattened.
#[derive(Debug, PartialEq)]
enum Tok {
    Ident(String),
    /// `::`.
    PathSep,
    Dollar,
    Other,
}

fn flatten(tokens: TokenStream) -> Vec<Tok> {
    let mut out = Vec::new();
    let mut iter = tokens.into_iter().peekable();
    while let Some(t) = iter.next() {
        match t {
            TokenTree::Ident(i) => out.push(Tok::Ident(i.to_string())),
            TokenTree::Group(g) => {
                out.push(Tok::Other);
                out.extend(flatten(g.stream()));
                out.push(Tok::Other);
            }
            TokenTree::Punct(p) if p.as_char() == '$' => out.push(Tok::Dollar),
            TokenTree::Punct(p)
                if p.as_char() == ':'
                    && p.spacing() == proc_macro2::Spacing::Joint
                    && matches!(iter.peek(), Some(TokenTree::Punct(q)) if q.as_char() == ':') =>
            {
                iter.next();
                out.push(Tok::PathSep);
            }
            _ => out.push(Tok::Other),
        }
    }
    out
}

impl<'ast> Visit<'ast> for Scope {
    fn visit_item_mod(&mut self, _: &'ast syn::ItemMod) {
        // A nested module (inside a function body) would be a module of its own: none here.
    }

    fn visit_stmt(&mut self, s: &'ast syn::Stmt) {
        if let syn::Stmt::Item(item) = s
            && let Some(name) = item_name(item)
        {
            self.items.insert(name);
        }
        syn::visit::visit_stmt(self, s);
    }

    fn visit_item_use(&mut self, u: &'ast syn::ItemUse) {
        let mut prefix = Vec::new();
        if u.leading_colon.is_some() {
            return; // `::name`: an extern crate.
        }
        self.use_tree(&mut prefix, &u.tree);
    }

    fn visit_path(&mut self, p: &'ast syn::Path) {
        if p.leading_colon.is_none() {
            self.refs
                .push(p.segments.iter().map(|s| s.ident.to_string()).collect());
        }
        syn::visit::visit_path(self, p);
    }

    fn visit_macro(&mut self, m: &'ast syn::Macro) {
        self.macro_tokens(m.tokens.clone());
        syn::visit::visit_macro(self, m);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A crate made of `files` (`path`, text) in a fresh folder under the temporary directory.
    fn synthetic(tag: &str, files: &[(&str, &str)]) -> Crate {
        let dir = std::env::temp_dir().join(format!("tidy-modules-{tag}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        for (path, text) in files {
            let p = dir.join(path);
            std::fs::create_dir_all(p.parent().unwrap()).unwrap();
            std::fs::write(&p, text).unwrap();
        }
        let krate = Crate::parse(&dir.join("lib.rs"));
        std::fs::remove_dir_all(&dir).unwrap();
        krate
    }

    #[test]
    fn the_cycle_finder_finds_a_cycle_and_none_in_a_dag() {
        let g: Graph = BTreeMap::from([
            ("a".to_string(), ["b".to_string()].into()),
            ("b".to_string(), ["c".to_string()].into()),
            ("c".to_string(), ["a".to_string()].into()),
            ("d".to_string(), Default::default()),
        ]);
        assert_eq!(
            find_cycle(&g),
            Some(vec!["a".into(), "b".into(), "c".into(), "a".into()])
        );
        let dag: Graph = BTreeMap::from([
            ("a".to_string(), ["b".to_string(), "c".to_string()].into()),
            ("b".to_string(), ["c".to_string()].into()),
            ("c".to_string(), Default::default()),
        ]);
        assert_eq!(find_cycle(&dag), None);
        assert!(cycles(&dag).is_empty());
        // Two separate cycles are both reported.
        let two: Graph = BTreeMap::from([
            ("a".to_string(), ["b".to_string()].into()),
            ("b".to_string(), ["a".to_string(), "c".to_string()].into()),
            ("c".to_string(), ["d".to_string()].into()),
            ("d".to_string(), ["c".to_string()].into()),
        ]);
        let found: Vec<Vec<String>> = cycles(&two).into_iter().map(|(c, _)| c).collect();
        assert_eq!(
            found,
            vec![
                vec!["a".to_string(), "b".into(), "a".into()],
                vec!["c".to_string(), "d".into(), "c".into()]
            ]
        );
    }

    #[test]
    fn a_cycle_between_nested_siblings_is_found_and_named() {
        // `outer::a` uses `outer::b` by `crate::`, `outer::b` uses `outer::a` through a
        // re-export of the parent (`super::A` is `a::A`): a cycle one level down, which a
        // top-level graph cannot see (the crate has one top-level module).
        let krate = synthetic(
            "nested",
            &[
                ("lib.rs", "pub mod outer;"),
                (
                    "outer/mod.rs",
                    "mod a; mod b; pub use a::A; pub struct Root; fn f() { let _ = b::g(); }",
                ),
                (
                    "outer/a.rs",
                    "use super::Root; pub struct A; pub fn f() { crate::outer::b::g(); }",
                ),
                ("outer/b.rs", "pub fn g() -> super::A { super::A }"),
            ],
        );
        assert_eq!(
            module_cycles(&krate),
            vec![
                "outer::a -> outer::b -> outer::a\n    \
                 outer::a -> outer::b: `outer::a` names `crate::outer::b::g`\n    \
                 outer::b -> outer::a: `outer::b` names `super::A`"
                    .to_string()
            ]
        );
        // The parent and its children use each other freely: no edge.
        let refs = krate.references();
        let p = |s: &str| -> Vec<String> { s.split("::").map(String::from).collect() };
        assert!(refs.contains_key(&(p("outer"), p("outer::b"))));
        assert_eq!(refs[&(p("outer::b"), p("outer::a"))], "super::A");
        assert!(krate.sibling_graphs()["outer"].graph["b"].contains("a"));
    }

    #[test]
    fn paths_in_macros_globs_and_fn_local_uses_count() {
        let krate = synthetic(
            "macros",
            &[
                (
                    "lib.rs",
                    "mod a; mod b; mod c; mod d;
                     #[cfg(test)] mod tests { use super::*; #[test] fn t() { a::f(); } }",
                ),
                ("a.rs", "pub fn f() { println!(\"{}\", crate::b::X); }"),
                (
                    "b.rs",
                    "pub const X: u8 = 1; fn g() { use crate::c::*; let _ = Y; }",
                ),
                (
                    "c.rs",
                    "pub const Y: u8 = 2; fn h() { assert!(matches!(super::d::Z, 3)); }",
                ),
                (
                    "d.rs",
                    "pub const Z: u8 = 3; use super::a as first; fn k() { first::f(); }",
                ),
            ],
        );
        let cycles = module_cycles(&krate);
        assert_eq!(cycles.len(), 1, "{cycles:?}");
        assert!(
            cycles[0].starts_with("a -> b -> c -> d -> a\n"),
            "{}",
            cycles[0]
        );
        assert!(
            cycles[0].contains("b -> c: `b` names `crate::c`"),
            "{}",
            cycles[0]
        );
    }

    #[test]
    fn outside_names_and_ancestors_make_no_edge() {
        let krate = synthetic(
            "outside",
            &[
                ("lib.rs", "pub mod x; pub mod y; pub use x::T;"),
                (
                    "x.rs",
                    "use std::collections::BTreeMap; pub struct T(BTreeMap<u8, u8>);
                     pub fn f() -> crate::T { let y = 1; let _ = y; crate::T(Default::default()) }",
                ),
                ("y.rs", "pub fn g() -> super::x::T { crate::x::f() }"),
            ],
        );
        assert!(module_cycles(&krate).is_empty());
        let refs = krate.references();
        assert_eq!(refs.len(), 2, "{refs:?}"); // crate -> x (re-export), y -> x
    }
}
