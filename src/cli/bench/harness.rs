//! The bench's machinery: an offscreen view that shows one volume, configurations timed
//! in interleaved rounds (each row's median frame and its per-round ratios, [`Paired`]),
//! samples counted by the CPU reference, and the rows of the report.

use std::sync::Arc;

use bevy::prelude::*;
use focal::dataset::{Dataset, VolumeView};
use focal::lens::Lens;
use focal::lens::systems::replace_lenses;
use focal::region::{Appearance, View};
use focal::render::counts::{RayCounts, decode};
use focal::render::headless::Offscreen;
use focal::volume::Volume;

#[derive(Clone, Debug)]
pub(super) struct Row {
    pub(super) group: String,
    pub(super) config: String,
    pub(super) ms: f64,
    pub(super) baseline: String,
    pub(super) ratio: f64,
    /// The picture's samples against the baseline's, where counted ([`Bench::counts`]
    /// on the GPU, or [`Bench::classified_samples`] by the CPU reference).
    pub(super) sample_ratio: Option<f64>,
    /// Half the interquartile range of the ratio over the rounds (each round's frame
    /// against the baseline's of the same round), where timed in rounds.
    pub(super) spread: Option<f64>,
    /// The ratio's standard error relative to it ([`Paired::se`]; over processes,
    /// `super::processes::combined_se`), where timed in rounds.
    pub(super) se: Option<f64>,
    /// The ray caster's passes on the GPU, ms per frame (timestamp queries).
    pub(super) gpu_ms: Option<f64>,
    pub(super) note: String,
    /// Each process's ratio, where the rounds ran in several (`super::processes`).
    pub(super) by_process: Vec<f64>,
}

/// A configuration's ratio against the first of its [`Bench::rounds`]: the geometric
/// mean of its per-round ratios (its frame time over the first configuration's in the
/// same round) with the lowest and highest fifth left out ([`TRIM`]), and half the
/// interquartile range of those ratios.
///
/// Why a trimmed mean and not the median: on llvmpipe on a shared two-core machine the
/// per-round ratios scatter by about ±10 % and nearly normally, where the median needs
/// about 1.6 times the rounds of a mean for the same precision; the trim keeps a frame
/// hit by other load from moving it. Three runs of `--lenses`, 60 rounds each (per-frame
/// times recorded with `FOCAL_BENCH_SAMPLES`), differed by at most 5.9 % per row with the
/// median and 2.7–2.8 % with such means (at 30 rounds: 7.8 % and about 4 %). Geometric,
/// as a ratio of two noisy times is skewed: its plain mean lies above the ratio of the
/// times by about the square of their scatter, the mean of its logarithm does not.
///
/// `se` is the standard error of that trimmed mean of the logarithms, which is the
/// ratio's standard error relative to it (Tukey and McLaughlin's estimate: the standard
/// deviation of the logarithms winsorized at the same cut, over (1 − 2·TRIM)·√n, as
/// `scipy.stats.mstats.trimmed_stde`); `super::processes` adds processes to a group
/// until each of its rows' is small enough.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) struct Paired {
    pub(super) ratio: f64,
    pub(super) spread: f64,
    pub(super) se: f64,
}

/// The share of the per-round ratios left out at each end of [`Paired::ratio`].
pub(super) const TRIM: f64 = 0.2;

impl Paired {
    /// From the per-round ratios.
    pub(super) fn of(mut ratios: Vec<f64>) -> Paired {
        if ratios.is_empty() {
            return Paired { ratio: f64::NAN, spread: f64::NAN, se: f64::NAN };
        }
        ratios.sort_by(f64::total_cmp);
        let q = |f: f64| {
            // Linear interpolation between order statistics (numpy's default).
            let x = f * (ratios.len() - 1) as f64;
            let (i, t) = (x.floor() as usize, x.fract());
            ratios[i] + (ratios[(i + 1).min(ratios.len() - 1)] - ratios[i]) * t
        };
        // (As scipy.stats.trim_mean of the logarithms: ⌊TRIM·n⌋ cut from each end.)
        let cut = (TRIM * ratios.len() as f64).floor() as usize;
        let n = ratios.len();
        let logs: Vec<f64> = ratios.iter().map(|r| r.max(f64::MIN_POSITIVE).ln()).collect();
        let kept = &logs[cut..n - cut];
        let log_mean = kept.iter().sum::<f64>() / kept.len() as f64;
        // The logarithms winsorized: each cut one replaced by the nearest kept one.
        let winsorized: Vec<f64> = logs.iter().map(|l| l.clamp(kept[0], kept[kept.len() - 1])).collect();
        let w_mean = winsorized.iter().sum::<f64>() / n as f64;
        let w_var = winsorized.iter().map(|l| (l - w_mean).powi(2)).sum::<f64>() / (n as f64 - 1.0);
        let se = if n < 2 { f64::NAN } else { w_var.sqrt() / ((1.0 - 2.0 * TRIM) * (n as f64).sqrt()) };
        Paired { ratio: log_mean.exp(), spread: 0.5 * (q(0.75) - q(0.25)), se }
    }
}

