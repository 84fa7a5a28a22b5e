//! `focal render`: a volume or phantom to PNG with the CPU reference renderer.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Instant;

use bevy::prelude::Transform;
use clap::Args;
use focal::FocalPlugins;
use focal::dataset::Dataset;
use focal::reference::{RenderScene, render};
use focal::region::{Appearance, Lookup, Mode, View};
use focal::render::VolumeView;
use focal::render::headless::Offscreen;
use focal::transfer::{LabelTransfer, Lut, presets};
use focal::volume::readers::RawSpec;
use focal::volume::{LabelTable, LabelVolume};

#[derive(Args)]
pub struct RenderArgs {
    /// Volume file, DICOM folder or `phantom:head|engine|sphere` (default: the head phantom).
    input: Option<PathBuf>,
    /// Render on the CPU with the reference renderer instead of the GPU.
    #[arg(long)]
    cpu: bool,
    /// Transfer-function preset name or `.ron` file (default: chosen for the data).
    #[arg(long)]
    preset: Option<String>,
    /// dvr, mip, minip, xray, gradient_dvr or iso.
    #[arg(long, default_value = "dvr")]
    mode: Mode,
    /// View: anterior/front, posterior, left, right, superior/top, inferior, oblique.
    #[arg(long, default_value = "oblique")]
    view: View,
    /// Orthographic projection instead of perspective.
    #[arg(long)]
    ortho: bool,
    /// Image size, WIDTHxHEIGHT.
    #[arg(long, default_value = "512x512")]
    size: String,
    /// Sample distance in units of the smallest voxel spacing.
    #[arg(long, default_value_t = 0.5)]
    step: f32,
    /// Iso-value in the data's units (iso mode; default: the middle of the value range).
    #[arg(long)]
    iso: Option<f64>,
    /// Jitter ray starts (removes wood-grain rings; adds fine noise).
    #[arg(long)]
    jitter: bool,
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
    raw: Option<RawSpec>,
    /// Resolution of generated phantoms.
    #[arg(long, default_value_t = 256)]
    resolution: u32,
    /// Output PNG.
    #[arg(long, short, default_value = "out/render.png")]
    out: PathBuf,
}

fn parse_size(s: &str) -> Result<(u32, u32), String> {
    let (w, h) = s.split_once(['x', 'X']).ok_or_else(|| format!("size '{s}' is not WIDTHxHEIGHT"))?;
    let p = |v: &str| {
        v.trim().parse::<u32>().ok().filter(|&n| (1..=8192).contains(&n)).ok_or_else(|| format!("size '{s}': {v} is not 1..8192"))
    };
    Ok((p(w)?, p(h)?))
}

pub fn run(args: &RenderArgs) -> Result<(), String> {
    let (w, h) = parse_size(&args.size)?;
    let t = Instant::now();
    let volume = super::load(args.input.as_deref(), args.raw.as_ref(), args.resolution)?;
    eprintln!("loaded {} ({}) in {:.2} s", volume.name, focal::volume::grid::fmt_dims(volume.dims()), t.elapsed().as_secs_f32());
    let labels;
    let (target, lookup) = if args.labels {
        let table = match &args.input {
            Some(p) => focal::volume::readers::label_table::read_sidecars(p).map_err(|e| e.to_string())?,
            None => LabelTable::default(),
        };
        labels = LabelVolume::from_volume(volume, table)?;
        let ids = labels.present_ids().into_iter().map(|(id, _)| id);
        let lookup = Lookup::Labels(LabelTransfer::from_table(&labels.table, ids, 0.6));
        (&labels.volume, lookup)
    } else {
        labels = LabelVolume { volume, table: LabelTable::default() };
        let tf = match &args.preset {
            Some(p) => presets::load(p)?,
            None if args.mode.is_projection() => presets::builtin("grayscale_ramp")?,
            None => presets::default_for(&labels.volume)?,
        };
        (&labels.volume, Lookup::Transfer(tf))
    };
    let mut appearance = Appearance { lookup, ..Appearance::new(args.mode, presets::builtin("grayscale_ramp")?) };
    appearance.step = args.step;
    appearance.shading.enabled = !args.no_shading;
    appearance.iso_value = args.iso.unwrap_or((target.stats.min + target.stats.max) * 0.5);
    let volume = Arc::new(target.clone());
    // Frame what the transfer function shows (the whole box for projections).
    let visible = match (&appearance.lookup, args.mode.is_projection()) {
        (Lookup::Transfer(tf), false) => Lut::for_volume(tf, target).visible_bounds(target),
        (Lookup::Labels(styles), _) => {
            let table = styles.bake(target.stats.code_max as usize + 1);
            let bricks = target.bricks();
            let keep = bricks.occupancy(|lo, hi| table[lo as usize..=hi as usize].iter().any(|c| c[3] > 0.0));
            bricks.bounds_where(&keep).map(|(lo, hi)| target.grid.index_box_world_bounds(lo, hi))
        }
        _ => None,
    };
    let (lo, hi) = visible.unwrap_or_else(|| target.grid.world_bounds());
    let camera = args.view.frame_box(lo, hi, w as f32 / h as f32, args.ortho);
    let t = Instant::now();
    let image = if args.cpu {
        let mut scene = RenderScene::single(volume, appearance);
        scene.jitter = args.jitter;
        scene.skip_empty = !args.no_skip;
        render(&scene, &camera, w, h)?.to_image()?
    } else {
        let mut off = Offscreen::new(w, h, |app| {
            app.add_plugins(FocalPlugins);
        })?;
        off.world_mut().spawn((Dataset::new(volume, appearance), Transform::default()));
        off.set_camera(&camera);
        off.set_view(VolumeView {
            jitter: args.jitter,
            skip_empty: !args.no_skip,
            early_termination: !args.no_early_termination,
            ..Default::default()
        });
        eprintln!("GPU: {}", off.adapter_name());
        off.capture()?
    };
    eprintln!("rendered {w}×{h} in {:.2} s", t.elapsed().as_secs_f32());
    write(&image, &args.out)
}

fn write(image: &image::RgbaImage, out: &Path) -> Result<(), String> {
    if let Some(dir) = out.parent().filter(|d| !d.as_os_str().is_empty()) {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    image.save(out).map_err(|e| format!("{}: {e}", out.display()))?;
    println!("{}", out.display());
    Ok(())
}

/// `focal [VOLUME]` without a window (the app comes with the GPU renderer): renders
/// the default view of the volume, or of the head phantom, to `out`.
pub fn run_default(volume: Option<&Path>, out: &Path) -> Result<(), String> {
    let args = RenderArgs {
        input: volume.map(Path::to_path_buf),
        cpu: false,
        preset: None,
        mode: Mode::Dvr,
        view: View::Oblique,
        ortho: false,
        size: "512x512".into(),
        step: 0.5,
        iso: None,
        jitter: true,
        no_shading: false,
        no_skip: false,
        no_early_termination: false,
        labels: false,
        raw: None,
        resolution: 256,
        out: out.to_path_buf(),
    };
    run(&args)
}
