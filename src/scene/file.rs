//! The scene file format (RON). Unknown fields are errors, so a typo is reported with
//! its line and column instead of being ignored.
//!
//! ```ron
//! (
//!     size: (512, 512),
//!     background: (0.0, 0.0, 0.0),
//!     datasets: [
//!         (source: Phantom(kind: head, resolution: 256), appearance: (mode: dvr, preset: "ct_skin_bone")),
//!         (source: File("../../shared/data/labels/aal.nii.gz"), appearance: (labels: Some((opacity: 0.3)))),
//!     ],
//!     camera: View(view: oblique),
//!     frames: [
//!         (name: "front", camera: Some(View(view: anterior))),
//!         (name: "bone", set: [Preset(dataset: 0, preset: "ct_bone")]),
//!     ],
//! )
//! ```
//! Paths are relative to the scene file.

use std::path::PathBuf;

use glam::Vec3;
use serde::{Deserialize, Serialize};

pub use super::camera::CameraSpec;
pub use crate::lens::stack::validate_lenses;

use crate::clip::Clipping;
use crate::context::ContextParams;

use crate::region::{AppearanceSpec, Light, Mode};
use crate::transfer::TransferFunction;
use crate::volume::phantom::Phantom;

fn default_size() -> (u32, u32) {
    (512, 512)
}

fn default_resolution() -> u32 {
    256
}

fn yes() -> bool {
    true
}

/// A whole scene: data, appearance, camera and the frames to capture.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct SceneFile {
    /// Image size of headless renders (width, height).
    #[serde(default = "default_size")]
    pub size: (u32, u32),
    /// Background colour (display sRGB).
    #[serde(default)]
    pub background: (f32, f32, f32),
    #[serde(default)]
    pub light: Light,
    #[serde(default)]
    pub rendering: RenderingSpec,
    #[serde(default)]
    pub datasets: Vec<DatasetSpec>,
    #[serde(default)]
    pub camera: CameraSpec,
    /// Magic lenses on the view, in order (the last on top).
    #[serde(default)]
    pub lenses: Vec<crate::lens::Lens>,
    /// Volumetric windows.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub windows: Vec<crate::windows::spec::WindowSpec>,
    /// The 3D pointer's position (world mm), for windows whose source follows it.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub pointer: Option<(f32, f32, f32)>,
    /// Interpretive markers (shown in every view of their point).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub markers: Vec<crate::windows::spec::MarkerSpec>,
    /// Distance rulers (placed in the slice views).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub rulers: Vec<crate::slices::ruler::RulerSpec>,
    /// Frames to capture; none means one frame of the scene as it is.
    #[serde(default)]
    pub frames: Vec<FrameSpec>,
    /// Keyframed tracks rendered as a movie (see [`super::animation`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub animation: Option<super::animation::Animation>,
}

/// Ray-caster switches.
#[derive(Clone, Copy, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RenderingSpec {
    #[serde(default = "yes")]
    pub jitter: bool,
    #[serde(default = "yes")]
    pub skip_empty: bool,
    #[serde(default = "yes")]
    pub early_termination: bool,
    /// Under lenses, sample compressed areas from the volume's mip chain (eq. 4).
    #[serde(default = "yes")]
    pub lens_antialias: bool,
    /// Bricked data under lenses steps along the ray at the context's rate
    /// (`VolumeView::lens_context_steps`: faster, thin structures may be missed).
    #[serde(default)]
    pub lens_context_steps: bool,
}

impl Default for RenderingSpec {
    fn default() -> Self {
        Self { jitter: true, skip_empty: true, early_termination: true, lens_antialias: true, lens_context_steps: false }
    }
}

impl RenderingSpec {
    /// The switches of a view (what a saved scene keeps of it).
    pub fn of(view: &crate::dataset::VolumeView) -> Self {
        Self {
            jitter: view.jitter,
            skip_empty: view.skip_empty,
            early_termination: view.early_termination,
            lens_antialias: view.lens_antialias,
            lens_context_steps: view.lens_context_steps,
        }
    }

