//! Session recovery: nothing a user built is lost to a crash, a kill or a lost device.
//!
//! While the app runs, the view as a scene file (datasets with their transfer functions
//! and positions, lenses, windows, exploded parts where they are, rulers, the camera) is
//! written to `recovery.ron` beside the settings ([`super::settings::Settings::path`])
//! every [`EVERY`] when it changed: whole to a temporary file, then renamed, so a kill
//! in the middle leaves the last complete copy. A clean exit removes it. A start that
//! finds one (the last session did not end cleanly) moves it aside to
//! `recovery-previous.ron`, out of this session's way, and offers to restore it;
//! `focal --restore` restores it at once.
//!
//! When rendering stops (a lost device, [`super::gpu_status`]), the view is written at
//! once and kept through the app's exit, with the reason beside it
//! (`recovery-reason.txt`), which the offer at the next start shows. A panic anywhere
//! (a driver failing under the renderer's own readbacks, a bug) keeps the last copy
//! too, and [`install_panic_hook`] writes what happened as the reason.

use std::path::{Path, PathBuf};
use std::sync::OnceLock;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::{Duration, Instant};

use bevy::prelude::*;
use bevy_egui::egui;

use super::loading::LoadRequest;
use crate::scene::SceneFile;

/// How often the view is written when it changed.
pub const EVERY: Duration = Duration::from_secs(3);

/// The file beside the recovery file that says why the session stopped.
const REASON: &str = "recovery-reason.txt";
/// The same, beside the last session's view moved aside.
const PREVIOUS_REASON: &str = "recovery-previous-reason.txt";

/// This session's recovery file, once it keeps one (for the panic hook).
static ACTIVE: OnceLock<PathBuf> = OnceLock::new();
/// Set by the panic hook: the recovery file stays whatever exit follows.
static CRASHED: AtomicBool = AtomicBool::new(false);
/// Whether the hook has said so (panics that follow the first say nothing more).
static TOLD: AtomicBool = AtomicBool::new(false);

/// Makes a panic keep this session's recovery file and write why beside it (unless a
/// reason is there already: rendering stopped first), and say so on standard error.
pub fn install_panic_hook() {
    let default = std::panic::take_hook();
    std::panic::set_hook(Box::new(move |info| {
        // (A parser's panic on a corrupt file is caught and reported as its error.)
        if crate::volume::caught::is_expected() {
            default(info);
            return;
        }
        CRASHED.store(true, Ordering::Relaxed);
        if let Some(path) = ACTIVE.get()
            && !TOLD.swap(true, Ordering::Relaxed)
        {
            let reason = path.with_file_name(REASON);
            if !reason.exists() {
                let _ = std::fs::write(&reason, panic_reason(info));
            }
            eprintln!(
                "Focal stopped: {}; the view is saved in {}: the next start offers to restore it (or run `focal --restore`)",
                std::fs::read_to_string(&reason).unwrap_or_default().trim(),
                path.display()
            );
        }
        default(info);
    }));
}

/// What a panic says, as the reason a session stopped: the renderer's (wgpu, Bevy's
/// renderer: a driver or device failure) or a crash at a place in Focal.
fn panic_reason(info: &std::panic::PanicHookInfo) -> String {
    let message = info
        .payload()
        .downcast_ref::<&str>()
        .map(|s| s.to_string())
        .or_else(|| info.payload().downcast_ref::<String>().cloned())
        .unwrap_or_else(|| "a panic".into());
    let first = message.lines().next().unwrap_or_default().trim().to_string();
    match info.location() {
        Some(l) if ["wgpu", "bevy_render"].iter().any(|c| l.file().contains(c)) => format!("the renderer failed ({first})"),
        Some(l) => format!("it crashed ({first}, at {}:{})", l.file(), l.line()),
        None => format!("it crashed ({first})"),
    }
}

