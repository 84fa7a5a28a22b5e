//! OME-Zarr against independent tools: pyramids written by zarr-python (Zarr v2 and v3,
//! NGFF 0.4 and 0.5, gzip, blosc, zstd, sharding) open with the values their formulas
//! give; pyramids `focal convert` writes are checked by zarr-python, nibabel and numpy
//! (tests/oracle/); chunks that are corrupt, absent or truncated, metadata that is wrong
//! and HTTP faults (a loopback server: 404, 500, a dropped connection) give messages
//! naming them and a picture of the rest; streamed, a source fetches and decodes each
//! chunk once for the boxes that share it.
//!
//! The oracle runs in `$FOCAL_ORACLE_PYTHON` (scripts/test.sh provides one with zarr,
//! numpy and nibabel), else in a `python3` that has them; with neither the tests say so
//! and pass only when `FOCAL_ORACLE_PYTHON` is unset.

mod common;
#[path = "ome_zarr/server.rs"]
mod server;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{data, scratch};
use focal::volume::convert::Downsample;
use focal::volume::convert::ome_zarr::{WriteOptions, ZarrVersion, write};
use focal::volume::readers::{ReadOptions, ome_zarr, read_volume};
use focal::volume::source::level::read_level;
use focal::volume::source::{FaultKind, VoxelSource};
use glam::{UVec3, Vec3};
use server::Fault;

/// The oracle's interpreter, if there is one.
fn python() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("FOCAL_ORACLE_PYTHON") {
        return Some(PathBuf::from(p));
    }
    let ok = Command::new("python3").args(["-c", "import zarr, numpy, nibabel"]).status().is_ok_and(|s| s.success());
    if ok {
        Some(PathBuf::from("python3"))
    } else {
        eprintln!("note: no Python with zarr, numpy and nibabel (scripts/test.sh sets FOCAL_ORACLE_PYTHON): oracle skipped");
        None
    }
}

fn oracle(script: &str, args: &[&Path]) -> Option<String> {
    let py = python()?;
    let script = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/oracle").join(script);
    let out = Command::new(&py).arg(&script).args(args).output().expect("the oracle runs");
    let stdout = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(out.status.success(), "{} {:?} failed:\n{stdout}\n{}", script.display(), args, String::from_utf8_lossy(&out.stderr));
    Some(stdout)
}

/// Pyramids written by zarr-python, once per test binary run.
fn fixtures() -> Option<PathBuf> {
    // Made once: the tests run in parallel and must not rewrite each other's files.
    static MADE: std::sync::OnceLock<Option<PathBuf>> = std::sync::OnceLock::new();
    MADE.get_or_init(|| {
        let dir = scratch("zarr-fixtures");
        oracle("ome_zarr_make.py", &[&dir])?;
        Some(dir)
    })
    .clone()
}

/// Every voxel of every level of `source`, against `expected(level, x, y, z)`.
fn check_levels(source: &dyn VoxelSource, tolerance: f64, expected: impl Fn(u32, u32, u32, u32) -> f64) {
    let info = source.info();
    for k in 0..info.levels.len() {
        let (v, faults) = read_level(source, k, &|_| {}).expect("level reads");
        assert!(faults.iter().all(|f| f.kind == FaultKind::Absent), "level {k}: {faults:?}");
        let d = v.dims();
        for z in 0..d.z {
            for y in 0..d.y {
                for x in 0..d.x {
                    let f = 1 << k;
                    let want = expected(k as u32, x * f, y * f, z * f);
                    let got = v.real(x, y, z);
                    assert!((got - want).abs() <= tolerance, "{}: level {k} voxel {x} {y} {z}: {got}, expected {want}", info.name);
                }
            }
        }
    }
}

