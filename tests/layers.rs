//! The shape of `src/` (docs/architecture.md): knowledge flows one way through the
//! folders, no two files use each other even indirectly, and the readers share only
//! `volume/readers/common`.
//!
//! The import graph is read from the sources ([`imports`]). Each rule has a test on a
//! small made-up tree that breaks it, so the checks are known to catch what they name.

#[path = "layers/imports.rs"]
mod imports;
#[path = "layers/source.rs"]
mod source;

use std::path::Path;

use imports::{Graph, Module};

/// The folders of `src/` from the bottom up: a file may use files of its own folder and
/// of folders before it, never of folders after it. `lib.rs` holds the plugin groups,
/// which gather the techniques' plugins and the renderer's; `main.rs` and `cli/` are the
/// binary.
const LAYERS: &[&str] = &[
    // Data: volumes, readers, phantoms.
    "volume",
    "transfer",
    // Pure math of a sample's opacity, used by the looks of regions.
    "context",
    // What the renderers see: planes, maps, looks, cameras, the scene of regions.
    "region",
    // The techniques, each with its components, math, spec (with serde) and systems.
    "clip",
    "twolevel",
    "dataset",
    "lens",
    "reference",
    "windows",
    "explode",
    // Slice views: a dataset's voxels in the three planes, through a window of values.
    "slices",
    // Streaming bricked datasets: the bricks every view (lenses, windows, parts) wants.
    "streaming",
    // Interactive resolution: what a moving view draws at.
    "interactive",
    // The GPU ray caster: packs what the techniques produce.
    "render",
    "lib.rs",
    // Scene files compose the techniques' specs.
    "scene",
    "ui",
    "cli",
    "main.rs",
];

/// Folders whose files are a technique: they never know scene files, the app, the
/// command line or the GPU renderer. (The order of [`LAYERS`] implies it; this rule
/// keeps it if the order is ever changed, and names the reason in its message.)
const TECHNIQUES: &[&str] = &["context", "clip", "twolevel", "lens", "windows", "explode", "slices"];
const ABOVE_TECHNIQUES: &[&str] = &["render", "scene", "ui", "cli"];

/// Every `.rs` file under `dir`, relative to it, with its text.
fn sources(dir: &Path) -> Vec<(String, String)> {
    fn walk(root: &Path, dir: &Path, out: &mut Vec<(String, String)>) {
        let Ok(entries) = std::fs::read_dir(dir) else { return };
        for e in entries.flatten() {
            let p = e.path();
            if p.is_dir() {
                walk(root, &p, out);
            } else if p.extension().is_some_and(|x| x == "rs") {
                let rel = p.strip_prefix(root).map(|r| r.to_string_lossy().replace('\\', "/")).unwrap_or_default();
                out.push((rel, std::fs::read_to_string(&p).unwrap_or_default()));
            }
        }
    }
    let mut out = Vec::new();
    walk(dir, dir, &mut out);
    out.sort();
    out
}

/// Files that use each other, one line per group with the edges inside it.
fn cycle_problems(graph: &Graph) -> Vec<String> {
    graph
        .cycles()
        .into_iter()
        .map(|group| {
            let inside: Vec<String> = group
                .iter()
                .flat_map(|m| {
                    graph.edges[m]
                        .iter()
                        .filter(|e| group.contains(&e.to))
                        .map(move |e| format!("{} → {} ({})", graph.file(m), graph.file(&e.to), e.via))
                })
                .collect();
            format!("files that use each other: {}", inside.join("; "))
        })
        .collect()
}

/// Imports that go up the layers, into a folder no layer lists, or from a technique to
/// what sits above the techniques.
fn layer_problems(graph: &Graph, layers: &[&str]) -> Vec<String> {
    let rank = |m: &Module| layers.iter().position(|l| *l == m.folder());
    let mut out = Vec::new();
    for m in graph.files.keys() {
        if rank(m).is_none() {
            out.push(format!("{}: folder '{}' is in no layer (add it to LAYERS)", graph.file(m), m.folder()));
        }
    }
    for (from, edges) in &graph.edges {
        for e in edges {
            let (Some(a), Some(b)) = (rank(from), rank(&e.to)) else { continue };
            let (fa, fb) = (from.folder(), e.to.folder());
            if TECHNIQUES.contains(&fa.as_str()) && ABOVE_TECHNIQUES.contains(&fb.as_str()) {
                out.push(format!("{} uses {} ({}): a technique never uses {fb}", graph.file(from), graph.file(&e.to), e.via));
            } else if b > a {
                out.push(format!("{} uses {} ({}): {fa} comes before {fb} in the layers", graph.file(from), graph.file(&e.to), e.via));
            }
        }
    }
    out
}