/// What the last session left.
pub struct Found {
    /// Where it was moved at start.
    pub path: PathBuf,
    pub scene: SceneFile,
    /// When it was written, as the user reads it ("4 min ago").
    pub age: String,
    /// Why the session stopped, where Focal knew (a lost device).
    pub reason: Option<String>,
}

/// The recovery file of this session, and the one the last session left.
#[derive(Resource, Default)]
pub struct Recovery {
    /// `recovery.ron` (`None`: no folder for settings, nothing is written).
    pub path: Option<PathBuf>,
    /// What this session wrote last.
    last: Option<String>,
    next: Option<Instant>,
    /// The last session's view, until the user restores or discards it.
    pub found: Option<Found>,
    /// Restore it at start without asking (`focal --restore`).
    pub restore_at_start: bool,
    /// Kept through this exit (rendering stopped): the next start finds it.
    keep: bool,
    /// A write asked for at once that has not happened yet.
    pending: bool,
}

impl Recovery {
    /// The recovery file beside the settings file.
    pub fn file() -> Option<PathBuf> {
        super::settings::Settings::path().map(|p| p.with_file_name("recovery.ron"))
    }

    /// At start: this session's recovery file, and the last session's view if it left
    /// one (moved aside; one that does not read is set aside as `.bad`, with a warning).
    /// Test automation (`automation`) neither writes nor offers one, unless it restores.
    pub fn at_start(restore_at_start: bool, automation: bool) -> Recovery {
        if automation && !restore_at_start {
            return Recovery::default();
        }
        let path = Recovery::file();
        // (A reason without a view beside it says nothing about the next stop.)
        if let Some(p) = path.as_deref().filter(|p| !p.is_file()) {
            let _ = std::fs::remove_file(p.with_file_name(REASON));
        }
        let found = path.as_deref().and_then(take_previous);
        if let Some(p) = &path {
            let _ = ACTIVE.set(p.clone());
        }
        Recovery { path, found, restore_at_start, ..Default::default() }
    }

    /// Writes `text` if it is time and it differs from what was written last.
    pub fn autosave(&mut self, now: Instant, text: impl FnOnce() -> Result<String, String>) {
        if self.next.is_some_and(|t| now < t) {
            return;
        }
        self.next = Some(now + EVERY);
        self.pending = false;
        let Some(path) = self.path.clone() else { return };
        let text = match text() {
            Ok(t) => t,
            Err(e) => {
                warn!("session not saved for recovery: {e}");
                return;
            }
        };
        if self.last.as_ref() == Some(&text) {
            return;
        }
        match super::settings::write_atomically(&path, &text) {
            Ok(()) => self.last = Some(text),
            Err(e) => warn!("session not saved for recovery: {e}"),
        }
    }

    /// Rendering stopped (`why`): the view is written at the next chance, whether it
    /// changed or not, and kept through the exit with the reason beside it.
    pub fn keep_for_next_start(&mut self, why: &str) {
        (self.keep, self.pending, self.next, self.last) = (true, true, None, None);
        if let Some(p) = &self.path
            && let Err(e) = super::settings::write_atomically(&p.with_file_name(REASON), why)
        {
            warn!("{e}");
        }
    }

    /// Whether a write asked for at once ([`Self::keep_for_next_start`]) is still to come.
    pub fn pending(&self) -> bool {
        self.pending && self.path.is_some()
    }

    /// A clean exit: nothing to recover (after a panic, whatever exit follows keeps it).
    pub fn remove(&self) {
        if CRASHED.load(Ordering::Relaxed) {
            return;
        }
        if let Some(p) = &self.path {
            for p in [p.clone(), p.with_file_name(REASON)] {
                if let Err(e) = std::fs::remove_file(&p)
                    && e.kind() != std::io::ErrorKind::NotFound
                {
                    warn!("{}: {e}", p.display());
                }
            }
        }
    }

