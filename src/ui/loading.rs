//! Loading files and scenes in the background.
//!
//! A load runs on the async compute pool and reports bytes read through a
//! [`Progress`]; the app shows a progress bar meanwhile. When it succeeds the current
//! datasets are replaced; when it fails the error is kept for the app to show and the
//! current data stays. A scene brings its lenses (replacing the current ones); a data
//! file keeps them. Works without a window (see `tests/app.rs`).

use std::path::{Path, PathBuf};

use bevy::prelude::*;
use bevy::tasks::{AsyncComputeTaskPool, Task, futures::check_ready};

use crate::dataset::{Dataset, SceneLight};
use crate::lens::Lens;
use crate::lens::systems::LensOrder;
use crate::region::AppearanceSpec;
use crate::scene::file::{DatasetSpec, SceneFile, SourceSpec};
use crate::scene::load::{LoadedDataset, load_datasets_with, read_scene, visible_bounds};
use crate::volume::readers::Progress;

/// What the app is showing: where it came from and what went wrong last.
#[derive(Resource, Default)]
pub struct Session {
    /// The scene as loaded (datasets' origins, camera), for saving.
    pub scene: Option<SceneFile>,
    /// Folder relative paths of the scene are resolved against.
    pub base: PathBuf,
    /// The last load error, shown until dismissed.
    pub error: Option<String>,
    /// Set when new data arrived: the camera should frame it.
    pub reframe: Option<Reframe>,
    /// The file, folder or scene a load just opened (for the recent files).
    pub opened: Option<PathBuf>,
}

/// How to place the camera on new data: the visible bounds, and a scene file's own
/// camera (a plain data file gets a standard oblique view).
#[derive(Clone, Debug, PartialEq)]
pub struct Reframe {
    pub bounds: (Vec3, Vec3),
    pub camera: Option<crate::scene::file::CameraSpec>,
}

/// What a finished load brings: the scene, the folder of its relative paths, the
/// datasets, and whether it is a scene of its own (its lenses replace the current ones;
/// a plain data file keeps them).
type Loaded = (SceneFile, PathBuf, Vec<LoadedDataset>, bool);

/// A load under way.
#[derive(Component)]
pub struct Loading {
    pub what: String,
    /// The file, folder or scene being opened (none for a scene made in the app).
    pub path: Option<PathBuf>,
    pub progress: Progress,
    task: Task<Result<Loaded, String>>,
}

/// A dataset entity made from a scene file: remembers its spec for saving.
#[derive(Component, Clone)]
pub struct DatasetOrigin(pub DatasetSpec);

/// Ask the app to load a file, a DICOM folder, a scene file, or the default scene.
#[derive(Message, Clone, Debug)]
pub enum LoadRequest {
    Path(PathBuf),
    /// A scene (boxed: a message is moved around by value) and its folder.
    Scene(Box<SceneFile>, PathBuf),
}

/// A scene showing one data file with its default look (labels shown as labels when a
/// label table lies beside it).
pub fn scene_for_file(path: &Path) -> SceneFile {
    let labels = crate::volume::readers::label_table::read_sidecars(path).map(|t| !t.is_empty()).unwrap_or(false);
    let mut scene = SceneFile::parse("()", "empty").unwrap_or_else(|_| unreachable!("an empty scene parses"));
    scene.datasets.push(DatasetSpec::of(
        SourceSpec::File(path.to_path_buf()),
        AppearanceSpec { labels: labels.then(Default::default), ..Default::default() },
    ));
    scene
}

/// Starts loads on the compute pool.
pub fn start_loads(mut commands: Commands, mut requests: MessageReader<LoadRequest>) {
    for request in requests.read() {
        let progress = Progress::default();
        let p = progress.clone();
        let path = match request {
            LoadRequest::Path(p) => Some(p.clone()),
            LoadRequest::Scene(..) => None,
        };
        let (what, job): (String, Box<dyn FnOnce() -> Result<Loaded, String> + Send>) = match request.clone() {
            LoadRequest::Path(path) => (
                path.display().to_string(),
                Box::new(move || {
                    let is_scene = path.extension().is_some_and(|e| e == "ron");
                    let (scene, base) = if is_scene {
                        (read_scene(&path)?, path.parent().map(Path::to_path_buf).unwrap_or_default())
                    } else {
                        (scene_for_file(&path), PathBuf::new())
                    };
                    let datasets = load_datasets_with(&scene, &base, Some(p))?;
                    Ok((scene, base, datasets, is_scene))
                }),
            ),
            LoadRequest::Scene(scene, base) => (
                "scene".to_string(),
                Box::new(move || {
                    let datasets = load_datasets_with(&scene, &base, Some(p))?;
                    Ok((*scene, base, datasets, true))
                }),
            ),
        };
        let task = AsyncComputeTaskPool::get().spawn(async move { job() });
        commands.spawn(Loading { what, path, progress, task });
    }
}

