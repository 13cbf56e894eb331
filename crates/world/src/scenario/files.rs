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
//!   [`crate::script::MAX_SAMPLES`] lines of 160 bytes) for a track, [`MAX_POINTS_BYTES`]
//!   (512 MiB, about 20 M lines of `x y z` with six decimals) for a points file. Beyond it,
//!   [`WorldError::TooLarge`].
//! * **Incremental**: tracks and points files are read line by line ([`for_each_line`]) and
//!   parsed as they are read; the parsers stop at their count caps
//!   ([`crate::script::MAX_SAMPLES`], [`super::scale::MAX_CLOUD_POINTS`]).
//! * **Relative paths** are resolved against the scenario file's folder and **may not leave
//!   it**: `data/walker.csv` and `data/../walker.csv` are accepted, `../walker.csv` is not
//!   ([`relative_path_problem`]; the check is on the path as written, so a symbolic link inside
//!   the folder is followed). An absolute path is read as written: the author named the file
//!   explicitly. A scenario made in code (no file) resolves against the current directory.
//! * **No file contents in messages** beyond the offending line, cut to [`MAX_ECHO_CHARS`]
//!   characters ([`echo`]).

use std::io::{BufRead, BufReader, Read};
use std::path::{Component, Path, PathBuf};

use crate::error::WorldError;

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
            limit_bytes: max_bytes,
            what,
        });
    }
    Ok(text)
}

/// Calls `line(number, text)` for every line of a regular file of at most `max_bytes` bytes
/// (1-based numbers, line ends removed), reading incrementally; `line` returns `Err((number,
/// message))` to stop with [`WorldError::PointsFile`].
///
/// # Errors
/// [`WorldError::NotAFile`], [`WorldError::TooLarge`], [`WorldError::Read`] (also for a line
/// that is not UTF-8), [`WorldError::PointsFile`] from `line`.
pub fn for_each_line(
    path: &Path,
    max_bytes: u64,
    what: &'static str,
    mut line: impl FnMut(usize, &str) -> Result<(), (usize, String)>,
) -> Result<(), WorldError> {
    let file = open_regular(path)?;
    let mut reader = BufReader::new(file.take(max_bytes + 1));
    let mut buf = String::new();
    let mut total: u64 = 0;
    let mut number = 0;
    loop {
        buf.clear();
        let n = reader
            .read_line(&mut buf)
            .map_err(|source| WorldError::Read {
                path: path.to_path_buf(),
                source,
            })?;
        if n == 0 {
            return Ok(());
        }
        total += n as u64;
        if total > max_bytes {
            return Err(WorldError::TooLarge {
                path: path.to_path_buf(),
                limit_bytes: max_bytes,
                what,
            });
        }
        number += 1;
        line(number, buf.trim_end_matches(['\n', '\r'])).map_err(|(line, message)| {
            WorldError::PointsFile {
                path: path.to_path_buf(),
                line,
                message,
            }
        })?;
    }
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
    fn the_cap_is_enforced_while_reading() {
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
        assert!(
            matches!(
                e,
                WorldError::TooLarge {
                    limit_bytes: 60,
                    ..
                }
            ),
            "{e}"
        );
        assert_eq!(lines, 10);
        assert!(read_text(&f, 600, "a test file").is_ok());
        assert!(read_text(&f, 599, "a test file").is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
