//! Readers on the real files of `../shared/data`, checked against values computed
//! independently with nibabel, pynrrd, SimpleITK, pydicom and a hand-written VTI decoder
//! in Python (the script and its output are summarised in each test).

mod common;

use common::{data, scratch};
use focal::volume::readers::{Problem, RawSpec, ReadOptions, label_table, read_label_volume, read_volume};
use focal::volume::{Volume, Voxels};
use glam::{Mat4, Vec3, Vec4};

/// Expected facts about one file. `affine` is the index→world RAS matrix, row-major, as
/// an independent reader prints it (in f64; Focal's grid holds f32).
struct Truth {
    dims: [u32; 3],
    bits: u32,
    min: f64,
    max: f64,
    mean: f64,
    /// (index, real value).
    samples: [([u32; 3], f64); 3],
    affine: [[f64; 4]; 3],
}

fn check(v: &Volume, t: &Truth, affine_tol: f32) {
    assert_eq!(v.dims().to_array(), t.dims, "{}", v.name);
    assert_eq!(v.voxels.bits(), t.bits, "{}", v.name);
    assert_eq!((v.stats.min, v.stats.max), (t.min, t.max), "{}", v.name);
    assert!((v.stats.mean - t.mean).abs() < 1e-3, "{} mean {} vs {}", v.name, v.stats.mean, t.mean);
    for (ijk, value) in t.samples {
        assert_eq!(v.real(ijk[0], ijk[1], ijk[2]), value, "{} at {ijk:?}", v.name);
    }
    let m = Mat4::from(v.grid.index_to_world());
    for (r, row) in t.affine.iter().enumerate() {
        let got = m.row(r);
        let want = Vec4::from_array(row.map(|x| x as f32));
        assert!((got - want).abs().max_element() < affine_tol, "{} affine row {r}: {got} vs {want}", v.name);
    }
}

fn read(rel: &str) -> Volume {
    read_volume(&data(rel), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"))
}

#[test]
fn nifti_ch2_uses_the_sform() {
    let v = read("mri/ch2.nii.gz");
    check(
        &v,
        &Truth {
            dims: [181, 217, 181],
            bits: 8,
            min: 0.0,
            max: 254.0,
            mean: 44.6118,
            samples: [([0, 0, 0], 0.0), ([90, 108, 90], 33.0), ([60, 54, 36], 92.0)],
            affine: [[1.0, 0.0, 0.0, -90.0], [0.0, 1.0, 0.0, -125.0], [0.0, 0.0, 1.0, -71.0]],
        },
        1e-4,
    );
    assert_eq!(v.source.format, "NIfTI-1");
    assert_eq!(v.grid.orientation_code(), "RAS");
    // World (0, 0, 0) is voxel (90, 125, 71) with value 32.
    let q = v.grid.world_to_index().transform_point3(Vec3::ZERO).round().as_uvec3();
    assert_eq!((q.to_array(), v.real(q.x, q.y, q.z)), ([90, 125, 71], 32.0));
}

#[test]
fn nifti_fuel() {
    let v = read("ct/fuel.nii.gz");
    check(
        &v,
        &Truth {
            dims: [64, 33, 32],
            bits: 8,
            min: 0.0,
            max: 255.0,
            mean: 7.5434,
            samples: [([0, 0, 0], 0.0), ([32, 16, 16], 189.0), ([21, 8, 6], 0.0)],
            affine: [[1.0, 0.0, 0.0, -31.0], [0.0, 1.0, 0.0, -16.0], [0.0, 0.0, 1.0, -16.0]],
        },
        1e-4,
    );
}

#[test]
fn nrrd_flair_is_oblique_lps() {
    let v = read("mri/FLAIR.nrrd");
    check(
        &v,
        &Truth {
            dims: [124, 160, 140],
            bits: 8,
            min: 0.0,
            max: 255.0,
            mean: 41.486,
            samples: [([0, 0, 0], 0.0), ([62, 80, 70], 170.0), ([41, 40, 28], 125.0)],
            affine: [
                [0.993592, 0.016005, 0.111887, -64.898239],
                [-0.049705, 0.950937, 0.305367, -110.431145],
                [-0.10151, -0.308971, 0.945639, -27.925539],
            ],
        },
        1e-4,
    );
    assert!(!v.grid.is_orthogonal() || v.grid.direction.x_axis.x < 0.9999, "oblique");
}

#[test]
fn metaimage_epi_int16_compressed() {
    let v = read("mri/epi_64x64x37.mha");
    check(
        &v,
        &Truth {
            dims: [64, 64, 37],
            bits: 16,
            min: 0.0,
            max: 6690.0,
            mean: 527.5062,
            samples: [([0, 0, 0], 0.0), ([32, 32, 18], 4369.0), ([21, 16, 7], 2123.0)],
            affine: [[-3.4375, 0.0, 0.0, 108.281], [0.0, 3.4375, 0.0, -82.3795], [0.0, 0.0, 3.8, -47.8356]],
        },
        1e-3,
    );
    assert_eq!(v.source.sample_type, "int16");
}

#[test]
fn vti_engine_raw_appended_uint64_zlib() {
    let v = read("ct/engine.vti");
    check(
        &v,
        &Truth {
            dims: [256, 256, 128],
            bits: 8,
            min: 0.0,
            max: 255.0,
            mean: 22.3488,
            samples: [([0, 0, 0], 0.0), ([128, 128, 64], 133.0), ([85, 64, 25], 97.0)],
            affine: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0]],
        },
        1e-6,
    );
}

