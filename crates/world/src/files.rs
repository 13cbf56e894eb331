//! Reading the files a scenario names: the scenario itself, CSV tracks
//! (`motion = { kind = "samples", file = … }`) and points files (`[static.point_cloud] path`).
//!
//! # Policy
//!
//! * **Only regular files** are read (after following symbolic links): a folder, a device such
//!   as `/dev/zero` or a pipe is [`WorldError::NotAFile`].
//! * **A size cap per kind of file**, enforced while reading (the file is read through a
//!   limit, so a file that grows while it is read cannot exceed it either):
//!   [`MAX_SCENARIO_BYTES`] (4 MiB) for a scenario, [`MAX_TRACK_BYTES`] (16 MiB, room for
//!   `script::MAX_SAMPLES` lines of 160 bytes) for a track, [`MAX_POINTS_BYTES`]
//!   (512 MiB, about 20 M lines of `x y z` with six decimals) for a points file. Beyond it,
//!   [`WorldError::TooLarge`].
//! * **Incremental**: tracks and points files are read line by line ([`for_each_line`], over the
//!   workspace's one line reader, `trust_runlog::files::BoundedLines`, decision 0041) and
//!   parsed as they are read; the parsers stop at their count caps
//!   (`script::MAX_SAMPLES`, `scenario::scale::MAX_CLOUD_POINTS`).
//! * **Relative paths** are resolved against the scenario file's folder and **may not leave
//!   it**: `data/walker.csv` and `data/../walker.csv` are accepted, `../walker.csv` is not
//!   ([`relative_path_problem`]; the check is on the path as written, so a symbolic link inside
//!   the folder is followed). An absolute path is read as written: the author named the file
//!   explicitly. A scenario made in code (no file) resolves against the current directory.
//! * **No file contents in messages** beyond the offending line, cut to [`MAX_ECHO_CHARS`]
//!   characters ([`echo`]).

use std::io::Read;

use std::path::{Component, Path, PathBuf};
use trust_runlog::files::BoundedLines;

use crate::error::WorldError;
use crate::problem::fmt_num;

/// Largest scenario file read (bytes): 4 MiB.
pub const MAX_SCENARIO_BYTES: u64 = 4 << 20;
/// Largest CSV track read (bytes): 16 MiB.
pub const MAX_TRACK_BYTES: u64 = 16 << 20;
/// Largest points file read (bytes): 512 MiB.
pub const MAX_POINTS_BYTES: u64 = 512 << 20;
/// Most characters of a file's line quoted in a message.
pub const MAX_ECHO_CHARS: usize = 60;

/// Opens `path` if it is a regular file.
fn open_regular(path: &Path) -> Result<std::fs::File, WorldError> {
    let read_err = |source| WorldError::Read {
        path: path.to_path_buf(),
        source,
    };
    let meta = std::fs::metadata(path).map_err(read_err)?;
    if !meta.is_file() {
        return Err(WorldError::NotAFile {
            path: path.to_path_buf(),
        });
    }
    std::fs::File::open(path).map_err(read_err)
}

/// Reads the whole of a regular file of at most `max_bytes` bytes as UTF-8 text.
///
/// # Errors
/// [`WorldError::NotAFile`], [`WorldError::TooLarge`], [`WorldError::Read`] (also for text that
/// is not UTF-8).
pub fn read_text(path: &Path, max_bytes: u64, what: &'static str) -> Result<String, WorldError> {
    let file = open_regular(path)?;
    let mut text = String::new();
    file.take(max_bytes + 1)
        .read_to_string(&mut text)
        .map_err(|source| WorldError::Read {
            path: path.to_path_buf(),
            source,
        })?;
    if text.len() as u64 > max_bytes {
        return Err(WorldError::TooLarge {
            path: path.to_path_buf(),
            limit: crate::error::fmt_bytes(max_bytes),
            what,
        });
    }
    Ok(text)
}

/// Calls `line(number, text)` for every line of a regular file of at most `max_bytes` bytes
/// (1-based numbers, line ends removed), read incrementally by the one line reader,
/// [`trust_runlog::files::BoundedLines`] (its byte and line caps); `line` returns `Err((number,
/// message))` to stop with [`WorldError::PointsFile`].
///
/// # Errors
/// [`WorldError::NotAFile`], [`WorldError::TooLarge`] (the file, or one line over
/// [`trust_runlog::files::MAX_LINE_BYTES`]), [`WorldError::Read`], [`WorldError::PointsFile`]
/// for a line that is not UTF-8 or from `line`.
pub fn for_each_line(
    path: &Path,
    max_bytes: u64,
    what: &'static str,
    mut line: impl FnMut(usize, &str) -> Result<(), (usize, String)>,
) -> Result<(), WorldError> {
    let mut lines = BoundedLines::open(path, max_bytes, what)?;
    while let Some((number, text)) = lines.next_line()? {
        line(number, text).map_err(|(line, message)| WorldError::PointsFile {
            path: path.to_path_buf(),
            line,
            message,
        })?;
    }
    Ok(())
}