#[test]
fn pyramids_written_by_zarr_python_open_with_their_values() {
    let Some(dir) = fixtures() else { return };

    // Zarr v2, uint16, gzip; micrometres become millimetres.
    let s = ome_zarr::open(&dir.join("v2_uint16.ome.zarr")).expect("opens");
    let info = s.info();
    assert_eq!(info.levels.len(), 3);
    assert_eq!(info.levels[0].grid.dims, UVec3::new(28, 24, 20));
    assert_eq!(info.levels[0].grid.spacing, Vec3::new(0.0005, 0.0005, 0.002));
    assert_eq!(info.levels[2].grid.dims, UVec3::new(7, 6, 5));
    assert_eq!(info.levels[1].chunk, UVec3::splat(8));
    assert!(info.source.format.contains("0.4") && info.source.format.contains("v2"), "{}", info.source.format);
    check_levels(&s, 0.0, |_, x, y, z| ((x * 7 + y * 13 + z * 31) % 4096) as f64);

    // Zarr v2, int16, blosc, "." keys, a translation, no unit (taken as millimetres).
    let s = ome_zarr::open(&dir.join("v2_int16_blosc.ome.zarr")).expect("opens");
    assert_eq!(s.info().levels[0].grid.origin, Vec3::new(7.0, 6.0, 5.0));
    assert!(s.info().warnings.iter().any(|w| w.contains("no unit")), "{:?}", s.info().warnings);
    check_levels(&s, 0.0, |_, x, y, z| x as f64 - 3.0 * y as f64 + 5.0 * z as f64 - 100.0);

    // Zarr v3, float32, sharded, two channels: channel 0 shown, values quantised over
    // the coarsest level's range (16 bits: within a step of the range).
    let s = ome_zarr::open(&dir.join("v3_float32_sharded.ome.zarr")).expect("opens");
    let info = s.info();
    assert!(info.source.format.contains("0.5") && info.source.format.contains("v3"), "{}", info.source.format);
    assert_eq!(info.levels[0].grid.dims, UVec3::new(24, 20, 16));
    assert_eq!(info.levels[0].chunk, UVec3::splat(4), "the read unit is the inner chunk");
    assert!(info.warnings.iter().any(|w| w.contains("\"c\" has 2 entries")), "{:?}", info.warnings);
    let step = info.values.slope;
    assert!(step > 0.0 && step < 1e-3, "quantisation step {step}");
    // The coarsest level spans 0 .. 0.5·22 + 14 = 25 (x, z even), finer levels reach 26.5:
    // values past the coarsest range clamp to it.
    check_levels(&s, step, |_, x, y, z| (x as f64 * 0.5 - y as f64 * 0.25 + z as f64).clamp(-4.5, 25.0));

    // Zarr v3, uint8, gzip, millimetres, a translation.
    let s = ome_zarr::open(&dir.join("v3_uint8.ome.zarr")).expect("opens");
    let g = &s.info().levels[0].grid;
    assert_eq!((g.spacing, g.origin), (Vec3::new(0.75, 1.0, 1.5), Vec3::new(30.0, 20.0, -10.0)));
    assert!(s.info().warnings.is_empty(), "{:?}", s.info().warnings);
    check_levels(&s, 0.0, |_, x, y, z| ((x + 2 * y + 3 * z) % 256) as f64);

    // float32 with a display window: quantised over it; a NaN voxel is drawn at its low
    // end and reported with its chunk.
    let s = ome_zarr::open(&dir.join("v3_float32_nan.ome.zarr")).expect("opens");
    assert_eq!((s.info().values.intercept, s.info().values.slope), (-100.0, 600.0 / 65535.0));
    let b = s.read_box(0, UVec3::ZERO, UVec3::new(8, 6, 4)).expect("box");
    let nan: Vec<_> = b.faults.iter().filter(|f| f.kind == FaultKind::NotFinite).collect();
    assert_eq!(nan.len(), 1, "{:?}", b.faults);
    assert_eq!(nan[0].chunk, "0/c/0/0/0", "z 1, y 2, x 3 lies in chunk (0, 0, 0) of 2×3×4");
    let real = |x: u32, y: u32, z: u32| s.info().values.to_real(b.voxels.code(((z * 6 + y) * 8 + x) as usize) as f64);
    assert_eq!(real(3, 2, 1), -100.0);
    assert!((real(7, 5, 3) - 357.0).abs() <= s.info().values.slope);

    // The reader dispatch opens them as volumes (level 0 fits in memory).
    let v = read_volume(&dir.join("v3_uint8.ome.zarr"), &ReadOptions::default()).expect("reads");
    assert_eq!(v.dims(), UVec3::new(16, 14, 12));
    // x + 2y + 3z at (3, 2, 1).
    assert_eq!(v.real(3, 2, 1), 10.0);
}