/// The reader a file of `volume/readers/` belongs to (`common` for the shared code;
/// `None` for the dispatch in `readers/mod.rs` and files elsewhere).
fn reader(m: &Module) -> Option<&str> {
    match m.path.as_slice() {
        [v, r, name, ..] if v == "volume" && r == "readers" => Some(name.trim_end_matches(".rs")),
        _ => None,
    }
}

/// Readers that use another reader (they may use `common` only).
fn reader_problems(graph: &Graph) -> Vec<String> {
    let mut out = Vec::new();
    for (from, edges) in &graph.edges {
        let Some(a) = reader(from) else { continue };
        for e in edges {
            if let Some(b) = reader(&e.to)
                && a != b
                && b != "common"
            {
                out.push(format!(
                    "{} uses {} ({}): readers share common and never use each other",
                    graph.file(from),
                    graph.file(&e.to),
                    e.via
                ));
            }
        }
    }
    out
}

/// Methods added to a type of another folder (`impl crate::volume::Volume { … }` in
/// `render/`): the callers' dependency on them shows in no path.
fn impl_problems(graph: &Graph) -> Vec<String> {
    graph
        .foreign_impls
        .iter()
        .map(|(file, of, via)| {
            format!("{}: {via} adds methods to a type of {}; they belong beside the type", graph.file(file), graph.file(of))
        })
        .collect()
}

fn problems(graph: &Graph) -> Vec<String> {
    [cycle_problems(graph), layer_problems(graph, LAYERS), reader_problems(graph), impl_problems(graph)].concat()
}

#[test]
fn src_keeps_its_layers() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let graph = Graph::of(&sources(&src));
    assert!(graph.files.len() > 100, "found only {} files under {}", graph.files.len(), src.display());
    let problems = problems(&graph);
    assert!(problems.is_empty(), "{} problems with the shape of src/:\n{}", problems.len(), problems.join("\n"));
}

/// The folder-level picture as `src/` has it now (printed with `--nocapture`, for
/// docs/architecture.md).
#[test]
fn folder_picture() {
    let graph = Graph::of(&sources(&Path::new(env!("CARGO_MANIFEST_DIR")).join("src")));
    for (from, to) in imports::folder_edges(&graph) {
        println!("{from} → {}", to.into_iter().collect::<Vec<_>>().join(", "));
    }
}

fn tree(files: &[(&str, &str)]) -> Graph {
    Graph::of(&files.iter().map(|(p, t)| (p.to_string(), t.to_string())).collect::<Vec<_>>())
}

fn edges_of(graph: &Graph, file: &str) -> Vec<String> {
    let m = graph.files.iter().find(|(_, f)| f.as_str() == file).map(|(m, _)| m.clone()).expect("file in the tree");
    let mut v: Vec<String> = graph.edges[&m].iter().map(|e| graph.file(&e.to).to_string()).collect();
    v.sort();
    v
}

#[test]
fn use_trees_expand_with_aliases_and_self() {
    let paths = source::expand("crate::a::{b, c::{d, e as f}, g::{self}}");
    let shown: Vec<String> =
        paths.iter().map(|(p, a)| format!("{}{}", p.join("::"), a.as_ref().map_or(String::new(), |a| format!(" as {a}")))).collect();
    assert_eq!(shown, ["crate::a::b", "crate::a::c::d", "crate::a::c::e as f", "crate::a::g"]);
}

#[test]
fn edges_follow_reexports_to_the_defining_file() {
    let g = tree(&[
        ("lib.rs", "pub mod lens; pub mod region;"),
        ("lens/mod.rs", "pub mod shape; pub use shape::Shape;"),
        ("lens/shape.rs", "pub struct Shape;"),
        ("region/mod.rs", "use crate::lens::Shape; fn f(_: Shape) {}"),
    ]);
    assert_eq!(edges_of(&g, "region/mod.rs"), ["lens/shape.rs"]);
    // A facade's re-export is not an edge of its own.
    assert!(edges_of(&g, "lens/mod.rs").is_empty());
}

