//! Label tables: names and colours of label ids.
//!
//! - Text tables, one label per line: `id name [r g b [a]]`, separated by spaces, tabs or
//!   commas. This covers the AAL `aal.nii.txt` (`1 Precentral_L 2001`: id, name, code),
//!   FreeSurfer-style colour tables (`17 Left-Hippocampus 220 216 20 0`) and a simple CSV
//!   (`id,name,r,g,b`, a header line is skipped). Lines starting with `#` are comments.
//! - Binary palettes of exactly 768 bytes (`aal.nii.lut`, MRIcron): 256 red values, then
//!   256 green, then 256 blue; they colour ids 1..255 (0 stays background).

use std::path::Path;

use super::common::{Problem, ReadError, file_len, read_text, sidecars};
use crate::volume::{Label, LabelTable, labels::generated_color};

/// Reads a label table file of any supported kind.
pub fn read(path: &Path) -> Result<LabelTable, ReadError> {
    let fail = |p: Problem| ReadError::new(path, p);
    if file_len(path)? == 768 && !looks_textual(path) {
        let bytes = std::fs::read(path).map_err(|e| fail(Problem::Io(e)))?;
        return Ok(palette(&bytes));
    }
    let text = read_text(path, 16 << 20)?;
    parse_text(&text).map_err(fail)
}

fn looks_textual(path: &Path) -> bool {
    std::fs::read(path).map(|b| b.iter().all(|&c| c == b'\n' || c == b'\r' || c == b'\t' || (32..127).contains(&c))).unwrap_or(false)
}

/// Colours from a 768-byte planar palette.
pub fn palette(bytes: &[u8]) -> LabelTable {
    let mut t = LabelTable::default();
    for id in 1..256usize.min(bytes.len() / 3 + 1) {
        let color = [bytes[id], bytes[256 + id], bytes[512 + id]];
        t.labels.insert(id as u32, Label { name: format!("label {id}"), color });
    }
    t
}

/// Parses a text table.
pub fn parse_text(text: &str) -> Result<LabelTable, Problem> {
    let mut t = LabelTable::default();
    for (n, line) in text.lines().enumerate() {
        let line = line.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let tokens: Vec<&str> = line.split(|c: char| c == ',' || c.is_whitespace()).filter(|s| !s.is_empty()).collect();
        let Ok(id) = tokens[0].parse::<u32>() else {
            if n == 0 || t.is_empty() {
                continue; // a header line such as "id,name,r,g,b"
            }
            return Err(Problem::Malformed(format!("line {}: '{}' is not a label id", n + 1, tokens[0])));
        };
        if id > 65535 {
            return Err(Problem::Malformed(format!("line {}: label id {id} is larger than 65535", n + 1)));
        }
        let name = tokens.get(1).map(|s| s.trim_matches('"').to_string()).unwrap_or_else(|| format!("label {id}"));
        let rgb: Option<Vec<u8>> = (tokens.len() >= 5).then(|| tokens[2..5].iter().map(|s| s.parse::<u8>().ok()).collect()).flatten();
        let color = rgb.map(|c| [c[0], c[1], c[2]]).unwrap_or_else(|| generated_color(id));
        t.labels.insert(id, Label { name, color });
    }
    if t.is_empty() {
        return Err(Problem::Malformed("no 'id name [r g b]' lines".into()));
    }
    Ok(t)
}

/// Reads the tables found beside a label volume: names from `.txt`/`.csv`, colours from
/// a `.lut` palette (which colours, but does not rename, the named labels).
pub fn read_sidecars(volume: &Path) -> Result<LabelTable, ReadError> {
    let mut table = LabelTable::default();
    for p in sidecars(volume, &["txt", "csv", "ctbl"]) {
        if p.is_file() {
            table.merge(read(&p)?);
            break;
        }
    }
    for p in sidecars(volume, &["lut"]) {
        if p.is_file() {
            let colors = read(&p)?;
            if table.is_empty() {
                table = colors;
            } else {
                for (id, l) in colors.labels {
                    if let Some(e) = table.labels.get_mut(&id) {
                        e.color = l.color;
                    }
                }
            }
            break;
        }
    }
    Ok(table)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_tables_of_each_style() {
        let aal = parse_text("1 Precentral_L 2001\n2 Precentral_R 2002\n").unwrap();
        assert_eq!(aal.get(2).unwrap().name, "Precentral_R");
        assert_eq!(aal.get(1).unwrap().color, generated_color(1));
        let csv = parse_text("id,name,r,g,b\n3,\"Liver\",200,10,20\n").unwrap();
        assert_eq!(csv.get(3).unwrap(), &Label { name: "Liver".into(), color: [200, 10, 20] });
        let fs = parse_text("# FreeSurfer\n17  Left-Hippocampus  220 216 20 0\n").unwrap();
        assert_eq!(fs.get(17).unwrap().color, [220, 216, 20]);
        assert!(parse_text("hello\nworld\n").is_err());
        assert!(parse_text("1 a\nx b\n").is_err());
    }

    #[test]
    fn planar_palette() {
        let mut b = vec![0u8; 768];
        b[5] = 10;
        b[256 + 5] = 20;
        b[512 + 5] = 30;
        assert_eq!(palette(&b).get(5).unwrap().color, [10, 20, 30]);
    }
}