/// Writes `src` with `focal convert`'s writer and checks it with the oracle.
fn convert_and_check(src: &Path, out: &Path, opts: &WriteOptions) -> Option<String> {
    let volume = read_volume(src, &ReadOptions::default()).expect("source reads");
    write(&volume, out, opts, &|_, _| {}).expect("pyramid writes");
    let labels = opts.downsample == Downsample::Nearest;
    let mut args: Vec<&Path> = vec![src, out];
    if labels {
        args.push(Path::new("--labels"));
    }
    let line = oracle("ome_zarr_check.py", &args)?;
    assert!(line.contains("\"ok\": true"), "{line}");
    // And Focal reads it back to the same grid and values.
    let back = ome_zarr::open(out).expect("reopens");
    assert_eq!(back.info().levels[0].grid.dims, volume.dims());
    let g = &back.info().levels[0].grid;
    assert!((g.origin - volume.grid.origin).length() < 1e-3 && (g.spacing - volume.grid.spacing).length() < 1e-5);
    assert!(g.direction.abs_diff_eq(volume.grid.direction, 1e-6));
    let (l0, faults) = read_level(&back, 0, &|_| {}).expect("level 0");
    assert!(faults.iter().all(|f| f.kind == FaultKind::Absent));
    let d = volume.dims();
    for (x, y, z) in [(0, 0, 0), (d.x - 1, d.y - 1, d.z - 1), (d.x / 2, d.y / 3, d.z / 2)] {
        assert_eq!(l0.real(x, y, z), volume.real(x, y, z));
    }
    Some(line)
}

#[test]
fn converted_pyramids_pass_the_independent_check() {
    let dir = scratch("zarr-convert");
    // uint8 CT, Zarr v3 sharded.
    let shard = WriteOptions { chunk: 16, shard: Some(2), ..Default::default() };
    let Some(line) = convert_and_check(&data("ct/fuel.nii.gz"), &dir.join("fuel.ome.zarr"), &shard) else { return };
    assert!(line.contains("\"zarr_format\": 3") && line.contains("uint8"), "{line}");
    // The same, blosc inside the shards (what most OME-Zarr writers use).
    let blosc = WriteOptions { compressor: focal::volume::convert::ome_zarr::Compressor::Blosc, ..shard };
    let line = convert_and_check(&data("ct/fuel.nii.gz"), &dir.join("fuel-blosc.ome.zarr"), &blosc).expect("oracle");
    assert!(line.contains("\"zarr_format\": 3"), "{line}");
    // An MRI with odd dimensions (181 × 217 × 181), Zarr v2.
    let v2 = WriteOptions { chunk: 32, version: ZarrVersion::V2, ..Default::default() };
    let line = convert_and_check(&data("mri/ch2.nii.gz"), &dir.join("ch2.ome.zarr"), &v2).expect("oracle");
    assert!(line.contains("\"levels\": 4") && line.contains("\"zarr_format\": 2"), "{line}");
    // A label atlas: levels keep label ids (nearest).
    let labels = WriteOptions { chunk: 64, downsample: Downsample::Nearest, ..Default::default() };
    convert_and_check(&data("labels/aal.nii.gz"), &dir.join("aal.ome.zarr"), &labels).expect("oracle");
    // Float values (a float32 NIfTI nibabel wrote): a float32 pyramid, checked within the
    // 16-bit codes' steps.
    let fixtures = fixtures().expect("the oracle made its fixtures");
    let line = convert_and_check(
        &fixtures.join("float32_source.nii.gz"),
        &dir.join("float.ome.zarr"),
        &WriteOptions { chunk: 8, ..Default::default() },
    )
    .expect("oracle");
    assert!(line.contains("float32"), "{line}");
    // Writing over a pyramid needs the overwrite flag; over anything else it is refused.
    let volume = read_volume(&data("ct/fuel.nii.gz"), &ReadOptions::default()).expect("reads");
    let again = write(&volume, &dir.join("fuel.ome.zarr"), &WriteOptions::default(), &|_, _| {}).expect_err("exists");
    assert!(again.contains("--force"), "{again}");
    let other = dir.join("not-zarr");
    std::fs::create_dir_all(&other).expect("dir");
    std::fs::write(other.join("notes.txt"), "keep me").expect("file");
    let err = write(&volume, &other, &WriteOptions { overwrite: true, ..Default::default() }, &|_, _| {}).expect_err("refused");
    assert!(err.contains("not a Zarr pyramid") && other.join("notes.txt").exists(), "{err}");
    // A conversion stopped half way (here by a panic in its progress callback) leaves a
    // Zarr group without multiscales: no reader takes it for a pyramid, and --force
    // replaces it.
    let stopped = dir.join("stopped.ome.zarr");
    let stop = |done: u64, _| assert!(done < 4096, "stopped by the test");
    let _ = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| write(&volume, &stopped, &WriteOptions::default(), &stop)));
    assert!(stopped.join("zarr.json").is_file(), "the stopped conversion left no group");
    let open = focal::volume::readers::ome_zarr::open(&stopped).err().expect("a half-written pyramid is refused");
    assert!(open.to_string().contains("multiscales"), "{open}");
    write(&volume, &stopped, &WriteOptions { overwrite: true, ..Default::default() }, &|_, _| {}).expect("--force replaces it");
    focal::volume::readers::ome_zarr::open(&stopped).expect("the pyramid opens");
}

