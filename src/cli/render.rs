//! `focal render`: scene files, or one data file with options, to PNG (GPU by default,
//! `--cpu` for the reference renderer).

use focal::context::ContextParams;
use std::path::{Path, PathBuf};

use clap::Args;
use focal::region::{AppearanceSpec, LabelsSpec};
use focal::region::{Mode, Shading, View};
use focal::scene::file::{CameraSpec, DatasetSpec, RenderingSpec, SceneFile, SourceSpec};
use focal::scene::run::{RunOptions, render_frames, render_scene_file};
use focal::volume::phantom::Phantom;
use focal::volume::source::procedural::{DEFAULT_SPACING_MM, parse_dims};

#[derive(Args)]
pub struct RenderArgs {
    /// Scene files (`.ron`), or one volume file, DICOM or OME-Zarr folder,
    /// `phantom:head|engine|sphere` or `procedural:N[xNxN]` (default: the head phantom).
    inputs: Vec<PathBuf>,
    /// Render on the CPU with the reference renderer instead of the GPU.
    #[arg(long)]
    cpu: bool,
    /// Output: a folder for scene files (default `out/`), a PNG for a data file
    /// (default `out/render.png`).
    #[arg(long, short)]
    out: Option<PathBuf>,
    /// Image size WIDTHxHEIGHT (default: the scene's, or 512x512).
    #[arg(long)]
    size: Option<String>,
    /// Transfer-function preset name or `.ron` file (default: chosen for the data).
    #[arg(long)]
    preset: Option<String>,
    /// dvr, mip, minip, xray, gradient_dvr or iso.
    #[arg(long, default_value = "dvr")]
    mode: Mode,
    /// View direction: +x/right, -x/left, +y/anterior/front, -y/posterior, +z/superior/top,
    /// -z/inferior, oblique.
    #[arg(long, default_value = "oblique")]
    view: View,
    /// Azimuth in degrees around the superior axis, from the anterior side (with
    /// --elevation, instead of --view).
    #[arg(long, allow_hyphen_values = true)]
    azimuth: Option<f32>,
    /// Elevation in degrees above the axial plane.
    #[arg(long, allow_hyphen_values = true)]
    elevation: Option<f32>,
    /// Orthographic projection instead of perspective.
    #[arg(long)]
    ortho: bool,
    /// Zoom factor (> 1 moves closer).
    #[arg(long, default_value_t = 1.0)]
    zoom: f32,
    /// Sample distance in units of the smallest voxel spacing.
    #[arg(long, default_value_t = 0.5)]
    step: f32,
    /// Iso-value in the data's units (iso mode; default: the middle of the value range).
    #[arg(long, allow_hyphen_values = true)]
    iso: Option<f64>,
    /// Projections (mip, minip, xray) take only samples within LOW,HIGH (the data's
    /// units): a MinIP above the air around an object, a MIP below metal.
    #[arg(long, value_name = "LOW,HIGH", allow_hyphen_values = true, value_parser = parse_range)]
    projection_range: Option<(f64, f64)>,
    /// Do not jitter ray starts.
    #[arg(long)]
    no_jitter: bool,
    /// Do not skip empty bricks (for measurements; the image is the same).
    #[arg(long)]
    no_skip: bool,
    /// Do not stop rays once they are opaque (for measurements).
    #[arg(long)]
    no_early_termination: bool,
    /// Turn Blinn-Phong shading off.
    #[arg(long)]
    no_shading: bool,
    /// Render as a label volume with the colours of its label table.
    #[arg(long)]
    labels: bool,
    /// Layout of headerless raw files: DIMS:TYPE[:le|be][:s=SPACING][:skip=BYTES].
    #[arg(long)]
    raw: Option<String>,
    /// Resolution of generated phantoms.
    #[arg(long, default_value_t = 256)]
    resolution: u32,
    /// κt of the context-preserving mode (`--mode context`): how deep the view reaches.
    #[arg(long)]
    kappa_t: Option<f32>,
    /// κs of the context-preserving mode: how sharp the transition is.
    #[arg(long)]
    kappa_s: Option<f32>,
    /// Print the process's peak resident memory when done (`peak resident memory: N MiB`).
    #[arg(long)]
    report_memory: bool,
    /// Write one slice view instead of the 3D view: axial, coronal or sagittal (or z, y,
    /// x), with the slice index along it (default: the middle), at the voxels'
    /// resolution (default output `out/slice-ORIENTATION.png`).
    #[arg(long, value_name = "ORIENTATION[:INDEX]", value_parser = super::slice::parse_slice)]
    slice: Option<(focal::slices::Orientation, Option<u32>)>,
    /// Window width of a slice view, in the data's units (with --level).
    #[arg(long, requires = "level")]
    window: Option<f64>,
    /// Window centre (level) of a slice view, in the data's units (with --window).
    #[arg(long, requires = "window", allow_hyphen_values = true)]
    level: Option<f64>,
    /// Write an orbit of N frames about the superior axis instead of one picture (of the
    /// data file or of one scene file), from
    /// --azimuth (default 0) at --elevation (default 20): a PNG sequence, an animated GIF
    /// and, where ffmpeg is installed, an MP4 in the --out folder (default `out/turntable`).
    #[arg(long, value_name = "N", value_parser = clap::value_parser!(u32).range(1..=3600), conflicts_with = "slice")]
    turntable: Option<u32>,
    /// Window preset of a slice view: auto (the 1st to 99th percentile, the default),
    /// soft tissue, lung, bone or brain (CT, Hounsfield units).
    #[arg(long, value_name = "PRESET", conflicts_with = "window")]
    window_preset: Option<String>,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size '{s}' is not WIDTHxHEIGHT"))?;
    let p = |v: &str| {
        v.trim().parse::<u32>().ok().filter(|&n| (1..=8192).contains(&n)).ok_or_else(|| format!("size '{s}': {v} is not 1..8192"))
    };
    Ok((p(w)?, p(h)?))
}

