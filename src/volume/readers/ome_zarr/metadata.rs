//! The OME-NGFF `multiscales` metadata of an image group, versions 0.4 (Zarr v2,
//! `.zattrs`) and 0.5 (Zarr v3, under `attributes.ome` in `zarr.json`).
//!
//! What is read: the axes (name, type, unit), each level's array path and its
//! `coordinateTransformations` (`scale`, then an optional `translation`, composed with
//! the multiscale's own when it has them), and the first channel's display window
//! (`omero`), used to fit floating-point data into 16-bit codes. Index `i` along an axis
//! lies at `i · scale + translation` in the axis's unit, at the voxel's centre.
//! Focal's own conversions also write a `focal` attribute with the orientation and
//! origin of the source in RAS millimetres, which NGFF has no place for yet.

use serde_json::{Map, Value};

/// The role of an axis.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AxisKind {
    Space,
    Time,
    Channel,
    Other,
}

/// One axis of the arrays.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub name: String,
    pub kind: AxisKind,
    /// Millimetres per unit of the axis (`None`: no unit given).
    pub mm_per_unit: Option<f64>,
    /// The unit as written.
    pub unit: Option<String>,
}

/// One resolution level.
#[derive(Clone, Debug, PartialEq)]
pub struct Dataset {
    /// Array path inside the group.
    pub path: String,
    /// Scale per axis (in the axes' order).
    pub scale: Vec<f64>,
    /// Translation per axis.
    pub translation: Vec<f64>,
}

/// The image group's multiscale description.
#[derive(Clone, Debug, PartialEq)]
pub struct Multiscale {
    /// NGFF version (`0.4`, `0.5`, …).
    pub version: String,
    pub name: Option<String>,
    pub axes: Vec<Axis>,
    /// Finest first.
    pub datasets: Vec<Dataset>,
    /// Display window `(min, max)` of the first channel, when given.
    pub window: Option<(f64, f64)>,
    /// Focal's orientation (columns x, y, z) and origin, when Focal wrote the pyramid.
    pub focal_frame: Option<([[f64; 3]; 3], [f64; 3])>,
    /// What had to be assumed.
    pub warnings: Vec<String>,
}

/// Millimetres per unit of an NGFF (UDUNITS-2) length unit.
pub fn mm_per_unit(unit: &str) -> Option<f64> {
    Some(match unit {
        "meter" => 1e3,
        "decimeter" => 1e2,
        "centimeter" => 10.0,
        "millimeter" => 1.0,
        "micrometer" => 1e-3,
        "nanometer" => 1e-6,
        "angstrom" => 1e-7,
        "picometer" => 1e-9,
        "kilometer" => 1e6,
        "inch" => 25.4,
        "foot" => 304.8,
        _ => return None,
    })
}

/// Reads the multiscale description from a group's attributes.
pub fn parse(attributes: &Map<String, Value>) -> Result<Multiscale, String> {
    // 0.5 nests everything under "ome" with one version for the group.
    let (root, nested_version) = match attributes.get("ome") {
        Some(Value::Object(ome)) => (ome, ome.get("version").and_then(Value::as_str).map(str::to_owned)),
        _ => (attributes, None),
    };
    let Some(list) = root.get("multiscales").and_then(Value::as_array) else {
        return Err("no OME-NGFF \"multiscales\" in the group's attributes (not an OME-Zarr image)".into());
    };
    let Some(Value::Object(ms)) = list.first() else {
        return Err("\"multiscales\" is empty".into());
    };
    let mut warnings = Vec::new();
    if list.len() > 1 {
        warnings.push(format!("{} multiscale images in the group: the first is shown", list.len()));
    }
    let version = nested_version.or_else(|| ms.get("version").and_then(Value::as_str).map(str::to_owned)).unwrap_or_else(|| "0.4".into());
    let datasets_json = ms.get("datasets").and_then(Value::as_array).ok_or("\"multiscales\" has no \"datasets\"")?;
    if datasets_json.is_empty() {
        return Err("\"datasets\" is empty: the image has no levels".into());
    }
    let ndim_hint = datasets_json.first().and_then(|d| transforms(d).ok()).map(|(s, _)| s.len());
    let axes = match ms.get("axes") {
        Some(a) => parse_axes(a)?,
        None => {
            // Before 0.4 axes were implicit: (t, c,) z, y, x.
            let n = ndim_hint.unwrap_or(5);
            warnings.push("no \"axes\": taken as (t, c,) z, y, x".into());
            let names = ["t", "c", "z", "y", "x"];
            names[5 - n.min(5)..].iter().map(|&n| implicit_axis(n)).collect()
        }
    };
    let global = ms.get("coordinateTransformations").map(|t| transforms_of(t, axes.len())).transpose()?;
    if let Some((gs, _)) = &global
        && gs.len() != axes.len()
    {
        return Err(format!("the multiscale's scale has {} values for {} axes", gs.len(), axes.len()));
    }
    let mut datasets = Vec::new();
    for d in datasets_json {
        let path = d.get("path").and_then(Value::as_str).ok_or("a dataset has no \"path\"")?.to_owned();
        let (mut scale, mut translation) = transforms(d).map_err(|e| format!("dataset \"{path}\": {e}"))?;
        if scale.len() != axes.len() {
            return Err(format!("dataset \"{path}\": {} scale values for {} axes", scale.len(), axes.len()));
        }
        if translation.is_empty() {
            translation = vec![0.0; axes.len()];
        }
        if let Some((gs, gt)) = &global {
            // The multiscale's transformations apply after the dataset's.
            for i in 0..axes.len() {
                scale[i] *= gs[i];
                translation[i] = translation[i] * gs[i] + gt.get(i).copied().unwrap_or(0.0);
            }
        }
        if scale.iter().any(|s| !s.is_finite() || *s <= 0.0) {
            return Err(format!("dataset \"{path}\": scale {scale:?} is not positive"));
        }
        if translation.iter().any(|t| !t.is_finite()) {
            return Err(format!("dataset \"{path}\": translation {translation:?} is not finite"));
        }
        datasets.push(Dataset { path, scale, translation });
    }
    let window = root
        .get("omero")
        .and_then(|o| o.get("channels"))
        .and_then(Value::as_array)
        .and_then(|c| c.first())
        .and_then(|c| c.get("window"))
        .and_then(|w| {
            let (lo, hi) = (w.get("min")?.as_f64()?, w.get("max")?.as_f64()?);
            (lo.is_finite() && hi.is_finite() && hi > lo).then_some((lo, hi))
        });
    let focal_frame = attributes.get("focal").or_else(|| root.get("focal")).and_then(focal_frame);
    Ok(Multiscale {
        version,
        name: ms.get("name").and_then(Value::as_str).map(str::to_owned),
        axes,
        datasets,
        window,
        focal_frame,
        warnings,
    })
}