#[test]
fn an_int16_volume_converts_exactly() {
    // The EPI MRI is int16 with an odd depth (37): levels are exact means in int16.
    let src = data("mri/epi_64x64x37.mha");
    let volume = read_volume(&src, &ReadOptions::default()).expect("reads");
    let dir = scratch("zarr-int16");
    let out = dir.join("epi.ome.zarr");
    let written = write(&volume, &out, &WriteOptions { chunk: 16, ..Default::default() }, &|_, _| {}).expect("writes");
    assert_eq!(written.sample.name(), "int16");
    assert_eq!(written.levels, vec![UVec3::new(64, 64, 37), UVec3::new(32, 32, 19), UVec3::new(16, 16, 10)]);
    let back = ome_zarr::open(&out).expect("reopens");
    // Level 1 voxel (3, 4, 18) is the rounded mean of level-0 x 6..7, y 8..9 and z 36
    // (the odd last slice stands in for the missing one).
    let (l1, _) = read_level(&back, 1, &|_| {}).expect("level 1");
    let mut sum = 0.0;
    for (x, y) in [(6, 8), (7, 8), (6, 9), (7, 9)] {
        sum += 2.0 * volume.real(x, y, 36);
    }
    assert_eq!(l1.real(3, 4, 18), ((sum + 4.0) / 8.0).floor());
}

/// A copy of a fixture to damage.
fn damaged(name: &str, fixture: &Path) -> PathBuf {
    let dir = scratch(name);
    let out = dir.join(fixture.file_name().expect("name"));
    copy_dir(fixture, &out);
    out
}

fn copy_dir(from: &Path, to: &Path) {
    std::fs::create_dir_all(to).expect("dir");
    for e in std::fs::read_dir(from).expect("list") {
        let e = e.expect("entry");
        let target = to.join(e.file_name());
        if e.path().is_dir() {
            copy_dir(&e.path(), &target);
        } else {
            std::fs::copy(e.path(), target).expect("copy");
        }
    }
}

