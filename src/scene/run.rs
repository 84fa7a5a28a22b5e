//! Rendering a scene file's frames headless, on the GPU (the default) or with the CPU
//! reference, into PNG files `<scene>-<frame>.png`.

use std::path::{Path, PathBuf};

use bevy::prelude::*;

use super::file::{FrameSpec, SceneFile};
use super::load::{LoadedDataset, apply, camera, load_datasets, read_scene, render_scene_with_windows, visible_bounds, window_appearances};
use crate::FocalPlugins;
use crate::dataset::VolumeView;
use crate::dataset::{Dataset, SceneLight};
use crate::lens::systems::replace_lenses;
use crate::reference::render_lensed;
use crate::render::headless::Offscreen;
use crate::windows::spec::{replace_markers, replace_windows};

/// How to render a scene file.
#[derive(Clone, Debug, Default)]
pub struct RunOptions {
    pub out_dir: PathBuf,
    /// Use the CPU reference renderer instead of the GPU.
    pub cpu: bool,
    /// Override the scene's image size.
    pub size: Option<(u32, u32)>,
    /// Say on stderr which frame of several is being drawn.
    pub progress: bool,
}

/// The frames to capture (one "default" frame when the file lists none).
fn frames(scene: &SceneFile) -> Vec<FrameSpec> {
    if scene.frames.is_empty() {
        vec![FrameSpec { name: "default".into(), camera: None, set: Vec::new(), settle: None }]
    } else {
        scene.frames.clone()
    }
}

/// A file-name-safe version of a frame name.
pub fn slug(name: &str) -> String {
    name.chars().map(|c| if c.is_ascii_alphanumeric() || c == '-' || c == '_' { c } else { '_' }).collect()
}

/// Renders every frame of the scene file at `path` into `options.out_dir`, and its
/// animation, if it has one, as a movie into the folder `<out_dir>/<scene>/`; returns
/// the files written. A scene with an animation and no frames writes the movie only.
pub fn render_scene_file(path: &Path, options: &RunOptions) -> Result<Vec<PathBuf>, String> {
    let scene = read_scene(path)?;
    let base = path.parent().map(Path::to_path_buf).unwrap_or_default();
    let stem = slug(&path.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into()));
    let in_file = |e: String| format!("{}: {e}", path.display());
    let mut written = Vec::new();
    if let Some(animation) = &scene.animation {
        let movie = SceneFile { frames: super::movie::animation_frames(animation, &scene, &stem), animation: None, ..scene.clone() };
        let mut writer = super::movie::MovieWriter::new(&options.out_dir.join(&stem), &stem, animation.fps)?;
        render_frames_into(movie, &base, &RunOptions { progress: true, ..options.clone() }, &mut |name, image| writer.add(&name, &image))
            .map_err(in_file)?;
        written.extend(writer.finish()?);
        if scene.frames.is_empty() {
            return Ok(written);
        }
    }
    let images = render_frames(scene, &base, options).map_err(in_file)?;
    std::fs::create_dir_all(&options.out_dir).map_err(|e| format!("{}: {e}", options.out_dir.display()))?;
    for (name, image) in images {
        let out = options.out_dir.join(format!("{stem}-{}.png", slug(&name)));
        image.save(&out).map_err(|e| format!("{}: {e}", out.display()))?;
        written.push(out);
    }
    Ok(written)
}

/// Renders every frame of `scene` (relative paths start at `base`): (frame name, image).
pub fn render_frames(scene: SceneFile, base: &Path, options: &RunOptions) -> Result<Vec<(String, image::RgbaImage)>, String> {
    let mut images = Vec::new();
    render_frames_into(scene, base, options, &mut |name, image| {
        images.push((name, image));
        Ok(())
    })?;
    Ok(images)
}