    /// The last session's view as a load request. Its file becomes this session's
    /// recovery file (should the restored view crash again, the next start finds it).
    pub fn restore(&mut self) -> Option<LoadRequest> {
        let found = self.found.take()?;
        if let Some(path) = &self.path
            && let Err(e) = std::fs::rename(&found.path, path)
        {
            warn!("{}: {e}", found.path.display());
        }
        info!("restored the last session's view from {}", found.path.display());
        let _ = std::fs::remove_file(found.path.with_file_name(PREVIOUS_REASON));
        let base = found.path.parent().map(Path::to_path_buf).unwrap_or_default();
        Some(LoadRequest::Scene(Box::new(found.scene), base))
    }

    /// The last session's view discarded.
    pub fn discard(&mut self) {
        if let Some(found) = self.found.take() {
            let _ = std::fs::remove_file(&found.path);
            let _ = std::fs::remove_file(found.path.with_file_name(PREVIOUS_REASON));
        }
    }
}

/// Moves a recovery file left at `path` aside and reads it (or the one moved aside
/// before, when the user closed that session without choosing).
fn take_previous(path: &Path) -> Option<Found> {
    let previous = path.with_file_name("recovery-previous.ron");
    if path.is_file() {
        if let Err(e) = std::fs::rename(path, &previous) {
            warn!("{}: {e}", path.display());
            return None;
        }
        let reason = path.with_file_name(REASON);
        match reason.is_file() {
            true => _ = std::fs::rename(&reason, path.with_file_name(PREVIOUS_REASON)),
            false => _ = std::fs::remove_file(path.with_file_name(PREVIOUS_REASON)),
        }
    } else if !previous.is_file() {
        return None;
    }
    let age = std::fs::metadata(&previous)
        .and_then(|m| m.modified())
        .ok()
        .and_then(|t| t.elapsed().ok())
        .map(|d| match d.as_secs() {
            s if s < 120 => format!("{s} s ago"),
            s if s < 7200 => format!("{} min ago", s / 60),
            s => format!("{} h ago", s / 3600),
        })
        .unwrap_or_else(|| "at an unknown time".into());
    match crate::scene::read_scene(&previous) {
        Ok(scene) => {
            let reason = std::fs::read_to_string(previous.with_file_name(PREVIOUS_REASON)).ok().filter(|r| !r.trim().is_empty());
            Some(Found { path: previous, scene, age, reason })
        }
        Err(e) => {
            let bad = previous.with_extension("ron.bad");
            let _ = std::fs::rename(&previous, &bad);
            warn!("the last session's view does not read ({e}); kept as {}", bad.display());
            None
        }
    }
}

/// The offer to restore the last session's view (a window until the user chooses).
pub fn offer(ctx: &egui::Context, recovery: &mut Recovery, load: &mut MessageWriter<LoadRequest>) {
    let Some(found) = &recovery.found else { return };
    let datasets = found.scene.datasets.len();
    let mut choice = None;
    egui::Window::new("Restore the last session?")
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, [0.0, 0.0])
        .show(ctx, |ui| {
        ui.label(format!(
            "The last session did not end cleanly. Its view ({datasets} dataset(s), with their looks, lenses, windows, parts and rulers) was saved {}.",
            found.age
        ));
        if let Some(reason) = &found.reason {
            ui.label(egui::RichText::new(format!("It stopped because {}.", reason.trim())).color(egui::Color32::from_rgb(255, 160, 60)));
        }
        ui.horizontal(|ui| {
            if ui.button("Restore").clicked() {
                choice = Some(true);
            }
            if ui.button("Discard").clicked() {
                choice = Some(false);
            }
        });
    });
    match choice {
        Some(true) => {
            if let Some(request) = recovery.restore() {
                load.write(request);
            }
        }
        Some(false) => recovery.discard(),
        None => {}
    }
}