    /// `view` with these switches.
    pub fn view(&self, view: crate::dataset::VolumeView) -> crate::dataset::VolumeView {
        crate::dataset::VolumeView {
            jitter: self.jitter,
            skip_empty: self.skip_empty,
            early_termination: self.early_termination,
            lens_antialias: self.lens_antialias,
            lens_context_steps: self.lens_context_steps,
            ..view
        }
    }
}

/// Where a dataset's voxels come from.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum SourceSpec {
    /// A built-in phantom.
    Phantom {
        kind: Phantom,
        #[serde(default = "default_resolution")]
        resolution: u32,
    },
    /// The label volume of the head phantom.
    PhantomLabels {
        #[serde(default = "default_resolution")]
        resolution: u32,
    },
    /// A volume file or DICOM folder.
    File(PathBuf),
    /// A headless raw file with its layout (`DIMS:TYPE[:le|be][:s=SPACING][:skip=N]`).
    Raw { path: PathBuf, layout: String },
    /// The procedural gyroid ball of any size (voxels along x, y, z), for tests and
    /// benchmarks at scale.
    Procedural {
        dims: (u32, u32, u32),
        #[serde(default = "default_procedural_spacing")]
        spacing_mm: f32,
    },
}

fn default_procedural_spacing() -> f32 {
    crate::volume::source::procedural::DEFAULT_SPACING_MM
}

/// A dataset in the scene.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct DatasetSpec {
    #[serde(default)]
    pub name: Option<String>,
    pub source: SourceSpec,
    #[serde(default)]
    pub appearance: AppearanceSpec,
    /// Placement: translation in millimetres and rotation (XYZ Euler angles, degrees).
    #[serde(default)]
    pub translation: (f32, f32, f32),
    #[serde(default)]
    pub rotation_deg: (f32, f32, f32),
    #[serde(default = "yes")]
    pub visible: bool,
    /// Clip planes and box, in the dataset's frame (mm).
    #[serde(default, skip_serializing_if = "is_unclipped")]
    pub clip: Clipping,
    /// An exploded view of this dataset ([`crate::explode::spec`]).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub explode: Option<crate::explode::spec::ExplodeSpec>,
}

impl DatasetSpec {
    /// A dataset from `source` with `appearance`, unnamed, unmoved, visible, unclipped.
    pub fn of(source: SourceSpec, appearance: AppearanceSpec) -> Self {
        Self {
            name: None,
            source,
            appearance,
            translation: (0.0, 0.0, 0.0),
            rotation_deg: (0.0, 0.0, 0.0),
            visible: true,
            clip: Clipping::default(),
            explode: None,
        }
    }
}

fn is_unclipped(c: &Clipping) -> bool {
    *c == Clipping::default()
}

/// One captured frame: an optional camera and changes applied before it (they stay).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameSpec {
    pub name: String,
    #[serde(default)]
    pub camera: Option<CameraSpec>,
    #[serde(default)]
    pub set: Vec<Change>,
    /// Physics steps of exploded views before the capture (1/120 s each; default
    /// [`SETTLE_STEPS`] when a dataset is exploded).
    #[serde(default)]
    pub settle: Option<u32>,
}

/// Physics steps before a frame of an exploded view is captured: 5 s, enough for the
/// parts to come to rest.
pub const SETTLE_STEPS: u32 = 600;

