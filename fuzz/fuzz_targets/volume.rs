//! Every reader on arbitrary bytes: the first byte picks the file name (so the format
//! detection by extension and by content both see the input), the rest is the file.
//! A reader may refuse the input with an error; it must not panic, hang or allocate
//! without bound (`-rss_limit_mb`, `-timeout`). Seed the corpus from `../shared/data`
//! and `tests/fixtures` (see `fuzz/README.md`).
#![no_main]

use focal::volume::readers::{ReadOptions, read_volume};
use libfuzzer_sys::fuzz_target;

/// The names the input is saved under.
const NAMES: &[&str] =
    &["in.nii", "in.nii.gz", "in.hdr", "in.nrrd", "in.nhdr", "in.mha", "in.mhd", "in.vti", "in.dat", "in.dcm", "in.raw", "in"];

fuzz_target!(|data: &[u8]| {
    let Some((&pick, bytes)) = data.split_first() else { return };
    let dir = std::env::temp_dir().join(format!("focal-fuzz-{}", std::process::id()));
    if std::fs::create_dir_all(&dir).is_err() {
        return;
    }
    let path = dir.join(NAMES[pick as usize % NAMES.len()]);
    if std::fs::write(&path, bytes).is_ok() {
        let _ = read_volume(&path, &ReadOptions::default());
    }
    let _ = std::fs::remove_file(&path);
});
