//! The bench's rounds spread over several processes of this binary, one after another,
//! and each row's ratio averaged over them (`focal bench --processes N`, default 3).
//!
//! Why: on llvmpipe a process has an offset of its own. Three runs of `--windows`, 60
//! rounds each, agreed within 1–3 % on most rows, but in one of them the baseline took
//! 92.1 ms a frame against 88.7 ms in another while every other row took less, so every
//! ratio of that run sat 2–6 % low: far beyond the 0.7 % that the scatter of its 60
//! rounds leaves (docs/performance.md, "Noise"). Where llvmpipe's compiled shaders and
//! the textures land in memory is fixed for a process, so more rounds in one process do
//! not average it; rounds in several processes do. Each process (`--processes 1
//! --json`, ⌈frames / N⌉ rounds) measures every row as a single run would; a row's
//! ratio is the mean of the processes' ratios (`ratio_by_process` in `--json`), its
//! `ms` and GPU time their medians, its spread the mean of theirs.
//!
//! How many processes: as many as a group's rows need for their ratios to agree from
//! run to run. Each process reports each ratio's standard error from its rounds
//! (`harness::Paired::se`); the mean's is the larger of what those leave and what the
//! processes' own scatter shows ([`combined_se`]). Where a row's is above `--precision`
//! (1 % by default), its group takes the same rounds again in one more process, and
//! again, up to `--max-processes` (12). At 1 % three runs' ratios lie within 3 % of
//! each other nine times in ten (the range of three draws of a normal scatter exceeds
//! 3 σ one time in ten). The rows' per-round ratios scatter by 4–15 % (one standard
//! deviation) on llvmpipe: from 20 rounds to about 240 ("own values").

use std::path::Path;
use std::process::{Command, Stdio};

use serde_json::Value;

use super::args::BenchArgs;
use super::harness::Row;

/// Runs `args` in `args.processes` processes of this binary, then more for the groups
/// whose rows are not yet precise enough ([`noisy_groups`]), and merges their rows.
pub(super) fn measure(args: &BenchArgs) -> Result<Vec<Row>, String> {
    let n = args.processes.max(1);
    let frames = args.frames.max(1).div_ceil(n);
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this program to run the bench's processes: {e}"))?;
    let mut runs = Vec::new();
    for k in 0..n {
        eprintln!("bench process {} of {n} ({frames} rounds)", k + 1);
        // (Only the first process saves the pictures: they are the same in each.)
        let (rows, stderr) = run(&exe, &args.child(frames, k == 0, None), &format!("{} of {n}", k + 1))?;
        if k == 0
            && let Some(gpu) = stderr.lines().find(|l| l.starts_with("GPU: "))
        {
            eprintln!("{gpu}, in {n} processes");
        }
        runs.push(rows);
    }
    let mut per_row = gather(runs)?;
    let target = args.precision / 100.0;
    for more in 1..=args.max_processes.saturating_sub(n) {
        let merged: Vec<Row> = per_row.iter().map(|all| combine(all)).collect();
        let noisy = noisy_groups(&merged, target);
        if noisy.is_empty() {
            break;
        }
        for r in merged.iter().filter(|r| noisy_row(r, target)) {
            eprintln!(
                "bench: {} / {}: ×{:.3}, standard error {:.2} % after {} processes (aim {} %)",
                r.group,
                r.config,
                r.ratio,
                100.0 * r.se.unwrap_or(f64::NAN),
                r.by_process.len(),
                args.precision
            );
        }
        eprintln!("bench process {} ({frames} rounds of {})", n + more, noisy.join(", "));
        let (rows, _) = run(&exe, &args.child(frames, false, Some(&noisy)), &format!("{}", n + more))?;
        absorb(&mut per_row, rows)?;
    }
    Ok(per_row.iter().map(|all| combine(all)).collect())
}

