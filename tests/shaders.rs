//! The WGSL composes and validates without a GPU (naga_oil + naga, as Bevy does), with
//! stand-ins for the two Bevy modules it imports. Errors name the function involved.

use std::collections::HashMap;
use std::path::Path;

use naga_oil::compose::{ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderDefValue, ShaderLanguage, ShaderType};

const BEVY_VIEW: &str = "#define_import_path bevy_render::view
struct View {
    world_from_clip: mat4x4<f32>,
    world_from_view: mat4x4<f32>,
    clip_from_view: mat4x4<f32>,
    world_position: vec3<f32>,
    viewport: vec4<f32>,
}";
const BEVY_FULLSCREEN: &str = "#define_import_path bevy_core_pipeline::fullscreen_vertex_shader
struct FullscreenVertexOutput { @builtin(position) position: vec4<f32>, @location(0) uv: vec2<f32> }";

const MODULES: [&str; 17] = [
    "types",
    "bindings",
    "camera",
    "regions",
    "bricked",
    "sampling",
    "lens",
    "footprint",
    "transfer",
    "shading",
    "compositing",
    "context",
    "selection",
    "samples",
    "segments",
    "two_level",
    "insets",
];

fn read(rel: &str) -> String {
    std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join(rel)).unwrap_or_else(|e| panic!("{rel}: {e}"))
}

fn add(composer: &mut Composer, source: &str, path: &str) {
    let result = composer.add_composable_module(ComposableModuleDescriptor {
        source,
        file_path: path,
        language: ShaderLanguage::Wgsl,
        ..Default::default()
    });
    if let Err(e) = result {
        panic!("{path}: {}", e.emit_to_string(composer));
    }
}

/// Shader defs of the ray caster (mirrors `render::gpu_types::features::NAMES`).
const DEFS: [&str; 25] = [
    "HAS_DVR",
    "HAS_GRADIENT_MODULATION",
    "HAS_LABELS",
    "HAS_PROJECTION",
    "HAS_ISO",
    "HAS_SHADING",
    "MULTI_REGION",
    "HAS_LENSES",
    "HAS_CONTEXT",
    "HAS_TWO_LEVEL",
    "DVR_PAIRS",
    "LENS_ANTIALIAS",
    "HAS_SELECTION",
    "HAS_HOLES",
    "DOI_CHANNEL",
    "COMPANION",
    "HAS_BRICKED",
    "BRICKED_ONLY",
    "OWN_VALUES",
    "INSETS",
    "SEVERAL_INSETS",
    "VALUE_RANGES",
    "UNIFORM_PLANES",
    "UNIFORM_REGIONS",
    "UNIFORM_OCCUPANCY",
];

