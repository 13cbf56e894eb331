//! Reading the files a run log involves — the log itself and its `static_points_file` — within
//! stated bounds, and writing numbers and lines into messages readably.
//!
//! # Policy
//!
//! * **Only regular files** are read (after following symbolic links): a folder, a device such as
//!   `/dev/zero` or a pipe is [`LogError::NotAFile`].
//! * **A size cap per kind of file**, enforced while reading (the file is read through a limit,
//!   so a file that grows while it is read cannot exceed it either): [`MAX_LOG_BYTES`] (16 GiB,
//!   about eight hours of an E4 flight with branch logging on) for a log, [`MAX_POINTS_BYTES`]
//!   (512 MiB, the cap `trust-world` puts on the points file the log's copy comes from) for a
//!   points file, and [`MAX_LINE_BYTES`] (64 MiB) for one line of either. Beyond it,
//!   [`LogError::TooLarge`].
//! * **Incremental**: both are read line by line ([`BoundedLines`]) and parsed as they are read;
//!   a points file stops at [`MAX_POINTS`] points. Reading a log streams it
//!   ([`crate::LogReader`]): memory is one line, whatever the file's length.
//! * **The points file's path** ([`resolve_points_file`]) is relative to the log's folder and
//!   **may not leave it**: `static_points.xyz` and `maps/../static_points.xyz` are accepted,
//!   `../static_points.xyz` and absolute paths are not (a log must carry its own evidence, and a
//!   log from elsewhere must not make the audit read an arbitrary file). The check is on the path
//!   as written, resolved lexically (`a/../b` is `b`): a symbolic link inside the folder is
//!   followed, and must name a regular file.
//! * **No file contents in messages** beyond the offending line, cut to [`MAX_ECHO_CHARS`]
//!   characters ([`echo`]); numbers in messages are written by [`readable`].

use std::fs::File;
use std::io::{BufRead, BufReader, Read, Take};
use std::path::{Component, Path, PathBuf};

use crate::LogError;

/// Largest magnitude of a coordinate the audit and the points reader accept (m): 1000 km.
pub const MAX_COORDINATE_M: f64 = 1e6;

/// Largest run log read (bytes): 16 GiB.
pub const MAX_LOG_BYTES: u64 = 16 << 30;
/// Largest static points file read (bytes): 512 MiB (as `trust-world`'s cap on points files).
pub const MAX_POINTS_BYTES: u64 = 512 << 20;
/// Longest line read, in a log or a points file (bytes): 64 MiB.
pub const MAX_LINE_BYTES: usize = 64 << 20;
/// Most points of a static points file (as `trust-world`'s cap on a cloud).
pub const MAX_POINTS: usize = 20_000_000;
/// Most characters of a line (or of a parser's message) quoted in a message.
pub const MAX_ECHO_CHARS: usize = 60;

