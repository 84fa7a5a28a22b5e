//! Throws truncated and corrupted versions of every real file, and of files written
//! from them in the other formats and encodings Focal reads, at the readers and at the
//! scene parser: each must return (a volume, a scene or an error) without panicking,
//! within a time limit, and without any single allocation larger than
//! [`MAX_ALLOCATION`]. Every input that ever failed is kept in `tests/fuzz_regressions`
//! and read again by [`regressions`]. Each test prints how many inputs it tried
//! (docs/reliability.md sums them). Long runs: the `cargo fuzz` targets in `fuzz/`.

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::Mutex;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use common::{data, scratch};
use focal::scene::file::SceneFile;
use focal::scene::load::read_scene;
use focal::volume::Voxels;
use focal::volume::readers::{RawSpec, ReadOptions, label_table, read_volume};

/// Largest single allocation a reader may make on these inputs (the largest real file
/// decodes to 32 MB).
const MAX_ALLOCATION: usize = 256 << 20;
const TIME_LIMIT: Duration = Duration::from_secs(60);

struct Counting;
static LARGEST: AtomicUsize = AtomicUsize::new(0);

unsafe impl GlobalAlloc for Counting {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc(layout) }
    }
    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        unsafe { System.dealloc(ptr, layout) }
    }
    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        LARGEST.fetch_max(layout.size(), Ordering::Relaxed);
        unsafe { System.alloc_zeroed(layout) }
    }
    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        LARGEST.fetch_max(new_size, Ordering::Relaxed);
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}

#[global_allocator]
static GLOBAL: Counting = Counting;

/// xorshift64*: deterministic mutations.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_F491_4F6C_DD1D)
    }
    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Mutated copies of `bytes`: truncations, byte overwrites (biased to the header),
/// ranges deleted, duplicated or moved (what a bad copy or a hand edit does to a text
/// header or a scene file), and for text headers, numbers replaced by huge, negative or
/// non-finite ones.
fn mutations(bytes: &[u8], seed: u64, count: usize) -> Vec<(String, Vec<u8>)> {
    let mut rng = Rng(seed | 1);
    let n = bytes.len();
    let mut out = Vec::new();
    for cut in [0, 1, 3, 10, 100, 131, 200, 347, 400, 1000, n / 4, n / 2, n.saturating_sub(100), n.saturating_sub(1)] {
        if cut < n {
            out.push((format!("truncated at {cut}"), bytes[..cut].to_vec()));
        }
    }
    let header = n.min(1024);
    for i in 0..count {
        let mut b = bytes.to_vec();
        let edits = 1 + rng.below(8);
        for _ in 0..edits {
            let at = if rng.below(4) > 0 { rng.below(header) } else { rng.below(n) };
            b[at] = match rng.below(4) {
                0 => 0xFF,
                1 => 0,
                2 => b'9',
                _ => rng.next() as u8,
            };
        }
        out.push((format!("corruption {i} ({edits} bytes)"), b));
    }
    for i in 0..count / 2 {
        let (a, len) = (rng.below(header), 1 + rng.below(64));
        let range = a..(a + len).min(n);
        let mut b = bytes.to_vec();
        let what = match rng.below(3) {
            0 => {
                b.drain(range.clone());
                "deleted"
            }
            1 => {
                let copy = b[range.clone()].to_vec();
                b.splice(range.end..range.end, copy);
                "duplicated"
            }
            _ => {
                let moved: Vec<u8> = b.drain(range.clone()).collect();
                let to = rng.below(b.len() + 1);
                b.splice(to..to, moved);
                "moved"
            }
        };
        out.push((format!("bytes {}..{} {what} ({i})", range.start, range.end), b));
    }
    // Text headers: replace a number with a huge, negative or non-finite one.
    let text_end = bytes.iter().take(4096).position(|&c| c == 0 || c > 127).unwrap_or(n.min(4096));
    let digits: Vec<usize> = (0..text_end).filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_digit())).collect();
    for (k, &at) in digits.iter().enumerate().take(60) {
        for repl in ["4294967295", "-7", "99999999999999999999", "0", "1e39", "NaN"] {
            let end = (at..text_end).find(|&i| !bytes[i].is_ascii_digit()).unwrap_or(text_end);
            let mut b = bytes[..at].to_vec();
            b.extend_from_slice(repl.as_bytes());
            b.extend_from_slice(&bytes[end..]);
            out.push((format!("number {k} at byte {at} → {repl}"), b));
        }
    }
    out
}

