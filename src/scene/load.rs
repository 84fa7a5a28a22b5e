//! From a scene file to volumes, appearances and cameras.

use std::path::{Path, PathBuf};
use std::sync::Arc;

use glam::{Affine3A, EulerRot, Quat, UVec3, Vec3};

use super::file::{CameraSpec, Change, DatasetSpec, SceneFile, SourceSpec, vec3};
use crate::clip::Clipping;
use crate::dataset::Dataset;
use crate::region::{Appearance, AppearanceSpec, Camera, Lookup, Orbit, Projection, RenderScene, Segmentation, SegmentationSpec, View};
use crate::streaming::bricked::{BrickedDataset, StreamBudget};
use crate::transfer::presets;
use crate::twolevel::spec::LabelSource;
use crate::volume::phantom::head;
use crate::volume::readers::{Progress, RawSpec, ReadOptions, label_table, read_volume};
use crate::volume::source::VoxelSource;
use crate::volume::source::level::{WHOLE_LEVEL_BYTES, load_finest_within};
use crate::volume::source::procedural::ProceduralSource;
use crate::volume::{LabelTable, LabelVolume, Volume};

/// A dataset of a scene, loaded.
#[derive(Clone, Debug)]
pub struct LoadedDataset {
    pub name: String,
    pub volume: Arc<Volume>,
    pub appearance: Appearance,
    /// Labels table when shown as a label volume.
    pub table: Option<LabelTable>,
    pub transform: Affine3A,
    pub visible: bool,
    pub clip: Clipping,
    pub spec: DatasetSpec,
    /// Its exploded view, loaded.
    pub explode: Option<crate::explode::spec::LoadedExplode>,
    /// Streamed brick by brick from a pyramid (its `volume` is the coarse level).
    pub bricked: Option<BrickedDataset>,
}

impl LoadedDataset {
    /// The dataset entity's component.
    pub fn component(&self) -> Dataset {
        Dataset {
            volume: self.volume.clone(),
            appearance: self.appearance.clone(),
            visible: self.visible,
            labels: self.table.clone().map(Arc::new),
            clip: self.clip.clone(),
        }
    }
}

/// A path of the scene file resolved against the scene's folder.
pub fn resolve(base: &Path, p: &Path) -> PathBuf {
    if p.is_absolute() || crate::volume::readers::ome_zarr::is_url(p) { p.to_path_buf() } else { base.join(p) }
}

