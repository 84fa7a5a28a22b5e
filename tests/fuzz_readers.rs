//! Throws truncated and corrupted versions of every real file at the readers: each
//! must return (a volume or an error) without panicking, within a time limit, and
//! without any single allocation larger than [`MAX_ALLOCATION`].

mod common;

use std::alloc::{GlobalAlloc, Layout, System};
use std::path::Path;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::mpsc;
use std::time::Duration;

use common::{data, scratch};
use focal::volume::readers::{ReadOptions, label_table, read_volume};

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
/// and for text headers, numbers replaced by huge or negative ones.
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
    // Text headers: replace a number with a huge or negative one.
    let text_end = bytes.iter().take(4096).position(|&c| c == 0 || c > 127).unwrap_or(n.min(4096));
    let digits: Vec<usize> = (0..text_end).filter(|&i| bytes[i].is_ascii_digit() && (i == 0 || !bytes[i - 1].is_ascii_digit())).collect();
    for (k, &at) in digits.iter().enumerate().take(60) {
        for repl in ["4294967295", "-7", "99999999999999999999", "0"] {
            let end = (at..text_end).find(|&i| !bytes[i].is_ascii_digit()).unwrap_or(text_end);
            let mut b = bytes[..at].to_vec();
            b.extend_from_slice(repl.as_bytes());
            b.extend_from_slice(&bytes[end..]);
            out.push((format!("number {k} at byte {at} → {repl}"), b));
        }
    }
    out
}

fn run_case(path: &Path, what: &str) -> Result<(), String> {
    let (tx, rx) = mpsc::channel();
    let p = path.to_path_buf();
    std::thread::spawn(move || {
        let r = std::panic::catch_unwind(|| {
            let _ = read_volume(&p, &ReadOptions::default());
            if p.extension().is_some_and(|e| e == "txt" || e == "lut") {
                let _ = label_table::read(&p);
            }
        });
        let _ = tx.send(r.is_ok());
    });
    match rx.recv_timeout(TIME_LIMIT) {
        Ok(true) => Ok(()),
        Ok(false) => Err(format!("{what}: panicked")),
        Err(_) => Err(format!("{what}: no answer within {TIME_LIMIT:?}")),
    }
}

fn fuzz(rel: &str, seed: u64, count: usize) {
    let src = data(rel);
    let bytes = std::fs::read(&src).unwrap();
    let name = src.file_name().unwrap().to_string_lossy().into_owned();
    let dir = scratch(&format!("fuzz-{}", name.replace('.', "_")));
    let mut failures = Vec::new();
    for (what, b) in mutations(&bytes, seed, count) {
        let p = dir.join(&name);
        std::fs::write(&p, &b).unwrap();
        LARGEST.store(0, Ordering::Relaxed);
        if let Err(e) = run_case(&p, &what) {
            failures.push(e);
        }
        let largest = LARGEST.load(Ordering::Relaxed);
        if largest > MAX_ALLOCATION {
            failures.push(format!("{what}: allocated {largest} bytes at once"));
        }
    }
    assert!(failures.is_empty(), "{rel}:\n{}", failures.join("\n"));
}

#[test]
fn nifti() {
    fuzz("ct/fuel.nii.gz", 1, 60);
    fuzz("mri/ch2.nii.gz", 2, 25);
}

#[test]
fn nrrd() {
    fuzz("mri/FLAIR.nrrd", 3, 40);
}

#[test]
fn metaimage() {
    fuzz("mri/epi_64x64x37.mha", 4, 60);
}

#[test]
fn vti() {
    fuzz("ct/engine.vti", 5, 40);
    fuzz("labels/frog_tissues.vti", 6, 25);
}

#[test]
fn dicom() {
    fuzz("dicom/mr_3slices/1-001.dcm", 7, 60);
    fuzz("dicom/enhanced_mr_multiframe.dcm", 8, 60);
}

#[test]
fn label_tables() {
    fuzz("labels/aal.nii.txt", 9, 40);
    fuzz("labels/aal.nii.lut", 10, 20);
}
