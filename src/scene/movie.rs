//! Movies: a scene's frames written as a PNG sequence (`NAME-0000.png` …), an animated
//! GIF (`NAME.gif`, looping) and, where `ffmpeg` is on the PATH, an MP4 (`NAME.mp4`,
//! H.264 in yuv420p, as players expect). They come from a scene's keyframed
//! [`animation`](super::animation) or from `focal render INPUT --turntable N`, an orbit
//! of N frames around the data.

use std::path::{Path, PathBuf};

use super::animation::Animation;
use super::file::{CameraSpec, Change, FrameSpec, SceneFile};

/// Frames a second of a turntable's GIF and MP4.
pub const FPS: u32 = super::animation::DEFAULT_FPS;

/// `scene` with `n` frames orbiting once about the superior axis from `azimuth_deg`, at
/// `elevation_deg` (the first frame is the view at `azimuth_deg`; frame k is at
/// `azimuth_deg + 360°·k/n`).
pub fn turntable(mut scene: SceneFile, n: u32, azimuth_deg: f32, elevation_deg: f32, orthographic: bool, zoom: f32) -> SceneFile {
    scene.frames = (0..n)
        .map(|k| FrameSpec {
            name: format!("turntable-{k:04}"),
            camera: Some(CameraSpec::Orbit { azimuth_deg: azimuth_deg + 360.0 * k as f32 / n as f32, elevation_deg, orthographic, zoom }),
            set: Vec::new(),
            settle: None,
        })
        .collect();
    scene
}

/// `scene`'s animation as frames `{prefix}-0000` …: each frame's camera and the changes
/// that set every track's value at its time, with 1/fps s of simulation before it when
/// a dataset is exploded. Starts from `scene` as the file gives it.
pub fn animation_frames(animation: &Animation, scene: &SceneFile, prefix: &str) -> Vec<FrameSpec> {
    let refers = scene.animation_refers();
    let exploded = refers.exploded.iter().any(|x| *x);
    let steps =
        if exploded { (crate::explode::ExplodeTiming::default().steps_per_second / animation.fps as f32).round() as u32 } else { 0 };
    (0..animation.frame_count())
        .map(|k| {
            let values = animation.values_at(animation.time_of(k), &scene.lenses, &refers);
            let mut set: Vec<Change> = values.contexts.into_iter().map(|(dataset, context)| Change::Context { dataset, context }).collect();
            set.extend(values.degrees.into_iter().map(|(dataset, d)| Change::Explode {
                dataset,
                degree: Some(d),
                viewing: None,
                deltas: None,
                fade: None,
            }));
            set.extend(values.lenses.map(Change::Lenses));
            FrameSpec { name: format!("{prefix}-{k:04}"), camera: values.camera, set, settle: Some(steps) }
        })
        .collect()
}

/// A movie being written into `dir` at `fps` frames a second, a frame at a time as it is
/// drawn: each frame's PNG (named as the frame), `{name}.gif` growing, and at the end
/// `{name}.mp4` where ffmpeg is.
pub struct MovieWriter {
    dir: PathBuf,
    name: String,
    fps: u32,
    gif: image::codecs::gif::GifEncoder<std::io::BufWriter<std::fs::File>>,
    written: Vec<PathBuf>,
}

impl MovieWriter {
    pub fn new(dir: &Path, name: &str, fps: u32) -> Result<MovieWriter, String> {
        use image::codecs::gif::{GifEncoder, Repeat};
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        let path = dir.join(format!("{name}.gif"));
        let fail = |e: &dyn std::fmt::Display| format!("{}: {e}", path.display());
        let file = std::fs::File::create(&path).map_err(|e| fail(&e))?;
        let mut gif = GifEncoder::new_with_speed(std::io::BufWriter::new(file), 10);
        gif.set_repeat(Repeat::Infinite).map_err(|e| fail(&e))?;
        Ok(MovieWriter { dir: dir.to_path_buf(), name: name.to_string(), fps, gif, written: Vec::new() })
    }