pub(super) struct Bench {
    pub(super) off: Offscreen,
    pub(super) frames: u32,
    pub(super) save: Option<std::path::PathBuf>,
    /// The camera of the last [`Self::place`].
    pub(super) camera: Option<focal::region::Camera>,
    /// The GPU's per-ray counts of each configuration of the last [`Self::rounds`]
    /// (`focal::render::counts`), from one frame of each before the timing.
    pub(super) counts: Vec<RayCounts>,
    /// The images of those counts (`--save` writes their heat maps).
    pub(super) count_images: Vec<image::RgbaImage>,
    /// Each configuration's ratio against the first of the last [`Self::rounds`].
    pub(super) paired: Vec<Paired>,
    /// Each configuration's ray-cast pass time on the GPU, where the adapter has
    /// timestamp queries ([`Self::gpu_pass_ms`]).
    pub(super) gpu_ms: Vec<Option<f64>>,
}

impl Bench {
    /// Shows `volume` alone, framed from the oblique view; the camera and the volume's
    /// centre.
    pub(super) fn place(&mut self, volume: Arc<Volume>, appearance: Appearance) -> (focal::region::Camera, Vec3) {
        let world = self.off.world_mut();
        let old: Vec<Entity> = world.query_filtered::<Entity, With<Dataset>>().iter(world).collect();
        for e in old {
            world.despawn(e);
        }
        let (lo, hi) = appearance.visible_bounds(&volume).unwrap_or_else(|| volume.grid.world_bounds());
        self.off.world_mut().spawn((Dataset::new(volume, appearance), Transform::default()));
        let camera = View::Oblique.frame_box(lo, hi, self.off.width as f32 / self.off.height as f32, false);
        self.off.set_camera(&camera);
        self.camera = Some(camera);
        (camera, (lo + hi) * 0.5)
    }
}

