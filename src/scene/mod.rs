//! Scene files (RON): the whole state — datasets with their files or phantoms,
//! appearances, camera, lighting — plus a list of frames to capture (camera moves and
//! parameter changes). `focal render SCENE.ron --out DIR` renders them headless
//! ([`run`]); the app opens and saves them.

pub mod animation;
pub mod camera;
pub mod file;
pub mod load;
pub mod movie;
pub mod run;
pub mod save;

pub use file::SceneFile;
pub use load::{LoadedDataset, load_datasets, read_scene};
