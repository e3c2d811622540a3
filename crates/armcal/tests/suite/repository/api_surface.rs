//! The public API, curated (issue 34): every path a user of the crate can name, with its kind
//! and, for a function or method, its signature, is committed in `tests/api-surface.txt`; the
//! test fails on any difference, so a change of the surface is a deliberate, reviewed diff.
//! Bless a change with `ARMCAL_BLESS_API=1 cargo test -p armcal --test suite api_surface`.
//!
//! The list is read from the source with `syn`, not from rustdoc's JSON output: that needs a
//! nightly compiler, and CI runs stable. The walk starts at `src/lib.rs`, follows `pub mod`
//! and `pub use` (resolving `crate::`, `self::`, `super::`, local names and globs) and stops at
//! any module that is not `pub`; an inherent `impl` adds its `pub` methods and constants under
//! every path of its type, a trait its items. `#[cfg(test)]` code is skipped.
//!
//! Its header counts the public modules, the public items (methods apart) and the items a user
//! can name by more than one path; the test fails on any such item (the front door gives
//! each item one path; 82 had two or three before).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

use quote::ToTokens;
use syn::{Attribute, ImplItem, Item, TraitItem, UseTree, Visibility};

/// The variable that rewrites the committed list instead of comparing with it.
const BLESS: &str = "ARMCAL_BLESS_API";

/// A module of the crate, public or not (a private one still resolves names).
struct Module {
    /// Its parent's index (`None` for the root).
    parent: Option<usize>,
    /// Its items outside `#[cfg(test)]`.
    items: Vec<Item>,
    /// Its definition (kind `mod`).
    def: usize,
}

/// Something a path can name: an item of the crate, or a name outside it.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord)]
enum Target {
    Def(usize),
    External(String),
}

/// An item of the crate at the place it is defined.
struct Def {
    /// Where it is defined (`armcal::model::chain::Chain`).
    path: String,
    kind: &'static str,
    /// A function's or method's signature, a constant's type; empty otherwise.
    signature: String,
    /// For a module, its index in `Crate::modules`.
    module: Option<usize>,
    /// For a module, whether it is declared `pub`: a `pub use` of a name that is both a
    /// private module and a public item (`mod f; pub use f::f;`) re-exports the item only.
    public_module: bool,
}

/// One name a `use` brings in.
struct Import {
    /// The name it binds; `None` for a glob.
    name: Option<String>,
    path: Vec<String>,
    public: bool,
}

struct Crate {
    modules: Vec<Module>,
    defs: Vec<Def>,
    /// Per module: the names it defines.
    defined: Vec<BTreeMap<String, Vec<usize>>>,
    /// Per module: its `use` items, flattened.
    imports: Vec<Vec<Import>>,
    /// Per type or trait: its `pub` methods and associated constants.
    members: BTreeMap<usize, Vec<usize>>,
}

fn is_test_only(attrs: &[Attribute]) -> bool {
    attrs
        .iter()
        .any(|a| a.path().is_ident("cfg") && a.meta.to_token_stream().to_string().contains("test"))
}

fn is_pub(vis: &Visibility) -> bool {
    matches!(vis, Visibility::Public(_))
}

/// A signature as `quote` prints it, with its token spacing normalised to rustfmt's.
fn normalise(tokens: String) -> String {
    let mut s = tokens.split_whitespace().collect::<Vec<_>>().join(" ");
    for (from, to) in [
        (" ::", "::"),
        (":: ", "::"),
        (" ,", ","),
        (" ;", ";"),
        ("( ", "("),
        (" )", ")"),
        (" (", "("),
        ("[ ", "["),
        (" ]", "]"),
        ("< ", "<"),
        (" <", "<"),
        (" >", ">"),
        ("& ", "&"),
        (" :", ":"),
        (" !", "!"),
        (",)", ")"),
        ("' ", "'"),
    ] {
        s = s.replace(from, to);
    }
    s
}