/// A configuration timed by [`Bench::interleaved`]: name, lenses, view switches.
pub(super) type Config = (&'static str, Vec<Lens>, VolumeView);

impl Bench {
    /// Shows `volume`, then times every configuration in rounds of one frame each and
    /// takes each configuration's median: drift of the machine (other load, clock
    /// changes) then hits all of them alike, which timing them one after another does
    /// not. With `orbit`, the camera turns half a degree about the volume before every
    /// frame (so what depends on the camera is recomputed each frame).
    pub(super) fn interleaved(
        &mut self,
        volume: Arc<Volume>,
        appearance: Appearance,
        configs: &[Config],
        orbit: bool,
    ) -> Result<(Vec<f64>, Vec<image::RgbaImage>), String> {
        self.interleaved_by(volume, appearance, configs.len(), orbit, |off, i| {
            let (_, lenses, view) = &configs[i];
            replace_lenses(off.world_mut(), lenses);
            off.set_view(*view);
        })
    }

    /// [`Self::interleaved`] over the appearances of one dataset (no lenses, `view`).
    pub(super) fn interleaved_appearances(
        &mut self,
        volume: Arc<Volume>,
        appearances: &[Appearance],
        view: VolumeView,
    ) -> Result<(Vec<f64>, Vec<image::RgbaImage>), String> {
        let first = appearances.first().ok_or("no appearance to time")?.clone();
        self.interleaved_by(volume, first, appearances.len(), false, |off, i| {
            off.set_view(view);
            let world = off.world_mut();
            let mut q = world.query::<&mut Dataset>();
            for mut d in q.iter_mut(world) {
                d.appearance = appearances[i].clone();
            }
        })
    }

    /// The timing loop of [`Self::interleaved`]: `set(off, i)` switches to
    /// configuration `i` of `count`.
    pub(super) fn interleaved_by(
        &mut self,
        volume: Arc<Volume>,
        appearance: Appearance,
        count: usize,
        orbit: bool,
        set: impl FnMut(&mut Offscreen, usize),
    ) -> Result<(Vec<f64>, Vec<image::RgbaImage>), String> {
        let (camera, centre) = self.place(volume, appearance);
        self.rounds(camera, centre, count, orbit, set)
    }

    /// The rounds of [`Self::interleaved_by`] over what the view shows now, seen by
    /// `camera` (orbiting about `centre` with `orbit`).
    pub(super) fn rounds(
        &mut self,
        camera: focal::region::Camera,
        centre: Vec3,
        count: usize,
        orbit: bool,
        mut set: impl FnMut(&mut Offscreen, usize),
    ) -> Result<(Vec<f64>, Vec<image::RgbaImage>), String> {
        let mut turn = 0u32;
        // Every configuration once first (pipelines, atlases), its picture and its
        // samples.
        let mut images = Vec::new();
        self.counts.clear();
        self.count_images.clear();
        for i in 0..count {
            set(&mut self.off, i);
            images.push(self.off.capture()?);
            let counts = self.off.capture_counts()?;
            self.counts.push(decode(&counts));
            self.count_images.push(counts);
        }
        let mut times = vec![Vec::new(); count];
        // One round untimed (caches, clocks), then the timed ones.
        for round in 0..=self.frames {
            for (i, samples) in times.iter_mut().enumerate() {
                set(&mut self.off, i);
                // (An untimed frame first takes the switch.)
                let t = self.off.time_frames_with(1, |off, _| {
                    if orbit {
                        turn += 1;
                        off.set_camera(&orbited(&camera, centre, turn));
                    }
                });
                if round > 0 {
                    samples.push(t.as_secs_f64() * 1000.0);
                }
            }
        }
        self.paired = times.iter().map(|v| Paired::of(v.iter().zip(&times[0]).map(|(t, base)| t / base.max(1e-9)).collect())).collect();
        self.gpu_ms = (0..count)
            .map(|i| {
                set(&mut self.off, i);
                self.gpu_pass_ms()
            })
            .collect();
        if std::env::var_os("FOCAL_BENCH_SAMPLES").is_some() {
            for (i, v) in times.iter().enumerate() {
                eprintln!("config {i}: {}", v.iter().map(|t| format!("{t:.0}")).collect::<Vec<_>>().join(" "));
            }
        }
        let medians = times
            .into_iter()
            .map(|mut v| {
                v.sort_by(f64::total_cmp);
                v[v.len() / 2]
            })
            .collect();
        Ok((medians, images))
    }
}

impl Bench {
    /// The samples the regions take in each of `count` configurations (`set` switches to
    /// one, as for [`Self::interleaved_by`]), counted by the CPU reference
    /// ([`focal::reference::RenderedImage::classified`]) at 128 pixels across with the
    /// bench's camera: what each picture costs a ray caster that skips empty space,
    /// whatever its hardware.
    pub(super) fn classified_samples(&mut self, count: usize, mut set: impl FnMut(&mut Offscreen, usize)) -> Result<Vec<u64>, String> {
        let camera = self.camera.ok_or("no view placed to count samples in")?;
        let across = 128.0 / self.off.width.max(self.off.height) as f32;
        let (w, h) = ((self.off.width as f32 * across).round().max(1.0) as u32, (self.off.height as f32 * across).round().max(1.0) as u32);
        (0..count)
            .map(|i| {
                set(&mut self.off, i);
                self.off.update();
                let scene = self.off.world_mut().resource::<focal::dataset::SceneRegions>().scene.clone();
                Ok(focal::reference::render(&scene, &camera, w, h)?.classified)
            })
            .collect()
    }
}

/// The passes of the ray caster, as `render::pass` names their diagnostics spans.
const PASSES: [&str; 2] = ["focal_raycast", "focal_upscale"];

/// Frames each configuration runs for its GPU pass times: the first half is left out
/// (read back late, their times may be the previous configuration's).
const GPU_FRAMES: usize = 6;

impl Bench {
    /// The GPU time of the ray caster's passes in the view as it is now (the median over
    /// the second half of [`GPU_FRAMES`] frames), from Bevy's render diagnostics
    /// (timestamp queries); `None` where the adapter has none.
    pub(super) fn gpu_pass_ms(&mut self) -> Option<f64> {
        use bevy::diagnostic::{DiagnosticPath, DiagnosticsStore};
        // (A pass's last measurement stays in the store after the pass is gone: only
        // those taken since this configuration began count.)
        for _ in 0..GPU_FRAMES / 2 {
            self.off.update();
        }
        let start = std::time::Instant::now();
        let mut each = Vec::new();
        for _ in 0..GPU_FRAMES / 2 {
            self.off.update();
            let store = self.off.world_mut().get_resource::<DiagnosticsStore>()?;
            let fresh: Vec<f64> = PASSES
                .iter()
                .filter_map(|p| store.get(&DiagnosticPath::new(format!("render/{p}/elapsed_gpu"))))
                .filter_map(|d| d.measurement().filter(|m| m.time >= start).map(|m| m.value))
                .collect();
            each.push((!fresh.is_empty()).then(|| fresh.iter().sum::<f64>()));
        }
        let mut last: Vec<f64> = each.into_iter().flatten().collect();
        last.sort_by(f64::total_cmp);
        last.get(last.len() / 2).copied()
    }
}

/// `camera` turned `turn` half degrees about the vertical through `centre` (the bench's
/// orbit: what depends on the camera is recomputed every frame).
pub(super) fn orbited(camera: &focal::region::Camera, centre: Vec3, turn: u32) -> focal::region::Camera {
    let q = Quat::from_rotation_y(turn as f32 * 0.5f32.to_radians());
    focal::region::Camera { position: centre + q * (camera.position - centre), rotation: q * camera.rotation, ..*camera }
}

/// Names of configurations.
pub(super) fn names(configs: &[Config]) -> Vec<&'static str> {
    configs.iter().map(|c| c.0).collect()
}