#[test]
fn bad_chunks_and_metadata_are_named_and_the_rest_is_drawn() {
    let Some(dir) = fixtures() else { return };
    // A corrupt gzip chunk (v2): its key is named, the others read.
    let p = damaged("zarr-corrupt", &dir.join("v2_uint16.ome.zarr"));
    std::fs::write(p.join("0/1/1/1"), b"this is not gzip").expect("corrupt");
    let s = ome_zarr::open(&p).expect("opens");
    let b = s.read_box(0, UVec3::ZERO, UVec3::new(28, 24, 20)).expect("box");
    let bad: Vec<_> = b.faults.iter().filter(|f| f.kind == FaultKind::Unreadable).collect();
    assert_eq!(bad.len(), 1, "{:?}", b.faults);
    assert_eq!(bad[0].chunk, "0/1/1/1");
    // A box the level does not hold is refused, naming the folder (the image's own
    // NGFF name, "fixture", tells a user nothing).
    let err = s.read_box(0, UVec3::ZERO, UVec3::splat(1000)).expect_err("outside the level");
    assert!(err.to_string().contains(&p.display().to_string()), "{err}");
    // Outside the bad chunk, the values are right.
    assert_eq!(b.voxels.code(0), 0);
    let at = |x: u32, y: u32, z: u32| b.voxels.code(((z * 24 + y) * 28 + x) as usize) as u32;
    // (7x + 13y + 31z) mod 4096 at (27, 23, 19): 189 + 299 + 589 = 1077.
    assert_eq!(at(27, 23, 19), 1077);
    assert_eq!(at(9, 9, 9), 0, "the corrupt chunk reads as the fill value");
    // An absent chunk is the fill value, noted by its key.
    std::fs::remove_file(p.join("0/0/0/0")).expect("remove");
    let b = s.read_box(0, UVec3::ZERO, UVec3::splat(4)).expect("box");
    assert_eq!(b.faults.len(), 1);
    assert_eq!((b.faults[0].kind, b.faults[0].chunk.as_str()), (FaultKind::Absent, "0/0/0/0"));
    // With a fill value of its own (700), the corrupt chunk and the absent one read as
    // that, not as 0.
    let zarray = p.join("0/.zarray");
    let meta: serde_json::Value = serde_json::from_str(&std::fs::read_to_string(&zarray).expect("metadata")).expect("json");
    let mut meta = meta;
    meta["fill_value"] = serde_json::json!(700);
    std::fs::write(&zarray, meta.to_string()).expect("edit");
    let filled = ome_zarr::open(&p).expect("opens");
    let b = filled.read_box(0, UVec3::ZERO, UVec3::new(28, 24, 20)).expect("box");
    let at = |x: u32, y: u32, z: u32| b.voxels.code(((z * 24 + y) * 28 + x) as usize) as u32;
    assert_eq!((at(9, 9, 9), at(1, 1, 1)), (700, 700), "the corrupt and the absent chunk read as the fill value");
    assert_eq!(at(27, 23, 19), 1077);
    // The volume read reports both as notes.
    let v = ome_zarr::read(&p, &ReadOptions::default()).expect("reads");
    let notes: Vec<&String> = v.source.details.iter().filter(|(k, _)| k == "note").map(|(_, n)| n).collect();
    assert!(notes.iter().any(|n| n.contains("0/1/1/1")), "{notes:?}");
    assert!(notes.iter().any(|n| n.contains("absent")), "{notes:?}");

    // A truncated shard (v3): the inner chunks past the cut fail, the shard is named.
    let p = damaged("zarr-truncated", &dir.join("v3_float32_sharded.ome.zarr"));
    let shard = p.join("0/c/0/0/0/0");
    let len = std::fs::metadata(&shard).expect("shard").len();
    let file = std::fs::OpenOptions::new().write(true).open(&shard).expect("open");
    file.set_len(len / 2).expect("truncate");
    let s = ome_zarr::open(&p).expect("opens");
    let b = s.read_box(0, UVec3::ZERO, UVec3::splat(8)).expect("box");
    assert!(b.faults.iter().any(|f| f.kind == FaultKind::Unreadable && f.chunk.contains("c/0/0/0/0")), "{:?}", b.faults);

    // Wrong metadata: the group and the problem are named.
    let p = damaged("zarr-metadata", &dir.join("v3_uint8.ome.zarr"));
    let text = std::fs::read_to_string(p.join("zarr.json")).expect("metadata");
    std::fs::write(p.join("zarr.json"), text.replace("\"scale\": [", "\"scale\": [0.0, ")).expect("edit");
    let err = ome_zarr::open(&p).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains("v3_uint8.ome.zarr") && err.contains("scale"), "{err}");
    std::fs::write(p.join("zarr.json"), "{ not json").expect("edit");
    let err = ome_zarr::open(&p).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains("v3_uint8.ome.zarr") && err.contains("zarr.json"), "{err}");
    // A level whose array is missing.
    let p = damaged("zarr-level", &dir.join("v2_int16_blosc.ome.zarr"));
    std::fs::remove_dir_all(p.join("1")).expect("remove level");
    let err = ome_zarr::open(&p).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains("level 1"), "{err}");
}