fn parse(file: &Path) -> Vec<Item> {
    let text = std::fs::read_to_string(file).unwrap_or_else(|e| panic!("{}: {e}", file.display()));
    syn::parse_file(&text)
        .unwrap_or_else(|e| panic!("{}: {e}", file.display()))
        .items
}

fn flatten(tree: &UseTree, prefix: &mut Vec<String>, public: bool, out: &mut Vec<Import>) {
    match tree {
        UseTree::Path(p) => {
            prefix.push(p.ident.to_string());
            flatten(&p.tree, prefix, public, out);
            prefix.pop();
        }
        UseTree::Name(n) => {
            let name = n.ident.to_string();
            let mut path = prefix.clone();
            let bound = if name == "self" {
                prefix.last().cloned()
            } else {
                path.push(name.clone());
                Some(name)
            };
            out.push(Import {
                name: bound,
                path,
                public,
            });
        }
        UseTree::Rename(r) => {
            let mut path = prefix.clone();
            if r.ident != "self" {
                path.push(r.ident.to_string());
            }
            out.push(Import {
                name: Some(r.rename.to_string()),
                path,
                public,
            });
        }
        UseTree::Glob(_) => out.push(Import {
            name: None,
            path: prefix.clone(),
            public,
        }),
        UseTree::Group(g) => {
            for t in &g.items {
                flatten(t, prefix, public, out);
            }
        }
    }
}

impl Crate {
    fn read(src: &Path) -> Crate {
        let mut krate = Crate {
            modules: Vec::new(),
            defs: Vec::new(),
            defined: Vec::new(),
            imports: Vec::new(),
            members: BTreeMap::new(),
        };
        krate.add_module(
            Vec::new(),
            None,
            parse(&src.join("lib.rs")),
            src.to_path_buf(),
        );
        krate.attach_members();
        krate
    }

    fn def(&mut self, path: String, kind: &'static str, signature: String) -> usize {
        self.defs.push(Def {
            path,
            kind,
            signature,
            module: None,
            public_module: false,
        });
        self.defs.len() - 1
    }

    /// Adds a module (its items, and its child modules, read from `dir`) and returns its index.
    fn add_module(
        &mut self,
        path: Vec<String>,
        parent: Option<usize>,
        items: Vec<Item>,
        dir: PathBuf,
    ) -> usize {
        let items: Vec<Item> = items
            .into_iter()
            .filter(|i| !is_test_only(item_attrs(i)))
            .collect();
        let index = self.modules.len();
        let full = std::iter::once("armcal".to_string())
            .chain(path.iter().cloned())
            .collect::<Vec<_>>()
            .join("::");
        let def = self.def(full.clone(), "mod", String::new());
        self.defs[def].module = Some(index);
        self.modules.push(Module {
            parent,
            items: Vec::new(),
            def,
        });
        self.defined.push(BTreeMap::new());
        self.imports.push(Vec::new());
        for item in &items {
            let named = |ident: &syn::Ident| format!("{full}::{ident}");
            let (name, def) = match item {
                Item::Mod(m) => {
                    let name = m.ident.to_string();
                    let child_dir = dir.join(&name);
                    let child_items = match &m.content {
                        Some((_, inline)) => inline.clone(),
                        None => {
                            let flat = dir.join(format!("{name}.rs"));
                            if flat.exists() {
                                parse(&flat)
                            } else {
                                parse(&child_dir.join("mod.rs"))
                            }
                        }
                    };
                    let mut child_path = path.clone();
                    child_path.push(name.clone());
                    let child = self.add_module(child_path, Some(index), child_items, child_dir);
                    let child_def = self.modules[child].def;
                    self.defs[child_def].public_module = is_pub(&m.vis);
                    (name, self.modules[child].def)
                }
                Item::Fn(f) => (
                    f.sig.ident.to_string(),
                    self.def(
                        named(&f.sig.ident),
                        "fn",
                        normalise(f.sig.to_token_stream().to_string()),
                    ),
                ),
                Item::Struct(s) => (
                    s.ident.to_string(),
                    self.def(named(&s.ident), "struct", String::new()),
                ),
                Item::Enum(e) => (
                    e.ident.to_string(),
                    self.def(named(&e.ident), "enum", String::new()),
                ),
                Item::Union(u) => (
                    u.ident.to_string(),
                    self.def(named(&u.ident), "union", String::new()),
                ),
                Item::Trait(t) => (
                    t.ident.to_string(),
                    self.def(named(&t.ident), "trait", String::new()),
                ),
                Item::Type(t) => (
                    t.ident.to_string(),
                    self.def(named(&t.ident), "type", String::new()),
                ),
                Item::Const(c) => (
                    c.ident.to_string(),
                    self.def(
                        named(&c.ident),
                        "const",
                        normalise(c.ty.to_token_stream().to_string()),
                    ),
                ),
                Item::Static(s) => (
                    s.ident.to_string(),
                    self.def(
                        named(&s.ident),
                        "static",
                        normalise(s.ty.to_token_stream().to_string()),
                    ),
                ),
                Item::Use(u) => {
                    let mut flat = Vec::new();
                    flatten(&u.tree, &mut Vec::new(), is_pub(&u.vis), &mut flat);
                    self.imports[index].extend(flat);
                    continue;
                }
                _ => continue,
            };
            self.defined[index].entry(name).or_default().push(def);
        }
        self.modules[index].items = items;
        index
    }