/// Renders every frame of `scene`, handing each to `sink` as soon as it is drawn (so a
/// movie never holds all its frames).
pub fn render_frames_into(
    mut scene: SceneFile,
    base: &Path,
    options: &RunOptions,
    sink: &mut dyn FnMut(String, image::RgbaImage) -> Result<(), String>,
) -> Result<(), String> {
    let mut datasets = load_datasets(&scene, base)?;
    let (w, h) = options.size.unwrap_or(scene.size);
    // Frame on what the first frame shows; a frame that sets a camera frames anew what it
    // shows, frames that only change parameters keep the framing.
    let mut bounds = visible_bounds(&datasets);
    let mut camera_spec = scene.camera.clone();
    let mut gpu = if options.cpu { None } else { Some(GpuRun::new(w, h, &datasets)?) };
    let all = frames(&scene);
    for (k, frame) in all.iter().enumerate() {
        if options.progress && all.len() > 1 {
            eprint!("\rframe {}/{}", k + 1, all.len());
        }
        for change in &frame.set {
            apply(change, &mut datasets, &mut scene, base).map_err(|e| format!("frame '{}': {e}", frame.name))?;
        }
        if let Some(c) = &frame.camera {
            camera_spec = c.clone();
            bounds = visible_bounds(&datasets);
        }
        let cam = camera(&camera_spec, bounds, w as f32 / h as f32);
        let exploded = datasets.iter().any(|d| d.explode.is_some());
        let settle = frame.settle.unwrap_or(if exploded { crate::scene::file::SETTLE_STEPS } else { 0 });
        let image = match &mut gpu {
            Some(g) => g.capture(&datasets, &scene, &cam, base, settle)?,
            None if exploded => return Err("exploded views are simulated in the app: render this scene without --cpu".into()),
            None => render_lensed(&render_scene_with_windows(&datasets, &scene, &cam, base)?, &cam, &scene.lenses, w, h)?.to_image()?,
        };
        sink(frame.name.clone(), image)?;
    }
    if options.progress && all.len() > 1 {
        eprintln!();
    }
    Ok(())
}

/// The offscreen app showing a scene's datasets.
struct GpuRun {
    off: Offscreen,
    entities: Vec<Entity>,
}

impl GpuRun {
    fn new(w: u32, h: u32, datasets: &[LoadedDataset]) -> Result<Self, String> {
        let mut off = Offscreen::new(w, h, |app| {
            app.add_plugins((FocalPlugins, crate::windows::frames::WindowFramePlugin));
        })?;
        let entities: Vec<Entity> = datasets
            .iter()
            .map(|d| {
                let mut e = off.world_mut().spawn((dataset_component(d), transform(d)));
                if let Some(b) = &d.bricked {
                    e.insert(b.clone());
                }
                e.id()
            })
            .collect();
        for (e, d) in entities.iter().zip(datasets) {
            crate::explode::spec::replace_explosion(off.world_mut(), *e, d.explode.as_ref());
        }
        // The camera is the viewer (user-attached windows, the viewing force).
        let camera = off.camera();
        off.world_mut().entity_mut(camera).insert(crate::windows::Viewer);
        Ok(GpuRun { off, entities })
    }

    fn capture(
        &mut self,
        datasets: &[LoadedDataset],
        scene: &SceneFile,
        cam: &crate::region::Camera,
        base: &Path,
        settle: u32,
    ) -> Result<image::RgbaImage, String> {
        for (e, d) in self.entities.iter().zip(datasets) {
            self.off.world_mut().entity_mut(*e).insert((dataset_component(d), transform(d)));
            // The parts stay where the last frame left them; the coefficients follow
            // the frame's changes.
            if let Some(x) = &d.explode
                && let Some(mut now) = self.off.world_mut().get_mut::<crate::explode::Exploded>(*e)
                && (now.coefficients != x.exploded.coefficients || now.viewing != x.exploded.viewing || now.fade != x.exploded.fade)
            {
                now.coefficients = x.exploded.coefficients;
                now.viewing = x.exploded.viewing;
                now.fade = x.exploded.fade;
            }
        }
        self.off.world_mut().insert_resource(SceneLight(scene.light));
        replace_lenses(self.off.world_mut(), &scene.lenses);
        let looks = window_appearances(scene, datasets, base)?;
        let camera = self.off.camera();
        let pointer = scene.pointer.map(|(x, y, z)| Vec3::new(x, y, z));
        replace_windows(self.off.world_mut(), &scene.windows, &looks, &self.entities, Some(camera), pointer);
        replace_markers(self.off.world_mut(), &scene.markers, &self.entities);
        self.off.set_view(scene.rendering.view(VolumeView::default()));
        self.off.set_background(scene.background());
        self.off.set_camera(cam);
        if settle > 0 {
            // One update first: the camera (the viewing force's eye), the explosion
            // points and the bodies are in place before the steps.
            self.off.update();
            crate::explode::step(self.off.world_mut(), settle);
        }
        self.off.capture()
    }
}

fn dataset_component(d: &LoadedDataset) -> Dataset {
    d.component()
}

fn transform(d: &LoadedDataset) -> Transform {
    Transform::from_matrix(Mat4::from(d.transform))
}
