//! The volumetric windows group of `focal bench`: frame rates with the windows of the
//! paper's figures on the head CT, against no window, in one run.
//!
//! The camera frames the head and every window's place, so all configurations show the
//! same view. Configurations:
//! - no window (the baseline);
//! - a clip window cutting into the skull on the side facing the camera, showing the
//!   dataset as it is (the same picture: the cost of the window's regions alone);
//! - the same clip window showing bone (figure 3: a cutaway, the rays go deeper);
//! - four clip windows on the skin, showing the dataset as it is (the same picture: the
//!   cost of four windows' regions alone);
//! - the four windows of figures 3–6: the cutaway, a ×2 magnifier of a source box around
//!   the calcifications posed beside the head, a window on the 3D pointer showing its
//!   neighbourhood in MIP, and a world-in-miniature (fit, coupled to the main view's
//!   orientation). These draw more than the head alone: pixels beside the head get
//!   content, and the MIP window's rays cross its whole box (no early termination);
//! - a window without clip over the head showing bone (its contents and the head
//!   composite sample by sample inside the box);
//! - the head as two datasets clipped to one half each (two regions, the same picture).
//!
//! Goals (issue 24): one clip window ≤ ×1.05, four windows ≤ ×1.15, for windows that
//! show the dataset as it is (the windows' own cost; such clip windows, and the bone
//! cutaway, are drawn in the dataset's samples: `render::pack::insets`);
//! the figures' windows are timed too, with what they add to the picture.

use std::sync::Arc;

use bevy::prelude::*;
use focal::clip::{ClipPlane, Clipping};
use focal::dataset::Dataset;
use focal::region::{Appearance, Mode, View};
use focal::transfer::presets;
use focal::volume::phantom::Phantom;
use focal::windows::{Automation, Content, Fit, Orientation, Pointer3d, Source, SourceBox, VolumeWindow};

use super::harness::{Bench, Row, difference, push_group};

/// Entities a configuration adds (removed before the next one).
#[derive(Component)]
struct Added;

/// A window placed at `center` (world, mm).
struct Placed {
    window: VolumeWindow,
    center: Vec3,
}

/// The cutaway of figure 3: a clip box into the skull on the camera's side.
fn cutaway(content: Vec<Content>) -> Placed {
    Placed { window: VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::splat(70.0), content) }, center: CUTAWAY }
}

/// The cutaway's centre: on the skin where the oblique view looks at the head.
const CUTAWAY: Vec3 = Vec3::new(-45.0, 62.0, 42.0);

/// Four places on the skin the oblique view sees, apart from each other.
const ON_THE_SKIN: [Vec3; 4] =
    [Vec3::new(-65.0, 23.0, 51.0), Vec3::new(-5.0, 76.0, 62.0), Vec3::new(-70.0, 43.0, 2.0), Vec3::new(-23.0, 94.0, 6.0)];

/// Where the calcifications are (`phantom::head`), the magnifier's source.
const CALCIFICATIONS: Vec3 = Vec3::new(28.0, 18.0, 22.0);

