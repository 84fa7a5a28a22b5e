//! What the app remembers between runs: the files opened last (File ▸ Open recent) and
//! the side panel's width. Kept as RON in `settings.ron` under `$FOCAL_CONFIG_DIR`, else
//! `$XDG_CONFIG_HOME/focal`, else `~/.config/focal`; written whole and renamed into
//! place, so a crash never leaves half a file. A missing file is a first run; one that
//! does not parse is set aside with a warning (the app starts with defaults).

use std::path::{Path, PathBuf};

use bevy::prelude::*;
use serde::{Deserialize, Serialize};

/// How many recent files are kept.
pub const MAX_RECENT: usize = 10;

/// The remembered settings.
#[derive(Resource, Clone, Debug, Default, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Settings {
    /// Files, folders and scenes opened, the newest first.
    pub recent: Vec<PathBuf>,
    /// The side panel's width in points, as the user left it.
    pub panel_width: Option<f32>,
}

impl Settings {
    /// The settings file (`None` when no folder can be named: no home).
    pub fn path() -> Option<PathBuf> {
        let env = |k: &str| std::env::var_os(k).filter(|v| !v.is_empty()).map(PathBuf::from);
        let dir = env("FOCAL_CONFIG_DIR")
            .or_else(|| env("XDG_CONFIG_HOME").map(|d| d.join("focal")))
            .or_else(|| env("HOME").map(|h| h.join(".config/focal")))?;
        Some(dir.join("settings.ron"))
    }

    /// Reads the settings at `path`: defaults when there is none, and when it does not
    /// parse (with the reason).
    pub fn read(path: &Path) -> (Settings, Option<String>) {
        match std::fs::read_to_string(path) {
            Err(e) if e.kind() == std::io::ErrorKind::NotFound => (Settings::default(), None),
            Err(e) => (Settings::default(), Some(format!("{}: {e}", path.display()))),
            Ok(text) => match ron::from_str::<Settings>(&text) {
                Ok(s) => (s, None),
                Err(e) => {
                    // Kept for the user (hand-edited, perhaps), out of the way of the next write.
                    let aside = path.with_extension("ron.bad");
                    let kept = match std::fs::rename(path, &aside) {
                        Ok(()) => format!("set aside as {}", aside.display()),
                        Err(r) => format!("not set aside: {r}"),
                    };
                    (Settings::default(), Some(format!("{}: {e} (starting with default settings; the file is {kept})", path.display())))
                }
            },
        }
    }

    /// Writes the settings to `path` (to a temporary file beside it, then renamed).
    pub fn write(&self, path: &Path) -> Result<(), String> {
        let text = ron::ser::to_string_pretty(self, ron::ser::PrettyConfig::default()).map_err(|e| format!("{}: {e}", path.display()))?;
        write_atomically(path, &text)
    }

    /// Puts `path` first among the recent files (once), keeping [`MAX_RECENT`].
    pub fn opened(&mut self, path: &Path) {
        let path = std::fs::canonicalize(path).unwrap_or_else(|_| path.to_path_buf());
        self.recent.retain(|p| *p != path);
        self.recent.insert(0, path);
        self.recent.truncate(MAX_RECENT);
    }
}

impl Settings {
    /// The settings of this user, at start-up (a warning in the log when the file is
    /// unreadable).
    pub fn load() -> Settings {
        let Some(path) = Settings::path() else { return Settings::default() };
        let (settings, warning) = Settings::read(&path);
        if let Some(w) = warning {
            warn!("{w}");
        }
        settings
    }

    /// The settings on disk now, without a warning (defaults where there are none).
    fn load_quiet() -> Settings {
        Settings::path().map(|p| Settings::read(&p).0).unwrap_or_default()
    }
}

/// Writes `text` to `path` whole: to a temporary file beside it, then renamed.
pub fn write_atomically(path: &Path, text: &str) -> Result<(), String> {
    let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| fail(&e))?;
    }
    let temporary = path.with_extension("ron.new");
    std::fs::write(&temporary, text).map_err(|e| fail(&e))?;
    std::fs::rename(&temporary, path).map_err(|e| fail(&e))
}

/// Writes the settings whenever they differ from what is on disk (as read at the first
/// run, then as last written).
pub fn save_settings(settings: Res<Settings>, mut written: Local<Option<Settings>>) {
    let last = written.get_or_insert_with(Settings::load_quiet);
    if *last == *settings {
        return;
    }
    if let Some(path) = Settings::path()
        && let Err(e) = settings.write(&path)
    {
        warn!("settings not saved: {e}");
    }
    *last = settings.clone();
}

/// Adds what a finished load opened to the recent files.
pub fn remember_opened(mut session: ResMut<super::loading::Session>, mut settings: ResMut<Settings>) {
    if let Some(path) = session.opened.take() {
        settings.opened(&path);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("focal-settings-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        dir
    }

    #[test]
    fn recent_files_come_newest_first_once_and_at_most_ten() {
        let mut s = Settings::default();
        for k in 0..12 {
            s.opened(Path::new(&format!("/nowhere/file{k}.nii")));
        }
        s.opened(Path::new("/nowhere/file5.nii"));
        assert_eq!(s.recent.len(), MAX_RECENT);
        assert_eq!(s.recent[0], Path::new("/nowhere/file5.nii"));
        assert_eq!(s.recent[1], Path::new("/nowhere/file11.nii"));
        assert_eq!(s.recent.iter().filter(|p| p.ends_with("file5.nii")).count(), 1);
        assert!(!s.recent.iter().any(|p| p.ends_with("file0.nii")), "the oldest went");
    }

    #[test]
    fn settings_survive_a_write_and_a_bad_file_starts_afresh() {
        let dir = scratch("roundtrip");
        let path = dir.join("settings.ron");
        assert_eq!(Settings::read(&path), (Settings::default(), None), "no file: a first run");
        let s = Settings { recent: vec![PathBuf::from("/data/ct.nii.gz")], panel_width: Some(412.0) };
        s.write(&path).unwrap();
        assert_eq!(Settings::read(&path), (s, None));
        assert!(!path.with_extension("ron.new").exists(), "the temporary file was renamed");
        std::fs::write(&path, "(recent: [42").unwrap();
        let (read, warning) = Settings::read(&path);
        assert_eq!(read, Settings::default());
        assert!(warning.is_some_and(|w| w.contains("settings.ron") && w.contains("set aside")));
        assert_eq!(std::fs::read_to_string(path.with_extension("ron.bad")).unwrap(), "(recent: [42", "the bad file is kept");
        assert!(!path.exists());
    }
}
