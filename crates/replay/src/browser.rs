//! Checking a replay page in a real browser: headless Chromium, driven from the command line with
//! the standard library only (no WebDriver client, no new dependencies).
//!
//! [`check_page`] opens the page twice, at `#t=0` and at `#t=T`: the fragment makes the page move
//! its time slider there (through the slider's own `input` handler) and stay paused. Each time it
//! reads the page's `#replay-status` element from `--dump-dom` (the script errors and console
//! errors the page caught, the time shown, the vehicle's position in canvas pixels) and takes a
//! `--screenshot`; the check passes when neither load reported an error, the page drew, the
//! vehicle's pixel position moved and the two screenshots differ in more than a few pixels.
//! `cargo xtask replay-check PAGE` runs it; CI installs Chromium from Debian's packages.

use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

use serde_json::Value;

use crate::ReplayError;

/// What the page reports about itself in `#replay-status`.
#[derive(Debug, Clone, PartialEq)]
pub struct PageStatus {
    /// Script errors, unhandled rejections and `console.error` calls caught by the page.
    pub errors: Vec<String>,
    /// Whether the page finished drawing its first frame.
    pub ready: bool,
    /// The time shown (s).
    pub t: f64,
    /// The vehicle's position in the top view's canvas (px).
    pub vehicle_px: [f64; 2],
    /// The vehicle's position (m).
    pub vehicle: [f64; 3],
}

/// The result of [`check_page`].
#[derive(Debug, Clone, PartialEq)]
pub struct BrowserCheck {
    /// The page at `#t=0`.
    pub start: PageStatus,
    /// The page at `#t=T`.
    pub later: PageStatus,
    /// How far the vehicle moved on the top view's canvas (px).
    pub moved_px: f64,
    /// Pixels that differ between the two screenshots.
    pub changed_pixels: usize,
    /// The screenshots.
    pub screenshots: [PathBuf; 2],
}

/// Chromium to use: `$TRUST_CHROMIUM` if set, else the first of `chromium`, `chromium-browser`,
/// `google-chrome` on the `PATH`.
pub fn find_chromium() -> Option<PathBuf> {
    if let Some(p) = std::env::var_os("TRUST_CHROMIUM") {
        return Some(PathBuf::from(p));
    }
    let path = std::env::var_os("PATH")?;
    for dir in std::env::split_paths(&path) {
        for name in ["chromium", "chromium-browser", "google-chrome"] {
            let candidate = dir.join(name);
            if candidate.is_file() {
                return Some(candidate);
            }
        }
    }
    None
}

/// How long one headless Chromium run may take.
const RUN_TIMEOUT: Duration = Duration::from_secs(90);

fn browser_error(page: &Path, message: impl Into<String>) -> ReplayError {
    ReplayError::Browser {
        page: page.to_path_buf(),
        message: message.into(),
    }
}