    /// Every name `module` binds to `name`: its own items, its imports, its globs. `seen`
    /// holds the lookups under way (a glob cycle ends there).
    fn lookup(
        &self,
        module: usize,
        name: &str,
        seen: &mut BTreeSet<(usize, String)>,
    ) -> Vec<Target> {
        let key = (module, name.to_string());
        if !seen.insert(key.clone()) {
            return Vec::new();
        }
        let found = self.lookup_uncached(module, name, seen);
        seen.remove(&key);
        found
    }

    fn lookup_uncached(
        &self,
        module: usize,
        name: &str,
        seen: &mut BTreeSet<(usize, String)>,
    ) -> Vec<Target> {
        let mut found: Vec<Target> = self.defined[module]
            .get(name)
            .into_iter()
            .flatten()
            .map(|&d| Target::Def(d))
            .collect();
        for import in &self.imports[module] {
            match &import.name {
                Some(n) if n == name => found.extend(self.resolve(module, &import.path, seen)),
                None => {
                    for target in self.resolve(module, &import.path, seen) {
                        if let Some(m) = self.module_of(&target) {
                            found.extend(self.lookup(m, name, seen));
                        }
                    }
                }
                _ => {}
            }
        }
        found.sort();
        found.dedup();
        found
    }

    /// Whether a path can go on after `target`: a module, an enum (its variants), an
    /// outside name.
    fn is_container(&self, target: &Target) -> bool {
        match target {
            Target::Def(d) => matches!(self.defs[*d].kind, "mod" | "enum"),
            Target::External(_) => true,
        }
    }

    fn module_of(&self, target: &Target) -> Option<usize> {
        match target {
            Target::Def(d) => self.defs[*d].module,
            Target::External(_) => None,
        }
    }