pub fn run(args: &RenderArgs) -> Result<(), String> {
    let result = render(args);
    if args.report_memory {
        match peak_resident_mib() {
            Some(mib) => eprintln!("peak resident memory: {mib:.0} MiB"),
            None => eprintln!("peak resident memory: unknown (no /proc/self/status)"),
        }
    }
    result
}

/// Peak resident set of this process (`VmHWM`), MiB.
fn peak_resident_mib() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let kb: f64 = status.lines().find_map(|l| l.strip_prefix("VmHWM:"))?.trim().trim_end_matches("kB").trim().parse().ok()?;
    Some(kb / 1024.0)
}

fn render(args: &RenderArgs) -> Result<(), String> {
    let size = args.size.as_deref().map(parse_size).transpose()?;
    let options = |out_dir: PathBuf| RunOptions { out_dir, cpu: args.cpu, size, progress: false };
    let scenes: Vec<&PathBuf> = args.inputs.iter().filter(|p| p.extension().is_some_and(|e| e == "ron")).collect();
    if !scenes.is_empty() {
        if scenes.len() != args.inputs.len() {
            return Err("give either scene files (.ron) or one data file, not both".into());
        }
        if let Some(n) = args.turntable {
            let [path] = scenes[..] else { return Err("--turntable takes one scene file".into()) };
            let scene = focal::scene::read_scene(path)?;
            let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
            return turntable(scene, n, &base, args, options(PathBuf::new())).map_err(|e| format!("{}: {e}", path.display()));
        }
        let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("out"));
        for s in scenes {
            let t = std::time::Instant::now();
            for p in render_scene_file(s, &options(dir.clone()))? {
                println!("{}", p.display());
            }
            eprintln!("{}: {:.1} s", s.display(), t.elapsed().as_secs_f32());
        }
        return Ok(());
    }
    if args.inputs.len() > 1 {
        return Err("give one data file (or several .ron scene files)".into());
    }
    let scene = scene_for(args.inputs.first().map(PathBuf::as_path), args)?;
    if let Some((orientation, index)) = args.slice {
        let datasets = focal::scene::load::load_datasets(&scene, Path::new("."))?;
        let dataset = datasets.first().ok_or("no dataset to slice")?;
        let window = super::slice::window_of(args.window, args.level, args.window_preset.as_deref(), dataset)?;
        let image = super::slice::picture(dataset, orientation, index, window)?;
        let out = args.out.clone().unwrap_or_else(|| PathBuf::from(format!("out/slice-{}.png", orientation.names().0)));
        return save(&image, &out);
    }
    if let Some(n) = args.turntable {
        return turntable(scene, n, Path::new("."), args, options(PathBuf::new()));
    }
    let out = args.out.clone().unwrap_or_else(|| PathBuf::from("out/render.png"));
    let images = render_frames(scene, Path::new("."), &options(PathBuf::new()))?;
    let (_, image) = images.into_iter().next().ok_or("nothing rendered")?;
    save(&image, &out)
}

/// Renders an orbit of `n` frames around `scene` (relative paths from `base`) into the
/// --out folder (default `out/turntable`).
fn turntable(scene: SceneFile, n: u32, base: &Path, args: &RenderArgs, options: RunOptions) -> Result<(), String> {
    use focal::scene::movie;
    let scene = movie::turntable(scene, n, args.azimuth.unwrap_or(0.0), args.elevation.unwrap_or(20.0), args.ortho, args.zoom);
    let dir = args.out.clone().unwrap_or_else(|| PathBuf::from("out/turntable"));
    let mut writer = movie::MovieWriter::new(&dir, "turntable", movie::FPS)?;
    focal::scene::run::render_frames_into(scene, base, &RunOptions { progress: true, ..options }, &mut |name, image| {
        writer.add(&name, &image)
    })?;
    for p in writer.finish()? {
        println!("{}", p.display());
    }
    Ok(())
}

