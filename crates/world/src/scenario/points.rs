//! Points files: one point per line, `x y z` (whitespace- or comma-separated), blank lines and
//! lines starting with `#` ignored.

use std::path::Path;

use trust_core::Vec3;

use crate::error::WorldError;

/// Reads a points file.
///
/// # Errors
/// [`WorldError::Read`] if the file cannot be read; [`WorldError::PointsFile`] naming the first line
/// that is not three finite numbers.
pub fn read_points_file(path: &Path) -> Result<Vec<Vec3>, WorldError> {
    let text = std::fs::read_to_string(path).map_err(|source| WorldError::Read {
        path: path.to_path_buf(),
        source,
    })?;
    parse_points(&text).map_err(|(line, message)| WorldError::PointsFile {
        path: path.to_path_buf(),
        line,
        message,
    })
}

/// Parses the text of a points file; on error, the 1-based line number and what is wrong.
pub fn parse_points(text: &str) -> Result<Vec<Vec3>, (usize, String)> {
    let mut points = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .collect();
        if fields.len() != 3 {
            return Err((
                i + 1,
                format!(
                    "{line:?} has {} fields, expected three numbers `x y z`",
                    fields.len()
                ),
            ));
        }
        let mut p = Vec3::zeros();
        for (k, f) in fields.iter().enumerate() {
            match f.parse::<f64>() {
                Ok(x) if x.is_finite() => p[k] = x,
                _ => {
                    return Err((
                        i + 1,
                        format!("{line:?}: field {} = {f:?} is not a finite number", k + 1),
                    ));
                }
            }
        }
        points.push(p);
    }
    Ok(points)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn parses_points_and_names_bad_lines() {
        let pts = parse_points("# cloud\n1 2 3\n\n4,5,6\n  7.5\t8 9 \n").unwrap();
        assert_eq!(pts.len(), 3);
        assert_eq!(pts[1], Vec3::new(4.0, 5.0, 6.0));
        let (line, msg) = parse_points("1 2 3\n1 2\n").unwrap_err();
        assert_eq!(line, 2);
        assert!(msg.contains("2 fields"), "{msg}");
        let (line, msg) = parse_points("1 2 nan\n").unwrap_err();
        assert_eq!(line, 1);
        assert!(msg.contains("not a finite number"), "{msg}");
    }
}