    /// What `path`, written in `module`, names.
    fn resolve(
        &self,
        module: usize,
        path: &[String],
        seen: &mut BTreeSet<(usize, String)>,
    ) -> Vec<Target> {
        let Some((first, rest)) = path.split_first() else {
            return Vec::new();
        };
        let mut current = match first.as_str() {
            "crate" => vec![Target::Def(self.modules[0].def)],
            "self" => vec![Target::Def(self.modules[module].def)],
            "super" => vec![Target::Def(
                self.modules[self.modules[module].parent.expect("super at the root")].def,
            )],
            _ => {
                let mut local = self.lookup(module, first, seen);
                if !rest.is_empty() {
                    local.retain(|t| self.is_container(t));
                }
                if local.is_empty() {
                    vec![Target::External(first.clone())]
                } else {
                    local
                }
            }
        };
        for segment in rest {
            let mut next = Vec::new();
            for target in &current {
                match target {
                    Target::External(p) => next.push(Target::External(format!("{p}::{segment}"))),
                    Target::Def(d) => match self.defs[*d].module {
                        Some(m) if segment == "super" => next.push(Target::Def(
                            self.modules[self.modules[m].parent.unwrap()].def,
                        )),
                        Some(m) => next.extend(self.lookup(m, segment, seen)),
                        // An enum's variant: named with its enum.
                        None => next.push(Target::External(format!(
                            "{}::{segment}",
                            self.defs[*d].path
                        ))),
                    },
                }
            }
            current = next;
        }
        // A name bound inside the crate hides an outside one (an import cycle ends at one).
        if current.iter().any(|t| matches!(t, Target::Def(_))) {
            current.retain(|t| matches!(t, Target::Def(_)));
        }
        current
    }

    /// Attaches every inherent `impl`'s `pub` methods and constants to its type, and every
    /// trait's items to the trait.
    fn attach_members(&mut self) {
        for m in 0..self.modules.len() {
            let items = std::mem::take(&mut self.modules[m].items);
            for item in &items {
                match item {
                    Item::Impl(imp) if imp.trait_.is_none() && !is_test_only(&imp.attrs) => {
                        let syn::Type::Path(ty) = &*imp.self_ty else {
                            continue;
                        };
                        let path: Vec<String> = ty
                            .path
                            .segments
                            .iter()
                            .map(|s| s.ident.to_string())
                            .collect();
                        let owners: Vec<usize> = self
                            .resolve(m, &path, &mut BTreeSet::new())
                            .into_iter()
                            .filter_map(|t| match t {
                                Target::Def(d) => Some(d),
                                Target::External(_) => None,
                            })
                            .filter(|&d| {
                                matches!(self.defs[d].kind, "struct" | "enum" | "union" | "type")
                            })
                            .collect();
                        for owner in owners {
                            let base = self.defs[owner].path.clone();
                            for member in &imp.items {
                                let def = match member {
                                    ImplItem::Fn(f)
                                        if is_pub(&f.vis) && !is_test_only(&f.attrs) =>
                                    {
                                        self.def(
                                            format!("{base}::{}", f.sig.ident),
                                            "method",
                                            normalise(f.sig.to_token_stream().to_string()),
                                        )
                                    }
                                    ImplItem::Const(c) if is_pub(&c.vis) => self.def(
                                        format!("{base}::{}", c.ident),
                                        "assoc-const",
                                        normalise(c.ty.to_token_stream().to_string()),
                                    ),
                                    _ => continue,
                                };
                                self.members.entry(owner).or_default().push(def);
                            }
                        }
                    }
                    Item::Trait(t) => {
                        let owner = self.defined[m][&t.ident.to_string()]
                            .iter()
                            .copied()
                            .find(|&d| self.defs[d].kind == "trait")
                            .unwrap();
                        let base = self.defs[owner].path.clone();
                        for member in &t.items {
                            let def = match member {
                                TraitItem::Fn(f) => self.def(
                                    format!("{base}::{}", f.sig.ident),
                                    "method",
                                    normalise(f.sig.to_token_stream().to_string()),
                                ),
                                TraitItem::Const(c) => self.def(
                                    format!("{base}::{}", c.ident),
                                    "assoc-const",
                                    normalise(c.ty.to_token_stream().to_string()),
                                ),
                                TraitItem::Type(ty) => self.def(
                                    format!("{base}::{}", ty.ident),
                                    "assoc-type",
                                    String::new(),
                                ),
                                _ => continue,
                            };
                            self.members.entry(owner).or_default().push(def);
                        }
                    }
                    _ => {}
                }
            }
            self.modules[m].items = items;
        }
    }