/// One process of the bench: its rows, and what it wrote on standard error.
fn run(exe: &Path, args: &[std::ffi::OsString], which: &str) -> Result<(Vec<Row>, String), String> {
    let out = Command::new(exe)
        .args(args)
        .stdin(Stdio::null())
        .output()
        .map_err(|e| format!("cannot start the bench process {}: {e}", exe.display()))?;
    let stderr = String::from_utf8_lossy(&out.stderr).to_string();
    if !out.status.success() {
        let tail: Vec<&str> = stderr.lines().rev().take(12).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(format!("bench process {which} failed ({}):\n{}", out.status, tail.join("\n")));
    }
    let v: Value = serde_json::from_slice(&out.stdout).map_err(|e| format!("bench process {which}: its JSON: {e}"))?;
    Ok((rows_of(&v).map_err(|e| format!("bench process {which}: {e}"))?, stderr))
}

/// Whether a row timed in rounds has a standard error above `target` (relative; 0: none
/// is ever above it).
fn noisy_row(r: &Row, target: f64) -> bool {
    target > 0.0 && r.se.is_some_and(|se| se > target)
}

/// The groups with a row above the aimed standard error, in the order of the rows.
fn noisy_groups(rows: &[Row], target: f64) -> Vec<String> {
    let mut groups: Vec<String> = Vec::new();
    for r in rows.iter().filter(|r| noisy_row(r, target)) {
        if !groups.contains(&r.group) {
            groups.push(r.group.clone());
        }
    }
    groups
}

/// The rows of a process's `--json`.
fn rows_of(v: &Value) -> Result<Vec<Row>, String> {
    let rows = v.as_array().ok_or("not a list of rows")?;
    rows.iter()
        .enumerate()
        .map(|(i, r)| {
            let text = |key: &str| r[key].as_str().map(str::to_string).ok_or_else(|| format!("row {i} has no '{key}'"));
            let number = |key: &str| r[key].as_f64();
            Ok(Row {
                group: text("group")?,
                config: text("config")?,
                ms: number("ms_per_frame").ok_or_else(|| format!("row {i} has no 'ms_per_frame'"))?,
                baseline: text("baseline")?,
                // (JSON has no NaN: serde_json writes a ratio that could not be taken as null.)
                ratio: number("ratio").unwrap_or(f64::NAN),
                sample_ratio: number("sample_ratio"),
                spread: number("ratio_spread"),
                se: number("ratio_se"),
                gpu_ms: number("gpu_pass_ms"),
                note: text("note").unwrap_or_default(),
                by_process: Vec::new(),
            })
        })
        .collect()
}

/// The first processes' rows gathered row by row (each of them measures the same rows
/// in the same order): each row's measurements, one per process.
fn gather(runs: Vec<Vec<Row>>) -> Result<Vec<Vec<Row>>, String> {
    let mut runs = runs.into_iter();
    let Some(first) = runs.next() else { return Ok(Vec::new()) };
    let mut per_row: Vec<Vec<Row>> = first.into_iter().map(|r| vec![r]).collect();
    for (k, run) in runs.enumerate() {
        for (i, all) in per_row.iter_mut().enumerate() {
            let row = &all[0];
            let other = run.get(i).filter(|o| o.group == row.group && o.config == row.config);
            let other =
                other.ok_or_else(|| format!("bench process {} did not measure '{} / {}' as row {i}", k + 2, row.group, row.config))?;
            all.push(other.clone());
        }
    }
    Ok(per_row)
}

/// A later process's rows (of some groups only) added to the rows they measured again.
fn absorb(per_row: &mut [Vec<Row>], rows: Vec<Row>) -> Result<(), String> {
    for r in rows {
        let all = per_row
            .iter_mut()
            .find(|all| all[0].group == r.group && all[0].config == r.config)
            .ok_or_else(|| format!("a later bench process measured '{} / {}', which the first did not", r.group, r.config))?;
        all.push(r);
    }
    Ok(())
}

/// A row's measurements in several processes merged: the mean ratio, the median ms and
/// GPU time, the mean spread, the standard error of the mean ratio ([`combined_se`]).
fn combine(all: &[Row]) -> Row {
    let ratios: Vec<f64> = all.iter().map(|r| r.ratio).collect();
    let spreads: Option<Vec<f64>> = all.iter().map(|r| r.spread).collect();
    let ses: Option<Vec<f64>> = all.iter().map(|r| r.se).collect();
    let gpu: Option<Vec<f64>> = all.iter().map(|r| r.gpu_ms).collect();
    Row {
        ratio: ratios.iter().sum::<f64>() / ratios.len() as f64,
        ms: median(all.iter().map(|r| r.ms).collect()),
        spread: spreads.map(|s| s.iter().sum::<f64>() / s.len() as f64),
        se: ses.map(|s| combined_se(&ratios, &s)),
        gpu_ms: gpu.map(median),
        by_process: ratios,
        ..all[0].clone()
    }
}

