//! The HTML page: a template with the style sheet, the script and the data put inline.

use std::path::Path;

use trust_runlog::{Header, Outcome, RunLog};

use crate::data::{page_data, script_safe_json};
use crate::{ReplayError, ReplayParams};

const TEMPLATE: &str = include_str!("../assets/replay.html");
const STYLE: &str = include_str!("../assets/replay.css");
const SCRIPT: &str = include_str!("../assets/replay.js");

/// Escapes text for an HTML text node or attribute.
fn escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The replay page of `log` (read from a file in `log_dir`, which resolves its static points
/// file): one self-contained HTML document (see the crate docs). The same log and parameters give
/// the same bytes.
///
/// # Errors
/// [`ReplayError::InvalidParam`] for bad parameters, [`ReplayError::Points`] for an unreadable
/// static points file.
pub fn page_html(
    log: &RunLog,
    log_dir: &Path,
    params: &ReplayParams,
) -> Result<String, ReplayError> {
    let data = page_data(log, log_dir, params)?;
    Ok(html_of(&log.header, &log.outcome, &data))
}

/// The page around its `data` ([`crate::data::PageBuilder::finish`]).
pub(crate) fn html_of(h: &Header, outcome: &Outcome, data: &serde_json::Value) -> String {
    let title = escape(&format!(
        "{} — {} (seed {}): {}",
        h.scenario,
        h.planner,
        h.seed,
        outcome.status.as_str()
    ));
    // The data goes last: it is the only part that may contain arbitrary text (escaped for a
    // script element by `script_safe_json`), so no placeholder can be found inside it.
    TEMPLATE
        .replace("{{TITLE}}", &title)
        .replace("{{STYLE}}", STYLE)
        .replace("{{SCRIPT}}", SCRIPT)
        .replace("{{DATA}}", &script_safe_json(data))
}