    /// Records every public path under `module`, reached as `prefix`.
    fn walk(&self, module: usize, prefix: &str, chain: &mut Vec<usize>, paths: &mut Paths) {
        if chain.contains(&module) {
            return;
        }
        chain.push(module);
        for item in &self.modules[module].items {
            let Some((vis, ident)) = item_name(item) else {
                continue;
            };
            if !is_pub(vis) {
                continue;
            }
            for &def in self.defined[module].get(&ident).into_iter().flatten() {
                self.record(Target::Def(def), format!("{prefix}::{ident}"), chain, paths);
            }
        }
        for import in self.imports[module].iter().filter(|i| i.public) {
            let targets = self.resolve(module, &import.path, &mut BTreeSet::new());
            match &import.name {
                Some(name) => {
                    let private_module = |t: &Target| match t {
                        Target::Def(d) => {
                            self.defs[*d].kind == "mod" && !self.defs[*d].public_module
                        }
                        Target::External(_) => false,
                    };
                    for t in targets.into_iter().filter(|t| !private_module(t)) {
                        self.record(t, format!("{prefix}::{name}"), chain, paths);
                    }
                }
                None => {
                    for source in targets.iter().filter_map(|t| self.module_of(t)) {
                        for name in self.public_names(source) {
                            for t in self.lookup(source, &name, &mut BTreeSet::new()) {
                                self.record(t, format!("{prefix}::{name}"), chain, paths);
                            }
                        }
                    }
                }
            }
        }
        chain.pop();
    }

    /// The names `module` makes public (for a glob re-export of it).
    fn public_names(&self, module: usize) -> BTreeSet<String> {
        let mut names: BTreeSet<String> = self.modules[module]
            .items
            .iter()
            .filter_map(item_name)
            .filter(|(vis, _)| is_pub(vis))
            .map(|(_, n)| n)
            .collect();
        names.extend(
            self.imports[module]
                .iter()
                .filter(|i| i.public)
                .filter_map(|i| i.name.clone()),
        );
        names
    }

    fn record(&self, target: Target, path: String, chain: &mut Vec<usize>, paths: &mut Paths) {
        if let Target::Def(d) = target {
            if let Some(m) = self.defs[d].module {
                self.walk(m, &path, chain, paths);
            }
            for &member in self.members.get(&d).into_iter().flatten() {
                let name = self.defs[member].path.rsplit("::").next().unwrap();
                paths
                    .entry(Target::Def(member))
                    .or_default()
                    .insert(format!("{path}::{name}"));
            }
        }
        paths.entry(target).or_default().insert(path);
    }
}

/// Every public item and the paths that name it.
type Paths = BTreeMap<Target, BTreeSet<String>>;

fn item_attrs(item: &Item) -> &[Attribute] {
    match item {
        Item::Const(i) => &i.attrs,
        Item::Enum(i) => &i.attrs,
        Item::Fn(i) => &i.attrs,
        Item::Impl(i) => &i.attrs,
        Item::Mod(i) => &i.attrs,
        Item::Static(i) => &i.attrs,
        Item::Struct(i) => &i.attrs,
        Item::Trait(i) => &i.attrs,
        Item::Type(i) => &i.attrs,
        Item::Union(i) => &i.attrs,
        Item::Use(i) => &i.attrs,
        _ => &[],
    }
}

/// An item's visibility and name, for the items that define a name.
fn item_name(item: &Item) -> Option<(&Visibility, String)> {
    Some(match item {
        Item::Const(i) => (&i.vis, i.ident.to_string()),
        Item::Enum(i) => (&i.vis, i.ident.to_string()),
        Item::Fn(i) => (&i.vis, i.sig.ident.to_string()),
        Item::Mod(i) => (&i.vis, i.ident.to_string()),
        Item::Static(i) => (&i.vis, i.ident.to_string()),
        Item::Struct(i) => (&i.vis, i.ident.to_string()),
        Item::Trait(i) => (&i.vis, i.ident.to_string()),
        Item::Type(i) => (&i.vis, i.ident.to_string()),
        Item::Union(i) => (&i.vis, i.ident.to_string()),
        _ => return None,
    })
}

