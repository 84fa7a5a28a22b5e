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

use std::process::{Command, Stdio};

use serde_json::Value;

use super::args::BenchArgs;
use super::harness::Row;

/// Runs `args` in `args.processes` processes of this binary and merges their rows.
pub(super) fn measure(args: &BenchArgs) -> Result<Vec<Row>, String> {
    let n = args.processes.max(1);
    let frames = args.frames.max(1).div_ceil(n);
    let exe = std::env::current_exe().map_err(|e| format!("cannot find this program to run the bench's processes: {e}"))?;
    let mut runs = Vec::new();
    for k in 0..n {
        eprintln!("bench process {} of {n} ({frames} rounds)", k + 1);
        // (Only the first process saves the pictures: they are the same in each.)
        let out = Command::new(&exe)
            .args(args.child(frames, k == 0))
            .stdin(Stdio::null())
            .output()
            .map_err(|e| format!("cannot start the bench process {}: {e}", exe.display()))?;
        let stderr = String::from_utf8_lossy(&out.stderr);
        if !out.status.success() {
            let tail: Vec<&str> = stderr.lines().rev().take(12).collect();
            let tail: Vec<&str> = tail.into_iter().rev().collect();
            return Err(format!("bench process {} of {n} failed ({}):\n{}", k + 1, out.status, tail.join("\n")));
        }
        if k == 0
            && let Some(gpu) = stderr.lines().find(|l| l.starts_with("GPU: "))
        {
            eprintln!("{gpu}, in {n} processes");
        }
        let v: Value = serde_json::from_slice(&out.stdout).map_err(|e| format!("bench process {} of {n}: its JSON: {e}", k + 1))?;
        runs.push(rows_of(&v).map_err(|e| format!("bench process {} of {n}: {e}", k + 1))?);
    }
    merge(runs)
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
                gpu_ms: number("gpu_pass_ms"),
                note: text("note").unwrap_or_default(),
                by_process: Vec::new(),
            })
        })
        .collect()
}

/// The processes' rows merged row by row (each process measures the same rows in the
/// same order): the mean ratio, the median ms and GPU time, the mean spread.
fn merge(runs: Vec<Vec<Row>>) -> Result<Vec<Row>, String> {
    let mut runs = runs.into_iter();
    let Some(first) = runs.next() else { return Ok(Vec::new()) };
    let rest: Vec<Vec<Row>> = runs.collect();
    first
        .into_iter()
        .enumerate()
        .map(|(i, row)| {
            let mut all = vec![&row];
            for (k, run) in rest.iter().enumerate() {
                let other = run.get(i).filter(|o| o.group == row.group && o.config == row.config);
                all.push(
                    other.ok_or_else(|| format!("bench process {} did not measure '{} / {}' as row {i}", k + 2, row.group, row.config))?,
                );
            }
            let ratios: Vec<f64> = all.iter().map(|r| r.ratio).collect();
            let spreads: Option<Vec<f64>> = all.iter().map(|r| r.spread).collect();
            let gpu: Option<Vec<f64>> = all.iter().map(|r| r.gpu_ms).collect();
            Ok(Row {
                ratio: ratios.iter().sum::<f64>() / ratios.len() as f64,
                ms: median(all.iter().map(|r| r.ms).collect()),
                spread: spreads.map(|s| s.iter().sum::<f64>() / s.len() as f64),
                gpu_ms: gpu.map(median),
                by_process: ratios,
                ..row.clone()
            })
        })
        .collect()
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
        let child = parse(&asked.child(3, true));
        assert_eq!(child, BenchArgs { frames: 3, processes: 1, json: true, ..asked.clone() });
        let later = parse(&asked.child(3, false));
        assert_eq!(later, BenchArgs { frames: 3, processes: 1, json: true, save: None, ..asked });
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
        let merged = merge(runs).unwrap();
        let a = &merged[1];
        assert!((a.ratio - 1.51).abs() < 1e-12, "{}", a.ratio);
        assert_eq!((a.ms, a.gpu_ms, a.spread, a.sample_ratio), (150.0, Some(150.0), None, Some(1.5)));
        assert_eq!(a.by_process, [1.50, 1.56, 1.47]);
        assert_eq!(merged[0].ms, 100.0);
        assert_eq!(median(vec![3.0, 1.0, 2.0, 10.0]), 2.5);
        // A process that measured other rows is an error, not a wrong mean.
        let odd = vec![vec![row("base", 1.0, 1.0, None)], vec![row("other", 1.0, 1.0, None)]];
        assert!(merge(odd).unwrap_err().contains("did not measure 'g / base'"));
    }

    #[test]
    fn a_process_s_json_reads_back_as_its_rows() {
        let v = serde_json::json!([{"group": "lenses", "config": "no lens", "ms_per_frame": 99.0, "baseline": "no lens", "ratio": 1.0,
            "sample_ratio": null, "ratio_spread": 0.0, "gpu_pass_ms": null, "note": "head"}]);
        let rows = rows_of(&v).unwrap();
        assert_eq!((rows[0].group.as_str(), rows[0].ms, rows[0].spread, rows[0].sample_ratio), ("lenses", 99.0, Some(0.0), None));
        assert!(rows_of(&serde_json::json!([{"config": "x"}])).unwrap_err().contains("row 0 has no 'group'"));
    }
}