#[test]
fn vti_frog_labels_inline_base64_uint32() {
    let path = data("labels/frog_tissues.vti");
    let v = read_volume(&path, &ReadOptions::default()).unwrap();
    check(
        &v,
        &Truth {
            dims: [500, 470, 136],
            bits: 8,
            min: 0.0,
            max: 29.0,
            mean: 0.3831,
            samples: [([0, 0, 0], 0.0), ([250, 235, 68], 6.0), ([166, 117, 27], 0.0)],
            affine: [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.5, 0.0]],
        },
        1e-6,
    );
    let labels = read_label_volume(&path, None, &ReadOptions::default()).unwrap();
    let ids: Vec<u32> = labels.present_ids().into_iter().map(|(id, _)| id).filter(|&id| id != 0).collect();
    assert_eq!(ids.len(), 25);
    assert!(!ids.contains(&18) && ids.contains(&29));
}

#[test]
fn dicom_series_sorted_along_the_normal() {
    let v = read("dicom/mr_3slices");
    check(
        &v,
        &Truth {
            dims: [512, 512, 3],
            bits: 16,
            min: 0.0,
            max: 507.0,
            mean: 79.4543,
            samples: [([0, 0, 0], 0.0), ([256, 256, 1], 32.0), ([170, 128, 0], 239.0)],
            affine: [[-0.41015625, 0.0, 0.0, 106.326809], [0.0, -0.41015625, 0.0, 123.074438], [0.0, 0.0, 1.5, -92.000669]],
        },
        2e-4,
    );
    assert_eq!(v.source.format, "DICOM series");
    // Opening one slice gathers the same series.
    let one = read("dicom/mr_3slices/1-002.dcm");
    assert_eq!(one.dims().to_array(), [512, 512, 3]);
    assert_eq!(one.voxels, v.voxels);
}