/// The committed list's text: a header with the counts, then one line per path.
fn surface() -> (String, Vec<String>) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let krate = Crate::read(&root.join("src"));
    let mut paths = Paths::new();
    krate.walk(0, "armcal", &mut Vec::new(), &mut paths);
    let kind = |t: &Target| match t {
        Target::Def(d) => krate.defs[*d].kind,
        Target::External(_) => "external",
    };
    let modules = paths.keys().filter(|t| kind(t) == "mod").count();
    let is_member = |t: &Target| matches!(kind(t), "method" | "assoc-const" | "assoc-type");
    let items: Vec<&Target> = paths
        .keys()
        .filter(|t| kind(t) != "mod" && !is_member(t))
        .collect();
    let members = paths.keys().filter(|t| is_member(t)).count();
    let multi: Vec<String> = paths
        .iter()
        .filter(|(t, p)| !is_member(t) && p.len() > 1)
        .map(|(_, p)| p.iter().cloned().collect::<Vec<_>>().join(" = "))
        .collect();
    let mut lines = Vec::new();
    for (target, names) in &paths {
        let signature = match target {
            Target::Def(d) => krate.defs[*d].signature.as_str(),
            Target::External(p) => p.as_str(),
        };
        for name in names {
            lines.push(
                format!("{name}  {}  {signature}", kind(target))
                    .trim_end()
                    .to_string(),
            );
        }
    }
    lines.sort();
    let text = format!(
        "# armcal's public API, one path a line: path, kind, signature \
         (crates/armcal/tests/suite/repository/api_surface.rs).\n\
         # public modules: {modules}; public items: {} (and {members} methods and associated \
         items); items reachable by more than one path: {}\n{}\n",
        items.len(),
        multi.len(),
        lines.join("\n")
    );
    (text, multi)
}

#[test]
fn api_surface_is_the_committed_one() {
    let (now, multi) = surface();
    let file = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/api-surface.txt");
    println!("{}", now.lines().nth(1).unwrap());
    for paths in &multi {
        println!("more than one path: {paths}");
    }
    if std::env::var_os(BLESS).is_some() {
        std::fs::write(&file, &now).unwrap();
    }
    let committed = std::fs::read_to_string(&file).unwrap_or_default();
    if committed != now {
        let old: BTreeSet<&str> = committed.lines().collect();
        let new: BTreeSet<&str> = now.lines().collect();
        let removed: Vec<&&str> = old.difference(&new).collect();
        let added: Vec<&&str> = new.difference(&old).collect();
        panic!(
            "the public API differs from tests/api-surface.txt\n removed: {removed:#?}\n \
             added: {added:#?}\nif the change is meant, bless it: \
             {BLESS}=1 cargo test -p armcal --test suite api_surface"
        );
    }
    // A front-door item is a root item only; an internal one keeps its module path only.
    assert!(
        multi.is_empty(),
        "{} items are reachable by more than one path: keep one path per item\n{multi:#?}",
        multi.len()
    );
}

/// `mod f { use super::*; … } pub use f::{f, S};` re-exports the function and the struct
/// only: the private module of the same name, which the glob brings into `f`, adds no path (it
/// once gave `TrackerShift` a second one, through `design::cell_constraints::tracker_shift`).
#[test]
fn a_private_module_named_like_its_re_export_adds_no_path() {
    let dir = std::env::temp_dir().join(format!("armcal-api-surface-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(
        dir.join("lib.rs"),
        "mod f { use super::*; pub fn f() {} pub struct S; } pub use f::{f, S};",
    )
    .unwrap();
    let krate = Crate::read(&dir);
    std::fs::remove_dir_all(&dir).unwrap();
    let mut paths = Paths::new();
    krate.walk(0, "armcal", &mut Vec::new(), &mut paths);
    let names: BTreeSet<&str> = paths.values().flatten().map(String::as_str).collect();
    assert_eq!(names, BTreeSet::from(["armcal::S", "armcal::f"]));
}