#[test]
fn pyramids_over_http_read_like_files_and_faults_are_named() {
    let Some(dir) = fixtures() else { return };
    let server = server::Server::start(dir.clone());
    let start = std::time::Instant::now();
    // Zarr v2 (gzip) and v3 (sharded, read by byte ranges) read over HTTP as from disk.
    for name in ["v2_uint16.ome.zarr", "v3_float32_sharded.ome.zarr"] {
        let url = format!("{}/{name}", server.url);
        let remote = ome_zarr::open(Path::new(&url)).expect("opens over HTTP");
        let local = ome_zarr::open(&dir.join(name)).expect("opens");
        assert_eq!(remote.info().levels, local.info().levels);
        for k in 0..local.info().levels.len() {
            let (r, faults) = read_level(&remote, k, &|_| {}).expect("level");
            let (l, _) = read_level(&local, k, &|_| {}).expect("level");
            assert!(faults.iter().all(|f| f.kind == FaultKind::Absent), "{name} level {k}: {faults:?}");
            assert_eq!(r.voxels, l.voxels, "{name} level {k}");
        }
    }
    // The reader dispatch takes an address too.
    let v = read_volume(Path::new(&format!("{}/v3_uint8.ome.zarr", server.url)), &ReadOptions::default()).expect("reads");
    assert_eq!(v.dims(), UVec3::new(16, 14, 12));

    // Faults: a 404 is an absent chunk; a 500 and a dropped connection are unreadable,
    // named by their keys, and the rest of the box is drawn.
    let url = format!("{}/v2_uint16.ome.zarr", server.url);
    let s = ome_zarr::open(Path::new(&url)).expect("opens");
    server.inject("v2_uint16.ome.zarr/0/0/0/0", Fault::Status(404));
    server.inject("v2_uint16.ome.zarr/0/0/0/1", Fault::Status(500));
    server.inject("v2_uint16.ome.zarr/0/0/1/0", Fault::Drop);
    let b = s.read_box(0, UVec3::ZERO, UVec3::new(16, 16, 8)).expect("box");
    let kind = |key: &str| b.faults.iter().find(|f| f.chunk == key).map(|f| (f.kind, f.problem.clone()));
    assert_eq!(kind("0/0/0/0").map(|k| k.0), Some(FaultKind::Absent), "{:?}", b.faults);
    let (k500, why) = kind("0/0/0/1").expect("the 500 is reported");
    assert!(k500 == FaultKind::Unreadable && why.contains("500"), "{why}");
    assert_eq!(kind("0/0/1/0").map(|k| k.0), Some(FaultKind::Unreadable), "{:?}", b.faults);
    assert_eq!(b.faults.len(), 3, "{:?}", b.faults);
    // Chunk (z 0, y 1, x 1) was served: its voxels are right.
    let at = |x: u32, y: u32, z: u32| b.voxels.code(((z * 16 + y) * 16 + x) as usize) as u32;
    // 7x + 13y at (9, 9, 0).
    assert_eq!(at(9, 9, 0), 180);
    assert_eq!(at(9, 1, 2), 0, "the 500 chunk (x 8..15, y 0..7) is drawn at the fill value");

    // The metadata failing: the address and the status are named, nothing hangs.
    server.inject("v2_int16_blosc.ome.zarr/.zgroup", Fault::Status(500));
    let url = format!("{}/v2_int16_blosc.ome.zarr", server.url);
    let err = ome_zarr::open(Path::new(&url)).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains(&url) && err.contains("500"), "{err}");
    server.inject("v3_uint8.ome.zarr/zarr.json", Fault::Drop);
    let err = ome_zarr::open(Path::new(&format!("{}/v3_uint8.ome.zarr", server.url))).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains("v3_uint8.ome.zarr"), "{err}");
    let err = ome_zarr::open(Path::new(&format!("{}/nothing.ome.zarr", server.url))).map(|_| ()).expect_err("refused").to_string();
    assert!(err.contains("nothing.ome.zarr"), "{err}");
    assert!(start.elapsed() < std::time::Duration::from_secs(60), "HTTP faults took {:?}", start.elapsed());
}

