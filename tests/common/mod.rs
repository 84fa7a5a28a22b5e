//! Helpers shared by the integration tests.
// Each test crate uses some of these helpers, none uses all of them.
#![allow(dead_code)]

use std::path::{Path, PathBuf};

/// A file of the shared real datasets (`../shared/data`, or `$FOCAL_DATA`).
pub fn data(rel: &str) -> PathBuf {
    let root =
        std::env::var_os("FOCAL_DATA").map(PathBuf::from).unwrap_or_else(|| Path::new(env!("CARGO_MANIFEST_DIR")).join("../shared/data"));
    let p = root.join(rel);
    assert!(p.exists(), "test data {} is missing (expected the shared datasets beside the project)", p.display());
    p
}

/// A fresh scratch directory for one test.
pub fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("focal-test-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).expect("scratch directory");
    d
}
