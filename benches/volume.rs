//! CPU benchmarks of the volume layer (run: `cargo bench --profile dev --bench volume`).
//!
//! - readers on the real files against only inflating the same compressed bytes (the
//!   ratio reader/decompress is printed; goal ≤ 1.5);
//! - phantom generation at 256³;
//! - brick min-max grid construction at 256³ (goal < 100 ms);
//! - CPU reference renderer throughput in samples per second.

use std::hint::black_box;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::time::{Duration, Instant};

use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use flate2::read::{GzDecoder, ZlibDecoder};
use std::sync::Arc;

use focal::reference::{RenderScene, render};
use focal::region::{Appearance, Mode, View};
use focal::transfer::presets;
use focal::volume::phantom::{self, Phantom};
use focal::volume::readers::{ReadOptions, read_volume};
use focal::volume::{BrickGrid, DEFAULT_BRICK_SIZE};

fn data(rel: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data").join(rel)
}

/// Inflates exactly what the reader has to inflate, without parsing or encoding.
fn decompress_only(name: &str, bytes: &[u8]) -> usize {
    let mut out = Vec::new();
    match name {
        "ch2.nii.gz" => GzDecoder::new(bytes).read_to_end(&mut out).map(|_| out.len()).unwrap_or(0),
        "FLAIR.nrrd" => {
            let start = bytes.windows(2).position(|w| w == b"\n\n").map(|p| p + 2).unwrap_or(0);
            GzDecoder::new(&bytes[start..]).read_to_end(&mut out).map(|_| out.len()).unwrap_or(0)
        }
        "epi_64x64x37.mha" => {
            let start = bytes
                .windows(16)
                .position(|w| w == b"ElementDataFile ")
                .and_then(|p| bytes[p..].iter().position(|&c| c == b'\n').map(|n| p + n + 1))
                .unwrap_or(0);
            ZlibDecoder::new(&bytes[start..]).read_to_end(&mut out).map(|_| out.len()).unwrap_or(0)
        }
        "engine.vti" => {
            // Raw appended data: UInt64 header [n, block, last, sizes…] then zlib blocks.
            let start = bytes
                .windows(13)
                .position(|w| w == b"<AppendedData")
                .and_then(|p| bytes[p..].iter().position(|&c| c == b'_').map(|u| p + u + 1))
                .unwrap_or(0);
            let u = |i: usize| u64::from_le_bytes(bytes[start + 8 * i..start + 8 * i + 8].try_into().unwrap_or([0; 8])) as usize;
            let n = u(0);
            let mut at = start + 8 * (3 + n);
            for i in 0..n {
                let size = u(3 + i);
                let mut block = Vec::new();
                let _ = ZlibDecoder::new(&bytes[at..at + size]).read_to_end(&mut block);
                out.extend_from_slice(&block);
                at += size;
            }
            out.len()
        }
        _ => 0,
    }
}

fn readers(c: &mut Criterion) {
    let mut g = c.benchmark_group("readers");
    g.sample_size(10).measurement_time(Duration::from_secs(3));
    let mut ratios = Vec::new();
    for rel in ["mri/ch2.nii.gz", "mri/FLAIR.nrrd", "mri/epi_64x64x37.mha", "ct/engine.vti"] {
        let path = data(rel);
        let Ok(bytes) = std::fs::read(&path) else {
            eprintln!("skipping {rel}: not found");
            continue;
        };
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned()).unwrap_or_default();
        let options = ReadOptions::default();
        let voxels = read_volume(&path, &options).map(|v| v.byte_len()).unwrap_or(0);
        g.throughput(Throughput::Bytes(voxels as u64));
        g.bench_function(format!("read {name}"), |b| b.iter(|| black_box(read_volume(&path, &options).map(|v| v.byte_len()))));
        g.bench_function(format!("inflate {name}"), |b| b.iter(|| black_box(decompress_only(&name, &bytes))));
        // One-run ratio, measured back to back.
        let time = |f: &dyn Fn()| {
            let t = Instant::now();
            for _ in 0..5 {
                f();
            }
            t.elapsed().as_secs_f64()
        };
        let r = time(&|| {
            black_box(read_volume(&path, &options).ok());
        }) / time(&|| {
            black_box(decompress_only(&name, &bytes));
        });
        ratios.push(format!("{name}: reader / inflate = {r:.2}"));
    }
    g.finish();
    for r in ratios {
        eprintln!("{r}");
    }
}

fn phantoms(c: &mut Criterion) {
    let mut g = c.benchmark_group("phantoms");
    g.sample_size(10);
    g.bench_function("head 256³ (CT + labels)", |b| b.iter(|| black_box(phantom::head::generate(256).map(|h| h.ct.byte_len()))));
    g.bench_function("engine 256×256×128", |b| b.iter(|| black_box(phantom::engine::generate(256).map(|v| v.byte_len()))));
    g.finish();
}

fn bricks(c: &mut Criterion) {
    let Ok(v) = Phantom::Head.generate(256) else { return };
    let mut g = c.benchmark_group("bricks");
    g.sample_size(10);
    g.bench_function("min-max grid 256³ (8³ bricks)", |b| {
        b.iter(|| black_box(BrickGrid::build(&v.voxels, v.dims(), DEFAULT_BRICK_SIZE).len()))
    });
    g.finish();
}

fn reference(c: &mut Criterion) {
    let Ok(v) = Phantom::Head.generate(128) else { return };
    let Ok(tf) = presets::builtin("ct_skin_bone") else { return };
    let scene = RenderScene::single(Arc::new(v.clone()), Appearance::new(Mode::Dvr, tf));
    let (lo, hi) = v.grid.world_bounds();
    let camera = View::Oblique.frame((lo + hi) * 0.5, (hi - lo).length() * 0.5, false);
    let samples = render(&scene, &camera, 128, 128).map(|i| i.samples).unwrap_or(0);
    let mut g = c.benchmark_group("reference");
    g.sample_size(10);
    g.throughput(Throughput::Elements(samples));
    g.bench_function("DVR 128² of head 128³ (elements = samples)", |b| {
        b.iter(|| black_box(render(&scene, &camera, 128, 128).map(|i| i.samples)))
    });
    g.finish();
}

criterion_group!(benches, readers, phantoms, bricks, reference);
criterion_main!(benches);