    /// Adds frame `frame` (its PNG's name).
    pub fn add(&mut self, frame: &str, image: &image::RgbaImage) -> Result<(), String> {
        let path = self.dir.join(format!("{frame}.png"));
        image.save(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        self.written.push(path);
        let delay = image::Delay::from_numer_denom_ms(1000, self.fps);
        self.gif
            .encode_frame(image::Frame::from_parts(image.clone(), 0, 0, delay))
            .map_err(|e| format!("{}: {e}", self.dir.join(format!("{}.gif", self.name)).display()))
    }

    /// Closes the GIF and makes the MP4; returns what was written.
    pub fn finish(self) -> Result<Vec<PathBuf>, String> {
        let MovieWriter { dir, name, fps, gif, mut written } = self;
        let count = written.len();
        drop(gif);
        written.push(dir.join(format!("{name}.gif")));
        match write_mp4(&dir, &name, fps, count) {
            Ok(Some(mp4)) => written.push(mp4),
            Ok(None) => eprintln!("no ffmpeg on the PATH: no MP4 (the PNG sequence and the GIF are written)"),
            Err(e) => eprintln!("warning: the MP4 was not written: {e}"),
        }
        Ok(written)
    }
}

/// `{name}.mp4` from the PNG sequence with ffmpeg; `None` where there is none.
/// (Only the first `count` frames: older, longer sequences may lie in the folder.)
fn write_mp4(dir: &Path, name: &str, fps: u32, count: usize) -> Result<Option<PathBuf>, String> {
    if std::process::Command::new("ffmpeg").arg("-version").output().is_err() {
        return Ok(None);
    }
    let mp4 = dir.join(format!("{name}.mp4"));
    let out = std::process::Command::new("ffmpeg")
        .args(["-y", "-loglevel", "error", "-framerate", &fps.to_string(), "-i"])
        .arg(dir.join(format!("{name}-%04d.png")))
        // (Even dimensions for yuv420p.)
        .args(["-frames:v", &count.to_string()])
        .args(["-vf", "pad=ceil(iw/2)*2:ceil(ih/2)*2", "-c:v", "libx264", "-pix_fmt", "yuv420p"])
        .arg(&mp4)
        .output()
        .map_err(|e| format!("ffmpeg: {e}"))?;
    if !out.status.success() {
        return Err(format!("ffmpeg: {}", String::from_utf8_lossy(&out.stderr).trim()));
    }
    Ok(Some(mp4))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_turntable_orbits_once_in_equal_steps() {
        let scene = SceneFile::parse("(datasets: [])", "test").unwrap();
        let t = turntable(scene, 8, 30.0, 20.0, false, 1.5);
        let azimuths: Vec<f32> = t
            .frames
            .iter()
            .map(|f| match f.camera {
                Some(CameraSpec::Orbit { azimuth_deg, elevation_deg, zoom, .. }) => {
                    assert_eq!((elevation_deg, zoom), (20.0, 1.5));
                    azimuth_deg
                }
                _ => panic!("not an orbit"),
            })
            .collect();
        assert_eq!(azimuths, vec![30.0, 75.0, 120.0, 165.0, 210.0, 255.0, 300.0, 345.0]);
        assert_eq!(t.frames[3].name, "turntable-0003");
    }

    #[test]
    fn an_animation_becomes_frames_with_each_tracks_changes() {
        let scene = SceneFile::parse(
            r#"(datasets: [(source: Phantom(kind: head, resolution: 16), appearance: (mode: context),
                            explode: Some((selection: Range(lo: 100, hi: 200), parts: Grid((2, 1, 1)))))],
                lenses: [(kind: magnifier(magnification: 2.0))],
                animation: Some((duration_s: 1, fps: 12, tracks: [
                    Explosion(dataset: 0, keys: [(t: 0, value: 0), (t: 1, value: 1)], ease: linear),
                    KappaT(dataset: 0, keys: [(t: 0, value: 2)]),
                ])))"#,
            "test",
        )
        .unwrap();
        scene.validate().unwrap();
        let frames = animation_frames(scene.animation.as_ref().unwrap(), &scene, "clip");
        assert_eq!(frames.len(), 13);
        assert_eq!(frames[6].name, "clip-0006");
        // Exploded: 1/12 s of simulation (10 steps of 1/120 s) before every frame.
        assert!(frames.iter().all(|f| f.settle == Some(10)));
        // Half-way: degree ½; κt 2 with the dataset's κs; no lens moves; no camera path.
        assert!(frames[6].set.contains(&Change::Explode { dataset: 0, degree: Some(0.5), viewing: None, deltas: None, fade: None }));
        let kappa_s = scene.datasets[0].appearance.context.kappa_s;
        assert!(
            frames[6]
                .set
                .iter()
                .any(|c| matches!(c, Change::Context { context, .. } if context.kappa_t == 2.0 && context.kappa_s == kappa_s))
        );
        assert!(!frames[6].set.iter().any(|c| matches!(c, Change::Lenses(_))));
        assert_eq!(frames[6].camera, None);
    }
}