/// What a fuzzed file is given to.
#[derive(Clone, Copy)]
enum Reader {
    /// `read_volume` (and the label-table reader for `.txt` and `.lut`).
    Volume,
    /// A headerless file with the layout of a fixed spec.
    Raw(&'static str),
    /// The scene parser and its checks, then what a valid scene's animation and frames
    /// compute before any dataset is loaded.
    Scene,
}

fn read_with(reader: Reader, p: &Path) {
    match reader {
        Reader::Volume => {
            let _ = read_volume(p, &ReadOptions::default());
            if p.extension().is_some_and(|e| e == "txt" || e == "lut") {
                let _ = label_table::read(p);
            }
        }
        Reader::Raw(spec) => {
            if let Ok(spec) = spec.parse::<RawSpec>() {
                let _ = read_volume(p, &ReadOptions { raw: Some(spec), ..Default::default() });
            }
        }
        Reader::Scene => {
            if let Ok(scene) = read_scene(p) {
                if let Some(a) = &scene.animation {
                    let _ = focal::scene::movie::animation_frames(a, &scene, "fuzz");
                }
                let _ = focal::scene::movie::turntable(scene, 3, 30.0, 20.0, false, 1.0);
            }
        }
    }
}

/// Inputs tried by this test binary.
static TRIED: AtomicUsize = AtomicUsize::new(0);
/// One test at a time, from its first allocation to its last: the allocation counter is
/// global, and a test preparing its inputs (a copy of a file, its mutations) beside
/// another's case would be counted as that case's.
static ONE_AT_A_TIME: Mutex<()> = Mutex::new(());

fn serial() -> std::sync::MutexGuard<'static, ()> {
    ONE_AT_A_TIME.lock().unwrap_or_else(|e| e.into_inner())
}

fn run_case(path: &Path, reader: Reader, what: &str) -> Result<(), String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| read_with(reader, &p));
        let _ = tx.send(r.is_ok());
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(true) => Ok(()),
        Ok(false) => Err(format!("{what}: panicked")),
        Err(_) => Err(format!("{what}: no answer within {TIME_LIMIT:?}")),
    }
}

/// Writes each mutation of `bytes` to `dir/name` and reads it with `reader`, restoring
/// the original afterwards. A failing input is kept beside the scratch folder under
/// `failed-…` for `tests/fuzz_regressions`.
fn fuzz_bytes(label: &str, dir: &Path, name: &str, bytes: &[u8], reader: Reader, seed: u64, count: usize) -> Vec<String> {
    let cases = mutations(bytes, seed, count);
    fuzz_cases(
        label,
        (&dir.join(name), &dir.join(name)),
        bytes,
        reader,
        cases,
        &dir.with_file_name(format!("failed-{}", name.replace('/', "_"))),
    )
}

/// Writes each of `cases` over `target` and reads `read` (the file itself, or the
/// OME-Zarr store `target` belongs to); `keep` names the copies of failing inputs.
fn fuzz_cases(
    label: &str,
    (target, read): (&Path, &Path),
    bytes: &[u8],
    reader: Reader,
    cases: Vec<(String, Vec<u8>)>,
    keep: &Path,
) -> Vec<String> {
    let mut failures = Vec::new();
    for (k, (what, b)) in cases.into_iter().enumerate() {
        std::fs::write(target, &b).unwrap();
        LARGEST.store(0, Ordering::Relaxed);
        let mut failed = run_case(read, reader, &format!("{label}: {what}")).err();
        let largest = LARGEST.load(Ordering::Relaxed);
        if largest > MAX_ALLOCATION {
            failed = Some(format!("{label}: {what}: allocated {largest} bytes at once"));
        }
        TRIED.fetch_add(1, Ordering::Relaxed);
        if let Some(e) = failed {
            let kept = keep.with_file_name(format!("{}-{k}", keep.file_name().unwrap().to_string_lossy()));
            let _ = std::fs::write(&kept, &b);
            failures.push(format!("{e} (kept as {})", kept.display()));
        }
    }
    std::fs::write(target, bytes).unwrap();
    failures
}

fn fuzz(rel: &str, seed: u64, count: usize) {
    let src = data(rel);
    let bytes = std::fs::read(&src).unwrap();
    fuzz_file(rel, &bytes, src.file_name().unwrap().to_str().unwrap(), Reader::Volume, seed, count);
}

