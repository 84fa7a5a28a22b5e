//! Movies from the app (File ▸ Record movie…): the view as it is now is saved as a scene
//! file, and `focal render` renders it in a child process, an orbit around it
//! (`--turntable N`) or the scene's keyframed animation, while the app stays usable. The
//! child's frame count on stderr (`frame k/N`, then `GIF frame k/N`) drives a progress
//! bar; when it ends the panel names the GIF, or gives the child's last words.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::{Arc, Mutex};

use bevy::prelude::*;
use bevy_egui::egui;

/// What to record.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum MovieKind {
    /// An orbit of `frames` frames about the superior axis at `elevation_deg`.
    Turntable { frames: u32, elevation_deg: f32 },
    /// The scene's own keyframed animation.
    Animation,
}

/// How far the child has got, from its stderr.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Progress {
    /// "frame" while rendering, "GIF frame" while encoding.
    pub stage: String,
    pub done: u32,
    pub total: u32,
    /// The last lines that were not progress (errors, warnings).
    pub said: Vec<String>,
}

impl Progress {
    /// Takes in one piece of stderr (split at `\r` and `\n`).
    fn read(&mut self, piece: &str) {
        let piece = piece.trim();
        if piece.is_empty() {
            return;
        }
        let counted = piece.rsplit_once(' ').and_then(|(stage, count)| {
            let (k, n) = count.split_once('/')?;
            Some((stage.to_string(), k.parse().ok()?, n.parse().ok()?))
        });
        match counted {
            Some((stage, done, total)) if stage.ends_with("frame") => (self.stage, self.done, self.total) = (stage, done, total),
            _ => {
                self.said.push(piece.to_string());
                let extra = self.said.len().saturating_sub(6);
                self.said.drain(..extra);
            }
        }
    }
}

/// Where a recording stands.
#[derive(Clone, Debug, PartialEq)]
pub enum MovieStatus {
    Running(Progress),
    /// Finished: the movie's GIF.
    Done(PathBuf),
    Failed(String),
}

/// A `focal render` child writing a movie.
pub struct MovieJob {
    child: Child,
    progress: Arc<Mutex<Progress>>,
    gif: PathBuf,
}

impl MovieJob {
    /// Starts `exe render SCENE …` writing into `dir` (`extra`: more arguments, e.g. a
    /// size). The animation's movie goes to `dir/<scene stem>/`.
    pub fn start(exe: &Path, scene: &Path, kind: MovieKind, dir: &Path, extra: &[String]) -> Result<MovieJob, String> {
        let mut command = Command::new(exe);
        command.arg("render").arg(scene).args(extra);
        // (Named as `focal render` names it.)
        let stem = crate::scene::run::slug(&scene.file_stem().map(|s| s.to_string_lossy().into_owned()).unwrap_or_else(|| "scene".into()));
        let gif = match kind {
            MovieKind::Turntable { frames, elevation_deg } => {
                command.args(["--turntable", &frames.to_string(), "--elevation", &elevation_deg.to_string(), "--out"]).arg(dir);
                dir.join("turntable.gif")
            }
            MovieKind::Animation => {
                command.arg("--out").arg(dir);
                dir.join(&stem).join(format!("{stem}.gif"))
            }
        };
        // Its own process group, so a cancel reaches its ffmpeg too.
        #[cfg(unix)]
        std::os::unix::process::CommandExt::process_group(&mut command, 0);
        let mut child =
            command.stdout(Stdio::null()).stderr(Stdio::piped()).spawn().map_err(|e| format!("could not start {}: {e}", exe.display()))?;
        let progress = Arc::new(Mutex::new(Progress::default()));
        if let Some(mut stderr) = child.stderr.take() {
            let progress = progress.clone();
            std::thread::spawn(move || {
                let mut buffer = [0u8; 512];
                let mut pending = String::new();
                while let Ok(n) = stderr.read(&mut buffer) {
                    if n == 0 {
                        break;
                    }
                    pending.push_str(&String::from_utf8_lossy(&buffer[..n]));
                    while let Some(end) = pending.find(['\r', '\n']) {
                        let piece: String = pending.drain(..=end).collect();
                        if let Ok(mut p) = progress.lock() {
                            p.read(&piece);
                        }
                    }
                }
                if let Ok(mut p) = progress.lock() {
                    p.read(&pending);
                }
            });
        }
        Ok(MovieJob { child, progress, gif })
    }

    /// Where the recording stands (never waits).
    pub fn poll(&mut self) -> MovieStatus {
        let progress = self.progress.lock().map(|p| p.clone()).unwrap_or_default();
        match self.child.try_wait() {
            Ok(None) => MovieStatus::Running(progress),
            Ok(Some(status)) if status.success() && self.gif.exists() => MovieStatus::Done(self.gif.clone()),
            Ok(Some(status)) if status.success() => {
                MovieStatus::Failed(format!("no movie was written ({} is missing)", self.gif.display()))
            }
            Ok(Some(status)) => {
                // (The reader may still hold the last words: wait for them briefly.)
                std::thread::sleep(std::time::Duration::from_millis(50));
                let said = self.progress.lock().map(|p| p.said.join("\n")).unwrap_or_default();
                MovieStatus::Failed(format!("focal render ended with {status}: {said}"))
            }
            Err(e) => MovieStatus::Failed(e.to_string()),
        }
    }