/// A parameter change between frames. `dataset` is the index in `datasets`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub enum Change {
    Mode {
        dataset: usize,
        mode: Mode,
    },
    Preset {
        dataset: usize,
        preset: String,
    },
    Transfer {
        dataset: usize,
        transfer: TransferFunction,
    },
    Step {
        dataset: usize,
        step: f32,
    },
    Iso {
        dataset: usize,
        value: f64,
    },
    /// Projections take only samples within `range` (`None`: all).
    ProjectionRange {
        dataset: usize,
        range: Option<(f64, f64)>,
    },
    Shading {
        dataset: usize,
        enabled: bool,
    },
    /// The context-preserving parameters.
    Context {
        dataset: usize,
        context: ContextParams,
    },
    /// Replaces the clip planes and box.
    Clip {
        dataset: usize,
        clip: Clipping,
    },
    Visible {
        dataset: usize,
        visible: bool,
    },
    LabelOpacity {
        dataset: usize,
        label: u32,
        opacity: f32,
    },
    /// One object of a segmented dataset (by index in its `objects`).
    Object {
        dataset: usize,
        object: usize,
        #[serde(default)]
        mode: Option<Mode>,
        #[serde(default)]
        visible: Option<bool>,
    },
    Background((f32, f32, f32)),
    Light(Light),
    /// Replaces the view's lenses.
    Lenses(Vec<crate::lens::Lens>),
    /// Replaces the volumetric windows.
    Windows(Vec<crate::windows::spec::WindowSpec>),
    /// Moves (or removes) the 3D pointer.
    Pointer(Option<(f32, f32, f32)>),
    /// Replaces the rendering switches.
    Rendering(RenderingSpec),
    /// The exploded view of a dataset: degree of explosion, viewing force, δ.
    Explode {
        dataset: usize,
        #[serde(default)]
        degree: Option<f32>,
        #[serde(default)]
        viewing: Option<bool>,
        #[serde(default)]
        deltas: Option<(f32, f32, f32)>,
        /// Parts fade by the viewing force on them (figure 9).
        #[serde(default)]
        fade: Option<bool>,
    },
}

impl SceneFile {
    /// Parses RON text; `origin` names it in errors (with line and column).
    pub fn parse(text: &str, origin: &str) -> Result<SceneFile, String> {
        ron::from_str(text).map_err(|e| format!("{origin}: {e}"))
    }

    /// Checks what parsing cannot: the lenses' parameters.
    pub fn validate(&self) -> Result<(), String> {
        validate_lenses(&self.lenses)?;
        for (i, d) in self.datasets.iter().enumerate() {
            if let Some(x) = &d.explode {
                x.validate(self.datasets.len()).map_err(|e| format!("dataset {i}: explode: {e}"))?;
            }
        }
        self.validate_windows(&self.windows)?;
        self.markers.iter().enumerate().try_for_each(|(i, m)| m.validate(i, self.datasets.len()))?;
        self.rulers.iter().enumerate().try_for_each(|(i, m)| m.validate(i, self.datasets.len()))?;
        if let Some(a) = &self.animation {
            a.validate(&self.animation_refers())?;
        }
        for frame in &self.frames {
            for change in &frame.set {
                let checked = match change {
                    Change::Lenses(lenses) => validate_lenses(lenses),
                    Change::Windows(windows) => self.validate_windows(windows),
                    Change::Explode { dataset, degree, deltas, .. } => self.validate_explode_change(*dataset, *degree, *deltas),
                    _ => Ok(()),
                };
                checked.map_err(|e| format!("frame '{}': {e}", frame.name))?;
            }
        }
        Ok(())
    }

    fn validate_explode_change(&self, dataset: usize, degree: Option<f32>, deltas: Option<(f32, f32, f32)>) -> Result<(), String> {
        match self.datasets.get(dataset) {
            None => return Err(format!("Explode refers to dataset {dataset}, the scene has {}", self.datasets.len())),
            Some(d) if d.explode.is_none() => return Err(format!("Explode: dataset {dataset} is not exploded (it has no explode)")),
            _ => {}
        }
        let values = degree.into_iter().chain(deltas.into_iter().flat_map(|(a, b, c)| [a, b, c]));
        if values.into_iter().any(|v| !v.is_finite() || v < 0.0) {
            return Err("Explode: the degree and deltas must be finite and not negative".into());
        }
        Ok(())
    }

    fn validate_windows(&self, windows: &[crate::windows::spec::WindowSpec]) -> Result<(), String> {
        windows.iter().enumerate().try_for_each(|(i, w)| w.validate(i, self.datasets.len(), windows.len()))
    }