/// A folder as users export them: the series's slices beside another series (the
/// enhanced MR), a slice of the same series whose pixel data does not decode as the
/// series's (Bits Allocated patched to 8), a file that is not DICOM and one that is
/// truncated. Opening a slice reads its own series and names what it skipped.
#[test]
fn dicom_slice_in_a_mixed_folder_reads_its_own_series() {
    let dir = scratch("dicom-mixed");
    for n in ["1-001.dcm", "1-002.dcm", "1-003.dcm"] {
        std::fs::copy(data(&format!("dicom/mr_3slices/{n}")), dir.join(n)).unwrap();
    }
    std::fs::copy(data("dicom/enhanced_mr_multiframe.dcm"), dir.join("0-enhanced.dcm")).unwrap();
    let mut odd = std::fs::read(data("dicom/mr_3slices/1-003.dcm")).unwrap();
    // (0028,0100) Bits Allocated, implicit VR: tag, 4-byte length, value 16 → 8.
    let at = odd.windows(4).position(|w| w == [0x28, 0, 0, 1]).unwrap() + 8;
    odd[at] = 8;
    std::fs::write(dir.join("1-004.dcm"), &odd).unwrap();
    std::fs::write(dir.join("notes.txt"), "exported by hand").unwrap();
    let whole = std::fs::read(data("dicom/mr_3slices/1-002.dcm")).unwrap();
    std::fs::write(dir.join("1-005.dcm"), &whole[..whole.len() / 2]).unwrap();
    let v = read_volume(&dir.join("1-002.dcm"), &ReadOptions::default()).unwrap();
    assert_eq!(v.dims().to_array(), [512, 512, 3]);
    assert_eq!(v.voxels, read("dicom/mr_3slices").voxels);
    let notes: Vec<&str> = v.source.details.iter().filter(|(k, _)| k == "note").map(|(_, n)| n.as_str()).collect();
    let skipped = notes.iter().find(|n| n.contains("skipped")).unwrap_or_else(|| panic!("{notes:?}"));
    assert!(skipped.contains("1-004.dcm") && skipped.contains("1-005.dcm") && skipped.starts_with("2 file(s)"), "{skipped}");
    assert!(notes.iter().any(|n| n.contains("1 other series")), "{notes:?}");
    // The opened file's own failure is the error, with its name.
    let e = read_volume(&dir.join("1-004.dcm"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("1-004.dcm"), "{e}");
}

#[test]
fn dicom_enhanced_multiframe() {
    let v = read("dicom/enhanced_mr_multiframe.dcm");
    check(
        &v,
        &Truth {
            dims: [64, 64, 6],
            bits: 16,
            min: 0.0,
            max: 1195.0,
            mean: 101.5113,
            samples: [([0, 0, 0], 0.0), ([32, 32, 3], 560.0), ([21, 16, 1], 11.0)],
            affine: [[-3.375, 0.0, 0.0, 109.79], [0.0, -3.375, 2e-5, 58.4773], [3e-6, 3e-6, 2.4, -5.40356]],
        },
        2e-4,
    );
    assert_eq!(v.source.format, "DICOM multi-frame");
}

#[test]
fn aal_labels_with_names_and_colours() {
    let path = data("labels/aal.nii.gz");
    let labels = read_label_volume(&path, None, &ReadOptions::default()).unwrap();
    let ids = labels.present_ids();
    assert_eq!(ids.iter().filter(|(id, _)| *id != 0).count(), 116);
    assert_eq!(labels.table.name(1), "Precentral_L");
    assert_eq!(labels.table.name(116), "Vermis_10");
    // Colours come from aal.nii.lut (planar R, G, B).
    let lut = std::fs::read(data("labels/aal.nii.lut")).unwrap();
    assert_eq!(labels.table.color(1), [lut[1], lut[257], lut[513]]);
    // The palette colours the named labels; it does not add 139 unnamed ones.
    assert_eq!(labels.table.len(), 116);
    assert_eq!(labels.id(60, 54, 36), 91);
    let table = label_table::read(&data("labels/aal.nii.txt")).unwrap();
    assert_eq!(table.len(), 116);
}

#[test]
fn nifti2_and_analyze_style_pair() {
    // Re-write fuel.nii.gz as NIfTI-2 (540-byte header) and as a NIfTI-1 .hdr/.img pair.
    let src = read("ct/fuel.nii.gz");
    let dir = scratch("nifti2");
    let Voxels::U8(codes) = &src.voxels else { panic!("fuel is 8-bit") };
    let mut h = vec![0u8; 544];
    h[0..4].copy_from_slice(&540i32.to_le_bytes());
    h[4..12].copy_from_slice(b"n+2\0\r\n\x1a\n");
    h[12..14].copy_from_slice(&2i16.to_le_bytes()); // uint8
    h[14..16].copy_from_slice(&8i16.to_le_bytes());
    for (i, d) in [3i64, 64, 33, 32, 1, 1, 1, 1].iter().enumerate() {
        h[16 + 8 * i..24 + 8 * i].copy_from_slice(&d.to_le_bytes());
    }
    for (i, p) in [1.0f64, 2.0, 2.0, 3.0, 1.0, 1.0, 1.0, 1.0].iter().enumerate() {
        h[104 + 8 * i..112 + 8 * i].copy_from_slice(&p.to_le_bytes());
    }
    h[168..176].copy_from_slice(&544i64.to_le_bytes());
    h[176..184].copy_from_slice(&2.0f64.to_le_bytes()); // scl_slope
    h[184..192].copy_from_slice(&(-10.0f64).to_le_bytes()); // scl_inter
    h[348..352].copy_from_slice(&2i32.to_le_bytes()); // sform_code
    let srow = [[2.0f64, 0.0, 0.0, 5.0], [0.0, 2.0, 0.0, 6.0], [0.0, 0.0, 3.0, 7.0]];
    for (r, row) in srow.iter().enumerate() {
        for (c, x) in row.iter().enumerate() {
            h[400 + 32 * r + 8 * c..408 + 32 * r + 8 * c].copy_from_slice(&x.to_le_bytes());
        }
    }
    h[500..504].copy_from_slice(&2i32.to_le_bytes()); // mm
    let mut file = h.clone();
    file.extend_from_slice(codes);
    let p2 = dir.join("fuel2.nii");
    std::fs::write(&p2, &file).unwrap();
    let v = read_volume(&p2, &ReadOptions::default()).unwrap();
    assert_eq!(v.source.format, "NIfTI-2");
    assert_eq!(v.grid.spacing, Vec3::new(2.0, 2.0, 3.0));
    assert_eq!(v.grid.origin, Vec3::new(5.0, 6.0, 7.0));
    assert_eq!(v.real(32, 16, 16), 189.0 * 2.0 - 10.0);
    // Truncated NIfTI-2 data is reported as such.
    std::fs::write(&p2, &file[..file.len() - 100]).unwrap();
    let e = read_volume(&p2, &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.problem, Problem::Truncated(_)), "{e}");
    assert!(e.to_string().contains("fuel2.nii"), "{e}");

    // NIfTI-1 pair: the header of fuel.nii.gz with magic "ni1" and vox_offset 0.
    let mut gz = flate2::read::GzDecoder::new(std::fs::File::open(data("ct/fuel.nii.gz")).unwrap());
    let mut all = Vec::new();
    std::io::Read::read_to_end(&mut gz, &mut all).unwrap();
    let mut hdr = all[..348].to_vec();
    hdr[108..112].copy_from_slice(&0f32.to_le_bytes());
    hdr[344..348].copy_from_slice(b"ni1\0");
    std::fs::write(dir.join("pair.hdr"), &hdr).unwrap();
    std::fs::write(dir.join("pair.img"), &all[352..]).unwrap();
    for p in ["pair.hdr", "pair.img"] {
        let v = read_volume(&dir.join(p), &ReadOptions::default()).unwrap();
        assert_eq!(v.voxels, src.voxels, "{p}");
    }
}