pub fn group(bench: &mut Bench, rows: &mut Vec<Row>, resolution: u32) -> Result<(), String> {
    let ct = Arc::new(Phantom::Head.generate(resolution)?);
    let skin = Appearance::new(Mode::Dvr, presets::builtin("ct_skin_bone")?);
    let bone = Appearance::new(Mode::Dvr, presets::builtin("ct_bone")?);
    let mip = Appearance::new(Mode::Mip, presets::builtin("grayscale_ramp")?);
    let names = [
        "no window",
        "one clip window, same look",
        "one clip window, bone",
        "four clip windows, same look",
        "four windows of figures 3–6",
        "window over the head, no clip",
        "no window, two halves",
    ];
    // The view: the head and every window's place, from the oblique view.
    let (head_lo, head_hi) = skin.visible_bounds(&ct).unwrap_or_else(|| ct.grid.world_bounds());
    let beside = [Vec3::new(-115.0, -85.0, 80.0), Vec3::new(-115.0, -85.0, -5.0), Vec3::new(115.0, 85.0, 70.0)];
    let (lo, hi) = beside.iter().fold((head_lo, head_hi), |(lo, hi), c| (lo.min(*c - 30.0), hi.max(*c + 30.0)));
    let camera = View::Oblique.frame_box(lo, hi, bench.off.width as f32 / bench.off.height as f32, false);
    let half = |flip: bool| Clipping { planes: vec![ClipPlane { flip, ..ClipPlane::new(Vec3::ZERO, Vec3::X) }], clip_box: None };
    let (ms, images) = bench.interleaved_by(ct.clone(), skin.clone(), names.len(), false, |off, i| {
        off.set_camera(&camera);
        let world = off.world_mut();
        let old: Vec<Entity> = world.query_filtered::<Entity, With<Added>>().iter(world).collect();
        for e in old {
            world.despawn(e);
        }
        let Some(data) = world.query_filtered::<Entity, With<Dataset>>().iter(world).next() else { return };
        if let Some(mut d) = world.get_mut::<Dataset>(data) {
            d.clip = if i == 6 { half(false) } else { Clipping::default() };
        }
        let content = |look: &Appearance| vec![Content { dataset: data, appearance: Some(look.clone()) }];
        let mut windows = Vec::new();
        match i {
            1 => windows.push(cutaway(content(&skin))),
            2 => windows.push(cutaway(content(&bone))),
            3 => {
                for c in ON_THE_SKIN {
                    windows.push(Placed {
                        window: VolumeWindow { clip: true, ..VolumeWindow::new(Vec3::splat(44.0), content(&skin)) },
                        center: c,
                    });
                }
            }
            4 => {
                windows.push(cutaway(content(&bone)));
                // Figure 4: a source box around the calcifications, magnified ×2 beside
                // the head.
                let source = world.spawn((SourceBox { size: Vec3::splat(30.0) }, Transform::from_translation(CALCIFICATIONS), Added)).id();
                windows.push(Placed {
                    window: VolumeWindow { source: Source::Box(source), ..VolumeWindow::new(Vec3::splat(60.0), content(&skin)) },
                    center: beside[1],
                });
                // Figure 5: the source follows the 3D pointer (on the lesion), in MIP.
                world.spawn((Pointer3d, Transform::from_translation(CALCIFICATIONS + Vec3::new(0.0, 0.0, 10.0)), Added));
                windows.push(Placed {
                    window: VolumeWindow {
                        source: Source::Pointer { size: Vec3::splat(40.0) },
                        ..VolumeWindow::new(Vec3::splat(60.0), content(&mip))
                    },
                    center: beside[0],
                });
                // Figure 6: a world-in-miniature of the whole head, oriented as the main
                // view.
                windows.push(Placed {
                    window: VolumeWindow {
                        automation: Automation { fit: Some(Fit::Uniform), orientation: Orientation::MainView },
                        ..VolumeWindow::new(Vec3::splat(55.0), vec![Content { dataset: data, appearance: None }])
                    },
                    center: beside[2],
                });
            }
            5 => windows.push(Placed { window: VolumeWindow::new(Vec3::splat(70.0), content(&bone)), center: CUTAWAY }),
            6 => {
                let mut other = Dataset::new(ct.clone(), skin.clone());
                other.clip = half(true);
                world.spawn((other, Transform::default(), Added));
            }
            _ => {}
        }
        for w in windows {
            world.spawn((w.window, Transform::from_translation(w.center), Added));
        }
    })?;
    bench.save_images("windows", &images)?;
    let note = format!(
        "the same-look windows and the two halves differ from no window by at most {}, {} and {} levels",
        difference(&images[0], &images[1]),
        difference(&images[0], &images[3]),
        difference(&images[0], &images[6])
    );
    push_group(rows, bench, "windows", &names, &ms, "head phantom", &note);
    Ok(())
}