/// Fuzzes `bytes` saved as `name` in a scratch folder of its own.
fn fuzz_file(label: &str, bytes: &[u8], name: &str, reader: Reader, seed: u64, count: usize) {
    let dir = scratch(&format!("fuzz-{}", name.replace('.', "_")));
    let failures = fuzz_bytes(label, &dir, name, bytes, reader, seed, count);
    report(label, failures);
}

fn report(label: &str, failures: Vec<String>) {
    eprintln!("{label}: {} inputs tried by this test binary so far", TRIED.load(Ordering::Relaxed));
    assert!(failures.is_empty(), "{label}:\n{}", failures.join("\n"));
}

/// The fuel CT's voxels (64×33×32, uint8), for files written in other formats.
fn fuel() -> Vec<u8> {
    let v = read_volume(&data("ct/fuel.nii.gz"), &ReadOptions::default()).unwrap();
    let Voxels::U8(codes) = v.voxels else { panic!("fuel is 8-bit") };
    codes
}

fn gunzip(bytes: &[u8]) -> Vec<u8> {
    let mut out = Vec::new();
    std::io::Read::read_to_end(&mut flate2::read::GzDecoder::new(bytes), &mut out).unwrap();
    out
}

fn gzip(bytes: &[u8]) -> Vec<u8> {
    let mut e = flate2::write::GzEncoder::new(Vec::new(), flate2::Compression::fast());
    std::io::Write::write_all(&mut e, bytes).unwrap();
    e.finish().unwrap()
}

#[test]
fn nifti() {
    let _serial = serial();
    fuzz("ct/fuel.nii.gz", 1, 60);
    fuzz("mri/ch2.nii.gz", 2, 25);
    // Uncompressed, and the gzip stream itself corrupted inside.
    let plain = gunzip(&std::fs::read(data("ct/fuel.nii.gz")).unwrap());
    fuzz_file("fuel.nii", &plain, "fuel.nii", Reader::Volume, 11, 60);
}

#[test]
fn nrrd() {
    let _serial = serial();
    fuzz("mri/FLAIR.nrrd", 3, 40);
    // The other encodings: raw, ascii, gzip, each with its header fuzzed.
    let codes = fuel();
    let head = |encoding: &str| {
        format!("NRRD0004\ntype: uchar\ndimension: 3\nsizes: 64 33 32\nencoding: {encoding}\nspace: RAS\nspace directions: (1,0,0) (0,1,0) (0,0,2)\nspace origin: (-5,3,1)\n\n")
            .into_bytes()
    };
    let ascii: String = codes.iter().map(|c| format!("{c} ")).collect();
    for (k, (encoding, body)) in [("raw", codes.clone()), ("ascii", ascii.into_bytes()), ("gzip", gzip(&codes))].into_iter().enumerate() {
        let mut file = head(encoding);
        file.extend(body);
        fuzz_file(&format!("fuel as {encoding} NRRD"), &file, &format!("fuel_{encoding}.nrrd"), Reader::Volume, 30 + k as u64, 40);
    }
}

#[test]
fn metaimage() {
    let _serial = serial();
    fuzz("mri/epi_64x64x37.mha", 4, 60);
}

#[test]
fn vti() {
    let _serial = serial();
    fuzz("ct/engine.vti", 5, 40);
    fuzz("labels/frog_tissues.vti", 6, 25);
}

#[test]
fn dicom() {
    let _serial = serial();
    fuzz("dicom/mr_3slices/1-001.dcm", 7, 60);
    fuzz("dicom/enhanced_mr_multiframe.dcm", 8, 60);
    // pydicom's RT Dose grids: big-endian 32-bit, and RLE-coded (Focal's own RLE decoder
    // for 32-bit samples); its deflated data set (inflated by the guard, then the parser)
    // and JPEG 2000 and JPEG-LS images (openjp2, CharLS).
    let fixtures = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pydicom");
    for (k, name) in ["rtdose_expb", "rtdose_rle", "image_dfl", "JPEG2000", "MR_small_jpeg_ls_lossless"].iter().enumerate() {
        let bytes = std::fs::read(fixtures.join(name).join(format!("{name}.dcm"))).unwrap();
        fuzz_file(name, &bytes, &format!("{name}.dcm"), Reader::Volume, 40 + k as u64, 60);
    }
    // A 1-bit segmentation (packed frames, per-frame segments and positions).
    let seg = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/dicom_seg/seg_binary/seg_binary.dcm");
    fuzz_file("seg_binary", &std::fs::read(seg).unwrap(), "seg_binary.dcm", Reader::Volume, 45, 80);
}