    /// Stops the child (and, on Unix, what it started: its process group).
    pub fn cancel(&mut self) {
        #[cfg(unix)]
        let _ = Command::new("kill").args(["-KILL", &format!("-{}", self.child.id())]).status();
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

/// The movie window's settings and the recording under way.
#[derive(Resource)]
pub struct MovieRecorder {
    pub open: bool,
    pub frames: u32,
    pub elevation_deg: f32,
    /// Width of the movie in pixels (the height follows the 3D view's aspect).
    pub width: u32,
    /// Set by the window's buttons; the panels save the scene and start the job.
    pub requested: Option<MovieKind>,
    pub job: Option<MovieJob>,
    pub status: Option<MovieStatus>,
}

impl Default for MovieRecorder {
    fn default() -> Self {
        MovieRecorder { open: false, frames: 72, elevation_deg: 20.0, width: 512, requested: None, job: None, status: None }
    }
}

impl MovieRecorder {
    /// Saves nothing itself: `save(path)` writes the current scene there. Starts the
    /// requested recording into a new folder under `out/movies/`.
    pub fn start_requested(&mut self, aspect: f32, save: impl FnOnce(&Path) -> Result<(), String>) {
        let Some(kind) = self.requested.take() else { return };
        let result = (|| {
            let stamp = std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map(|d| d.as_secs()).unwrap_or(0);
            let dir = PathBuf::from("out/movies").join(format!("movie-{stamp}"));
            std::fs::create_dir_all(&dir).map_err(|e| format!("{}: {e}", dir.display()))?;
            let scene = dir.join("scene.ron");
            save(&scene)?;
            let exe = std::env::current_exe().map_err(|e| format!("the focal binary: {e}"))?;
            let height = ((self.width as f32 / aspect.max(0.1)).round() as u32).clamp(16, 4096);
            MovieJob::start(&exe, &scene, kind, &dir, &["--size".into(), format!("{}x{height}", self.width)])
        })();
        match result {
            Ok(job) => {
                self.job = Some(job);
                self.status = None;
            }
            Err(e) => self.status = Some(MovieStatus::Failed(e)),
        }
    }

    /// Follows the recording under way.
    fn update(&mut self) {
        if let Some(job) = &mut self.job {
            let status = job.poll();
            if !matches!(status, MovieStatus::Running(_)) {
                self.job = None;
            }
            self.status = Some(status);
        }
    }

    /// The movie window. `animation`: the scene's animation's length, if it has one.
    pub fn window(&mut self, ctx: &egui::Context, animation: Option<(f32, u32)>) {
        self.update();
        let mut open = self.open;
        egui::Window::new("Record movie").open(&mut open).resizable(false).collapsible(false).show(ctx, |ui| {
            let busy = self.job.is_some();
            ui.add_enabled_ui(!busy, |ui| {
                ui.horizontal(|ui| {
                    ui.label("Width");
                    ui.add(egui::DragValue::new(&mut self.width).range(64..=2048).suffix(" px"))
                        .on_hover_text("The height follows the 3D view's proportions");
                });
                ui.separator();
                ui.horizontal(|ui| {
                    ui.add(egui::DragValue::new(&mut self.frames).range(2..=720).suffix(" frames"));
                    ui.add(egui::DragValue::new(&mut self.elevation_deg).range(-89.0..=89.0).suffix("° elevation"));
                });
                if ui.button("Record a turntable").on_hover_text("One turn about the vertical axis, 25 frames a second").clicked() {
                    self.requested = Some(MovieKind::Turntable { frames: self.frames, elevation_deg: self.elevation_deg });
                }
                if let Some((seconds, fps)) = animation {
                    ui.separator();
                    if ui.button(format!("Render the scene's animation ({seconds} s at {fps} fps)")).clicked() {
                        self.requested = Some(MovieKind::Animation);
                    }
                }
            });
            match self.status.clone() {
                Some(MovieStatus::Running(p)) => {
                    let fraction = if p.total > 0 { p.done as f32 / p.total as f32 } else { 0.0 };
                    ui.horizontal(|ui| {
                        let stage = if p.stage.is_empty() { "starting" } else { p.stage.as_str() };
                        ui.add(egui::ProgressBar::new(fraction).text(format!("{stage} {}/{}", p.done, p.total)));
                        if ui.button("Cancel").clicked()
                            && let Some(mut job) = self.job.take()
                        {
                            job.cancel();
                            self.status = Some(MovieStatus::Failed("cancelled".into()));
                        }
                    });
                }
                Some(MovieStatus::Done(gif)) => {
                    ui.label(format!("Written: {} (and its PNG frames beside it)", gif.display()));
                }
                Some(MovieStatus::Failed(e)) => {
                    ui.colored_label(egui::Color32::LIGHT_RED, e);
                }
                None => {}
            }
        });
        self.open = open;
    }
}

impl Drop for MovieRecorder {
    fn drop(&mut self) {
        if let Some(job) = &mut self.job {
            job.cancel();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn progress_is_read_from_the_renderers_stderr() {
        let mut p = Progress::default();
        for piece in ["frame 1/4", "frame 2/4", "warning: something", "GIF frame 3/4", ""] {
            p.read(piece);
        }
        assert_eq!((p.stage.as_str(), p.done, p.total), ("GIF frame", 3, 4));
        assert_eq!(p.said, vec!["warning: something".to_string()]);
        p.read("scene.ron: frame 'a': change refers to dataset 3, the scene has 1");
        assert_eq!(p.said.len(), 2, "an error that is not a count is kept");
        assert_eq!(p.done, 3);
    }
}