/// A line of a file for a message: quoted, cut to [`MAX_ECHO_CHARS`] characters (`…` marks the
/// cut).
pub fn echo(line: &str) -> String {
    if line.chars().count() <= MAX_ECHO_CHARS {
        format!("{line:?}")
    } else {
        let head: String = line.chars().take(MAX_ECHO_CHARS).collect();
        format!("{head:?}…")
    }
}

/// A parser's message that quotes the file, made to follow the policy (module docs): toml shows
/// the offending line under a `N | ` gutter with a caret line below it, at the `column C` its
/// first line names; a quoted line longer than [`MAX_ECHO_CHARS`] characters is cut to a window
/// of that many around the column (`…` marks each cut, the caret moves with the text). In the
/// other lines, numbers of more than 12 digits are written readably ([`fmt_num`]: serde writes
/// a wrong float value in full, 309 digits for `1e308`), and each line is cut to four times
/// [`MAX_ECHO_CHARS`] (serde quotes a wrong string value whole).
pub fn parser_message(message: &str) -> String {
    let w = MAX_ECHO_CHARS;
    let column = message
        .lines()
        .next()
        .and_then(|l| l.rsplit_once("column "))
        .and_then(|(_, c)| c.trim().parse::<usize>().ok())
        .unwrap_or(1);
    // A gutter line: where its text starts, and whether it is numbered (the quote) or not (the
    // caret).
    let gutter = |line: &str| -> Option<(usize, bool)> {
        let bar = line.find("| ")?;
        let g = line[..bar].trim();
        g.chars()
            .all(|c| c.is_ascii_digit())
            .then_some((bar + 2, !g.is_empty()))
    };
    let long_quote = message
        .lines()
        .any(|l| gutter(l).is_some_and(|(at, numbered)| numbered && l[at..].chars().count() > w));
    let start = column.saturating_sub(1).saturating_sub(w / 2);
    let mut out: Vec<String> = Vec::new();
    for line in message.lines() {
        match gutter(line) {
            Some((at, numbered)) if long_quote => {
                let text: Vec<char> = line[at..].chars().collect();
                let end = (start + w).min(text.len());
                let mut cut: String = text[start.min(end)..end].iter().collect();
                if numbered && end < text.len() {
                    cut.push('…');
                }
                let lead = match (start > 0, numbered) {
                    (true, true) => "…",
                    (true, false) => " ",
                    (false, _) => "",
                };
                out.push(format!("{}{lead}{cut}", &line[..at]));
            }
            Some(_) => out.push(line.to_string()),
            None => {
                let line = readable_numbers(line);
                if line.chars().count() > 4 * w {
                    let head: String = line.chars().take(4 * w).collect();
                    out.push(format!("{head}…"));
                } else {
                    out.push(line);
                }
            }
        }
    }
    out.join("\n")
}

/// `line` with every number of more than 12 digits written by [`fmt_num`].
fn readable_numbers(line: &str) -> String {
    let mut out = String::with_capacity(line.len());
    let mut rest = line;
    while let Some(i) = rest.find(|c: char| c.is_ascii_digit()) {
        out.push_str(&rest[..i]);
        let tail = &rest[i..];
        let len = tail
            .find(|c: char| !(c.is_ascii_digit() || c == '.'))
            .unwrap_or(tail.len());
        let token = tail[..len].trim_end_matches('.');
        let digits = token.chars().filter(char::is_ascii_digit).count();
        match token.parse::<f64>() {
            Ok(x) if digits > 12 => out.push_str(&fmt_num(x)),
            _ => out.push_str(token),
        }
        rest = &tail[token.len()..];
    }
    out.push_str(rest);
    out
}

/// Why a relative `path` from a scenario file is refused: it leaves the scenario's folder
/// (module docs); `None` for an accepted path (every absolute path, and relative paths that stay
/// inside).
pub fn relative_path_problem(path: &Path) -> Option<String> {
    if path.is_absolute() {
        return None;
    }
    let mut depth: i64 = 0;
    for c in path.components() {
        match c {
            Component::ParentDir => depth -= 1,
            Component::Normal(_) => depth += 1,
            Component::CurDir => {}
            // A Windows prefix or root: not relative.
            Component::Prefix(_) | Component::RootDir => return None,
        }
        if depth < 0 {
            return Some(
                "a path inside the scenario's folder: a relative path may not leave it with `..` \
                 (give an absolute path to read a file elsewhere)"
                    .to_string(),
            );
        }
    }
    None
}

