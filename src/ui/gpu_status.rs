//! What the GPU refused or why rendering stopped, for the user: the messages of
//! [`crate::render::health`] at the top of the viewport (orange, until dismissed), and,
//! when rendering stops (a lost device), the app's way out: the view is written for the
//! next start ([`super::recovery::Recovery::keep_for_next_start`]), the reason printed,
//! and the app quits with an error.

use bevy::prelude::*;
use bevy::render::renderer::RenderDevice;
use bevy::window::PrimaryWindow;
use bevy_egui::{EguiContexts, egui};

use super::recovery::Recovery;
use super::state::MainCamera;
use super::viewport::viewport_rect;
use crate::render::RenderProgress;
use crate::render::health::{GpuMessages, RenderHealth};

/// Frames the app waits for the panels to write the view before it quits anyway (the
/// last periodic copy, at most a few seconds old, stays).
const SAVE_FRAMES: u32 = 30;

/// The messages at the top of the viewport, with a button that dismisses them.
pub fn gpu_status(
    mut contexts: EguiContexts,
    mut messages: ResMut<GpuMessages>,
    windows: Query<&Window, With<PrimaryWindow>>,
    cams: Query<&Camera, With<MainCamera>>,
) -> Result {
    if messages.0.is_empty() {
        return Ok(());
    }
    let ctx = contexts.ctx_mut()?.clone();
    let rect = viewport_rect(&ctx, &windows, &cams);
    let margin = 8.0;
    let mut dismissed = false;
    egui::Area::new("gpu status".into()).fixed_pos(rect.left_top() + egui::vec2(margin, margin)).constrain_to(rect).show(&ctx, |ui| {
        ui.set_max_width((rect.width() - 2.0 * margin).max(1.0));
        egui::Frame::popup(ui.style()).show(ui, |ui| {
            for m in messages.0.iter().rev().take(3) {
                ui.label(egui::RichText::new(format!("⚠ {m}")).color(egui::Color32::from_rgb(255, 160, 60)).small());
            }
            dismissed = ui.small_button("Dismiss").clicked();
        });
    });
    if dismissed {
        messages.0.clear();
    }
    Ok(())
}

/// Rendering stopped: the view is written for the next start, then the app quits with
/// the reason (once the panels wrote it, or after [`SAVE_FRAMES`] frames).
pub fn quit_when_rendering_stops(
    health: Res<RenderHealth>,
    mut recovery: ResMut<Recovery>,
    mut exit: MessageWriter<AppExit>,
    mut waited: Local<Option<u32>>,
) {
    let Some(why) = health.stopped() else { return };
    let frames = waited.get_or_insert_with(|| {
        recovery.keep_for_next_start(&why);
        0
    });
    if *frames == u32::MAX {
        return;
    }
    *frames += 1;
    if recovery.pending() && *frames < SAVE_FRAMES {
        return;
    }
    let kept = match &recovery.path {
        Some(p) if p.exists() => {
            format!("the view is saved in {}: the next start offers to restore it (or run `focal --restore`)", p.display())
        }
        _ => "no view could be saved".into(),
    };
    error!("Focal stopped: {why}; {kept}");
    eprintln!("Focal stopped: {why}; {kept}");
    *frames = u32::MAX;
    exit.write(AppExit::error());
}

/// (Testing) Destroys the GPU device once the volumes were drawn this many times, as a
/// driver reset does (`focal --lose-device-after N`).
#[derive(Resource, Clone, Copy, Debug)]
pub struct LoseDeviceAfter(pub u64);

pub fn lose_device(
    after: Option<Res<LoseDeviceAfter>>,
    progress: Option<Res<RenderProgress>>,
    device: Option<Res<RenderDevice>>,
    mut done: Local<bool>,
) {
    let (Some(after), Some(progress), Some(device)) = (after, progress, device) else { return };
    if !*done && progress.volumes_drawn() >= after.0 {
        warn!("destroying the GPU device after {} drawn frames (--lose-device-after)", after.0);
        device.wgpu_device().destroy();
        *done = true;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Rendering stopped: the recovery file is asked for at once and kept, and the app
    /// quits with an error (here without panels to write it: after [`SAVE_FRAMES`]).
    #[test]
    fn the_app_keeps_the_session_and_quits_when_rendering_stops() {
        let dir = std::env::temp_dir().join(format!("focal-gpu-status-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("recovery.ron");
        std::fs::write(&path, "(datasets: [])").unwrap();
        let mut app = App::new();
        let mut recovery = Recovery::default();
        recovery.path = Some(path.clone());
        app.add_plugins(MinimalPlugins)
            .insert_resource(RenderHealth::default())
            .insert_resource(recovery)
            .add_systems(Update, quit_when_rendering_stops);
        app.update();
        assert!(app.world_mut().resource_mut::<Messages<AppExit>>().drain().next().is_none(), "nothing stopped");
        let _ = (crate::render::health::error_handler().0)(
            &bevy::render::error_handler::RenderError {
                ty: bevy::render::error_handler::ErrorType::DeviceLost,
                description: "test".into(),
                source: None,
            },
            app.world_mut(),
            &mut World::new(),
        );
        let mut exits = Vec::new();
        for _ in 0..SAVE_FRAMES + 2 {
            app.update();
            exits.extend(app.world_mut().resource_mut::<Messages<AppExit>>().drain());
        }
        assert_eq!(exits, vec![AppExit::error()]);
        assert!(std::fs::read_to_string(dir.join("recovery-reason.txt")).unwrap().contains("the graphics device was lost (test)"));
        // The exit keeps the file.
        assert!(app.world().resource::<Recovery>().pending(), "no panel wrote it here");
        let _ = std::fs::remove_dir_all(&dir);
    }
}