/// Reads a scene file.
pub fn read_scene(path: &Path) -> Result<SceneFile, String> {
    let text = std::fs::read_to_string(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let scene = SceneFile::parse(&text, &path.display().to_string())?;
    scene.validate().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(scene)
}

/// Loads every dataset of `scene`; relative paths start at `base`.
pub fn load_datasets(scene: &SceneFile, base: &Path) -> Result<Vec<LoadedDataset>, String> {
    load_datasets_with(scene, base, None)
}

/// Like [`load_datasets`], reporting the bytes read to `progress`.
pub fn load_datasets_with(scene: &SceneFile, base: &Path, progress: Option<Progress>) -> Result<Vec<LoadedDataset>, String> {
    let options = ReadOptions { progress, ..Default::default() };
    let mut datasets: Vec<LoadedDataset> = scene
        .datasets
        .iter()
        .enumerate()
        .map(|(i, d)| load_dataset(d, base, &options).map_err(|e| format!("dataset {i}: {e}")))
        .collect::<Result<_, _>>()?;
    // Segmentations and exploded views refer to other datasets: resolved once all are
    // loaded.
    for i in 0..datasets.len() {
        if let Some(spec) = &scene.datasets[i].appearance.segmentation {
            let seg = segmentation(spec, &datasets, &datasets[i].volume, base).map_err(|e| format!("dataset {i}: segmentation: {e}"))?;
            datasets[i].appearance.segmentation = Some(seg);
        }
        if let Some(spec) = &scene.datasets[i].explode {
            let x = explosion(spec, &datasets, i, base).map_err(|e| format!("dataset {i}: explode: {e}"))?;
            datasets[i].explode = Some(x);
        }
    }
    Ok(datasets)
}

/// The exploded view a spec describes for dataset `i`.
pub fn explosion(
    spec: &crate::explode::spec::ExplodeSpec,
    datasets: &[LoadedDataset],
    i: usize,
    base: &Path,
) -> Result<crate::explode::spec::LoadedExplode, String> {
    let data = &datasets[i].volume;
    let label = |d: usize| {
        let ds = datasets.get(d)?;
        Some(LabelVolume { volume: (*ds.volume).clone(), table: ds.table.clone()? })
    };
    let selection = spec.selection(data, label)?;
    let look = spec.look.as_ref().map(|l| l.appearance(data, None, base)).transpose().map_err(|e| format!("look: {e}"))?;
    Ok(crate::explode::spec::LoadedExplode { exploded: spec.exploded(selection, look), parts: spec.parts(data)?, spec: spec.clone() })
}

/// The segmentation a spec describes for data volume `data`: its label volume is the
/// scene's dataset `spec.labels`.
pub fn segmentation(spec: &SegmentationSpec, datasets: &[LoadedDataset], data: &Volume, base: &Path) -> Result<Segmentation, String> {
    let n = datasets.len();
    let source = datasets.get(spec.labels).ok_or_else(|| format!("labels refers to dataset {}, the scene has {n}", spec.labels))?;
    let labels = LabelSource { name: &source.name, volume: &source.volume, table: source.table.as_ref() };
    crate::twolevel::spec::segmentation(spec, labels, data, base)
}

/// A pyramid opened for streaming (its coarse level read), or `None` where one whole
/// level serves (the reason is logged).
fn open_bricked(source: Arc<dyn VoxelSource>) -> Result<Option<(BrickedDataset, Volume)>, String> {
    match BrickedDataset::open(source, StreamBudget::default().cpu_bytes)? {
        Ok(opened) => Ok(Some(opened)),
        Err(why) => {
            bevy::log::warn!("{why}");
            Ok(None)
        }
    }
}

fn load_dataset(spec: &DatasetSpec, base: &Path, options: &ReadOptions) -> Result<LoadedDataset, String> {
    let (volume, sidecar_from, bricked) = match &spec.source {
        SourceSpec::Phantom { kind, resolution } => (kind.generate(*resolution)?, None, None),
        SourceSpec::PhantomLabels { resolution } => {
            let h = head::generate(*resolution)?;
            let table = h.labels.table.clone();
            let app = spec.appearance.appearance(&h.labels.volume, Some(&table), base)?;
            return dataset(spec, h.labels.volume, app, Some(table));
        }
        SourceSpec::File(p) if crate::volume::readers::ome_zarr::is_zarr(&resolve(base, p)) => {
            let p = resolve(base, p);
            let source = crate::volume::readers::ome_zarr::open(&p).map_err(|e| e.to_string())?;
            for w in &source.info().warnings {
                bevy::log::warn!("{}: {w}", p.display());
            }
            let source: Arc<dyn VoxelSource> = Arc::new(source);
            match open_bricked(source.clone())? {
                Some((b, coarse)) => (coarse, Some(p), Some(b)),
                None => {
                    (crate::volume::readers::ome_zarr::read_source(source.as_ref(), &p, options).map_err(|e| e.to_string())?, Some(p), None)
                }
            }
        }
        SourceSpec::File(p) => {
            let p = resolve(base, p);
            (read_volume(&p, options).map_err(|e| e.to_string())?, Some(p), None)
        }
        SourceSpec::Raw { path, layout } => {
            let raw: RawSpec = layout.parse()?;
            let p = resolve(base, path);
            (read_volume(&p, &ReadOptions { raw: Some(raw), ..options.clone() }).map_err(|e| e.to_string())?, Some(p), None)
        }
        SourceSpec::Procedural { dims, spacing_mm } => {
            let source: Arc<dyn VoxelSource> =
                Arc::new(ProceduralSource::new(UVec3::new(dims.0, dims.1, dims.2), Vec3::splat(*spacing_mm))?);
            match open_bricked(source.clone())? {
                Some((b, coarse)) => (coarse, None, Some(b)),
                None => (
                    load_finest_within(source.as_ref(), WHOLE_LEVEL_BYTES.min(options.max_bytes), &|_| {}).map_err(|e| e.to_string())?,
                    None,
                    None,
                ),
            }
        }
    };
    let mut d = labelled(spec, base, volume, sidecar_from)?;
    d.bricked = bricked;
    Ok(d)
}

/// The dataset of a spec's volume: as labels where the spec says so, or where the file
/// carries its own label table (a DICOM segmentation). The table: the spec's, else the
/// sidecar files', else the file's own, else generated colours.
fn labelled(spec: &DatasetSpec, base: &Path, mut volume: Volume, sidecar_from: Option<PathBuf>) -> Result<LoadedDataset, String> {
    let carried = volume.label_table.take();
    let shown_as = match (&spec.appearance.labels, &carried) {
        (Some(labels), _) => Some(labels.clone()),
        (None, Some(_)) => Some(Default::default()),
        (None, None) => None,
    };
    match shown_as {
        Some(labels) => {
            let sidecars = match (&labels.table, &sidecar_from) {
                (Some(t), _) => Some(label_table::read(&resolve(base, t)).map_err(|e| e.to_string())?),
                (None, Some(p)) => Some(label_table::read_sidecars(p).map_err(|e| e.to_string())?).filter(|t| !t.is_empty()),
                (None, None) => None,
            };
            let table = sidecars.or(carried).unwrap_or_default();
            let lv = LabelVolume::from_volume(volume, table)?;
            let spec = DatasetSpec { appearance: AppearanceSpec { labels: Some(labels), ..spec.appearance.clone() }, ..spec.clone() };
            let app = spec.appearance.appearance(&lv.volume, Some(&lv.table), base)?;
            dataset(&spec, lv.volume, app, Some(lv.table))
        }
        None => {
            let app = spec.appearance.appearance(&volume, None, base)?;
            dataset(spec, volume, app, None)
        }
    }
}

fn dataset(spec: &DatasetSpec, volume: Volume, appearance: Appearance, table: Option<LabelTable>) -> Result<LoadedDataset, String> {
    let (rx, ry, rz) = spec.rotation_deg;
    let rotation = Quat::from_euler(EulerRot::XYZ, rx.to_radians(), ry.to_radians(), rz.to_radians());
    Ok(LoadedDataset {
        name: spec.name.clone().unwrap_or_else(|| volume.name.clone()),
        volume: Arc::new(volume),
        appearance,
        table,
        transform: Affine3A::from_rotation_translation(rotation, vec3(spec.translation)),
        visible: spec.visible,
        clip: spec.clip.clone().validated()?,
        spec: spec.clone(),
        explode: None,
        bricked: None,
    })
}

/// World bounds of what the visible datasets show (union; their boxes if nothing shows).
pub fn visible_bounds(datasets: &[LoadedDataset]) -> (Vec3, Vec3) {
    let mut out: Option<(Vec3, Vec3)> = None;
    for d in datasets.iter().filter(|d| d.visible) {
        let Some((lo, hi)) = d.appearance.visible_bounds(&d.volume).or_else(|| Some(d.volume.grid.world_bounds())) else { continue };
        let corners = (0..8).map(|c| {
            d.transform.transform_point3(Vec3::new(
                if c & 1 == 0 { lo.x } else { hi.x },
                if c & 2 == 0 { lo.y } else { hi.y },
                if c & 4 == 0 { lo.z } else { hi.z },
            ))
        });
        for c in corners {
            out = Some(match out {
                None => (c, c),
                Some((a, b)) => (a.min(c), b.max(c)),
            });
        }
    }
    out.unwrap_or((Vec3::splat(-100.0), Vec3::splat(100.0)))
}

/// The camera a spec describes, framing `bounds` in a view of `aspect`.
pub fn camera(spec: &CameraSpec, bounds: (Vec3, Vec3), aspect: f32) -> Camera {
    let (lo, hi) = bounds;
    let zoomed = |mut cam: Camera, zoom: f32| {
        let target = (lo + hi) * 0.5;
        let zoom = zoom.max(1e-3);
        match &mut cam.projection {
            Projection::Orthographic { height } => *height /= zoom,
            Projection::Perspective { .. } => cam.position = target + (cam.position - target) / zoom,
        }
        cam
    };
    match *spec {
        CameraSpec::View { view, orthographic, zoom } => zoomed(view.frame_box(lo, hi, aspect, orthographic), zoom),
        CameraSpec::Orbit { azimuth_deg, elevation_deg, orthographic, zoom } => {
            // Frame with the standard machinery, then turn to the requested angles.
            let framed = View::Anterior.frame_box(lo, hi, aspect, orthographic);
            let target = (lo + hi) * 0.5;
            let distance = (framed.position - target).length().max((hi - lo).length());
            let orbit = Orbit { target, azimuth_deg, elevation_deg, distance, projection: framed.projection };
            zoomed(orbit.camera(), zoom)
        }
        CameraSpec::LookAt { eye, target, up, orthographic_height, fov_deg } => {
            let projection = match orthographic_height {
                Some(height) => Projection::Orthographic { height },
                None => Projection::Perspective { fov_y: fov_deg.to_radians() },
            };
            Camera::look_at(vec3(eye), vec3(target), vec3(up), projection)
        }
    }
}

/// Applies a between-frames change to the datasets (and the scene settings).
pub fn apply(change: &Change, datasets: &mut [LoadedDataset], scene: &mut SceneFile, base: &Path) -> Result<(), String> {
    let n = datasets.len();
    let get = |i: usize| if i < n { Ok(i) } else { Err(format!("change refers to dataset {i}, the scene has {n}")) };
    match change {
        Change::Mode { dataset, mode } => datasets[get(*dataset)?].appearance.mode = *mode,
        Change::Preset { dataset, preset } => {
            datasets[get(*dataset)?].appearance.lookup = Lookup::Transfer(presets::load_relative(preset, base)?)
        }
        Change::Transfer { dataset, transfer } => {
            datasets[get(*dataset)?].appearance.lookup = Lookup::Transfer(transfer.clone().validated()?)
        }
        Change::Step { dataset, step } => datasets[get(*dataset)?].appearance.step = *step,
        Change::Iso { dataset, value } => datasets[get(*dataset)?].appearance.iso_value = *value,
        Change::ProjectionRange { dataset, range } => {
            if let Some(r) = range {
                crate::region::appearance_spec::check_projection_range(*r)?;
            }
            datasets[get(*dataset)?].appearance.projection_range = *range;
        }
        Change::Shading { dataset, enabled } => datasets[get(*dataset)?].appearance.shading.enabled = *enabled,
        Change::Context { dataset, context } => datasets[get(*dataset)?].appearance.context = context.validated()?,
        Change::Clip { dataset, clip } => datasets[get(*dataset)?].clip = clip.clone().validated()?,
        Change::Visible { dataset, visible } => datasets[get(*dataset)?].visible = *visible,
        Change::LabelOpacity { dataset, label, opacity } => match &mut datasets[get(*dataset)?].appearance.lookup {
            Lookup::Labels(styles) => {
                if let Some(s) = styles.styles.get_mut(label) {
                    s.opacity = *opacity;
                }
            }
            Lookup::Transfer(_) => return Err(format!("dataset {dataset} is not shown as labels")),
        },
        Change::Object { dataset, object, mode, visible } => {
            let seg =
                datasets[get(*dataset)?].appearance.segmentation.as_mut().ok_or_else(|| format!("dataset {dataset} is not segmented"))?;
            let count = seg.objects.len();
            let o =
                seg.objects.get_mut(*object).ok_or_else(|| format!("change refers to object {object}, dataset {dataset} has {count}"))?;
            if let Some(m) = mode {
                o.appearance.mode = *m;
            }
            if let Some(v) = visible {
                o.visible = *v;
            }
        }
        Change::Background(c) => scene.background = *c,
        Change::Light(l) => scene.light = *l,
        Change::Lenses(l) => scene.lenses = l.clone(),
        Change::Windows(w) => scene.windows = w.clone(),
        Change::Pointer(p) => scene.pointer = *p,
        Change::Rendering(r) => scene.rendering = *r,
        Change::Explode { dataset, degree, viewing, deltas, fade } => {
            let x = datasets[get(*dataset)?].explode.as_mut().ok_or_else(|| format!("Explode: dataset {dataset} is not exploded"))?;
            let c = &mut x.exploded.coefficients;
            if let Some(d) = degree {
                c.degree = *d;
            }
            if let Some((e, v, s)) = deltas {
                (c.delta_explosion, c.delta_viewing, c.delta_spacing) = (*e, *v, *s);
            }
            if let Some(v) = viewing {
                x.exploded.viewing = *v;
            }
            if let Some(f) = fade {
                x.exploded.fade = *f;
            }
        }
    }
    Ok(())
}

/// The datasets as a scene the CPU reference renders (one region per visible dataset).
pub fn render_scene(datasets: &[LoadedDataset], scene: &SceneFile) -> RenderScene {
    let mut out = RenderScene {
        background: scene.background(),
        light: scene.light,
        jitter: scene.rendering.jitter,
        skip_empty: scene.rendering.skip_empty,
        lens_antialias: scene.rendering.lens_antialias,
        ..Default::default()
    };
    for d in datasets.iter().filter(|d| d.visible) {
        let i = out.volumes.len();
        out.regions.push(d.clip.region(&d.volume.grid, d.transform, i));
        out.volumes.push(d.volume.clone());
        out.appearances.push(d.appearance.clone());
    }
    out
}

/// Each window content's appearance (`None`: the dataset's own).
pub fn window_appearances(scene: &SceneFile, datasets: &[LoadedDataset], base: &Path) -> Result<Vec<Vec<Option<Appearance>>>, String> {
    scene
        .windows
        .iter()
        .enumerate()
        .map(|(i, w)| {
            w.contents
                .iter()
                .map(|c| {
                    let d = datasets.get(c.dataset).ok_or_else(|| format!("window {i}: content refers to dataset {}", c.dataset))?;
                    c.appearance
                        .as_ref()
                        .map(|a| a.appearance(&d.volume, d.table.as_ref(), base).map_err(|e| format!("window {i}: {e}")))
                        .transpose()
                })
                .collect()
        })
        .collect()
}

/// [`render_scene`] with the scene's windows seen from `camera` (the CPU reference's
/// scene; the app builds the same regions from window entities).
pub fn render_scene_with_windows(
    datasets: &[LoadedDataset],
    scene: &SceneFile,
    camera: &Camera,
    base: &Path,
) -> Result<RenderScene, String> {
    use crate::windows::regions::{PlacedContent, add_windows};
    use crate::windows::spec::{placed, placed_boxes};
    let mut out = render_scene(datasets, scene);
    if scene.windows.is_empty() {
        return Ok(out);
    }
    let dataset_regions = out.regions.len();
    // Volume index of each dataset (hidden ones are added when a window shows them).
    let mut index: Vec<Option<usize>> = Vec::with_capacity(datasets.len());
    let mut next = 0;
    for d in datasets {
        index.push(d.visible.then(|| {
            next += 1;
            next - 1
        }));
    }
    let looks = window_appearances(scene, datasets, base)?;
    let view = crate::render::headless::camera_bundle(camera).0.compute_affine();
    let transforms: Vec<Affine3A> = datasets.iter().map(|d| d.transform).collect();
    let boxes = placed_boxes(&scene.windows, view, &transforms, scene.pointer.map(vec3));
    let mut windows = Vec::new();
    for ((w, b), looks) in scene.windows.iter().zip(boxes).zip(&looks) {
        let Some(b) = b else { continue };
        let mut contents = Vec::new();
        for (c, look) in w.contents.iter().zip(looks) {
            let d = &datasets[c.dataset];
            let volume_index = *index[c.dataset].get_or_insert_with(|| {
                out.volumes.push(d.volume.clone());
                out.volumes.len() - 1
            });
            let appearance = look.clone().unwrap_or_else(|| d.appearance.clone());
            contents.push(PlacedContent { volume: d.volume.clone(), volume_index, dataset_to_world: d.transform, appearance });
        }
        windows.push(placed(w, b, contents));
    }
    add_windows(&mut out, dataset_regions, &windows);
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn phantom_scene_loads_and_frames() {
        let s = SceneFile::parse("(datasets: [(source: Phantom(kind: sphere, resolution: 24)), (source: PhantomLabels(resolution: 32), appearance: (labels: Some(())))])", "t").unwrap();
        let d = load_datasets(&s, Path::new(".")).unwrap();
        assert_eq!(d.len(), 2);
        assert!(matches!(d[1].appearance.lookup, Lookup::Labels(_)));
        let cam = camera(&s.camera, visible_bounds(&d), 1.0);
        assert!(cam.position.length() > 10.0);
        let mut s2 = s.clone();
        let mut d2 = d.clone();
        apply(&Change::Mode { dataset: 0, mode: crate::region::Mode::Mip }, &mut d2, &mut s2, Path::new(".")).unwrap();
        assert_eq!(d2[0].appearance.mode, crate::region::Mode::Mip);
        assert!(apply(&Change::Visible { dataset: 5, visible: false }, &mut d2, &mut s2, Path::new(".")).is_err());
        assert_eq!(render_scene(&d2, &s2).regions.len(), 2);
    }

    #[test]
    fn clipping_comes_from_the_scene_and_its_frames() {
        let text = "(datasets: [(source: Phantom(kind: sphere, resolution: 24), translation: (5.0, 0.0, 0.0),
            clip: (planes: [(point: (0.0, 0.0, 0.0), normal: (1.0, 0.0, 0.0))], box: Some((min: (-5.0, -5.0, -5.0), max: (5.0, 5.0, 5.0)))))])";
        let s = SceneFile::parse(text, "t").unwrap();
        let mut d = load_datasets(&s, Path::new(".")).unwrap();
        // The box's 6 planes, the clip plane and its 6 box faces.
        let region = &render_scene(&d, &s).regions[0];
        assert_eq!(region.planes.len(), 6 + 1 + 6);
        // In the dataset's frame x ≤ 0 is kept; the dataset sits at x + 5 in the world.
        assert!(region.contains(Vec3::new(4.0, 0.0, 0.0)) && !region.contains(Vec3::new(6.0, 0.0, 0.0)));
        let mut s2 = s.clone();
        apply(&Change::Clip { dataset: 0, clip: Clipping::default() }, &mut d, &mut s2, Path::new(".")).unwrap();
        assert_eq!(render_scene(&d, &s2).regions[0].planes.len(), 6);
        // A clip that cuts nothing sensibly is an error naming the dataset.
        let bad = SceneFile::parse("(datasets: [(source: Phantom(kind: sphere, resolution: 24), clip: (planes: [(point: (0.0, 0.0, 0.0), normal: (0.0, 0.0, 0.0))]))])", "t").unwrap();
        let e = load_datasets(&bad, Path::new(".")).unwrap_err();
        assert!(e.contains("dataset 0") && e.contains("clip plane 0"), "{e}");
        // Saved and read back.
        let round = SceneFile::parse(&s.to_ron().unwrap(), "again").unwrap();
        assert_eq!(round.datasets[0].clip, s.datasets[0].clip);
    }

    #[test]
    fn a_projection_range_comes_from_the_scene_and_its_frames() {
        let text = "(datasets: [(source: Phantom(kind: engine, resolution: 24), appearance: (mode: minip, projection_range: Some((80.0, 255.0))))])";
        let s = SceneFile::parse(text, "t").unwrap();
        let mut d = load_datasets(&s, Path::new(".")).unwrap();
        assert_eq!(d[0].appearance.projection_range, Some((80.0, 255.0)));
        let mut s2 = s.clone();
        apply(&Change::ProjectionRange { dataset: 0, range: None }, &mut d, &mut s2, Path::new(".")).unwrap();
        assert_eq!(d[0].appearance.projection_range, None);
        // Low above high, or not finite, is refused with the field named.
        let e = apply(&Change::ProjectionRange { dataset: 0, range: Some((5.0, 1.0)) }, &mut d, &mut s2, Path::new(".")).unwrap_err();
        assert!(e.contains("projection_range"), "{e}");
        let bad = SceneFile::parse(&text.replace("(80.0, 255.0)", "(80.0, inf)"), "t").unwrap();
        let e = load_datasets(&bad, Path::new(".")).unwrap_err();
        assert!(e.contains("projection_range") && e.contains("dataset 0"), "{e}");
    }

    #[test]
    fn missing_files_name_the_dataset_and_the_file() {
        let s = SceneFile::parse(r#"(datasets: [(source: File("nope.nii.gz"))])"#, "t").unwrap();
        let e = load_datasets(&s, Path::new("/tmp")).unwrap_err();
        assert!(e.contains("dataset 0") && e.contains("nope.nii.gz"), "{e}");
    }
}