/// Runs headless Chromium on `url` with `extra` arguments, returns its standard output.
fn run_chromium(
    chromium: &Path,
    page: &Path,
    url: &str,
    extra: &[String],
    profile: &Path,
) -> Result<String, ReplayError> {
    let mut cmd = Command::new(chromium);
    cmd.args([
        "--headless=new",
        "--disable-gpu",
        "--no-sandbox",
        "--no-first-run",
        "--no-default-browser-check",
        "--disable-extensions",
        "--disable-dev-shm-usage",
        "--hide-scrollbars",
        "--window-size=1280,1100",
    ])
    .arg(format!("--user-data-dir={}", profile.display()))
    .args(extra)
    .arg(url)
    .stdin(Stdio::null())
    .stdout(Stdio::piped())
    .stderr(Stdio::piped());
    let mut child = cmd
        .spawn()
        .map_err(|e| browser_error(page, format!("cannot start {}: {e}", chromium.display())))?;
    // Read both pipes on their own threads so a chatty browser cannot block on a full pipe.
    let mut stdout = child.stdout.take();
    let mut stderr = child.stderr.take();
    let out = std::thread::spawn(move || {
        let mut s = String::new();
        if let Some(o) = stdout.as_mut() {
            let _ = o.read_to_string(&mut s);
        }
        s
    });
    let err = std::thread::spawn(move || {
        let mut s = String::new();
        if let Some(e) = stderr.as_mut() {
            let _ = e.read_to_string(&mut s);
        }
        s
    });
    let start = Instant::now();
    let status = loop {
        match child.try_wait() {
            Ok(Some(status)) => break status,
            Ok(None) if start.elapsed() > RUN_TIMEOUT => {
                let _ = child.kill();
                let _ = child.wait();
                return Err(browser_error(
                    page,
                    format!(
                        "{} did not finish within {RUN_TIMEOUT:?}",
                        chromium.display()
                    ),
                ));
            }
            Ok(None) => std::thread::sleep(Duration::from_millis(50)),
            Err(e) => return Err(browser_error(page, format!("waiting for chromium: {e}"))),
        }
    };
    let stdout = out.join().unwrap_or_default();
    let stderr = err.join().unwrap_or_default();
    if !status.success() {
        return Err(browser_error(
            page,
            format!("chromium exited with {status}: {}", stderr.trim()),
        ));
    }
    Ok(stdout)
}

/// Undoes the escaping of an HTML text node (`&amp;`, `&lt;`, `&gt;`, `&quot;`, `&#39;`).
fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&#39;", "'")
        .replace("&amp;", "&")
}

/// Reads the `#replay-status` element out of a dumped DOM.
pub fn parse_status(dom: &str) -> Result<PageStatus, String> {
    let open = "id=\"replay-status\"";
    let at = dom
        .find(open)
        .ok_or("the page has no #replay-status element (did the script run?)")?;
    let rest = &dom[at..];
    let start = rest.find('>').ok_or("unterminated #replay-status tag")? + 1;
    let end = rest[start..]
        .find("</pre>")
        .ok_or("unterminated #replay-status element")?;
    let text = unescape(&rest[start..start + end]);
    let v: Value = serde_json::from_str(&text)
        .map_err(|e| format!("#replay-status is not JSON ({e}): {text}"))?;
    let f = |v: &Value| v.as_f64().unwrap_or(f64::NAN);
    let arr = |v: &Value, n: usize| -> Vec<f64> { (0..n).map(|i| f(&v[i])).collect() };
    let px = arr(&v["vehicle_px"], 2);
    let p = arr(&v["vehicle"], 3);
    Ok(PageStatus {
        errors: v["errors"]
            .as_array()
            .map(|a| {
                a.iter()
                    .map(|e| e.as_str().map_or_else(|| e.to_string(), str::to_string))
                    .collect()
            })
            .unwrap_or_default(),
        ready: v["ready"].as_bool().unwrap_or(false),
        t: f(&v["t"]),
        vehicle_px: [px[0], px[1]],
        vehicle: [p[0], p[1], p[2]],
    })
}

/// Decodes an RGB(A) PNG screenshot into `(width, height, rgba bytes)`.
fn read_png(path: &Path, page: &Path) -> Result<(u32, u32, Vec<u8>), ReplayError> {
    let bad = |m: String| browser_error(page, format!("{}: {m}", path.display()));
    let file = std::fs::File::open(path).map_err(|e| bad(e.to_string()))?;
    let mut decoder = png::Decoder::new(file);
    decoder.set_transformations(png::Transformations::EXPAND | png::Transformations::STRIP_16);
    let mut reader = decoder.read_info().map_err(|e| bad(e.to_string()))?;
    let mut buf = vec![0; reader.output_buffer_size()];
    let info = reader
        .next_frame(&mut buf)
        .map_err(|e| bad(e.to_string()))?;
    buf.truncate(info.buffer_size());
    let channels = info.color_type.samples();
    let rgba = match channels {
        4 => buf,
        3 => buf
            .chunks_exact(3)
            .flat_map(|c| [c[0], c[1], c[2], 255])
            .collect(),
        n => return Err(bad(format!("unexpected {n} channels"))),
    };
    Ok((info.width, info.height, rgba))
}

