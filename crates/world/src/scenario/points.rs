//! Points files: one point per line, `x y z` (whitespace- or comma-separated), blank lines and
//! lines starting with `#` ignored. Read incrementally, at most
//! [`crate::files::MAX_POINTS_BYTES`] bytes and [`super::scale::MAX_CLOUD_POINTS`] points
//! ([`super::files`] for the policy).

use std::path::Path;

use trust_core::Vec3;

use super::scale::MAX_CLOUD_POINTS;
use crate::error::WorldError;
use crate::files::{MAX_POINTS_BYTES, echo, for_each_line};

/// Reads a points file.
///
/// # Errors
/// [`WorldError::Read`], [`WorldError::NotAFile`] or [`WorldError::TooLarge`] if the file cannot
/// be read; [`WorldError::PointsFile`] naming the first line that is not three finite numbers, or
/// the line beyond [`MAX_CLOUD_POINTS`] points.
pub fn read_points_file(path: &Path) -> Result<Vec<Vec3>, WorldError> {
    let mut points = Vec::new();
    for_each_line(path, MAX_POINTS_BYTES, "a points file", |n, line| {
        push_point(&mut points, n, line)
    })?;
    Ok(points)
}

/// Parses the text of a points file; on error, the 1-based line number and what is wrong.
pub fn parse_points(text: &str) -> Result<Vec<Vec3>, (usize, String)> {
    let mut points = Vec::new();
    for (i, raw) in text.lines().enumerate() {
        push_point(&mut points, i + 1, raw)?;
    }
    Ok(points)
}

/// Parses line `n` (1-based) and appends its point, if any.
fn push_point(points: &mut Vec<Vec3>, n: usize, raw: &str) -> Result<(), (usize, String)> {
    let line = raw.trim();
    if line.is_empty() || line.starts_with('#') {
        return Ok(());
    }
    if points.len() >= MAX_CLOUD_POINTS {
        return Err((
            n,
            format!("more than {MAX_CLOUD_POINTS} points (the cap on a cloud, scale policy)"),
        ));
    }
    let mut p = Vec3::zeros();
    let mut count = 0;
    for f in line
        .split(|c: char| c.is_whitespace() || c == ',')
        .filter(|f| !f.is_empty())
    {
        if count < 3 {
            match f.parse::<f64>() {
                Ok(x) if x.is_finite() => p[count] = x,
                _ => {
                    return Err((
                        n,
                        format!(
                            "{}: field {} = {} is not a finite number",
                            echo(line),
                            count + 1,
                            echo(f)
                        ),
                    ));
                }
            }
        }
        count += 1;
    }
    if count != 3 {
        return Err((
            n,
            format!(
                "{} has {count} fields, expected three numbers `x y z`",
                echo(line)
            ),
        ));
    }
    points.push(p);
    Ok(())
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
        // A long bad line is quoted cut short.
        let (_, msg) = parse_points(&format!("1 2 {}\n", "9".repeat(1000))).unwrap_err();
        assert!(msg.len() < 200, "{msg}");
    }
}