#[test]
fn raw_and_volvis_dat() {
    let src = read("ct/fuel.nii.gz");
    let Voxels::U8(codes) = &src.voxels else { panic!("fuel is 8-bit") };
    let dir = scratch("raw");
    std::fs::write(dir.join("fuel.raw"), codes).unwrap();
    let spec: RawSpec = "64x33x32:uint8:s=1x1x2".parse().unwrap();
    let opts = ReadOptions { raw: Some(spec), ..Default::default() };
    let v = read_volume(&dir.join("fuel.raw"), &opts).unwrap();
    assert_eq!(v.voxels, src.voxels);
    assert_eq!(v.grid.spacing.z, 2.0);
    // The same through a volvis .dat header.
    std::fs::write(
        dir.join("fuel.dat"),
        "ObjectFileName: fuel.raw\nTaggedFileName: ---\nResolution: 64 33 32\nSliceThickness: 1 1 1\nFormat: UCHAR\n",
    )
    .unwrap();
    let d = read_volume(&dir.join("fuel.dat"), &ReadOptions::default()).unwrap();
    assert_eq!(d.voxels, src.voxels);
    // Saved with a byte-order mark (non-ASCII first bytes: not taken for a binary header).
    std::fs::write(dir.join("bom.dat"), "\u{feff}ObjectFileName: fuel.raw\nResolution: 64 33 32\nFormat: UCHAR\n").unwrap();
    assert_eq!(read_volume(&dir.join("bom.dat"), &ReadOptions::default()).unwrap().voxels, src.voxels);
    // TU Wien binary .dat: three u16 dims, then u16 voxels.
    let mut bin: Vec<u8> = [4u16, 2, 2].iter().flat_map(|d| d.to_le_bytes()).collect();
    bin.extend((0..16u16).flat_map(|v| (v * 100).to_le_bytes()));
    std::fs::write(dir.join("tiny.dat"), &bin).unwrap();
    let t = read_volume(&dir.join("tiny.dat"), &ReadOptions::default()).unwrap();
    assert_eq!((t.dims().to_array(), t.real(3, 1, 1)), ([4, 2, 2], 1500.0));
    // A raw file too short for its dimensions.
    let short = ReadOptions { raw: Some("64x33x33:uint8".parse().unwrap()), ..Default::default() };
    let e = read_volume(&dir.join("fuel.raw"), &short).unwrap_err();
    assert!(matches!(e.problem, Problem::Truncated(_)), "{e}");
}