/// Removes the recovery file when the app exits cleanly (not when rendering stopped).
pub fn remove_on_exit(mut exits: MessageReader<AppExit>, recovery: Res<Recovery>) {
    if exits.read().next().is_some() && !recovery.keep {
        recovery.remove();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_view_is_written_when_it_changed_and_not_more_often_than_every_few_seconds() {
        let dir = std::env::temp_dir().join(format!("focal-recovery-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("recovery.ron");
        let mut r = Recovery { path: Some(path.clone()), ..Default::default() };
        let t0 = Instant::now();
        let mut asked = 0;
        r.autosave(t0, || {
            asked += 1;
            Ok("(datasets: [])".into())
        });
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "(datasets: [])");
        // Within EVERY: not even asked for the text.
        r.autosave(t0 + EVERY / 2, || {
            asked += 1;
            Ok("(changed)".into())
        });
        assert_eq!((asked, std::fs::read_to_string(&path).unwrap().as_str()), (1, "(datasets: [])"));
        r.autosave(t0 + EVERY, || Ok("(changed)".into()));
        assert_eq!(std::fs::read_to_string(&path).unwrap(), "(changed)");
        assert!(!path.with_extension("ron.new").exists());
        // The next start finds it, moves it aside and reads it; a clean exit removes it.
        std::fs::write(&path, "(datasets: [(source: Phantom(kind: engine, resolution: 32))])").unwrap();
        let found = take_previous(&path).unwrap();
        assert_eq!(found.scene.datasets.len(), 1);
        assert!(!path.exists() && found.path.exists());
        let mut next = Recovery { path: Some(path.clone()), found: Some(found), ..Default::default() };
        assert!(matches!(next.restore(), Some(LoadRequest::Scene(..))));
        // Now this session's recovery file, until this session writes its own.
        assert!(!dir.join("recovery-previous.ron").exists() && path.exists());
        next.autosave(t0, || Ok("(x)".into()));
        next.remove();
        assert!(!path.exists());
        // Closed without a choice: offered again at the next start.
        std::fs::write(dir.join("recovery-previous.ron"), "(datasets: [])").unwrap();
        assert!(take_previous(&path).is_some_and(|f| f.scene.datasets.is_empty()));
        std::fs::remove_file(dir.join("recovery-previous.ron")).unwrap();
        // One that does not read is set aside, not offered.
        std::fs::write(&path, "(datasets: [(source: Nonsense)])").unwrap();
        assert!(take_previous(&path).is_none());
        assert!(dir.join("recovery-previous.ron.bad").exists());
    }

    /// Rendering stopped: the view is written at once (unchanged or not), kept through
    /// the exit, and found at the next start with the reason.
    #[test]
    fn a_stopped_session_is_kept_with_its_reason() {
        let dir = std::env::temp_dir().join(format!("focal-recovery-kept-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        let path = dir.join("recovery.ron");
        let mut r = Recovery { path: Some(path.clone()), ..Default::default() };
        let t0 = Instant::now();
        r.autosave(t0, || Ok("(datasets: [])".into()));
        r.keep_for_next_start("the graphics device was lost (test)");
        assert!(r.pending());
        // At once, though EVERY has not passed and the text is the same.
        r.autosave(t0 + EVERY / 10, || Ok("(datasets: [])".into()));
        assert!(!r.pending());
        assert!(r.keep, "the exit keeps it");
        let found = take_previous(&path).unwrap();
        assert_eq!(found.reason.as_deref(), Some("the graphics device was lost (test)"));
        assert!(!dir.join(REASON).exists() && dir.join(PREVIOUS_REASON).exists());
        let mut next = Recovery { path: Some(path.clone()), found: Some(found), ..Default::default() };
        next.discard();
        assert!(!dir.join(PREVIOUS_REASON).exists() && !dir.join("recovery-previous.ron").exists());
        // A clean exit after an ordinary session leaves no reason behind either.
        next.autosave(t0, || Ok("(x)".into()));
        next.remove();
        assert!(!path.exists() && !dir.join(REASON).exists());
    }
}
