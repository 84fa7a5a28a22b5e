//! The `focal` binary: `info --json` and `render --cpu` end to end.

mod common;

use std::process::Command;

use common::{data, scratch};

fn focal() -> Command {
    Command::new(env!("CARGO_BIN_EXE_focal"))
}

#[test]
fn info_json_describes_the_file() {
    let out = focal().args(["info", "--json"]).arg(data("ct/fuel.nii.gz")).output().unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["dimensions"], serde_json::json!([64, 33, 32]));
    assert_eq!(v["format"], "NIfTI-1");
    assert_eq!(v["values"]["max"], 255.0);
    assert_eq!(v["histogram"]["bins"].as_array().unwrap().len(), 256);
}

#[test]
fn info_reports_labels_and_bad_files() {
    let out = focal().arg("info").arg(data("labels/aal.nii.gz")).output().unwrap();
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(text.contains("116 present"), "{text}");
    let dir = scratch("cli-bad");
    let bad = dir.join("broken.nii.gz");
    std::fs::write(&bad, b"\x1f\x8b garbage").unwrap();
    let out = focal().arg("info").arg(&bad).output().unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(err.contains("broken.nii.gz"), "{err}");
}

#[test]
fn render_cpu_writes_a_png() {
    let dir = scratch("cli-render");
    let png = dir.join("sphere.png");
    let out = focal()
        .args(["render", "phantom:sphere", "--cpu", "--mode", "iso", "--size", "48x32", "--resolution", "32", "--out"])
        .arg(&png)
        .output()
        .unwrap();
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let img = image::open(&png).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (48, 32));
    // The sphere is lit in the middle and the corners show the black background.
    assert!(img.get_pixel(24, 16)[0] > 100);
    assert_eq!(img.get_pixel(0, 0)[0], 0);
    let bad = focal().args(["render", "phantom:sphere", "--cpu", "--mode", "volumetric"]).output().unwrap();
    assert!(!bad.status.success());
}