/// Opens `path` if it is a regular file (after following links) of at most `max_bytes` bytes.
///
/// # Errors
/// [`LogError::Io`], [`LogError::NotAFile`], [`LogError::TooLarge`].
pub fn open_regular(path: &Path, max_bytes: u64, what: &'static str) -> Result<File, LogError> {
    let io = |source| LogError::Io {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(io)?;
    if !meta.is_file() {
        return Err(LogError::NotAFile {
            path: path.to_path_buf(),
            what,
        });
    }
    if meta.len() > max_bytes {
        return Err(LogError::TooLarge {
            path: path.to_path_buf(),
            what,
            limit: format!("{max_bytes} bytes"),
        });
    }
    File::open(path).map_err(io)
}

/// The lines of a regular file, read through a byte cap and a line-length cap.
#[derive(Debug)]
pub struct BoundedLines {
    path: PathBuf,
    what: &'static str,
    max_bytes: u64,
    reader: BufReader<Take<File>>,
    read_bytes: u64,
    line: Vec<u8>,
    number: usize,
}

impl BoundedLines {
    /// Opens `path` ([`open_regular`]) to read at most `max_bytes` bytes, in lines of at most
    /// [`MAX_LINE_BYTES`]; `what` names the kind of file in messages ("a run log").
    ///
    /// # Errors
    /// As [`open_regular`].
    pub fn open(path: &Path, max_bytes: u64, what: &'static str) -> Result<Self, LogError> {
        let file = open_regular(path, max_bytes, what)?;
        Ok(BoundedLines {
            path: path.to_path_buf(),
            what,
            max_bytes,
            reader: BufReader::with_capacity(1 << 16, file.take(max_bytes.saturating_add(1))),
            read_bytes: 0,
            line: Vec::new(),
            number: 0,
        })
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// The 1-based number of the line last returned.
    pub fn number(&self) -> usize {
        self.number
    }

    /// The next line without its end (`\n` or `\r\n`) and its 1-based number, or `None` at
    /// the end of the file.
    ///
    /// # Errors
    /// [`LogError::Io`], [`LogError::TooLarge`] (file or line), [`LogError::Parse`] for a line
    /// that is not UTF-8.
    pub fn next_line(&mut self) -> Result<Option<(usize, &str)>, LogError> {
        self.line.clear();
        let mut any = false;
        loop {
            let buf = self.reader.fill_buf().map_err(|source| LogError::Io {
                path: self.path.clone(),
                source,
            })?;
            if buf.is_empty() {
                break;
            }
            any = true;
            let (chunk, done) = match buf.iter().position(|&b| b == b'\n') {
                Some(i) => (&buf[..i], i + 1),
                None => (buf, buf.len()),
            };
            let end = chunk.len() < done;
            if self.line.len() + chunk.len() > MAX_LINE_BYTES {
                return Err(LogError::TooLarge {
                    path: self.path.clone(),
                    what: self.what,
                    limit: format!("line {}: {MAX_LINE_BYTES} bytes a line", self.number + 1),
                });
            }
            self.line.extend_from_slice(chunk);
            self.reader.consume(done);
            self.read_bytes += done as u64;
            if self.read_bytes > self.max_bytes {
                return Err(LogError::TooLarge {
                    path: self.path.clone(),
                    what: self.what,
                    limit: format!("{} bytes", self.max_bytes),
                });
            }
            if end {
                break;
            }
        }
        if !any {
            return Ok(None);
        }
        self.number += 1;
        if self.line.last() == Some(&b'\r') {
            self.line.pop();
        }
        match std::str::from_utf8(&self.line) {
            Ok(s) => Ok(Some((self.number, s))),
            Err(e) => Err(LogError::Parse {
                path: self.path.clone(),
                line: self.number,
                message: format!("not UTF-8 text (byte {})", e.valid_up_to() + 1),
            }),
        }
    }
}

/// The points file `name` of a log in `log_dir`, under the module's path policy.
///
/// # Errors
/// A message naming the path when it is empty, absolute, or leaves the log's folder.
pub fn resolve_points_file(log_dir: &Path, name: &str) -> Result<PathBuf, String> {
    let path = Path::new(name);
    if name.is_empty() {
        return Err("static_points_file is empty".into());
    }
    // Resolved lexically: `a/../b` is `b` whether or not `a` exists.
    let mut inside = PathBuf::new();
    for c in path.components() {
        match c {
            Component::Normal(part) => inside.push(part),
            Component::CurDir => {}
            Component::ParentDir => {
                if !inside.pop() {
                    return Err(format!(
                        "static_points_file {} leaves the log's folder (`..`); it must name a \
                         file inside it",
                        echo(name)
                    ));
                }
            }
            Component::RootDir | Component::Prefix(_) => {
                return Err(format!(
                    "static_points_file {} is absolute; it must be relative to the log's folder",
                    echo(name)
                ));
            }
        }
    }
    if inside.as_os_str().is_empty() {
        return Err(format!(
            "static_points_file {} names the log's folder, not a file",
            echo(name)
        ));
    }
    Ok(log_dir.join(inside))
}

/// Reads a static points file: one point per line, `x y z` (whitespace- or comma-separated),
/// blank lines and lines starting with `#` ignored, and an optional header line `x y z`
/// (case-insensitive, same separators) before the first point. Every coordinate must be finite
/// and at most [`MAX_COORDINATE_M`] in magnitude.
///
/// # Errors
/// A message naming the file (and the line, quoted by [`echo`]): unreadable or not a regular
/// file, over a cap, a line that is not three numbers, or a file without any point ("only a
/// header", "empty").
pub fn read_points(path: &Path) -> Result<Vec<[f64; 3]>, String> {
    let mut lines = BoundedLines::open(path, MAX_POINTS_BYTES, "a static points file")
        .map_err(|e| e.to_string())?;
    let mut points = Vec::new();
    let mut header = None;
    let at = |n: usize| format!("{}:{n}", path.display());
    while let Some((n, raw)) = lines.next_line().map_err(|e| e.to_string())? {
        let line = raw.trim();
        if line.is_empty() || line.starts_with('#') {
            continue;
        }
        let fields: Vec<&str> = line
            .split(|c: char| c.is_whitespace() || c == ',')
            .filter(|f| !f.is_empty())
            .collect();
        let is_header = fields.len() == 3
            && fields
                .iter()
                .zip(["x", "y", "z"])
                .all(|(f, name)| f.eq_ignore_ascii_case(name));
        if is_header && points.is_empty() && header.is_none() {
            header = Some(n);
            continue;
        }
        if fields.len() != 3 {
            return Err(format!(
                "{}: {} has {} fields, expected three numbers `x y z`",
                at(n),
                echo(line),
                fields.len()
            ));
        }
        if points.len() >= MAX_POINTS {
            return Err(format!(
                "{}: more than {MAX_POINTS} points (the cap)",
                at(n)
            ));
        }
        let mut p = [0.0; 3];
        for (k, f) in fields.iter().enumerate() {
            match f.parse::<f64>() {
                Ok(x) if x.is_finite() && x.abs() <= MAX_COORDINATE_M => p[k] = x,
                _ => {
                    return Err(format!(
                        "{}: field {} = {} is not a finite number within ±{} m",
                        at(n),
                        k + 1,
                        echo(f),
                        readable(MAX_COORDINATE_M)
                    ));
                }
            }
        }
        points.push(p);
    }
    if points.is_empty() {
        return Err(match header {
            Some(n) => format!(
                "{}: no points, only a header (line {n}); expected `x y z` lines",
                path.display()
            ),
            None => format!(
                "{}: no points (the file is empty or only comments); expected `x y z` lines",
                path.display()
            ),
        });
    }
    Ok(points)
}

/// `text` quoted for a message, cut to [`MAX_ECHO_CHARS`] characters (an ellipsis marks the cut).
pub fn echo(text: &str) -> String {
    if text.chars().count() <= MAX_ECHO_CHARS {
        format!("{text:?}")
    } else {
        let head: String = text.chars().take(MAX_ECHO_CHARS).collect();
        format!("{head:?}…")
    }
}

/// A parser's message cut to a few times [`MAX_ECHO_CHARS`] (serde's messages quote the
/// offending value, which may be a whole line).
pub(crate) fn cut_message(message: &str) -> String {
    let max = 4 * MAX_ECHO_CHARS;
    if message.chars().count() <= max {
        message.to_string()
    } else {
        let head: String = message.chars().take(max).collect();
        format!("{head}…")
    }
}

/// A number as a person reads it in a message: at most 6 significant digits, in scientific
/// notation beyond (`1e300`, `1.23457e7`, `-2.5e-5`), plain otherwise (`0.3`, `12.5`, `-4`);
/// `inf`, `-inf` and `NaN` as such.
pub fn readable(x: f64) -> String {
    if !x.is_finite() {
        return format!("{x}");
    }
    if x == 0.0 {
        return "0".into();
    }
    let a = x.abs();
    // Round to 6 significant digits first: 999999.7 is 1e6, not "1000000".
    let s = format!("{x:.5e}");
    let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
    let exponent: i32 = exponent.parse().unwrap_or(0);
    if (1e-4..1e6).contains(&a) && (-4..6).contains(&exponent) {
        let decimals = (5 - exponent).max(0) as usize;
        let plain = format!("{x:.decimals$}");
        trim_zeros(&plain).to_string()
    } else {
        format!("{}e{exponent}", trim_zeros(mantissa))
    }
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_readable() {
        assert_eq!(readable(1e300), "1e300");
        assert_eq!(readable(-1e300), "-1e300");
        assert_eq!(readable(0.1 + 0.2), "0.3");
        assert_eq!(readable(12.5), "12.5");
        assert_eq!(readable(-4.0), "-4");
        assert_eq!(readable(123_456_789.0), "1.23457e8");
        assert_eq!(readable(999_999.7), "1e6");
        assert_eq!(readable(2.5e-5), "2.5e-5");
        assert_eq!(readable(0.000_123_456_78), "0.000123457");
        assert_eq!(readable(f64::INFINITY), "inf");
        assert_eq!(readable(0.0), "0");
        assert!(readable(f64::MAX).len() < 16, "{}", readable(f64::MAX));
    }

    #[test]
    fn echo_cuts_long_lines() {
        assert_eq!(echo("1 2 3"), "\"1 2 3\"");
        let e = echo(&"x".repeat(500));
        assert!(e.chars().count() < 70 && e.ends_with('…'), "{e}");
    }

    #[test]
    fn a_points_file_may_not_leave_the_logs_folder() {
        let dir = Path::new("/logs/run");
        assert_eq!(
            resolve_points_file(dir, "static_points.xyz").unwrap(),
            dir.join("static_points.xyz")
        );
        assert_eq!(
            resolve_points_file(dir, "maps/../static_points.xyz").unwrap(),
            dir.join("static_points.xyz")
        );
        assert!(resolve_points_file(dir, "./maps/cloud.xyz").is_ok());
        for bad in [
            "../cloud.xyz",
            "maps/../../cloud.xyz",
            "/etc/passwd",
            "",
            ".",
            "maps/..",
        ] {
            assert!(resolve_points_file(dir, bad).is_err(), "{bad}");
        }
        let e = resolve_points_file(dir, "../cloud.xyz").unwrap_err();
        assert!(e.contains("leaves the log's folder"), "{e}");
    }
}