fn implicit_axis(name: &str) -> Axis {
    let kind = match name {
        "t" => AxisKind::Time,
        "c" => AxisKind::Channel,
        _ => AxisKind::Space,
    };
    Axis { name: name.into(), kind, mm_per_unit: None, unit: None }
}

fn parse_axes(v: &Value) -> Result<Vec<Axis>, String> {
    let list = v.as_array().ok_or("\"axes\" is not a list")?;
    list.iter()
        .map(|a| {
            // 0.3 wrote axes as plain names.
            if let Some(name) = a.as_str() {
                return Ok(implicit_axis(name));
            }
            let name = a.get("name").and_then(Value::as_str).ok_or("an axis has no \"name\"")?.to_owned();
            let kind = match a.get("type").and_then(Value::as_str) {
                Some("space") => AxisKind::Space,
                Some("time") => AxisKind::Time,
                Some("channel") => AxisKind::Channel,
                Some(_) => AxisKind::Other,
                None => implicit_axis(&name).kind,
            };
            let unit = a.get("unit").and_then(Value::as_str).map(str::to_owned);
            Ok(Axis { mm_per_unit: unit.as_deref().and_then(mm_per_unit), unit, name, kind })
        })
        .collect()
}

/// A dataset's scale and translation.
fn transforms(d: &Value) -> Result<(Vec<f64>, Vec<f64>), String> {
    match d.get("coordinateTransformations") {
        Some(t) => transforms_of(t, 0),
        None => Err("no \"coordinateTransformations\"".into()),
    }
}

/// `scale` and `translation` of a list of transformations (`n` > 0: their length).
fn transforms_of(t: &Value, n: usize) -> Result<(Vec<f64>, Vec<f64>), String> {
    let list = t.as_array().ok_or("\"coordinateTransformations\" is not a list")?;
    let numbers = |v: &Value, key: &str| -> Result<Vec<f64>, String> {
        let a = v
            .get(key)
            .and_then(Value::as_array)
            .ok_or_else(|| format!("a \"{key}\" transformation without a list of numbers (a path to a file is not supported)"))?;
        a.iter().map(|x| x.as_f64().ok_or_else(|| format!("\"{key}\" holds {x}, not a number"))).collect()
    };
    let (mut scale, mut translation) = (Vec::new(), Vec::new());
    for item in list {
        match item.get("type").and_then(Value::as_str) {
            Some("scale") => scale = numbers(item, "scale")?,
            Some("translation") => translation = numbers(item, "translation")?,
            Some("identity") => {}
            Some(other) => return Err(format!("transformation \"{other}\" is not supported")),
            None => return Err("a transformation has no \"type\"".into()),
        }
    }
    if scale.is_empty() {
        if n == 0 {
            return Err("no \"scale\" transformation".into());
        }
        scale = vec![1.0; n];
    }
    if !translation.is_empty() && translation.len() != scale.len() {
        return Err(format!("{} translation values for {} scale values", translation.len(), scale.len()));
    }
    Ok((scale, translation))
}