#[test]
fn inline_paths_comments_strings_and_test_modules() {
    let g = tree(&[
        ("lib.rs", "pub mod a; pub mod b; pub mod c; pub mod d;"),
        (
            "a/mod.rs",
            "pub mod kid; fn f() { kid::go(); crate::b::x(); }\n// crate::c::x()\nconst S: &str = r#\"crate::c::y\"#;\n#[cfg(test)]\nmod tests { use crate::d::Z; }",
        ),
        ("a/kid.rs", "pub fn go() { let c = 'x'; fn g<'a>(_: &'a str) {} }"),
        ("b/mod.rs", "pub fn x() {}"),
        ("c/mod.rs", ""),
        ("d/mod.rs", "pub struct Z;"),
    ]);
    assert_eq!(edges_of(&g, "a/mod.rs"), ["a/kid.rs", "b/mod.rs"]);
}

#[test]
fn the_binary_reaches_the_library_by_its_name() {
    let g = tree(&[
        ("lib.rs", "pub mod scene;"),
        ("scene/mod.rs", "pub fn run() {}"),
        ("main.rs", "mod cli; fn main() { cli::go() }"),
        ("cli/mod.rs", "use focal::scene::run; pub fn go() { run() }"),
    ]);
    assert_eq!(edges_of(&g, "main.rs"), ["cli/mod.rs"]);
    assert_eq!(edges_of(&g, "cli/mod.rs"), ["scene/mod.rs"]);
}

#[test]
fn a_cycle_through_two_folders_is_found() {
    let g = tree(&[
        ("lib.rs", "pub mod region; pub mod clip;"),
        ("region/mod.rs", "pub struct Plane; pub fn cut(_: &crate::clip::Clipping) {}"),
        ("clip/mod.rs", "use crate::region::Plane; pub struct Clipping(Vec<Plane>);"),
    ]);
    let p = cycle_problems(&g);
    assert_eq!(p.len(), 1, "{p:?}");
    assert!(p[0].contains("region/mod.rs → clip/mod.rs") && p[0].contains("clip/mod.rs → region/mod.rs"), "{}", p[0]);
}

#[test]
fn a_parent_and_child_that_use_each_other_are_a_cycle() {
    let g = tree(&[
        ("lib.rs", "pub mod ui;"),
        ("ui/mod.rs", "pub mod panel; pub struct State; fn plugin() { panel::draw(); }"),
        ("ui/panel.rs", "use super::State; pub fn draw() {}"),
    ]);
    assert_eq!(cycle_problems(&g).len(), 1);
}

#[test]
fn a_technique_that_uses_the_scene_is_refused() {
    let g = tree(&[
        ("lib.rs", "pub mod windows; pub mod scene; pub mod region;"),
        ("region/mod.rs", "pub struct Look;"),
        ("windows/spec.rs", "use crate::scene::file::LookSpec;"),
        ("windows/mod.rs", "pub mod spec; use crate::region::Look;"),
        ("scene/mod.rs", "pub mod file;"),
        ("scene/file.rs", "pub struct LookSpec;"),
    ]);
    let p = layer_problems(&g, LAYERS);
    assert_eq!(p.len(), 1, "{p:?}");
    assert!(p[0].starts_with("windows/spec.rs uses scene/file.rs") && p[0].contains("never uses scene"), "{}", p[0]);
}

#[test]
fn an_import_up_the_layers_or_from_an_unlisted_folder_is_refused() {
    let g = tree(&[
        ("lib.rs", "pub mod volume; pub mod region; pub mod extra;"),
        ("volume/mod.rs", "fn f(_: crate::region::Ray) {}"),
        ("region/mod.rs", "pub struct Ray;"),
        ("extra/mod.rs", ""),
    ]);
    let p = layer_problems(&g, LAYERS);
    assert_eq!(p.len(), 2, "{p:?}");
    assert!(p.iter().any(|s| s.contains("folder 'extra' is in no layer")));
    assert!(p.iter().any(|s| s.starts_with("volume/mod.rs uses region/mod.rs") && s.contains("volume comes before region")));
}

#[test]
fn a_reader_that_uses_another_reader_is_refused() {
    let g = tree(&[
        ("lib.rs", "pub mod volume;"),
        ("volume/mod.rs", "pub mod readers;"),
        ("volume/readers/mod.rs", "pub mod common; pub mod nifti; pub mod nrrd; pub mod dicom;"),
        ("volume/readers/common.rs", "pub struct ReadError;"),
        ("volume/readers/nifti.rs", "use super::common::ReadError; pub fn volume_name() {}"),
        ("volume/readers/nrrd.rs", "use super::common::ReadError; use super::nifti::volume_name;"),
        ("volume/readers/dicom/mod.rs", "pub mod series; use super::common::ReadError;"),
        ("volume/readers/dicom/series.rs", "use super::super::common::ReadError;"),
    ]);
    let p = reader_problems(&g);
    assert_eq!(p.len(), 1, "{p:?}");
    assert!(p[0].starts_with("volume/readers/nrrd.rs uses volume/readers/nifti.rs"), "{}", p[0]);
}