#[test]
fn nrrd_detached_ascii_and_big_endian() {
    let dir = scratch("nrrd");
    let values: Vec<i16> = (0..24).map(|i| i * 10 - 50).collect();
    std::fs::write(dir.join("d.raw"), values.iter().flat_map(|v| v.to_be_bytes()).collect::<Vec<u8>>()).unwrap();
    std::fs::write(dir.join("d.nhdr"), "NRRD0004\ntype: short\ndimension: 3\nsizes: 4 3 2\nencoding: raw\nendian: big\nspace: RAS\nspace directions: (2,0,0) (0,2,0) (0,0,3)\nspace origin: (1,2,3)\ndata file: d.raw\n").unwrap();
    let v = read_volume(&dir.join("d.nhdr"), &ReadOptions::default()).unwrap();
    assert_eq!(v.real(3, 2, 1), 23.0 * 10.0 - 50.0);
    assert_eq!(v.grid.origin, Vec3::new(1.0, 2.0, 3.0));
    let text: String = values.iter().map(|v| v.to_string()).collect::<Vec<_>>().join(" ");
    std::fs::write(
        dir.join("a.nrrd"),
        format!("NRRD0004\ntype: short\ndimension: 3\nsizes: 4 3 2\nencoding: ascii\nspacings: 1 1 2\n\n{text}\n"),
    )
    .unwrap();
    let a = read_volume(&dir.join("a.nrrd"), &ReadOptions::default()).unwrap();
    assert_eq!(a.voxels, v.voxels);
    assert_eq!(a.grid.spacing.z, 2.0);
    // Unknown encodings and types are named.
    std::fs::write(dir.join("b.nrrd"), "NRRD0004\ntype: short\ndimension: 3\nsizes: 4 3 2\nencoding: zstd\nendian: little\n\n").unwrap();
    let e = read_volume(&dir.join("b.nrrd"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("zstd") && e.to_string().contains("b.nrrd"), "{e}");
}

#[test]
fn absurd_sizes_are_refused_before_allocating() {
    let dir = scratch("absurd");
    std::fs::write(
        dir.join("huge.nhdr"),
        "NRRD0004\ntype: float\ndimension: 3\nsizes: 60000 60000 60000\nencoding: raw\nendian: little\ndata file: x.raw\n",
    )
    .unwrap();
    let e = read_volume(&dir.join("huge.nhdr"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.problem, Problem::TooLarge(_)), "{e}");
    std::fs::write(
        dir.join("huge.mha"),
        "ObjectType = Image\nNDims = 3\nDimSize = 2000 2000 2000\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n",
    )
    .unwrap();
    let e = read_volume(&dir.join("huge.mha"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.problem, Problem::TooLarge(_)), "{e}");
    // Within the limits but far larger than the file: truncation, no 4 GB buffer.
    std::fs::write(
        dir.join("big.mha"),
        "ObjectType = Image\nNDims = 3\nDimSize = 1000 1000 1000\nElementType = MET_UCHAR\nElementDataFile = LOCAL\n\x01\x02",
    )
    .unwrap();
    let e = read_volume(&dir.join("big.mha"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.problem, Problem::Truncated(_)), "{e}");
}

#[test]
fn unknown_files_are_named() {
    let dir = scratch("unknown");
    std::fs::write(dir.join("notes.xyz"), "hello").unwrap();
    let e = read_volume(&dir.join("notes.xyz"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("notes.xyz") && e.to_string().contains("unknown file format"), "{e}");
    let e = read_volume(&dir.join("missing.nii"), &ReadOptions::default()).unwrap_err();
    assert!(matches!(e.problem, Problem::Io(_)), "{e}");
    // A float volume with an infinite sample is refused (no place on the value axis).
    let mut inf = b"ObjectType = Image\nNDims = 3\nDimSize = 2 1 1\nElementType = MET_FLOAT\nElementDataFile = LOCAL\n".to_vec();
    inf.extend(1.0f32.to_le_bytes());
    inf.extend(f32::INFINITY.to_le_bytes());
    std::fs::write(dir.join("inf.mha"), inf).unwrap();
    let e = read_volume(&dir.join("inf.mha"), &ReadOptions::default()).unwrap_err();
    assert!(e.to_string().contains("infinite") && e.to_string().contains("inf.mha"), "{e}");
}

/// A masked float NIfTI, as resampling and masking tools write them: fuel's zero voxels
/// made NaN. It opens, NaN as no data: counted in a note, left out of the statistics and
/// the histogram, every true value as before.
#[test]
fn a_float_nifti_with_nan_voxels_opens_with_them_as_empty_space() {
    let src = read("ct/fuel.nii.gz");
    let dir = scratch("nan");
    common::masked_fuel_nifti(&dir.join("masked.nii"));
    let reals: Vec<f64> = (0..src.voxels.len()).map(|i| src.values.to_real(src.voxels.code(i) as f64)).collect();
    let nan = reals.iter().filter(|&&v| v == 0.0).count();
    let v = read_volume(&dir.join("masked.nii"), &ReadOptions::default()).unwrap();
    assert!(nan > 1000, "fuel has background: {nan}");
    assert_eq!(v.stats.no_data, nan as u64);
    let note = v.source.details.iter().find(|(k, n)| k == "note" && n.contains("NaN")).map(|(_, n)| n.clone());
    assert!(note.as_deref().is_some_and(|n| n.starts_with(&format!("{nan} of {}", reals.len()))), "{note:?}");
    assert_eq!(v.stats.histogram.total(), (reals.len() - nan) as u64);
    let finite: Vec<f64> = reals.iter().copied().filter(|&v| v != 0.0).collect();
    assert_eq!(v.stats.min, finite.iter().copied().fold(f64::INFINITY, f64::min));
    assert_eq!(v.stats.max, src.stats.max);
    for (i, &r) in reals.iter().enumerate().step_by(97) {
        let got = v.values.to_real(v.voxels.code(i) as f64);
        if r == 0.0 {
            assert_eq!(v.voxels.code(i), 0, "voxel {i} is no data");
        } else {
            assert!((got - r).abs() < 1e-9, "voxel {i}: {got} for {r}");
        }
    }
}

#[test]
fn metaimage_uncompressed_with_a_data_file() {
    // The epi volume re-saved as an uncompressed .mhd + .raw pair, big-endian.
    let src = read("mri/epi_64x64x37.mha");
    let dir = scratch("mhd");
    let raw: Vec<u8> = (0..src.voxels.len()).flat_map(|i| (src.values.to_real(src.voxels.code(i) as f64) as i16).to_be_bytes()).collect();
    std::fs::write(dir.join("epi.raw"), raw).unwrap();
    std::fs::write(
        dir.join("epi.mhd"),
        "ObjectType = Image\nNDims = 3\nBinaryData = True\nBinaryDataByteOrderMSB = True\nCompressedData = False\n\
         TransformMatrix = 1 0 0 0 -1 0 0 0 1\nOffset = -108.281 82.3795 -47.8356\nElementSpacing = 3.4375 3.4375 3.8\n\
         DimSize = 64 64 37\nElementType = MET_SHORT\nElementDataFile = epi.raw\n",
    )
    .unwrap();
    let v = read_volume(&dir.join("epi.mhd"), &ReadOptions::default()).unwrap();
    assert_eq!(v.voxels, src.voxels);
    assert_eq!(v.grid, src.grid);
}

/// A file of pydicom's public test data (`tests/fixtures/pydicom`, one a folder).
fn pydicom(name: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/pydicom").join(name).join(format!("{name}.dcm"))
}

/// An RT Dose grid of 15 frames (Grid Frame Offset Vector 0, 5, … 70 mm; Dose Grid
/// Scaling 1e-6), as written (implicit VR), big-endian and RLE-coded with 32-bit
/// samples: every frame, at its offset, in dose units. Values read by pydicom 3.0.1.
#[test]
fn rt_dose_grids_read_every_frame_at_its_offset_in_dose_units() {
    for name in ["rtdose", "rtdose_expb", "rtdose_rle"] {
        let v = read_volume(&pydicom(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert_eq!(v.dims().to_array(), [10, 10, 15], "{name}");
        assert!((v.grid.spacing - Vec3::new(10.0, 10.0, 5.0)).length() < 1e-4, "{name}: {:?}", v.grid.spacing);
        // pydicom: pixel_array[frame, row, column] × 1e-6; 32-bit values spanning 459 000
        // steps are quantised to 16-bit codes (volume::encode): within half a code.
        let half_code = 0.5 * (1.254 - 0.795) / 65535.0 + 1e-9;
        for ((x, y, z), dose) in [((0, 0, 0), 1.249), ((1, 2, 3), 1.139), ((6, 4, 7), 1.026), ((9, 9, 14), 0.799)] {
            assert!((v.real(x, y, z) - dose).abs() <= half_code, "{name} ({x}, {y}, {z}): {} for {dose}", v.real(x, y, z));
        }
        assert!((v.stats.min - 0.795).abs() < 1e-9 && (v.stats.max - 1.254).abs() < 1e-9, "{name}: {:?}", v.stats);
        assert_eq!(v.values.units.as_deref(), Some("relative"), "{name}");
    }
}

/// One MR image in several transfer syntaxes: RLE, lossless JPEG 2000 and lossless
/// JPEG-LS decode to the same voxels; 12-bit JPEG Extended, which Focal's JPEG decoder
/// lacks, is refused naming the file, the transfer syntax and the decoder's reason.
/// Values read by pydicom 3.0.1.
#[test]
fn transfer_syntaxes_decode_alike_or_are_named() {
    let plain = read_volume(&pydicom("MR_small"), &ReadOptions::default()).unwrap();
    assert_eq!((plain.real(10, 20, 0), plain.real(0, 63, 0), plain.stats.min, plain.stats.max), (228.0, 378.0, 127.0, 2145.0));
    for name in ["MR_small_RLE", "MR_small_jp2klossless", "MR_small_jpeg_ls_lossless"] {
        let coded = read_volume(&pydicom(name), &ReadOptions::default()).unwrap();
        assert_eq!(coded.voxels, plain.voxels, "{name}");
    }
    // (12-bit JPEG Extended: jpeg-decoder takes 8-bit samples; pydicom with Pillow refuses
    // it too.)
    let e = read_volume(&pydicom("JPEG-lossy"), &ReadOptions::default()).unwrap_err().to_string();
    assert!(e.contains("JPEG-lossy.dcm") && e.contains("1.2.840.10008.1.2.4.51 (JPEG Extended"), "{e}");
    assert!(e.contains("SamplePrecision(12)"), "the decoder's reason is named: {e}");
}

/// JPEG 2000 images, lossy and lossless (one whose code stream is unsigned where its
/// header says signed), decode as pydicom 3.0.1 with Pillow's OpenJPEG reads them, in
/// real values (Rescale Intercept −1024 for the CT): pixels (row, column) and sums.
#[test]
fn jpeg_2000_images_decode_as_pydicom_reads_them() {
    for (name, pixels, sum) in [
        ("JPEG2000", [((0, 0), 0.0), ((100, 200), -2.0), ((1023, 3), 0.0)], 3_527_976.0),
        ("693_J2KI", [((0, 0), -3040.0), ((100, 200), -895.0), ((511, 3), -3040.0)], -270_617_240.0),
        ("J2K_pixelrep_mismatch", [((0, 0), -2000.0), ((100, 200), -285.0), ((511, 3), -2000.0)], -172_605_258.0),
    ] {
        let v = read_volume(&pydicom(name), &ReadOptions::default()).unwrap_or_else(|e| panic!("{e}"));
        for ((row, col), value) in pixels {
            assert_eq!(v.real(col, row, 0), value, "{name} ({row}, {col})");
        }
        let n = v.voxels.len() as f64;
        assert!((v.stats.mean * n - sum).abs() < 1e-6 * sum.abs(), "{name}: sum {} for {sum}", v.stats.mean * n);
    }
}

/// A data set in the deflated transfer syntax (the whole set after the meta group one
/// deflate stream) reads as pydicom 3.0.1 reads it.
#[test]
fn a_deflated_data_set_reads_as_pydicom_reads_it() {
    let v = read_volume(&pydicom("image_dfl"), &ReadOptions::default()).unwrap();
    assert_eq!(v.dims().to_array(), [512, 512, 1]);
    // pydicom: pixel_array[0, 0], [100, 200], [511, 3] (row, column); the sum 33 322 688.
    assert_eq!((v.real(0, 0, 0), v.real(200, 100, 0), v.real(3, 511, 0)), (213.0, 41.0, 115.0));
    assert!((v.stats.mean - 33_322_688.0 / (512.0 * 512.0)).abs() < 1e-9, "{}", v.stats.mean);
}

/// The segmentations written by `tests/fixtures/dicom_seg/make_segs.py` (pydicom packs
/// the bits), with the label volumes numpy made beside them.
fn segmentation(name: &str) -> (Volume, Vec<u8>) {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/fixtures/dicom_seg");
    let v = read_volume(&dir.join(format!("seg_{name}/seg_{name}.dcm")), &ReadOptions::default()).unwrap();
    (v, std::fs::read(dir.join(format!("expected_{name}.u8"))).unwrap())
}

/// A 1-bit segmentation (19 × 13 pixels: frames share bytes) is a label volume: every
/// frame on its slice of the 2.5 mm grid (slice 4, with no frame, background), the
/// higher segment where two overlap, the segments' names and CIELab colours in its table.
#[test]
fn a_binary_segmentation_reads_as_a_label_volume() {
    let (v, expected) = segmentation("binary");
    assert_eq!(v.dims().to_array(), [19, 13, 6]);
    let codes: Vec<u8> = (0..v.voxels.len()).map(|i| v.voxels.code(i) as u8).collect();
    let ids: Vec<f64> = (0..v.voxels.len()).map(|i| v.values.to_real(v.voxels.code(i) as f64)).collect();
    assert!(
        ids.iter().zip(&expected).all(|(a, &b)| *a == b as f64),
        "{} voxels differ",
        ids.iter().zip(&expected).filter(|(a, b)| **a != **b as f64).count()
    );
    assert!(codes.iter().skip(4 * 19 * 13).take(19 * 13).all(|&c| c == 0), "the slice without a frame is background");
    // Spacing (columns, rows, slices) and the oblique rows: LPS (0.8, 0.6, 0) is RAS (−0.8, −0.6, 0).
    assert!((v.grid.spacing - Vec3::new(0.9, 0.7, 2.5)).length() < 1e-5, "{:?}", v.grid.spacing);
    assert!((v.grid.direction.x_axis - Vec3::new(-0.8, -0.6, 0.0)).length() < 1e-5);
    assert!((v.grid.origin - Vec3::new(10.0, -20.0, 30.0)).length() < 1e-4, "{:?}", v.grid.origin);
    let table = v.label_table.as_ref().expect("the segments' table");
    let names: Vec<_> = table.labels.iter().map(|(id, l)| (*id, l.name.as_str())).collect();
    assert_eq!(names, vec![(1, "liver"), (2, "tumour"), (3, "vessel")]);
    // (CIELab of sRGB red, green and blue.)
    for (id, rgb) in [(1, [255, 0, 0]), (2, [0, 255, 0]), (3, [0, 0, 255])] {
        assert!(table.color(id).iter().zip(rgb).all(|(a, b)| a.abs_diff(b) <= 2), "{id}: {:?}", table.color(id));
    }
    assert!(v.source.details.iter().any(|(_, n)| n.contains("24 voxel(s) in more than one segment")), "{:?}", v.source.details);
}

/// An 8-bit FRACTIONAL segmentation: a voxel is in its segment from half the Maximum
/// Fractional Value (200) up.
#[test]
fn a_fractional_segmentation_is_thresholded_at_half_its_maximum() {
    let (v, expected) = segmentation("fractional");
    assert_eq!(v.dims().to_array(), [19, 13, 2]);
    let ids: Vec<u8> = (0..v.voxels.len()).map(|i| v.values.to_real(v.voxels.code(i) as f64) as u8).collect();
    assert_eq!(ids, expected);
    assert_eq!(v.label_table.as_ref().and_then(|t| t.get(4)).map(|l| l.name.as_str()), Some("probable lesion"));
}

/// A scene (or the app, or `focal render`) opening a segmentation without saying
/// `labels` shows it as labels, with the segments' names.
#[test]
fn a_segmentation_opens_as_labels_with_its_names() {
    let scene = focal::scene::SceneFile::parse(
        r#"(datasets: [(source: File("tests/fixtures/dicom_seg/seg_binary/seg_binary.dcm"))])"#,
        "segmentation scene",
    )
    .unwrap();
    let d = focal::scene::load::load_datasets(&scene, std::path::Path::new(env!("CARGO_MANIFEST_DIR"))).unwrap();
    let table = d[0].table.as_ref().expect("shown as labels");
    assert_eq!(table.name(2), "tumour");
    assert!(d[0].spec.appearance.labels.is_some(), "saved as labels");
}