impl Bench {
    /// Writes a group's pictures when `--save` asked for them, and the heat maps of the
    /// samples of the last [`Self::rounds`]' configurations (`GROUP-samples-N.png`, all
    /// on the scale of the group's most samples in a ray, printed).
    pub(super) fn save_images(&self, group: &str, images: &[image::RgbaImage]) -> Result<(), String> {
        let Some(dir) = &self.save else { return Ok(()) };
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
        for (i, im) in images.iter().enumerate() {
            let path = dir.join(format!("{group}-{i}.png"));
            im.save(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        let most = self.counts.iter().map(|c| c.most).max().unwrap_or(0);
        for (i, counts) in self.count_images.iter().enumerate() {
            let path = dir.join(format!("{group}-samples-{i}.png"));
            focal::render::counts::heat_map(counts, most).save(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        }
        if !self.count_images.is_empty() {
            eprintln!("{group}: sample heat maps scaled to {most} samples a ray (white)");
        }
        Ok(())
    }
}

impl Row {
    /// The frame rate as a percentage of the baseline's (the paper's table 1 reports
    /// it so): 100 / ratio.
    pub(super) fn frame_rate_percent(&self) -> f64 {
        100.0 / self.ratio.max(1e-9)
    }
}

/// The rows of a group timed by [`Bench::rounds`], the first its baseline, each with its
/// paired ratio and spread ([`Bench::paired`]) and its picture's GPU samples against the
/// baseline's ([`Bench::counts`]).
pub(super) fn push_group(rows: &mut Vec<Row>, bench: &Bench, group: &'static str, names: &[&str], ms: &[f64], base_note: &str, note: &str) {
    let base = names[0].to_string();
    let base_samples = bench.counts.first().map(|c| c.samples);
    for (i, (name, t)) in names.iter().zip(ms).enumerate() {
        let note = if i == 0 { base_note } else { note };
        rows.push(Row {
            group: group.into(),
            config: name.to_string(),
            ms: *t,
            baseline: base.clone(),
            ratio: bench.paired.get(i).map_or(t / ms[0].max(1e-9), |p| p.ratio),
            sample_ratio: base_samples.zip(bench.counts.get(i)).map(|(b, c)| c.samples as f64 / b.max(1) as f64),
            spread: bench.paired.get(i).map(|p| p.spread),
            se: bench.paired.get(i).map(|p| p.se),
            gpu_ms: bench.gpu_ms.get(i).copied().flatten(),
            note: note.into(),
            by_process: Vec::new(),
        });
    }
}

/// The CPU the bench runs on, from `/proc/cpuinfo`'s first model name (and family and
/// model, which tell a generation apart where the name does not), with its threads.
pub(super) fn cpu(cpuinfo: &str, threads: usize) -> String {
    let field =
        |key: &str| cpuinfo.lines().find_map(|l| l.split_once(':').filter(|(k, _)| k.trim() == key).map(|(_, v)| v.trim().to_string()));
    let name = field("model name").unwrap_or_else(|| "an unknown CPU".into());
    let generation = field("cpu family").zip(field("model")).map_or(String::new(), |(f, m)| format!(", family {f} model {m}"));
    format!("{name}{generation}, {threads} threads")
}

/// Largest channel difference between two images, in 8-bit levels.
pub(super) fn difference(a: &image::RgbaImage, b: &image::RgbaImage) -> u8 {
    a.pixels().zip(b.pixels()).flat_map(|(p, q)| (0..3).map(move |c| p[c].abs_diff(q[c]))).max().unwrap_or(0)
}

/// The share (%) of the pixels drawn in either picture (not black in both) where some
/// channel differs by more than `levels`.
pub(super) fn share_differing(a: &image::RgbaImage, b: &image::RgbaImage, levels: u8) -> f64 {
    let drawn = |p: &image::Rgba<u8>| p.0[..3].iter().any(|&c| c > 0);
    let (mut n, mut over) = (0usize, 0usize);
    for (p, q) in a.pixels().zip(b.pixels()).filter(|(p, q)| drawn(p) || drawn(q)) {
        n += 1;
        over += usize::from((0..3).any(|c| p[c].abs_diff(q[c]) > levels));
    }
    100.0 * over as f64 / n.max(1) as f64
}

#[cfg(test)]
mod tests {
    use super::{Paired, cpu};

    #[test]
    fn the_cpu_is_named_with_its_family_model_and_threads() {
        let info = "processor\t: 0\nvendor_id\t: AuthenticAMD\ncpu family\t: 25\nmodel\t\t: 1\nmodel name\t: AMD EPYC\n\nprocessor\t: 1\nmodel name\t: AMD EPYC\n";
        assert_eq!(cpu(info, 2), "AMD EPYC, family 25 model 1, 2 threads");
        assert_eq!(cpu("", 4), "an unknown CPU, 4 threads");
    }

    #[test]
    fn a_paired_ratio_is_the_trimmed_geometric_mean_and_half_the_interquartile_range() {
        // Five: ⌊0.2·5⌋ = 1 cut from each end of 1.0 1.25 1.6 2.0 9.0 (the outlier 9.0
        // left out), the geometric mean of 1.25 1.6 2.0 = ∛4 (numpy:
        // np.exp(np.mean(np.log([1.25, 1.6, 2.0])))); quartiles at 1.25 and 2.0.
        // Its standard error: scipy.stats.mstats.trimmed_stde(np.log(r), limits=(0.2, 0.2)).
        let p = Paired::of(vec![2.0, 1.0, 9.0, 1.6, 1.25]);
        assert!((p.ratio - 4f64.cbrt()).abs() < 1e-12 && (p.spread - 0.375).abs() < 1e-12, "{p:?}");
        assert!((p.se - 0.175204605085629).abs() < 1e-12, "{p:?}");
        // Ten: two cut from each end, the middle six 1.0 1.0 1.0 1.1 1.9 2.0: their
        // geometric mean 4.18^(1/6) = 1.269… (numpy; the median would be 1.05, the
        // plain mean 1.333). Quartiles (numpy) at 1.0 and 1.975.
        let p = Paired::of(vec![9.0, 1.0, 0.1, 1.1, 8.0, 1.0, 0.2, 1.9, 1.0, 2.0]);
        assert!((p.ratio - 4.18f64.powf(1.0 / 6.0)).abs() < 1e-12 && (p.spread - 0.4875).abs() < 1e-12, "{p:?}");
        assert!((p.se - 0.181649911596974).abs() < 1e-12, "{p:?}");
        // Four: none cut (⌊0.8⌋ = 0): the geometric mean of 1.0 1.1 1.1 1.21 is
        // 1.4641^(1/4) = 1.1; quartiles at 1.075 and 1.1275.
        let p = Paired::of(vec![1.0, 1.1, 1.21, 1.1]);
        assert!((p.ratio - 1.1).abs() < 1e-12 && (p.spread - 0.02625).abs() < 1e-12, "{p:?}");
        assert!(Paired::of(Vec::new()).ratio.is_nan() && Paired::of(vec![1.2]).se.is_nan());
    }
}
