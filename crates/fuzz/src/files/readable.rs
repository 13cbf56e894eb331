//! The readability oracle on every message a file group sees (errors, validation problems, audit
//! findings): numbers a person can read, and no more of the file than the offending line.
//!
//! * **Numbers**: no number printed with more than [`MAX_DIGITS`] significant digits or
//!   [`MAX_NUMBER_CHARS`] characters (`1e308` must not print as 309 digits) — unless the number
//!   is the file's own text, quoted (a parser showing the offending line shows what the file
//!   wrote).
//! * **Quotes**: no line of a message longer than [`MAX_LINE_CHARS`] characters (a parser that
//!   echoes a 10 000-character line), a file name counting as at most [`PATH_CHARS`] (a message
//!   names the file it could not read, whatever its length; the system bounds it), and no more
//!   than one line of the file quoted whole per line of the message (a message lists one problem
//!   a line, each with its offending line; lines of at least [`DISTINCT_LINE_CHARS`]
//!   characters, so that `[mission]` or `t,x,y,z` quoted as a name does not count).

/// Most significant digits of a number in a message.
pub const MAX_DIGITS: usize = 12;
/// Most characters of a number in a message (`0.000000000000000001` is unreadable too).
pub const MAX_NUMBER_CHARS: usize = 24;
/// Longest line of a message (characters): the files' policies quote at most 60 characters of
/// a line, parsers' messages are cut at 240.
pub const MAX_LINE_CHARS: usize = 600;
/// What a file name (a word with a `/`) counts for in a message line's length.
pub const PATH_CHARS: usize = 80;
/// Lines of the file at least this long count as quoted when a message holds them whole.
pub const DISTINCT_LINE_CHARS: usize = 24;

/// Why `message` is unreadable for a reader of `input` (the file's text), if it is.
pub fn problem(message: &str, input: &str) -> Option<String> {
    if let Some(p) = long_number(message, input) {
        return Some(p);
    }
    if let Some((n, line)) = message
        .lines()
        .map(line_chars)
        .enumerate()
        .find(|&(_, n)| n > MAX_LINE_CHARS)
        .map(|(i, n)| (n, i + 1))
    {
        return Some(format!(
            "line {line} of the message has {n} characters (more than {MAX_LINE_CHARS})"
        ));
    }
    // Candidates: the file's distinctive lines the message holds anywhere; then, per line of
    // the message (a message lists one problem per line, each with its own offending line).
    let mut candidates: Vec<&str> = input
        .lines()
        .map(str::trim)
        .filter(|l| l.len() >= DISTINCT_LINE_CHARS && message.contains(*l))
        .collect();
    candidates.sort_unstable();
    candidates.dedup();
    if candidates.len() > 1 {
        for (i, m) in message.lines().enumerate() {
            // A file line within another quoted one (a line joined to the next) is not a
            // second quote.
            let found: Vec<&str> = candidates
                .iter()
                .copied()
                .filter(|l| m.contains(*l))
                .collect();
            let n = found
                .iter()
                .filter(|l| !found.iter().any(|o| o.len() > l.len() && o.contains(**l)))
                .count();
            if n > 1 {
                return Some(format!(
                    "line {} of the message quotes {n} lines of the file whole (at most the \
                     offending one)",
                    i + 1
                ));
            }
        }
    }
    None
}

/// The length of a message line, file names counted as at most [`PATH_CHARS`].
fn line_chars(line: &str) -> usize {
    line.split_inclusive(' ')
        .map(|w| {
            let n = w.chars().count();
            if w.contains('/') {
                n.min(PATH_CHARS)
            } else {
                n
            }
        })
        .sum()
}

/// A number of `message` printed with too many digits that `input` does not hold as such.
fn long_number(message: &str, input: &str) -> Option<String> {
    let bytes = message.as_bytes();
    let mut i = 0;
    while i < bytes.len() {
        if !bytes[i].is_ascii_digit() {
            i += 1;
            continue;
        }
        let start = i;
        while i < bytes.len() && (bytes[i].is_ascii_digit() || bytes[i] == b'.') {
            i += 1;
        }
        let token = message[start..i].trim_end_matches('.');
        let digits: String = token.chars().filter(char::is_ascii_digit).collect();
        let significant = digits.trim_start_matches('0').len();
        if (significant > MAX_DIGITS || token.len() > MAX_NUMBER_CHARS) && !input.contains(token) {
            let shown: String = token.chars().take(40).collect();
            return Some(format!(
                "a number with {significant} significant digits ({} characters): {shown}{}",
                token.len(),
                if token.len() > 40 { "…" } else { "" }
            ));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn long_numbers_are_unreadable_unless_quoted_from_the_file() {
        let huge = format!("1{}", "0".repeat(308));
        assert!(problem(&format!("radius_m: {huge} — expected"), "radius_m = 1e308").is_some());
        assert!(problem("radius_m: 1e308 — expected", "radius_m = 1e308").is_none());
        assert!(problem(&format!("line 3: x = {huge}"), &format!("x = {huge}")).is_none());
        assert!(problem("0.30000000000000004", "").is_some());
        assert!(problem("16 GiB is 17179869184 bytes; 0.3", "").is_none());
        assert!(problem("at 12.345678901234", "").is_some());
    }

    #[test]
    fn quoting_more_than_one_line_or_a_long_line_is_unreadable() {
        let input = "first line of the file, long enough\nsecond line of the file, long too\n";
        assert!(problem("error at first line of the file, long enough", input).is_none());
        assert!(
            problem(
                "first line of the file, long enough; second line of the file, long too",
                input
            )
            .is_some()
        );
        // A line joined to the next one is one quote.
        let joined =
            "[obstacles.motion] kind = \"random-maneuvers\"\nkind = \"random-maneuvers\"\n";
        assert!(
            problem(
                "48 | [obstacles.motion] kind = \"random-maneuvers\"",
                joined
            )
            .is_none()
        );
        // Two problems, each quoting its own line.
        assert!(
            problem(
                "first line of the file, long enough\nsecond line of the file, long too",
                input
            )
            .is_none()
        );
        assert!(problem(&"x".repeat(700), "").is_some());
        let path = format!("/tmp/{}x.csv", "a/".repeat(2000));
        assert!(problem(&format!("cannot read {path}: File name too long"), "").is_none());
    }
}
