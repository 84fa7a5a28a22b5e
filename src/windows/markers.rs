//! Interpretive markers and the 3D pointer in every view (Borst et al., section 3:
//! markers placed with the pointer "appear in all windows that show their region").
//!
//! A marker belongs to a dataset and sits at a point of it (the dataset's own frame),
//! so it moves with the dataset. It shows in the main view at that point, unless a clip
//! window cuts the main view away there, and in every window showing its dataset whose
//! source holds it, at the window point that maps onto it: `w = M⁻¹ · p` with `M` the
//! window → source map of [`super::mapping`]. The pointer shows the same way: the data
//! point under it is the pointer itself in the main view, or `M · pointer` when it
//! reaches into a window (so reaching into a magnifier places markers on the magnified
//! data, which then show where that data is in the main view and in the other windows).

use bevy::prelude::*;

use super::boxes::OrientedBox;
use super::mapping::window_to_source;

/// A marker at `position` in the frame of `dataset`.
#[derive(Component, Clone, Copy, Debug, PartialEq)]
pub struct Marker {
    pub dataset: Entity,
    pub position: Vec3,
}

/// One view of a marker: the world point where it shows and its size there (the
/// window's magnification; 1 in the main view).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MarkerView {
    pub at: Vec3,
    pub scale: f32,
}

/// Where a marker (or the pointer) shows: the main view first, then the windows in
/// their order. Kept by [`super::systems::propagate_markers`].
#[derive(Component, Clone, Debug, Default, PartialEq)]
pub struct MarkerViews(pub Vec<MarkerView>);

/// A window as placed this frame: its box, its (fitted, coupled) source, whether it
/// clips, and the datasets it shows.
#[derive(Clone, Debug, PartialEq)]
pub struct WindowView {
    pub window: OrientedBox,
    pub source: OrientedBox,
    pub clip: bool,
    pub datasets: Vec<Entity>,
}

impl WindowView {
    /// The data (world) point shown at window point `w`.
    pub fn to_source(&self, w: Vec3) -> Vec3 {
        window_to_source(&self.window, &self.source).transform_point3(w)
    }

    /// How much the window magnifies (the geometric mean over its axes).
    pub fn scale(&self) -> f32 {
        let m = super::mapping::magnification(&self.window, &self.source);
        (m.x * m.y * m.z).abs().cbrt()
    }

    /// The window point that shows data point `p`.
    pub fn to_window(&self, p: Vec3) -> Vec3 {
        window_to_source(&self.window, &self.source).inverse().transform_point3(p)
    }
}

/// The windows placed this frame, in entity order (written with the regions).
#[derive(Resource, Clone, Debug, Default)]
pub struct PlacedWindows(pub Vec<(Entity, WindowView)>);

impl PlacedWindows {
    pub fn get(&self, e: Entity) -> Option<&WindowView> {
        self.0.iter().find(|(k, _)| *k == e).map(|(_, v)| v)
    }
}

/// Where data point `p` (world) of `dataset` shows (`None`: of any dataset, as the
/// pointer): the main view unless a clip window's box holds it, then every window
/// showing the dataset whose source holds it.
pub fn views(p: Vec3, dataset: Option<Entity>, windows: &[(Entity, WindowView)]) -> Vec<MarkerView> {
    let mut out = Vec::new();
    if !windows.iter().any(|(_, w)| w.clip && w.window.contains(p)) {
        out.push(MarkerView { at: p, scale: 1.0 });
    }
    for (_, w) in windows {
        if dataset.is_some_and(|d| !w.datasets.contains(&d)) || w.datasets.is_empty() {
            continue;
        }
        let q = w.to_window(p);
        if q.is_finite() && w.window.contains(q) {
            out.push(MarkerView { at: q, scale: w.scale() });
        }
    }
    out
}

/// The data point under world point `pointer` and the window it reaches into (the
/// smallest box holding it, as for the focus), if any.
pub fn data_point(pointer: Vec3, windows: &[(Entity, WindowView)]) -> (Vec3, Option<Entity>) {
    let boxes: Vec<(Entity, OrientedBox)> = windows.iter().filter(|(_, w)| !w.datasets.is_empty()).map(|(e, w)| (*e, w.window)).collect();
    match super::interaction::focus(&boxes, None, Some(pointer)).flatten() {
        Some(e) => {
            let w = windows.iter().find(|(k, _)| *k == e).map(|(_, w)| w);
            (w.map_or(pointer, |w| w.to_source(pointer)), Some(e))
        }
        None => (pointer, None),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    #[test]
    fn a_point_shows_in_the_main_view_and_in_the_windows_that_hold_it() {
        let (a, b) = (Entity::from_raw_u32(1).unwrap(), Entity::from_raw_u32(2).unwrap());
        let data = Entity::from_raw_u32(9).unwrap();
        // A ×2 magnifier at x = 100 of the source box [−5, 5]³ around the origin, and a
        // clip window (own source) around (20, 0, 0).
        let magnifier = WindowView {
            window: OrientedBox { center: Vec3::new(100.0, 0.0, 0.0), rotation: Quat::IDENTITY, half: Vec3::splat(10.0) },
            source: OrientedBox { center: Vec3::ZERO, rotation: Quat::IDENTITY, half: Vec3::splat(5.0) },
            clip: false,
            datasets: vec![data],
        };
        let clip_box = OrientedBox { center: Vec3::new(20.0, 0.0, 0.0), rotation: Quat::IDENTITY, half: Vec3::splat(4.0) };
        let clipper = WindowView { window: clip_box, source: clip_box, clip: true, datasets: vec![data] };
        let windows = [(a, magnifier), (b, clipper)];
        let at = |v: Vec<MarkerView>| v.iter().map(|v| v.at).collect::<Vec<_>>();
        // (1, 2, 3) in the source: main view, and in the magnifier at 100 + 2·(1, 2, 3),
        // twice as large there.
        let shown = views(Vec3::new(1.0, 2.0, 3.0), Some(data), &windows);
        assert_eq!(at(shown.clone()), vec![Vec3::new(1.0, 2.0, 3.0), Vec3::new(102.0, 4.0, 6.0)]);
        assert_eq!((shown[0].scale, shown[1].scale), (1.0, 2.0));
        // Inside the clip box: not in the main view (cut away), in the clip window.
        assert_eq!(views(Vec3::new(21.0, 0.0, 0.0), Some(data), &windows), vec![MarkerView { at: Vec3::new(21.0, 0.0, 0.0), scale: 1.0 }]);
        // Another dataset's marker shows in the main view only.
        let other = Entity::from_raw_u32(7).unwrap();
        assert_eq!(at(views(Vec3::new(1.0, 2.0, 3.0), Some(other), &windows)), vec![Vec3::new(1.0, 2.0, 3.0)]);
        // Reaching into the magnifier at (104, 0, 0) points at data (2, 0, 0).
        assert_eq!(data_point(Vec3::new(104.0, 0.0, 0.0), &windows), (Vec3::new(2.0, 0.0, 0.0), Some(a)));
        assert_eq!(data_point(Vec3::new(50.0, 0.0, 0.0), &windows), (Vec3::new(50.0, 0.0, 0.0), None));
    }
}