/// Replaces the datasets when a load finishes, or records its error.
pub fn finish_loads(
    mut commands: Commands,
    mut loads: Query<(Entity, &mut Loading)>,
    old: Query<Entity, With<Dataset>>,
    old_lenses: Query<Entity, With<Lens>>,
    old_parts: Query<Entity, With<crate::explode::Part>>,
    mut session: ResMut<Session>,
    // (The light and the view's switches a scene brings; the headless app has no view.)
    (mut light, mut state): (ResMut<SceneLight>, Option<ResMut<super::state::AppState>>),
) {
    for (entity, mut load) in &mut loads {
        let Some(result) = check_ready(&mut load.task) else { continue };
        commands.entity(entity).despawn();
        match result {
            Ok((scene, base, datasets, is_scene)) => {
                for e in old.iter().chain(&old_parts) {
                    commands.entity(e).despawn();
                }
                if is_scene {
                    for e in &old_lenses {
                        commands.entity(e).despawn();
                    }
                    for (i, lens) in scene.lenses.iter().enumerate() {
                        commands.spawn((lens.clone(), LensOrder(i as u32), Name::new(format!("lens {}", lens.kind_name()))));
                    }
                }
                let entities: Vec<Entity> = datasets
                    .iter()
                    .map(|d| {
                        let mut e = commands.spawn((
                            d.component(),
                            Transform::from_matrix(Mat4::from(d.transform)),
                            DatasetOrigin(d.spec.clone()),
                            Name::new(d.name.clone()),
                        ));
                        if let Some(b) = &d.bricked {
                            e.insert(b.clone());
                        }
                        e.id()
                    })
                    .collect();
                // Exploded datasets get their parts and joints, at rest.
                let explosions: Vec<_> = datasets.iter().zip(&entities).filter_map(|(d, e)| Some((*e, d.explode.clone()?))).collect();
                if !explosions.is_empty() {
                    commands.queue(move |world: &mut World| {
                        for (e, x) in &explosions {
                            crate::explode::spec::replace_explosion(world, *e, Some(x));
                        }
                    });
                }
                let mut window_error = None;
                if is_scene {
                    // A scene's windows replace the current ones.
                    match crate::scene::load::window_appearances(&scene, &datasets, &base) {
                        Ok(looks) => {
                            let (windows, pointer) = (scene.windows.clone(), scene.pointer.map(|(x, y, z)| Vec3::new(x, y, z)));
                            let (markers, rulers) = (scene.markers.clone(), scene.rulers.clone());
                            commands.queue(move |world: &mut World| {
                                crate::windows::spec::replace_windows(world, &windows, &looks, &entities, None, pointer);
                                crate::windows::spec::replace_markers(world, &markers, &entities);
                                crate::slices::ruler::replace_rulers(world, &rulers, &entities);
                            });
                        }
                        Err(e) => window_error = Some(format!("{}: {e}", load.what)),
                    }
                }
                light.0 = scene.light;
                if let Some(state) = state.as_mut().filter(|_| is_scene) {
                    state.view = scene.rendering.view(state.view);
                }
                session.reframe = Some(Reframe { bounds: visible_bounds(&datasets), camera: is_scene.then(|| scene.camera.clone()) });
                session.scene = Some(scene);
                session.base = base;
                session.error = window_error;
                session.opened = load.path.clone();
            }
            Err(e) => {
                error!("{}: {e}", load.what);
                session.error = Some(format!("Could not open {}: {e}", load.what));
            }
        }
    }
}

/// Loading without a window: the messages and the systems.
pub struct LoadingPlugin;

impl Plugin for LoadingPlugin {
    fn build(&self, app: &mut App) {
        app.init_resource::<Session>().add_message::<LoadRequest>().add_systems(Update, (start_loads, finish_loads).chain());
    }
}