#[test]
fn every_shader_variant_composes_and_validates() {
    let bit = |name: &str| 1u32 << DEFS.iter().position(|d| *d == name).unwrap();
    // Every combination the renderer can ask for: anti-aliasing only with lenses, DVR
    // pairs and selection weights only with DVR, the degree of interest in the data's
    // second channel only with weights, companions only with it.
    let needs = |a: &str, b: &str, bits: u32| bits & bit(a) == 0 || bits & bit(b) != 0;
    // Holes touch the interval code only: with the defs that share it, not every other.
    let interval_defs = bit("HAS_HOLES") | bit("HAS_DVR") | bit("MULTI_REGION") | bit("DVR_PAIRS") | bit("HAS_TWO_LEVEL");
    let possible = |bits: u32| {
        needs("LENS_ANTIALIAS", "HAS_LENSES", bits)
            && needs("DVR_PAIRS", "HAS_DVR", bits)
            && needs("HAS_SELECTION", "HAS_DVR", bits)
            && needs("DOI_CHANNEL", "HAS_SELECTION", bits)
            && needs("COMPANION", "DOI_CHANNEL", bits)
            && needs("BRICKED_ONLY", "HAS_BRICKED", bits)
            && (bits & bit("HAS_HOLES") == 0 || bits & !interval_defs == 0)
    };
    // Bricked sampling sits inside the sampling functions under its own def, beside the
    // others' code but not inside it: with every pair of other defs and with all of
    // them (every combination doubled the test's 3½ minutes), each with and without
    // BRICKED_ONLY.
    let bricked = bit("HAS_BRICKED") | bit("BRICKED_ONLY");
    // (The uniform copies: with up to two other defs and with all, below.)
    let copies = bit("UNIFORM_PLANES") | bit("UNIFORM_REGIONS") | bit("UNIFORM_OCCUPANCY");
    let full = ((1u32 << DEFS.len()) - 1) & !copies;
    let all_but_holes = full & !bricked & !bit("HAS_HOLES");
    let possible =
        |bits: u32| possible(bits) && (bits & bricked == 0 || (bits & !bricked).count_ones() <= 2 || bits & !bricked == all_but_holes);
    // Own values at object boundaries sit in the two-level code alone: with it and up to
    // two other defs, and with all of them.
    let own = bit("OWN_VALUES");
    let possible = |bits: u32| {
        possible(bits)
            && (bits & own == 0
                || (bits & bit("HAS_TWO_LEVEL") != 0 && ((bits & !own).count_ones() <= 3 || (bits | bricked | bit("HAS_HOLES")) == full)))
    };
    // Windows drawn in place touch the DVR loop alone: with DVR and up to two other
    // defs, and with all of them.
    // (With one window or several: the choice among them alone differs.)
    let insets = bit("INSETS") | bit("SEVERAL_INSETS");
    let possible = |bits: u32| {
        let others = (bits & !insets & !bit("HAS_DVR")).count_ones();
        possible(bits)
            && needs("SEVERAL_INSETS", "INSETS", bits)
            && (bits & insets == 0
                || (needs("INSETS", "HAS_DVR", bits) && (others <= 2 || bits & !insets == full & !insets & !bit("HAS_HOLES"))))
    };
    // Objects' value ranges sit in the two-level code alone, as own values do.
    let ranges = bit("VALUE_RANGES");
    let possible = |bits: u32| {
        possible(bits)
            && (bits & ranges == 0
                || (bits & bit("HAS_TWO_LEVEL") != 0
                    && ((bits & !ranges).count_ones() <= 3 || (bits | bricked | bit("HAS_HOLES") | insets) == full)))
    };
    // The uniform copies of the records, the planes and the occupancy bits change
    // where each is read from, not the code: all three with up to two other defs, and
    // each set of them with every def that can be on together.
    let everything = (0u32..(1 << DEFS.len())).filter(|b| b & copies == 0 && possible(*b)).max_by_key(|b| b.count_ones()).unwrap_or(0);
    let possible = |bits: u32| {
        possible(bits & !copies)
            && (bits & copies == 0 || (bits & copies == copies && (bits & !copies).count_ones() <= 2) || bits & !copies == everything)
    };
    let variants: Vec<u32> = (0u32..(1 << DEFS.len())).filter(|b| possible(*b)).collect();
    // (On every core: the variants are independent, and one after another they were
    // six of the suite's minutes. A variant that fails panics its thread, and the scope
    // the test.)
    let threads = std::thread::available_parallelism().map_or(1, |n| n.get());
    std::thread::scope(|scope| {
        for first in 0..threads {
            let variants = &variants;
            scope.spawn(move || {
                for bits in variants.iter().skip(first).step_by(threads) {
                    let defs: HashMap<String, ShaderDefValue> = DEFS
                        .iter()
                        .enumerate()
                        .filter(|(i, _)| bits & (1 << i) != 0)
                        .map(|(_, d)| (d.to_string(), ShaderDefValue::Bool(true)))
                        .collect();
                    compose_and_validate("shaders/raycast.wgsl", defs);
                }
            });
        }
    });
}

/// The lens kinds' and shapes' defs (mirrors `render::gpu_types::features::LENS_NAMES`).
const LENS_DEFS: [&str; 5] = ["HAS_MAGNIFIER", "HAS_SAMPLING_LENS", "HAS_ANGULAR_LENS", "HAS_POLYGON_LENS", "HAS_FEATURE_LENS"];