/// `path` resolved against `dir` (the scenario's folder) if relative.
pub(crate) fn resolve(dir: Option<&Path>, path: &Path) -> PathBuf {
    match dir {
        Some(dir) if path.is_relative() => dir.join(path),
        _ => path.to_path_buf(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn relative_paths_stay_in_the_folder() {
        for ok in [
            "a.csv",
            "data/a.csv",
            "data/../a.csv",
            "./a.csv",
            "/tmp/a.csv",
        ] {
            assert!(relative_path_problem(Path::new(ok)).is_none(), "{ok}");
        }
        for bad in ["../a.csv", "data/../../a.csv", "./../x/a.csv"] {
            assert!(relative_path_problem(Path::new(bad)).is_some(), "{bad}");
        }
    }

    #[test]
    fn parser_messages_keep_a_window_around_the_column_and_readable_numbers() {
        let line = format!("x = [{}]", "1, ".repeat(1000));
        let message = format!(
            "TOML parse error at line 3, column 1503\n  |\n3 | {line}\n  | {}^\ninvalid type",
            " ".repeat(1502)
        );
        let cut = parser_message(&message);
        assert!(cut.lines().all(|l| l.chars().count() < 80), "{cut}");
        let lines: Vec<&str> = cut.lines().collect();
        let caret = lines[3].chars().position(|c| c == '^').unwrap();
        // "3 | " and "…", 60 characters of the line, "…"; the caret under the same character.
        assert_eq!(lines[2].chars().count(), 4 + 1 + 60 + 1, "{cut}");
        assert_eq!(caret, 4 + 1 + 30, "{cut}");
        assert_eq!(lines[2].chars().nth(caret), line.chars().nth(1502), "{cut}");
        assert!(lines[4] == "invalid type");
        // A short quote is left as it is.
        let short = "TOML parse error at line 1, column 5\n  |\n1 | a = =\n  |     ^\nexpected";
        assert_eq!(parser_message(short), short);
        // Another long line (a quoted value) is cut to four times the echo.
        let long = format!("invalid type: string \"{}\"", "y".repeat(1000));
        assert!(parser_message(&long).chars().count() <= 4 * MAX_ECHO_CHARS + 1);
        // serde writes a wrong float in full: 309 digits for 1e308.
        let huge = format!(
            "invalid type: floating point `1{}.0`, expected a table",
            "0".repeat(308)
        );
        assert_eq!(
            parser_message(&huge),
            "invalid type: floating point `1e308`, expected a table"
        );
    }

    #[test]
    fn echo_cuts_long_lines() {
        assert_eq!(echo("1 2 3"), "\"1 2 3\"");
        let long = "x".repeat(500);
        let e = echo(&long);
        assert!(e.len() < 70 && e.ends_with('…'), "{e}");
    }

    #[test]
    fn devices_and_folders_are_not_read() {
        assert!(matches!(
            read_text(Path::new("/dev/zero"), 10, "a test file"),
            Err(WorldError::NotAFile { .. })
        ));
        assert!(matches!(
            for_each_line(Path::new("/"), 10, "a test file", |_, _| Ok(())),
            Err(WorldError::NotAFile { .. })
        ));
    }

    #[test]
    fn the_cap_is_enforced_and_lines_are_utf8() {
        let dir = std::env::temp_dir().join(format!("trust-files-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let f = dir.join("big.txt");
        std::fs::write(&f, "0 0 0\n".repeat(100)).unwrap();
        let mut lines = 0;
        let e = for_each_line(&f, 60, "a test file", |_, _| {
            lines += 1;
            Ok(())
        })
        .unwrap_err();
        // Refused before any line is parsed (the reader checks the size first, then reads
        // through the cap: a file that grows while it is read cannot pass it either).
        assert!(
            matches!(&e, WorldError::TooLarge { limit, .. } if limit == "60 bytes"),
            "{e}"
        );
        assert_eq!(lines, 0);
        let bad = dir.join("latin1.txt");
        std::fs::write(&bad, b"1 2 3\n4 5 \xe9\n").unwrap();
        let e = for_each_line(&bad, 600, "a test file", |_, _| Ok(())).unwrap_err();
        assert!(
            matches!(&e, WorldError::PointsFile { line: 2, message, .. } if message.contains("UTF-8")),
            "{e}"
        );
        assert!(read_text(&f, 600, "a test file").is_ok());
        assert!(read_text(&f, 599, "a test file").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
