//! `focal info FILE…`: what a volume file holds.

use std::path::PathBuf;

use clap::Args;
use focal::volume::readers::{RawSpec, ReadOptions, label_table, read_volume};
use focal::volume::source::level::{WHOLE_LEVEL_BYTES, load_finest_within};
use focal::volume::source::procedural::{DEFAULT_SPACING_MM, ProceduralSource, parse_dims};
use focal::volume::{LabelTable, LabelVolume, Volume};
use glam::Vec3;
use serde_json::{Value, json};

#[derive(Args)]
pub struct InfoArgs {
    /// Volume files, DICOM or OME-Zarr folders, or `procedural:N[xNxN]`.
    #[arg(required = true)]
    files: Vec<PathBuf>,
    /// Print JSON (an array when several files are given).
    #[arg(long)]
    json: bool,
    /// Layout of headerless raw files: DIMS:TYPE[:le|be][:s=SPACING][:skip=BYTES].
    #[arg(long)]
    raw: Option<RawSpec>,
    /// Treat the files as label volumes (also automatic when a label table lies beside).
    #[arg(long)]
    labels: bool,
}

pub fn run(args: &InfoArgs) -> Result<(), String> {
    let options = ReadOptions { raw: args.raw.clone(), ..Default::default() };
    let mut reports = Vec::new();
    let mut failures = Vec::new();
    for f in &args.files {
        let read = match f.to_string_lossy().strip_prefix("procedural:") {
            Some(size) => procedural(size).map_err(|e| format!("{}: {e}", f.display())),
            None => read_volume(f, &options).map_err(|e| e.to_string()),
        };
        match read {
            Ok(v) => {
                // (The sidecar table, else the one the file carries: a segmentation's.)
                let sidecars = label_table::read_sidecars(f).map_err(|e| e.to_string())?;
                let carried = v.label_table.clone();
                let shown = args.labels || !sidecars.is_empty() || carried.is_some();
                let table = if sidecars.is_empty() { carried.unwrap_or_default() } else { sidecars };
                let labels = shown.then(|| LabelVolume::from_volume(v.clone(), table)).transpose()?;
                reports.push(report(&v, labels.as_ref()));
            }
            Err(e) => failures.push(e),
        }
    }
    if args.json {
        let out = if reports.len() == 1 && args.files.len() == 1 { reports.remove(0) } else { Value::Array(reports) };
        println!("{}", serde_json::to_string_pretty(&out).map_err(|e| e.to_string())?);
    } else {
        for r in &reports {
            print_text(r);
        }
    }
    if failures.is_empty() { Ok(()) } else { Err(failures.join("\nerror: ")) }
}

/// The procedural source of `size`, its finest level that fits the whole-level budget.
fn procedural(size: &str) -> Result<Volume, String> {
    let source = ProceduralSource::new(parse_dims(size)?, Vec3::splat(DEFAULT_SPACING_MM))?;
    load_finest_within(&source, WHOLE_LEVEL_BYTES, &|_| {}).map_err(|e| e.to_string())
}

/// Most labels listed by name.
const LISTED_LABELS: usize = 24;

fn report(v: &Volume, labels: Option<&LabelVolume>) -> Value {
    let g = &v.grid;
    let s = &v.stats;
    let d = g.direction;
    let label_json = labels.map(|l| {
        let ids = l.present_ids();
        let named = |t: &LabelTable, id: u32| t.name(id);
        json!({
            "count": ids.iter().filter(|(id, _)| *id != 0).count(),
            "table_entries": l.table.len(),
            "largest": ids.iter().filter(|(id, _)| *id != 0).max_by_key(|(_, c)| *c).map(|(id, c)| json!({"id": id, "name": named(&l.table, *id), "voxels": c})),
            "present": ids.iter().filter(|(id, _)| *id != 0).take(LISTED_LABELS).map(|(id, c)| json!({"id": id, "name": named(&l.table, *id), "voxels": c})).collect::<Vec<_>>(),
        })
    });
    json!({
        "name": v.name,
        "path": v.source.path.as_ref().map(|p| p.display().to_string()),
        "format": v.source.format,
        "sample_type": v.source.sample_type,
        "stored_bits": v.voxels.bits(),
        "dimensions": g.dims.to_array(),
        "spacing_mm": g.spacing.to_array(),
        "origin_mm": g.origin.to_array(),
        "direction": [d.x_axis.to_array(), d.y_axis.to_array(), d.z_axis.to_array()],
        "orientation": g.orientation_code(),
        "extent_mm": g.extent().to_array(),
        "values": {
            "units": v.values.units,
            "min": s.min, "max": s.max, "mean": s.mean, "std": s.std_dev,
            "p01": s.p01, "median": s.median, "p99": s.p99,
            "rescale": {"slope": v.values.slope, "intercept": v.values.intercept},
        },
        "histogram": {"min": s.histogram.min, "max": s.histogram.max, "bins": s.histogram.counts},
        "labels": label_json,
        "details": v.source.details.iter().map(|(k, val)| json!([k, val])).collect::<Vec<_>>(),
    })
}