/// A one-dataset scene from the command-line options.
fn scene_for(input: Option<&Path>, args: &RenderArgs) -> Result<SceneFile, String> {
    let source = match input {
        None => SourceSpec::Phantom { kind: Phantom::Head, resolution: args.resolution },
        Some(p) if p.to_string_lossy().starts_with("phantom:") => {
            SourceSpec::Phantom { kind: p.to_string_lossy()["phantom:".len()..].parse()?, resolution: args.resolution }
        }
        Some(p) if p.to_string_lossy().starts_with("procedural:") => {
            let d = parse_dims(&p.to_string_lossy()["procedural:".len()..])?;
            SourceSpec::Procedural { dims: (d.x, d.y, d.z), spacing_mm: DEFAULT_SPACING_MM }
        }
        Some(p) => match &args.raw {
            Some(layout) => SourceSpec::Raw { path: p.to_path_buf(), layout: layout.clone() },
            None => SourceSpec::File(p.to_path_buf()),
        },
    };
    let shading = args.no_shading.then(|| Shading { enabled: false, ..Default::default() });
    let appearance = AppearanceSpec {
        mode: args.mode,
        preset: args.preset.clone(),
        transfer: None,
        labels: args.labels.then(LabelsSpec::default),
        shading,
        step: args.step,
        iso: args.iso,
        projection_range: args.projection_range,
        context: {
            let d = ContextParams::default();
            ContextParams { kappa_t: args.kappa_t.unwrap_or(d.kappa_t), kappa_s: args.kappa_s.unwrap_or(d.kappa_s), ..d }
        },
        segmentation: None,
    };
    let camera = match (args.azimuth, args.elevation) {
        (None, None) => CameraSpec::View { view: args.view, orthographic: args.ortho, zoom: args.zoom },
        (a, e) => {
            CameraSpec::Orbit { azimuth_deg: a.unwrap_or(0.0), elevation_deg: e.unwrap_or(0.0), orthographic: args.ortho, zoom: args.zoom }
        }
    };
    Ok(SceneFile {
        size: (512, 512),
        background: (0.0, 0.0, 0.0),
        light: Default::default(),
        rendering: RenderingSpec {
            jitter: !args.no_jitter,
            skip_empty: !args.no_skip,
            early_termination: !args.no_early_termination,
            lens_antialias: true,
            lens_context_steps: false,
        },
        datasets: vec![DatasetSpec::of(source, appearance)],
        camera,
        lenses: Vec::new(),
        windows: Vec::new(),
        pointer: None,
        markers: Vec::new(),
        rulers: Vec::new(),
        frames: Vec::new(),
        animation: None,
    })
}

fn save(image: &image::RgbaImage, out: &Path) -> Result<(), String> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    image.save(out).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("{}", out.display());
    Ok(())
}

/// The default scene (the head phantom), embedded.
pub const DEFAULT_SCENE: &str = include_str!("../../assets/scenes/default.ron");

/// `focal [VOLUME]` on a machine without a display: renders the default scene (or the
/// volume with its default look) to `out` and says where.
pub fn run_headless(volume: Option<&Path>, out: &Path) -> Result<(), String> {
    let scene = match volume {
        None => SceneFile::parse(DEFAULT_SCENE, "assets/scenes/default.ron")?,
        Some(v) => {
            let mut s = SceneFile::parse(DEFAULT_SCENE, "assets/scenes/default.ron")?;
            s.datasets = vec![DatasetSpec::of(SourceSpec::File(v.to_path_buf()), AppearanceSpec::default())];
            s
        }
    };
    let images = render_frames(scene, Path::new("."), &RunOptions::default())?;
    let (_, image) = images.into_iter().next().ok_or("nothing rendered")?;
    eprintln!("no display: rendered the default view headless");
    save(&image, out)
}

/// `LOW,HIGH` as two numbers.
fn parse_range(text: &str) -> Result<(f64, f64), String> {
    let (lo, hi) = text.split_once(',').ok_or_else(|| format!("'{text}' is not LOW,HIGH"))?;
    let number = |t: &str| t.trim().parse::<f64>().map_err(|e| format!("'{t}' in '{text}': {e}"));
    let range = (number(lo)?, number(hi)?);
    focal::region::appearance_spec::check_projection_range(range)?;
    Ok(range)
}