/// The standard error of the mean of `k` processes' ratios, relative to it, each with
/// its own relative standard error `ses` (from its rounds): the larger of what the
/// rounds' scatter leaves (√Σse² / k) and what the processes' own scatter shows (their
/// standard deviation over √k, from two processes on). The second holds the offset of
/// each process, which the first cannot see; the first keeps two or three processes that
/// happen to agree from passing for more precise than their rounds allow.
fn combined_se(ratios: &[f64], ses: &[f64]) -> f64 {
    let k = ratios.len() as f64;
    let within = ses.iter().map(|s| s * s).sum::<f64>().sqrt() / k;
    if ratios.len() < 2 {
        return within;
    }
    let mean = ratios.iter().sum::<f64>() / k;
    let sd = (ratios.iter().map(|r| (r - mean).powi(2)).sum::<f64>() / (k - 1.0)).sqrt();
    within.max(sd / k.sqrt() / mean)
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    let n = v.len();
    match n {
        0 => f64::NAN,
        _ if n % 2 == 1 => v[n / 2],
        _ => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;
    use std::ffi::OsString;

    #[derive(Parser)]
    struct Cli {
        #[command(subcommand)]
        command: Sub,
    }

    #[derive(clap::Subcommand)]
    enum Sub {
        Bench(BenchArgs),
    }

    fn parse(args: &[OsString]) -> BenchArgs {
        let Sub::Bench(a) = Cli::parse_from(std::iter::once(OsString::from("focal")).chain(args.iter().cloned())).command;
        a
    }

    #[test]
    fn a_process_measures_what_was_asked_in_its_share_of_the_rounds() {
        let asked = parse(
            &["bench", "--lenses", "--explode", "--parts", "1,64", "--frames", "7", "--size", "64x32", "--save", "pics"]
                .map(OsString::from),
        );
        assert_eq!(asked.processes, 3);
        let child = parse(&asked.child(3, true, None));
        assert_eq!(child, BenchArgs { frames: 3, processes: 1, json: true, ..asked.clone() });
        let later = parse(&asked.child(3, false, None));
        assert_eq!(later, BenchArgs { frames: 3, processes: 1, json: true, save: None, ..asked.clone() });
        // A later process for the noisy groups only (the parts go with the exploded views).
        let more = parse(&asked.child(3, false, Some(&["explode".to_string()])));
        assert_eq!(more, BenchArgs { frames: 3, processes: 1, json: true, save: None, lenses: false, ..asked.clone() });
        let more = parse(&asked.child(3, false, Some(&["lenses".to_string()])));
        assert_eq!(more, BenchArgs { frames: 3, processes: 1, json: true, save: None, explode: false, parts: Vec::new(), ..asked });
        // Asked for every group (no flag): a later process names those it measures again.
        let all = parse(&["bench", "--precision", "0.5", "--max-processes", "5"].map(OsString::from));
        assert_eq!((all.precision, all.max_processes), (0.5, 5));
        let more = parse(&all.child(20, false, Some(&["twolevel".to_string(), "windows".to_string()])));
        assert_eq!(more, BenchArgs { frames: 20, processes: 1, json: true, twolevel: true, windows: true, ..all });
    }

    fn row(config: &str, ms: f64, ratio: f64, spread: Option<f64>) -> Row {
        Row {
            group: "g".into(),
            config: config.into(),
            ms,
            baseline: "base".into(),
            ratio,
            sample_ratio: Some(1.5),
            spread,
            se: spread.map(|s| s / 10.0),
            gpu_ms: Some(ms),
            note: String::new(),
            by_process: Vec::new(),
        }
    }

    #[test]
    fn rows_merge_to_the_mean_ratio_and_the_median_times() {
        let runs = vec![
            vec![row("base", 100.0, 1.0, Some(0.0)), row("a", 150.0, 1.50, Some(0.10))],
            vec![row("base", 90.0, 1.0, Some(0.0)), row("a", 140.0, 1.56, Some(0.04))],
            vec![row("base", 120.0, 1.0, Some(0.0)), row("a", 160.0, 1.47, None)],
        ];
        let merged: Vec<Row> = gather(runs).unwrap().iter().map(|all| combine(all)).collect();
        let a = &merged[1];
        assert!((a.ratio - 1.51).abs() < 1e-12, "{}", a.ratio);
        assert_eq!((a.ms, a.gpu_ms, a.spread, a.sample_ratio), (150.0, Some(150.0), None, Some(1.5)));
        assert_eq!(a.by_process, [1.50, 1.56, 1.47]);
        assert_eq!(merged[0].ms, 100.0);
        assert_eq!(median(vec![3.0, 1.0, 2.0, 10.0]), 2.5);
        // A process that measured other rows is an error, not a wrong mean.
        let odd = vec![vec![row("base", 1.0, 1.0, None)], vec![row("other", 1.0, 1.0, None)]];
        assert!(gather(odd).unwrap_err().contains("did not measure 'g / base'"));
    }

    #[test]
    fn a_later_process_adds_to_the_rows_it_measured_again() {
        let mut other = row("x", 50.0, 2.0, Some(0.2));
        other.group = "h".into();
        let mut per_row = gather(vec![vec![row("base", 100.0, 1.0, Some(0.0)), row("a", 150.0, 1.5, Some(0.1)), other.clone()]]).unwrap();
        absorb(&mut per_row, vec![row("base", 100.0, 1.0, Some(0.0)), row("a", 160.0, 1.6, Some(0.1))]).unwrap();
        let merged: Vec<Row> = per_row.iter().map(|all| combine(all)).collect();
        assert_eq!((merged[1].by_process.as_slice(), merged[2].by_process.as_slice()), ([1.5, 1.6].as_slice(), [2.0].as_slice()));
        assert!(absorb(&mut per_row, vec![row("new", 1.0, 1.0, None)]).unwrap_err().contains("'g / new'"));
    }

    #[test]
    fn a_mean_ratio_s_standard_error_is_the_larger_of_its_rounds_and_its_processes() {
        // Processes apart by more than their rounds' scatter says: their own standard
        // deviation (0.0458…) over √3, relative to the mean 1.51 (numpy: 0.0175215…).
        let se = combined_se(&[1.50, 1.56, 1.47], &[0.01, 0.02, 0.02]);
        assert!((se - 0.017521531861355).abs() < 1e-12, "{se}");
        // Processes that agree: what their rounds leave, √(0.03² + 0.04²) / 2.
        assert!((combined_se(&[1.0, 1.0], &[0.03, 0.04]) - 0.025).abs() < 1e-12);
        assert_eq!(combined_se(&[1.2], &[0.02]), 0.02);
        // Which groups need another process at 1 %: those with a row above it; rows not
        // timed in rounds (no standard error) never ask for one, nor does an aim of 0.
        let mut rows = vec![row("base", 1.0, 1.0, Some(0.0)), row("a", 1.0, 1.2, Some(0.2)), row("b", 1.0, 1.2, None)];
        rows[2].group = "h".into();
        assert_eq!(noisy_groups(&rows, 0.01), ["g"]);
        assert!(noisy_groups(&rows, 0.03).is_empty() && noisy_groups(&rows, 0.0).is_empty());
    }

    #[test]
    fn a_process_s_json_reads_back_as_its_rows() {
        let v = serde_json::json!([{"group": "lenses", "config": "no lens", "ms_per_frame": 99.0, "baseline": "no lens", "ratio": 1.0,
            "sample_ratio": null, "ratio_spread": 0.0, "ratio_se": 0.01, "gpu_pass_ms": null, "note": "head"}]);
        let rows = rows_of(&v).unwrap();
        assert_eq!((rows[0].group.as_str(), rows[0].ms, rows[0].spread, rows[0].sample_ratio), ("lenses", 99.0, Some(0.0), None));
        assert_eq!(rows[0].se, Some(0.01));
        assert!(rows_of(&serde_json::json!([{"config": "x"}])).unwrap_err().contains("row 0 has no 'group'"));
    }
}