/// Boxes of 10³ every 6 voxels over level 0 (clipped to it): neighbours share chunks,
/// as streamed bricks and their aprons do.
fn overlapping_boxes(dims: UVec3) -> Vec<(UVec3, UVec3)> {
    let starts = |n: u32| (0..n).step_by(6).collect::<Vec<u32>>();
    let mut out = Vec::new();
    for z in starts(dims.z) {
        for y in starts(dims.y) {
            for x in starts(dims.x) {
                let lo = UVec3::new(x, y, z);
                out.push((lo, (dims - lo).min(UVec3::splat(10))));
            }
        }
    }
    out
}

#[test]
fn a_streamed_source_fetches_each_chunk_once_and_reads_as_without() {
    let Some(dir) = fixtures() else { return };
    let server = server::Server::start(dir.clone());
    // Zarr v2 (a chunk a file) and v3 sharded (inner chunks by byte ranges).
    for name in ["v2_uint16.ome.zarr", "v3_float32_sharded.ome.zarr"] {
        let url = format!("{}/{name}", server.url);
        let plain = ome_zarr::open(Path::new(&url)).expect("opens over HTTP");
        let kept = ome_zarr::open(Path::new(&url)).expect("opens over HTTP");
        assert_eq!(kept.keep_decoded(8 << 20), 8 << 20);
        let boxes = overlapping_boxes(plain.info().levels[0].grid.dims);
        let before = server.requests();
        let read_plain: Vec<_> = boxes.iter().map(|&(lo, size)| plain.read_box(0, lo, size).expect("box")).collect();
        let (between, read_kept): (usize, Vec<_>) =
            (server.requests(), boxes.iter().map(|&(lo, size)| kept.read_box(0, lo, size).expect("box")).collect());
        let (without, with) = (between - before, server.requests() - between);
        assert_eq!(read_kept, read_plain, "{name}: the same voxels and faults");
        // Every box touches up to 8 chunks of 8³ shared with its neighbours: without
        // keeping them, each is fetched again for every box.
        assert!(with * 3 < without, "{name}: {with} requests kept, {without} without ({} boxes)", boxes.len());
    }
    // A chunk that could not be read is not kept: the next box tries it again, and its
    // fault is named for every box that touches it.
    let url = format!("{}/v2_uint16.ome.zarr", server.url);
    let s = ome_zarr::open(Path::new(&url)).expect("opens");
    s.keep_decoded(8 << 20);
    server.inject("v2_uint16.ome.zarr/0/0/0/1", Fault::Status(500));
    let unreadable = |b: &focal::volume::source::Block| b.faults.iter().filter(|f| f.kind == FaultKind::Unreadable).count();
    let first = s.read_box(0, UVec3::ZERO, UVec3::new(16, 8, 8)).expect("box");
    let again = s.read_box(0, UVec3::new(4, 0, 0), UVec3::new(12, 8, 8)).expect("box");
    assert_eq!((unreadable(&first), unreadable(&again)), (1, 1), "{:?}", again.faults);
    server.heal("v2_uint16.ome.zarr/0/0/0/1");
    let healed = s.read_box(0, UVec3::ZERO, UVec3::new(16, 8, 8)).expect("box");
    assert_eq!(unreadable(&healed), 0, "{:?}", healed.faults);
    // 7x + 13y at (9, 1, 0), in the chunk that failed before.
    assert_eq!(healed.voxels.code(9 + 16), 76);
}