    /// What an animation of this scene may refer to.
    pub fn animation_refers(&self) -> super::animation::Refers {
        super::animation::Refers {
            lenses: self.lenses.len(),
            exploded: self.datasets.iter().map(|d| d.explode.is_some()).collect(),
            contexts: self.datasets.iter().map(|d| d.appearance.context).collect(),
        }
    }

    /// Writes RON text.
    pub fn to_ron(&self) -> Result<String, String> {
        ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| e.to_string())
    }

    pub fn background(&self) -> [f32; 3] {
        [self.background.0, self.background.1, self.background.2]
    }
}

/// A tuple as a vector.
pub fn vec3((x, y, z): (f32, f32, f32)) -> Vec3 {
    Vec3::new(x, y, z)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn minimal_and_full_scenes_parse() {
        let s = SceneFile::parse("(datasets: [(source: Phantom(kind: head))])", "t.ron").unwrap();
        assert_eq!(s.size, (512, 512));
        assert_eq!(s.datasets[0].appearance.mode, Mode::Dvr);
        assert_eq!(s.datasets[0].source, SourceSpec::Phantom { kind: Phantom::Head, resolution: 256 });
        let full = r#"(
            size: (64, 48),
            datasets: [(source: File("a.nii.gz"), appearance: (mode: mip, preset: Some("grayscale_ramp"), labels: Some((opacity: 0.3, styles: {3: (visible: Some(false))}))))],
            camera: Orbit(azimuth_deg: 30.0, elevation_deg: 10.0),
            frames: [(name: "a", set: [Mode(dataset: 0, mode: xray), Background((1.0, 1.0, 1.0))])],
        )"#;
        let s = SceneFile::parse(full, "full.ron").unwrap();
        assert_eq!(s.frames[0].set.len(), 2);
        assert_eq!(s.datasets[0].appearance.labels.as_ref().unwrap().styles[&3].visible, Some(false));
        // Round trip.
        let again = SceneFile::parse(&s.to_ron().unwrap(), "again").unwrap();
        assert_eq!(again, s);
    }

    #[test]
    fn a_views_switches_go_into_the_scene_and_back() {
        // Every switch off the default, through the scene file's text and back.
        let view = crate::dataset::VolumeView {
            jitter: false,
            skip_empty: false,
            early_termination: false,
            lens_antialias: false,
            lens_context_steps: true,
            ..Default::default()
        };
        let scene = SceneFile { rendering: RenderingSpec::of(&view), ..SceneFile::parse("(datasets: [])", "t").unwrap() };
        let again = SceneFile::parse(&scene.to_ron().unwrap(), "again").unwrap();
        assert_eq!(again.rendering.view(Default::default()), view);
        // A scene without them keeps the defaults.
        assert_eq!(SceneFile::parse("(datasets: [])", "t").unwrap().rendering, RenderingSpec::default());
    }

    #[test]
    fn rulers_are_read_checked_and_written() {
        let text = "(datasets: [(source: Phantom(kind: head, resolution: 32))], rulers: [(dataset: 0, from: (1.0, 2.0, 3.0), to: (4.0, 6.0, 15.0))])";
        let scene = SceneFile::parse(text, "t").unwrap();
        assert_eq!(scene.rulers.len(), 1);
        let again = SceneFile::parse(&scene.to_ron().unwrap(), "t").unwrap();
        assert_eq!(again.rulers, scene.rulers);
        scene.validate().unwrap();
        let e = SceneFile::parse(&text.replace("dataset: 0", "dataset: 3"), "t").unwrap().validate().unwrap_err();
        assert!(e.contains("ruler 0: refers to dataset 3"), "{e}");
    }

    #[test]
    fn typos_are_errors_with_a_position() {
        let e = SceneFile::parse("(datasets: [(source: Phantom(kind: head), apperance: (mode: mip))])", "typo.ron").unwrap_err();
        assert!(e.starts_with("typo.ron") && e.contains("apperance") && e.contains("1:"), "{e}");
        let e = SceneFile::parse("(datasets: [(source: Phantom(kind: brain))])", "kind.ron").unwrap_err();
        assert!(e.contains("brain"), "{e}");
    }
}