#[test]
fn a_glob_import_uses_what_the_code_takes_from_it() {
    let g = tree(&[
        ("lib.rs", "pub mod lens;"),
        ("lens/mod.rs", "pub mod screen; pub mod stack; pub use screen::Screen; pub use stack::Resolved;"),
        ("lens/screen.rs", "use super::*; pub struct Screen; fn f(_: Resolved) {}"),
        ("lens/stack.rs", "use super::screen::Screen; pub struct Resolved(Screen);"),
    ]);
    assert_eq!(edges_of(&g, "lens/screen.rs"), ["lens/mod.rs", "lens/stack.rs"]);
    assert_eq!(cycle_problems(&g).len(), 1);
}

#[test]
fn a_use_through_an_earlier_use_is_followed() {
    let g = tree(&[
        ("lib.rs", "pub mod lens; pub mod region;"),
        ("lens/mod.rs", "pub mod stack;"),
        ("lens/stack.rs", "pub fn lens_ray() {}"),
        ("region/mod.rs", "use crate::lens; use lens::stack::lens_ray; fn f() { lens_ray() }"),
    ]);
    assert_eq!(edges_of(&g, "region/mod.rs"), ["lens/mod.rs", "lens/stack.rs"]);
}

#[test]
fn inline_modules_resolve_super_from_their_own_path() {
    let g = tree(&[
        ("lib.rs", "pub mod lens; pub mod scene;"),
        ("lens/mod.rs", "pub mod stack;"),
        ("lens/stack.rs", "pub mod detail { use super::super::super::scene::SceneFile; pub struct X(SceneFile); }"),
        ("scene/mod.rs", "pub struct SceneFile;"),
    ]);
    assert_eq!(edges_of(&g, "lens/stack.rs"), ["scene/mod.rs"]);
    assert_eq!(layer_problems(&g, LAYERS).len(), 1);
}

#[test]
fn a_reexport_of_what_sits_above_is_an_upward_import() {
    let g = tree(&[
        ("lib.rs", "pub mod region; pub mod scene;"),
        ("region/mod.rs", "pub use crate::scene::SceneFile;"),
        ("scene/mod.rs", "pub struct SceneFile;"),
    ]);
    let p = layer_problems(&g, LAYERS);
    assert!(p.len() == 1 && p[0].starts_with("region/mod.rs uses scene/mod.rs"), "{p:?}");
}

#[test]
fn methods_added_to_another_folders_type_are_refused() {
    let g = tree(&[
        ("lib.rs", "pub mod volume; pub mod render;"),
        ("volume/mod.rs", "pub struct Volume;\nimpl Volume {\n    fn own(&self) {}\n}"),
        (
            "render/mod.rs",
            "use crate::volume::Volume;\nimpl Volume {\n    pub fn gpu_bytes(&self) -> usize { 0 }\n}\nimpl Clone for Gpu {}\nfn f() -> impl Iterator<Item = u8> { None.into_iter() }",
        ),
    ]);
    let p = impl_problems(&g);
    assert!(p.len() == 1 && p[0].starts_with("render/mod.rs: impl Volume adds methods to a type of volume/mod.rs"), "{p:?}");
}

#[test]
fn test_code_with_more_attributes_and_test_files_are_left_out() {
    let g = tree(&[
        ("lib.rs", "pub mod render; pub mod scene;"),
        ("render/mod.rs", "pub mod pack;"),
        ("render/pack.rs", "#[cfg(test)]\n#[allow(unused)]\nmod inline { use crate::scene::A; }\n#[cfg(test)]\nmod tests;"),
        ("render/pack/tests.rs", "use crate::scene::A;"),
        ("scene/mod.rs", "pub struct A;"),
    ]);
    assert!(edges_of(&g, "render/pack.rs").is_empty());
    assert!(!g.files.values().any(|f| f == "render/pack/tests.rs"));
}

#[test]
fn visibility_paths_are_no_dependency() {
    let g = tree(&[("lib.rs", "pub mod a; pub mod b;"), ("a/mod.rs", "pub(in crate::b) fn f() {}"), ("b/mod.rs", "")]);
    assert!(edges_of(&g, "a/mod.rs").is_empty());
}