#[test]
fn label_tables() {
    let _serial = serial();
    fuzz("labels/aal.nii.txt", 9, 40);
    fuzz("labels/aal.nii.lut", 10, 20);
}

#[test]
fn volvis_dat_and_raw() {
    let _serial = serial();
    let codes = fuel();
    let dir = scratch("fuzz-dat");
    std::fs::write(dir.join("fuel.raw"), &codes).unwrap();
    // The text header beside its raw file, fuzzed.
    let text = b"ObjectFileName: fuel.raw\nTaggedFileName: ---\nResolution: 64 33 32\nSliceThickness: 1 1 2\nFormat: UCHAR\n";
    let mut failures = fuzz_bytes("volvis .dat text header", &dir, "fuel.dat", text, Reader::Volume, 12, 60);
    // TU Wien's binary .dat: three u16 dims, then u16 voxels.
    let mut bin: Vec<u8> = [64u16, 33, 32].iter().flat_map(|d| d.to_le_bytes()).collect();
    bin.extend(codes.iter().flat_map(|&c| (c as u16 * 16).to_le_bytes()));
    failures.extend(fuzz_bytes("binary .dat", &dir, "fuel_bin.dat", &bin, Reader::Volume, 13, 60));
    // Headerless: the file fuzzed under a fixed spec, and specs fuzzed over the file.
    failures.extend(fuzz_bytes("raw", &dir, "fuel2.raw", &codes, Reader::Raw("64x33x32:uint8:s=1x1x2"), 14, 30));
    for (k, (what, spec)) in mutations(b"64x33x32:uint16:be:s=1x1x2", 15, 80).into_iter().enumerate() {
        let spec = String::from_utf8_lossy(&spec).into_owned();
        let leaked: &'static str = Box::leak(spec.into_boxed_str());
        LARGEST.store(0, Ordering::Relaxed);
        if let Err(e) = run_case(&dir.join("fuel.raw"), Reader::Raw(leaked), &format!("raw spec {what} ({k}): {leaked:?}")) {
            failures.push(e);
        }
        TRIED.fetch_add(1, Ordering::Relaxed);
    }
    report("volvis .dat and raw", failures);
}

#[test]
fn scene_files() {
    let _serial = serial();
    // Every example scene, parsed and checked (its datasets are not loaded).
    let examples = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples");
    let mut names: Vec<_> = std::fs::read_dir(&examples).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).collect();
    names.retain(|p| p.extension().is_some_and(|e| e == "ron"));
    names.sort();
    let dir = scratch("fuzz-scenes");
    let mut failures = Vec::new();
    for (k, p) in names.iter().enumerate() {
        let text = std::fs::read(p).unwrap();
        let name = p.file_name().unwrap().to_str().unwrap();
        assert!(SceneFile::parse(&String::from_utf8_lossy(&text), name).is_ok(), "{name} parses unchanged");
        failures.extend(fuzz_bytes(name, &dir, name, &text, Reader::Scene, 100 + k as u64, 24));
    }
    report("scene files", failures);
}

#[test]
fn ome_zarr_metadata_and_chunks() {
    let _serial = serial();
    use focal::volume::convert::ome_zarr::{Compressor, WriteOptions, ZarrVersion, write};
    let volume = read_volume(&data("ct/fuel.nii.gz"), &ReadOptions::default()).unwrap();
    let mut failures = Vec::new();
    let stores = [
        ("v3 sharded", WriteOptions { chunk: 16, shard: Some(2), ..Default::default() }),
        // (Blosc inside the shards: the guard walks a shard's index to check each frame.)
        ("v3 sharded blosc", WriteOptions { chunk: 16, shard: Some(2), compressor: Compressor::Blosc, ..Default::default() }),
        ("v2", WriteOptions { chunk: 16, version: ZarrVersion::V2, ..Default::default() }),
    ];
    for (k, (what, opts)) in stores.into_iter().enumerate() {
        let dir = scratch(&format!("fuzz-zarr-{k}"));
        let store = dir.join("fuel.zarr");
        write(&volume, &store, &opts, &|_, _| {}).unwrap();
        // Its metadata files and the first chunk (or shard) of each level.
        let mut files: Vec<String> = Vec::new();
        let mut stack = vec![store.clone()];
        while let Some(d) = stack.pop() {
            let mut entries: Vec<_> = std::fs::read_dir(&d).unwrap().filter_map(|e| e.ok()).map(|e| e.path()).collect();
            entries.sort();
            let mut chunk_taken = false;
            for e in entries {
                let rel = e.strip_prefix(&dir).unwrap().to_str().unwrap().to_owned();
                let file = e.file_name().unwrap().to_str().unwrap();
                if e.is_dir() {
                    stack.push(e);
                } else if file.starts_with('.') || file.ends_with(".json") {
                    files.push(rel);
                } else if !chunk_taken {
                    files.push(rel);
                    chunk_taken = true;
                }
            }
        }
        assert!(files.len() >= 4, "{what}: {files:?}");
        for (i, rel) in files.iter().enumerate() {
            let bytes = std::fs::read(dir.join(rel)).unwrap();
            let label = format!("OME-Zarr {what} {rel}");
            failures.extend(fuzz_store(&label, &dir, rel, &bytes, 200 + (k * 50 + i) as u64));
        }
    }
    report("OME-Zarr", failures);
}