fn focal_frame(v: &Value) -> Option<([[f64; 3]; 3], [f64; 3])> {
    let three = |v: &Value| -> Option<[f64; 3]> {
        let a = v.as_array()?;
        (a.len() == 3).then_some(())?;
        Some([a[0].as_f64()?, a[1].as_f64()?, a[2].as_f64()?])
    };
    let d = v.get("direction")?.as_array()?;
    (d.len() == 3).then_some(())?;
    Some(([three(&d[0])?, three(&d[1])?, three(&d[2])?], three(v.get("origin_mm")?)?))
}

#[cfg(test)]
mod tests {
    use serde_json::json;

    use super::*;

    fn attrs(v: Value) -> Map<String, Value> {
        match v {
            Value::Object(m) => m,
            _ => Map::new(),
        }
    }

    #[test]
    fn version_0_4_with_units_and_a_global_scale() {
        let a = attrs(json!({"multiscales": [{
            "version": "0.4", "name": "cells",
            "axes": [{"name": "c", "type": "channel"}, {"name": "z", "type": "space", "unit": "micrometer"},
                     {"name": "y", "type": "space", "unit": "micrometer"}, {"name": "x", "type": "space", "unit": "micrometer"}],
            "datasets": [
                {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 2.0, 0.5, 0.5]}]},
                {"path": "1", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 4.0, 1.0, 1.0]},
                                                            {"type": "translation", "translation": [0.0, 1.0, 0.25, 0.25]}]}],
            "coordinateTransformations": [{"type": "scale", "scale": [1.0, 3.0, 1.0, 1.0]}]}],
            "omero": {"channels": [{"window": {"min": -5.0, "max": 300.0, "start": 0, "end": 100}}]}}));
        let m = parse(&a).expect("parses");
        assert_eq!(m.version, "0.4");
        assert_eq!(m.axes.len(), 4);
        assert_eq!(m.axes[0].kind, AxisKind::Channel);
        assert_eq!(m.axes[1].mm_per_unit, Some(1e-3));
        // The global scale multiplies the dataset's scale and its translation.
        assert_eq!(m.datasets[0].scale, vec![1.0, 6.0, 0.5, 0.5]);
        assert_eq!(m.datasets[1].scale, vec![1.0, 12.0, 1.0, 1.0]);
        assert_eq!(m.datasets[1].translation, vec![0.0, 3.0, 0.25, 0.25]);
        assert_eq!(m.window, Some((-5.0, 300.0)));
        assert!(m.warnings.is_empty());
    }

    #[test]
    fn version_0_5_nests_under_ome() {
        let a = attrs(json!({"ome": {"version": "0.5", "multiscales": [{
            "axes": [{"name": "z", "type": "space", "unit": "millimeter"}, {"name": "y", "type": "space"}, {"name": "x", "type": "space"}],
            "datasets": [{"path": "s0", "coordinateTransformations": [{"type": "scale", "scale": [1.5, 1.0, 1.0]}]}]}]},
            "focal": {"direction": [[-1, 0, 0], [0, -1, 0], [0, 0, 1]], "origin_mm": [10, 20, 30]}}));
        let m = parse(&a).expect("parses");
        assert_eq!(m.version, "0.5");
        assert_eq!(m.datasets[0].path, "s0");
        assert_eq!(m.datasets[0].translation, vec![0.0; 3]);
        assert_eq!(m.axes[1].unit, None);
        assert_eq!(m.focal_frame, Some(([[-1.0, 0.0, 0.0], [0.0, -1.0, 0.0], [0.0, 0.0, 1.0]], [10.0, 20.0, 30.0])));
    }

    #[test]
    fn bad_metadata_says_what_is_wrong() {
        let err = |v: Value| parse(&attrs(v)).expect_err("refused");
        assert!(err(json!({"other": 1})).contains("multiscales"));
        assert!(err(json!({"multiscales": [{"axes": ["z", "y", "x"], "datasets": []}]})).contains("no levels"));
        let bad_scale = json!({"multiscales": [{"axes": ["z", "y", "x"], "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 0.0, 1.0]}]}]}]});
        assert!(err(bad_scale).contains("not positive"));
        let short = json!({"multiscales": [{"axes": ["z", "y", "x"], "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0]}]}]}]});
        assert!(err(short).contains("2 scale values for 3 axes"));
        let short_global = json!({"multiscales": [{"axes": ["z", "y", "x"], "coordinateTransformations": [{"type": "scale", "scale": [1.0, 2.0]}],
            "datasets": [{"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0, 1.0]}]}]}]});
        assert!(err(short_global).contains("2 values for 3 axes"));
        let by_file = json!({"multiscales": [{"axes": ["z", "y", "x"], "datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "path": "scale.bin"}]}]}]});
        assert!(err(by_file).contains("not supported"));
        // Axes may be left out (0.3): taken from the scale's length, with a warning.
        let implicit = parse(&attrs(json!({"multiscales": [{"datasets": [
            {"path": "0", "coordinateTransformations": [{"type": "scale", "scale": [1.0, 1.0, 1.0]}]}]}]})))
        .expect("parses");
        assert_eq!(implicit.axes.iter().map(|a| a.name.as_str()).collect::<Vec<_>>(), vec!["z", "y", "x"]);
        assert_eq!(implicit.warnings.len(), 1);
    }
}
