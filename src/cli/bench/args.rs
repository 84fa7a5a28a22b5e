//! `focal bench`'s command line, and the arguments of each of its processes
//! (`super::processes`).

use std::ffi::OsString;

use clap::Args;

#[derive(Args, Clone, Debug, PartialEq)]
pub struct BenchArgs {
    /// Rounds timed (a frame of every configuration each, after one untimed round), in
    /// all processes together.
    #[arg(long, default_value_t = 60)]
    pub(super) frames: u32,
    /// Processes of this program that take the rounds in turn, each row's ratio the mean
    /// of theirs: a process's own offset (where llvmpipe's shaders and textures land in
    /// memory) is not averaged by more rounds in it. 1: all in this one.
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=16))]
    pub(super) processes: u32,
    /// The standard error (%) aimed at for each ratio timed in rounds: after the first
    /// processes, a group with a row above it takes the same rounds again in one more
    /// process, until none is or --max-processes is reached (with --processes 2 or
    /// more). 0: no more processes.
    #[arg(long, default_value_t = 1.0, value_name = "PCT")]
    pub(super) precision: f64,
    /// At most this many processes for a group's rows, the first ones included.
    #[arg(long, default_value_t = 12, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub(super) max_processes: u32,
    /// Image size WIDTHxHEIGHT.
    #[arg(long, default_value = "256x256")]
    pub(super) size: String,
    /// Phantom resolution.
    #[arg(long, default_value_t = 128)]
    pub(super) resolution: u32,
    /// Only the empty-space-skipping group.
    #[arg(long)]
    pub(super) skipping: bool,
    /// Only the early-termination group.
    #[arg(long)]
    pub(super) termination: bool,
    /// Only the modes group.
    #[arg(long)]
    pub(super) modes: bool,
    /// Only the lenses group.
    #[arg(long)]
    pub(super) lenses: bool,
    /// Only the context-preserving group.
    #[arg(long)]
    pub(super) context: bool,
    /// Only the two-level group.
    #[arg(long)]
    pub(super) twolevel: bool,
    /// Only the volumetric windows group.
    #[arg(long)]
    pub(super) windows: bool,
    /// Only the exploded views group (the paper's table 1).
    #[arg(long)]
    pub(super) explode: bool,
    /// Only the bricked-streaming group (issue 23).
    #[arg(long)]
    pub(super) bricked: bool,
    /// Only the interactive-resolution group (the moving camera at fewer pixels).
    #[arg(long)]
    pub(super) interactive: bool,
    /// With --explode: only these part counts (1, 2, 4, 8, 16, 32, 64; comma-separated).
    #[arg(long, value_delimiter = ',', value_name = "N,...")]
    pub(super) parts: Vec<usize>,
    /// Print JSON.
    #[arg(long)]
    pub(super) json: bool,
    /// Save the picture of every configuration timed in rounds into this folder
    /// (`GROUP-N.png`, N in the order of the group's lines) and heat maps of their
    /// samples per ray (`GROUP-samples-N.png`).
    #[arg(long, value_name = "DIR")]
    pub(super) save: Option<std::path::PathBuf>,
}

impl BenchArgs {
    /// The groups by their flags' names, and whether each was asked for.
    pub(super) fn groups(&self) -> [(&'static str, bool); 10] {
        [
            ("skipping", self.skipping),
            ("termination", self.termination),
            ("modes", self.modes),
            ("lenses", self.lenses),
            ("context", self.context),
            ("twolevel", self.twolevel),
            ("windows", self.windows),
            ("explode", self.explode),
            ("bricked", self.bricked),
            ("interactive", self.interactive),
        ]
    }

    /// The arguments of one of its processes: `frames` rounds, JSON, one process; the
    /// picture folder only with `save`; `only` these groups (by their flags' names, as
    /// the rows name them), or those asked for.
    pub(super) fn child(&self, frames: u32, save: bool, only: Option<&[String]>) -> Vec<OsString> {
        let mut a: Vec<OsString> = ["bench", "--processes", "1", "--json", "--frames"].map(OsString::from).to_vec();
        a.push(frames.to_string().into());
        a.extend(["--size".into(), self.size.clone().into(), "--resolution".into(), self.resolution.to_string().into()]);
        a.extend(["--precision".into(), self.precision.to_string().into()]);
        a.extend(["--max-processes".into(), self.max_processes.to_string().into()]);
        let wanted = |flag: &str, asked: bool| only.map_or(asked, |only| only.iter().any(|g| g == flag));
        for (flag, asked) in self.groups() {
            if wanted(flag, asked) {
                a.push(format!("--{flag}").into());
            }
        }
        // (The part counts go with the exploded views: asked for, or every group.)
        let every = !self.groups().iter().any(|(_, asked)| *asked);
        let explode = wanted("explode", self.explode || every);
        if explode && !self.parts.is_empty() {
            a.push("--parts".into());
            a.push(self.parts.iter().map(|p| p.to_string()).collect::<Vec<_>>().join(",").into());
        }
        if save && let Some(dir) = &self.save {
            a.push("--save".into());
            a.push(dir.clone().into());
        }
        a
    }
}