#[test]
fn every_lens_kind_variant_composes_and_validates() {
    let names: Vec<&str> = focal::render::gpu_types::features::LENS_NAMES.iter().map(|(_, n)| *n).collect();
    assert_eq!(names, LENS_DEFS);
    // Each set of kinds and shapes, under lenses with and without anti-aliasing, over
    // memory and bricked data (they touch ray generation alone).
    for bits in 0u32..(1 << LENS_DEFS.len()) {
        for base in [&["HAS_DVR", "HAS_LENSES", "LENS_ANTIALIAS"][..], &["HAS_DVR", "HAS_LENSES", "HAS_BRICKED", "BRICKED_ONLY"]] {
            let defs: HashMap<String, ShaderDefValue> = LENS_DEFS
                .iter()
                .enumerate()
                .filter(|(i, _)| bits & (1 << i) != 0)
                .map(|(_, d)| *d)
                .chain(base.iter().copied())
                .map(|d| (d.to_string(), ShaderDefValue::Bool(true)))
                .collect();
            compose_and_validate("shaders/raycast.wgsl", defs);
        }
    }
}

#[test]
fn the_feature_lens_compute_shader_composes_and_validates() {
    compose_and_validate("shaders/feature.wgsl", HashMap::new());
}

/// The sizes the shaders take as constants are the renderer's.
#[test]
fn shader_constants_match_the_renderer() {
    let types = read("shaders/focal/types.wgsl");
    let constant = |name: &str| {
        let line = types.lines().find(|l| l.starts_with(&format!("const {name}: u32 = "))).unwrap_or_else(|| panic!("no {name}"));
        line.trim_start_matches(&format!("const {name}: u32 = ")).trim_end_matches("u;").parse::<u32>().unwrap()
    };
    assert_eq!(constant("LUT_ATLAS_WIDTH"), focal::render::pack::LUT_ATLAS_WIDTH);
    assert_eq!(constant("MAX_INSETS") as usize, focal::render::gpu_types::MAX_INSETS);
    assert_eq!(constant("MAX_UNIFORM_REGIONS") as usize, focal::render::gpu_types::MAX_UNIFORM_REGIONS);
    assert_eq!(constant("MAX_UNIFORM_PLANES") as usize, focal::render::gpu_types::MAX_UNIFORM_PLANES);
    assert_eq!(constant("MAX_UNIFORM_OCCUPANCY") as usize, focal::render::gpu_types::MAX_UNIFORM_OCCUPANCY);
}

#[test]
fn def_names_match_the_renderer() {
    let names: Vec<&str> = focal::render::gpu_types::features::NAMES.iter().map(|(_, n)| *n).collect();
    assert_eq!(names, DEFS);
}

fn compose_and_validate(entry: &str, shader_defs: HashMap<String, ShaderDefValue>) {
    let label = format!("{entry} {:?}", shader_defs.keys().collect::<Vec<_>>());
    let mut composer = Composer::default();
    add(&mut composer, BEVY_VIEW, "bevy_view.wgsl");
    add(&mut composer, BEVY_FULLSCREEN, "fullscreen.wgsl");
    // Modules in dependency order.
    let sources: Vec<(String, String)> =
        MODULES.iter().map(|m| (format!("shaders/focal/{m}.wgsl"), read(&format!("shaders/focal/{m}.wgsl")))).collect();
    for (path, source) in &sources {
        add(&mut composer, source, path);
    }
    let main = read(entry);
    let module = composer
        .make_naga_module(NagaModuleDescriptor {
            source: &main,
            file_path: entry,
            shader_type: ShaderType::Wgsl,
            shader_defs,
            additional_imports: &[],
        })
        .unwrap_or_else(|e| panic!("{}", e.emit_to_string(&composer)));
    let mut validator = naga::valid::Validator::new(naga::valid::ValidationFlags::all(), naga::valid::Capabilities::all());
    if let Err(e) = validator.validate(&module) {
        let functions: Vec<String> =
            module.functions.iter().map(|(h, f)| format!("{h:?} = {}", f.name.clone().unwrap_or_default())).collect();
        let types: Vec<String> =
            module.types.iter().map(|(h, t)| format!("{h:?} = {:?}", t.name.clone().unwrap_or_else(|| format!("{:?}", t.inner)))).collect();
        panic!("{label}: validation failed: {e:?}\nfunctions: {functions:#?}\ntypes: {types:#?}");
    }
}