fn print_text(r: &Value) {
    let f = |v: &Value| match v {
        Value::Number(_) => f_num(v),
        Value::String(s) => s.clone(),
        Value::Array(a) => a
            .iter()
            .map(|x| match x {
                Value::Number(_) => f_num(x),
                _ => x.to_string(),
            })
            .collect::<Vec<_>>()
            .join(" × "),
        Value::Null => "—".into(),
        other => other.to_string(),
    };
    let v = &r["values"];
    let units = v["units"].as_str().map(|u| format!(" {u}")).unwrap_or_default();
    println!("{}", r["path"].as_str().unwrap_or(r["name"].as_str().unwrap_or("volume")));
    println!("  format       {} ({}, stored as {}-bit)", f(&r["format"]), f(&r["sample_type"]), f(&r["stored_bits"]));
    println!("  dimensions   {}", f(&r["dimensions"]));
    println!("  spacing      {} mm", f(&r["spacing_mm"]));
    println!("  extent       {} mm", f(&r["extent_mm"]));
    println!(
        "  origin       {} mm (RAS)",
        r["origin_mm"].as_array().map(|a| a.iter().map(f_num).collect::<Vec<_>>().join(", ")).unwrap_or_default()
    );
    println!("  orientation  {} (axes point to)", f(&r["orientation"]));
    if let Some(rows) = r["direction"].as_array() {
        for (axis, row) in ["i", "j", "k"].iter().zip(rows) {
            println!(
                "    {axis} axis    ({})",
                row.as_array().map(|a| a.iter().map(f_num).collect::<Vec<_>>().join(", ")).unwrap_or_default()
            );
        }
    }
    println!("  values       {} .. {}{units}  mean {}  sd {}", f_num(&v["min"]), f_num(&v["max"]), f_num(&v["mean"]), f_num(&v["std"]));
    println!("  percentiles  1%: {}  50%: {}  99%: {}", f_num(&v["p01"]), f_num(&v["median"]), f_num(&v["p99"]));
    if let Some(bins) = r["histogram"]["bins"].as_array() {
        println!("  histogram    {}", sparkline(bins));
    }
    if let Some(l) = r["labels"].as_object() {
        println!("  labels       {} present, {} in the table", f_num(&l["count"]), f_num(&l["table_entries"]));
        for p in l["present"].as_array().into_iter().flatten() {
            println!("    {:>5}  {} ({} voxels)", f_num(&p["id"]), p["name"].as_str().unwrap_or(""), f_num(&p["voxels"]));
        }
    }
    if let Some(details) = r["details"].as_array() {
        for d in details {
            println!("  {:<12} {}", d[0].as_str().unwrap_or(""), d[1].as_str().unwrap_or(""));
        }
    }
}

fn f_num(v: &Value) -> String {
    let clean = |x: f64| if x.abs() < 5e-5 { 0.0 } else { x };
    v.as_f64()
        .map(clean)
        .map(|x| if x.fract() == 0.0 && x.abs() < 1e15 { format!("{x}") } else { format!("{x:.4}") })
        .unwrap_or_else(|| v.to_string())
}

/// 32-character log-scaled sparkline of a histogram.
fn sparkline(bins: &[Value]) -> String {
    let counts: Vec<u64> = bins.iter().filter_map(Value::as_u64).collect();
    let group = counts.len().div_ceil(32).max(1);
    let grouped: Vec<f64> = counts.chunks(group).map(|c| (c.iter().sum::<u64>() as f64 + 1.0).ln()).collect();
    let max = grouped.iter().cloned().fold(0.0, f64::max).max(1e-9);
    let marks = [' ', '▁', '▂', '▃', '▄', '▅', '▆', '▇', '█'];
    grouped.iter().map(|v| marks[((v / max) * 8.0).round() as usize]).collect()
}