/// Fuzzes one file of the store in `dir` (read through the store's folder).
fn fuzz_store(label: &str, dir: &Path, rel: &str, bytes: &[u8], seed: u64) -> Vec<String> {
    let cases = mutations(bytes, seed, 12).into_iter().take(60).collect();
    let keep = dir.join(format!("failed-{}", rel.replace('/', "_")));
    fuzz_cases(label, (&dir.join(rel), &dir.join("fuel.zarr")), bytes, Reader::Volume, cases, &keep)
}

/// Inputs that once failed, each read again as the fuzzer read it: a volume, or a
/// scene where the file ends in `.ron`.
#[test]
fn regressions() {
    let _serial = serial();
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fuzz_regressions");
    let mut failures = Vec::new();
    let mut count = 0;
    for entry in std::fs::read_dir(&root).unwrap().filter_map(|e| e.ok()) {
        let p = entry.path();
        let reader = match p.extension().and_then(|e| e.to_str()) {
            Some("ron") => Reader::Scene,
            Some("md") => continue,
            _ => Reader::Volume,
        };
        LARGEST.store(0, Ordering::Relaxed);
        if let Err(e) = run_case(&p, reader, &p.display().to_string()) {
            failures.push(e);
        }
        let largest = LARGEST.load(Ordering::Relaxed);
        if largest > MAX_ALLOCATION {
            failures.push(format!("{}: allocated {largest} bytes at once", p.display()));
        }
        count += 1;
    }
    assert!(count > 0, "no regression cases in {}", root.display());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// Every format with a header that claims 10¹² voxels (10 000 along each axis; 65 535
/// where the field is 16 bits) in a file of a few hundred bytes: refused with the file's
/// name and the numbers it claims, before any buffer for the voxels is made.
#[test]
fn headers_claiming_a_trillion_voxels_are_refused_before_any_buffer() {
    let _serial = serial();
    let dir = scratch("trillion");
    let fuel_nii = gunzip(&std::fs::read(data("ct/fuel.nii.gz")).unwrap());
    let mut nii = fuel_nii[..352].to_vec();
    for (i, d) in [10000i16, 10000, 10000].iter().enumerate() {
        nii[42 + 2 * i..44 + 2 * i].copy_from_slice(&d.to_le_bytes());
    }
    nii.extend_from_slice(&fuel_nii[352..1352]);
    let mut nifti2 = vec![0u8; 544];
    nifti2[0..4].copy_from_slice(&540i32.to_le_bytes());
    nifti2[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
    nifti2[12..14].copy_from_slice(&2i16.to_le_bytes());
    nifti2[14..16].copy_from_slice(&8i16.to_le_bytes());
    for (i, d) in [3i64, 10000, 10000, 10000, 1, 1, 1, 1].iter().enumerate() {
        nifti2[16 + 8 * i..24 + 8 * i].copy_from_slice(&d.to_le_bytes());
    }
    for i in 0..8 {
        nifti2[104 + 8 * i..112 + 8 * i].copy_from_slice(&1.0f64.to_le_bytes());
    }
    nifti2[168..176].copy_from_slice(&544i64.to_le_bytes());
    let mut bin_dat: Vec<u8> = [65535u16; 3].iter().flat_map(|d| d.to_le_bytes()).collect();
    bin_dat.extend([0u8; 64]);
    let vti = r#"<?xml version="1.0"?><VTKFile type="ImageData" version="1.0" byte_order="LittleEndian" header_type="UInt64"><ImageData WholeExtent="0 9999 0 9999 0 9999" Origin="0 0 0" Spacing="1 1 1"><Piece Extent="0 9999 0 9999 0 9999"><PointData Scalars="s"><DataArray type="UInt8" Name="s" format="ascii">1 2 3</DataArray></PointData></Piece></ImageData></VTKFile>"#;
    std::fs::write(dir.join("small.raw"), [7u8; 100]).unwrap();
    let files: Vec<(&str, Vec<u8>)> = vec![
        ("huge.nii", nii.clone()),
        ("huge.nii.gz", gzip(&nii)),
        ("huge2.nii", nifti2),
        ("huge.nrrd", b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10000 10000 10000\nencoding: raw\n\n\x01\x02\x03".to_vec()),
        ("huge_gz.nrrd", b"NRRD0004\ntype: uchar\ndimension: 3\nsizes: 10000 10000 10000\nencoding: gzip\n\n\x1f\x8b".to_vec()),
        (
            "huge.mha",
            b"ObjectType = Image\nNDims = 3\nDimSize = 10000 10000 10000\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n\x01".to_vec(),
        ),
        ("huge.vti", vti.as_bytes().to_vec()),
        ("huge.dat", b"ObjectFileName: small.raw\nResolution: 10000 10000 10000\nSliceThickness: 1 1 1\nFormat: UCHAR\n".to_vec()),
        ("huge_bin.dat", bin_dat),
    ];
    let mut cases: Vec<(std::path::PathBuf, ReadOptions, &str)> = Vec::new();
    for (name, bytes) in &files {
        std::fs::write(dir.join(name), bytes).unwrap();
        let claim = if name.starts_with("huge_bin") { "65535" } else { "10000" };
        cases.push((dir.join(name), ReadOptions::default(), claim));
    }
    // Headerless, with the dimensions given.
    let raw = ReadOptions { raw: Some("10000x10000x10000:uint8".parse().unwrap()), ..Default::default() };
    cases.push((dir.join("small.raw"), raw, "10000"));
    // DICOM: the enhanced MR's 6 frames of 64² said to be 99 frames of 10 000² (its
    // explicit-VR elements patched in place: Number of Frames, Rows, Columns).
    let mut dcm = std::fs::read(data("dicom/enhanced_mr_multiframe.dcm")).unwrap();
    for (tag, value) in
        [([0x28u8, 0, 0x08, 0], *b"99"), ([0x28, 0, 0x10, 0], 10000u16.to_le_bytes()), ([0x28, 0, 0x11, 0], 10000u16.to_le_bytes())]
    {
        let at = dcm.windows(4).position(|w| w == tag).expect("the element is in the file") + 8;
        dcm[at..at + 2].copy_from_slice(&value);
    }
    std::fs::write(dir.join("huge.dcm"), dcm).unwrap();
    cases.push((dir.join("huge.dcm"), ReadOptions::default(), "10000"));
    // OME-Zarr: every level's array said to be 10 000³.
    let volume = read_volume(&data("ct/fuel.nii.gz"), &ReadOptions::default()).unwrap();
    let store = dir.join("huge.zarr");
    focal::volume::convert::ome_zarr::write(&volume, &store, &Default::default(), &|_, _| {}).unwrap();
    for level in std::fs::read_dir(&store).unwrap().filter_map(|e| e.ok()).filter(|e| e.path().is_dir()) {
        let meta = level.path().join("zarr.json");
        let text = std::fs::read_to_string(&meta).unwrap();
        let mut json: serde_json::Value = serde_json::from_str(&text).unwrap();
        json["shape"] = serde_json::json!([10000, 10000, 10000]);
        std::fs::write(&meta, json.to_string()).unwrap();
    }
    cases.push((store, ReadOptions::default(), "10000"));

    let mut failures = Vec::new();
    for (path, options, claim) in &cases {
        let name = path.file_name().unwrap().to_str().unwrap();
        LARGEST.store(0, Ordering::Relaxed);
        let result = read_volume(path, options);
        let largest = LARGEST.load(Ordering::Relaxed);
        match result {
            Ok(v) => failures.push(format!("{name}: opened as {:?}", v.dims())),
            Err(e) => {
                let text = e.to_string();
                if !text.contains(name) || !text.contains(claim) {
                    failures.push(format!("{name}: the error does not name the file and {claim}: {text}"));
                }
            }
        }
        if largest > 1 << 20 {
            failures.push(format!("{name}: {largest} bytes allocated at once before refusing"));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