/// Opens `page` in headless Chromium at `#t=0` and at `#t=later_s` (see the module docs), writing
/// the screenshots into `work_dir`.
///
/// # Errors
/// [`ReplayError::Browser`] when Chromium cannot run, the page reports an error or did not draw,
/// the vehicle did not move, or the screenshots are identical.
pub fn check_page(
    chromium: &Path,
    page: &Path,
    later_s: f64,
    work_dir: &Path,
) -> Result<BrowserCheck, ReplayError> {
    let page_abs = std::fs::canonicalize(page)
        .map_err(|e| browser_error(page, format!("cannot open the page: {e}")))?;
    std::fs::create_dir_all(work_dir).map_err(|source| ReplayError::Write {
        path: work_dir.to_path_buf(),
        source,
    })?;
    let url = |t: f64| format!("file://{}#t={t}", page_abs.display());
    let profile = work_dir.join("chromium-profile");
    let mut statuses = Vec::new();
    let mut shots = Vec::new();
    for (k, t) in [0.0, later_s].into_iter().enumerate() {
        let dom = run_chromium(chromium, page, &url(t), &["--dump-dom".into()], &profile)?;
        let status = parse_status(&dom).map_err(|m| browser_error(page, m))?;
        if !status.errors.is_empty() {
            return Err(browser_error(
                page,
                format!("errors at #t={t}: {:?}", status.errors),
            ));
        }
        if !status.ready {
            return Err(browser_error(page, format!("nothing drawn at #t={t}")));
        }
        let shot = work_dir.join(format!("replay-{k}.png"));
        let _ = std::fs::remove_file(&shot);
        run_chromium(
            chromium,
            page,
            &url(t),
            &[format!("--screenshot={}", shot.display())],
            &profile,
        )?;
        if !shot.is_file() {
            return Err(browser_error(
                page,
                format!("no screenshot written at {}", shot.display()),
            ));
        }
        statuses.push(status);
        shots.push(shot);
    }
    let (a, b) = (read_png(&shots[0], page)?, read_png(&shots[1], page)?);
    if (a.0, a.1) != (b.0, b.1) {
        return Err(browser_error(page, "the two screenshots differ in size"));
    }
    let changed_pixels =
        a.2.chunks_exact(4)
            .zip(b.2.chunks_exact(4))
            .filter(|(p, q)| p != q)
            .count();
    let later = statuses.pop().unwrap_or_else(|| unreachable!());
    let start = statuses.pop().unwrap_or_else(|| unreachable!());
    let moved_px = (later.vehicle_px[0] - start.vehicle_px[0])
        .hypot(later.vehicle_px[1] - start.vehicle_px[1]);
    if moved_px.is_nan() || moved_px <= 2.0 {
        return Err(browser_error(
            page,
            format!(
                "the vehicle did not move on the canvas: {:?} at t = {} and {:?} at t = {}",
                start.vehicle_px, start.t, later.vehicle_px, later.t
            ),
        ));
    }
    if changed_pixels < 20 {
        return Err(browser_error(
            page,
            format!("the screenshots differ in only {changed_pixels} pixel(s)"),
        ));
    }
    let screenshots = [shots[0].clone(), shots[1].clone()];
    Ok(BrowserCheck {
        start,
        later,
        moved_px,
        changed_pixels,
        screenshots,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_status_element_is_read_from_a_dumped_dom() {
        let dom = r#"<html><body><pre id="replay-status" hidden="">{"errors":["x &lt; y"],"ready":true,"t":5,"vehicle_px":[10.5,20],"vehicle":[1,2,3]}</pre></body></html>"#;
        let s = parse_status(dom).unwrap();
        assert_eq!(s.errors, vec!["x < y".to_string()]);
        assert!(s.ready);
        assert_eq!(s.vehicle_px, [10.5, 20.0]);
        assert_eq!(s.vehicle, [1.0, 2.0, 3.0]);
        assert!(parse_status("<html></html>").is_err());
    }
}
