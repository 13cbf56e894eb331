//! Mutation primitives the file groups share: numbers at the edges of the scale policy and of
//! the run-log audit's policy (each cap at `cap − 1`, `cap`, `cap + 1` and one ulp either side),
//! the special paths a file name can be swapped for, and byte-level edits of a file's text
//! (truncation, lines deleted, duplicated or swapped, bytes no parser expects, numbers no `f64`
//! holds).

use std::path::Path;

use rand::Rng as _;
use rand_chacha::ChaCha8Rng;
use trust_runlog::audit as policy;
use trust_world::scenario::scale;

/// The random source of one case.
pub type Rng = ChaCha8Rng;

/// The float caps of the scale policy (`trust_world::scenario::scale`, `trust_world::script`)
/// and of the audit (`trust_runlog::audit`), and the contract's step and stand-in values.
const FLOAT_CAPS: [f64; 24] = [
    scale::MAX_COORD_M,
    scale::MAX_SPEED_M_S,
    scale::MAX_OBSTACLE_ACCEL_M_S2,
    scale::V_MAX_RANGE.0,
    scale::V_MAX_RANGE.1,
    scale::A_MAX_RANGE.0,
    scale::MAX_VEHICLE_RADIUS_M,
    scale::MAX_NOISE_M,
    scale::MAX_WARMUP_S,
    scale::MAX_FAULT_LEVEL,
    scale::PHYSICS_DT_RANGE.0,
    scale::PHYSICS_DT_RANGE.1,
    scale::MAX_TIME_LIMIT_S,
    scale::MAX_SCRIPT_TIME_S,
    trust_world::script::LOOP_CLOSURE_M,
    trust_world::scenario::MAX_CPU_SCALE,
    policy::MAX_COORDINATE_M,
    policy::MAX_SPEED_M_S,
    policy::MAX_ACCEL_M_S2,
    policy::MAX_TIME_S,
    policy::POSITION_STEP_TOLERANCE_M,
    policy::VELOCITY_STEP_TOLERANCE_M_S,
    0.02,
    1e9,
];

/// The count caps: obstacles, shapes, cloud points, samples, harmonics, endpoint draws,
/// placement work, voxels.
const COUNT_CAPS: [i64; 9] = [
    scale::MAX_OBSTACLE_COUNT as i64,
    scale::MAX_STATIC_SHAPE_COUNT as i64,
    scale::MAX_CLOUD_POINTS as i64,
    trust_world::script::MAX_SAMPLES as i64,
    trust_world::script::MAX_HARMONICS as i64,
    scale::MAX_ENDPOINT_WORK as i64,
    40_200,
    scale::MAX_PLACEMENT_WORK as i64,
    trust_geometry::MAX_VOXELS as i64,
];

/// Values every reader must survive, whatever the field.
const FLOAT_SPECIALS: [f64; 16] = [
    0.0,
    -0.0,
    5e-324,
    1e-300,
    1e-12,
    1.0,
    -1.0,
    1e308,
    -1e308,
    f64::MAX,
    f64::MIN,
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    9_007_199_254_740_993.0,
    0.300_000_000_000_000_04,
];

/// An index in `0..n` (`n > 0`).
pub fn pick(rng: &mut Rng, n: usize) -> usize {
    rng.random_range(0..n)
}

/// True with probability `p`.
pub fn chance(rng: &mut Rng, p: f64) -> bool {
    rng.random_bool(p.clamp(0.0, 1.0))
}

/// A float at an edge: a cap of either policy (at `cap − 1`, `cap`, `cap + 1`, one ulp either
/// side, negated), a special value (±0, subnormal, ±1e308, `f64::MAX`, NaN, ±∞, beyond 2⁵³), or
/// `current` nudged (one ulp, ×1e6, negated).
pub fn float_edge(rng: &mut Rng, current: Option<f64>) -> f64 {
    match (pick(rng, 10), current) {
        (0..=4, _) => {
            let c = FLOAT_CAPS[pick(rng, FLOAT_CAPS.len())];
            match pick(rng, 7) {
                0 => c - 1.0,
                1 => c + 1.0,
                2 => c.next_up(),
                3 => c.next_down(),
                4 => -c,
                5 => c * (1.0 + 1e-9),
                _ => c,
            }
        }
        (5..=7, _) | (_, None) => FLOAT_SPECIALS[pick(rng, FLOAT_SPECIALS.len())],
        (_, Some(x)) => match pick(rng, 6) {
            0 => x.next_up(),
            1 => -x,
            2 => x * 1e6,
            3 => x / 1e6,
            4 => x + 1.0,
            _ => x * (1.0 + 1e-9),
        },
    }
}

/// An integer at an edge: a count cap at `cap − 1`, `cap`, `cap + 1`, 0, ±1, `i64::MAX`,
/// `i64::MIN`, 2³², 2⁵³ + 1, or `current` nudged.
pub fn int_edge(rng: &mut Rng, current: Option<i64>) -> i64 {
    match (pick(rng, 10), current) {
        (0..=5, _) => {
            let c = COUNT_CAPS[pick(rng, COUNT_CAPS.len())];
            c + [-1, 0, 1][pick(rng, 3)]
        }
        (6..=8, _) | (_, None) => [
            0,
            1,
            -1,
            2,
            i64::MAX,
            i64::MIN,
            1 << 31,
            1 << 32,
            (1 << 53) + 1,
            i64::from(u32::MAX),
        ][pick(rng, 10)],
        (_, Some(x)) => match pick(rng, 4) {
            0 => x.saturating_add(1),
            1 => x.saturating_sub(1),
            2 => x.saturating_neg(),
            _ => x.saturating_mul(1000),
        },
    }
}

/// Number texts no `f64` parser accepts as a finite value, or that only a careful one reads.
pub fn number_text(rng: &mut Rng) -> String {
    match pick(rng, 10) {
        0 => format!("1{}", "0".repeat(400)),
        1 => "1e400".into(),
        2 => "-1e400".into(),
        3 => format!("0.{}1", "0".repeat(400)),
        4 => "9".repeat(30),
        5 => "NaN".into(),
        6 => "-Infinity".into(),
        7 => "1e".into(),
        8 => "0x10".into(),
        _ => "-".into(),
    }
}

/// A file name the readers must refuse or read safely, relative to a scenario's (or a log's)
/// folder `dir` (which [`crate::files::corpus::CaseDir`] furnishes with `dir/`, `link_*` and
/// `../outside.*`): devices, a folder, paths climbing out, missing files, symbolic links (to a
/// file inside, out of the folder, to a device, to a folder, dangling, a loop), a FIFO, an
/// absolute path, names too long or with a NUL byte.
pub fn special_path(rng: &mut Rng, dir: &Path, inside: &str, ext: &str) -> String {
    let abs = |p: &str| dir.join(p).display().to_string();
    match pick(rng, 26) {
        0 => "/dev/zero".into(),
        1 => "/dev/null".into(),
        2 => "/dev/urandom".into(),
        3 => "/proc/self/maps".into(),
        4 => "/proc/self/mem".into(),
        5 => "dir".into(),
        6 => ".".into(),
        7 => String::new(),
        8 => "/".into(),
        9 => format!("../outside.{ext}"),
        10 => format!("data/../../outside.{ext}"),
        11 => format!("./../outside.{ext}"),
        12 => format!("missing.{ext}"),
        13 => format!("data/missing/x.{ext}"),
        14 => "link_in".into(),
        15 => "link_out".into(),
        16 => "link_dev".into(),
        17 => "link_dir".into(),
        18 => "link_loop".into(),
        19 => "link_dangling".into(),
        20 => "fifo".into(),
        21 => abs(inside),
        22 => abs(&format!("../outside.{ext}")),
        23 => format!("{}x.{ext}", "a/".repeat(2100)),
        24 => format!("data/\u{0}.{ext}"),
        _ => format!("{}{inside}", "dir/../".repeat(pick(rng, 40) + 1)),
    }
}

/// Junk that no text format expects: NUL, bytes that are not UTF-8, a byte-order mark, lone
/// line ends, quotes and brackets, a long line.
fn junk(rng: &mut Rng) -> Vec<u8> {
    match pick(rng, 12) {
        0 => b"\0".to_vec(),
        1 => b"\xff\xfe".to_vec(),
        2 => b"\xef\xbb\xbf".to_vec(),
        3 => b"\r".to_vec(),
        4 => b"\n".to_vec(),
        5 => b"\"".to_vec(),
        6 => b"[".to_vec(),
        7 => b"{".to_vec(),
        8 => "é\u{2028}".as_bytes().to_vec(),
        9 => b"\\u0000".to_vec(),
        10 => vec![b'x'; 10_000],
        _ => b",,,".to_vec(),
    }
}

/// Byte offsets of line starts in `text` (0 first).
fn line_starts(text: &[u8]) -> Vec<usize> {
    let mut v = vec![0];
    v.extend(
        text.iter()
            .enumerate()
            .filter(|&(i, &b)| b == b'\n' && i + 1 < text.len())
            .map(|(i, _)| i + 1),
    );
    v
}

/// The byte range of line `k` (its end included).
fn line_range(text: &[u8], starts: &[usize], k: usize) -> std::ops::Range<usize> {
    let end = starts.get(k + 1).copied().unwrap_or(text.len());
    starts[k]..end
}

/// One byte-level edit of `text`, with what it did: truncation at a random offset, a line
/// deleted, duplicated or swapped with another, junk inserted, a number replaced by one no
/// `f64` holds, every line end made CRLF, or one byte flipped.
pub fn raw_edit(rng: &mut Rng, text: &mut Vec<u8>) -> &'static str {
    if text.is_empty() {
        text.extend(junk(rng));
        return "junk in an empty file";
    }
    let starts = line_starts(text);
    match pick(rng, 9) {
        0 => {
            let at = pick(rng, text.len());
            text.truncate(at);
            "truncated"
        }
        1 => {
            let r = line_range(text, &starts, pick(rng, starts.len()));
            text.drain(r);
            "line deleted"
        }
        2 => {
            let r = line_range(text, &starts, pick(rng, starts.len()));
            let line = text[r].to_vec();
            let at = starts[pick(rng, starts.len())];
            let mut line = line;
            if line.last() != Some(&b'\n') {
                line.push(b'\n');
            }
            text.splice(at..at, line);
            "line duplicated"
        }
        3 if starts.len() > 1 => {
            let (a, b) = (pick(rng, starts.len()), pick(rng, starts.len()));
            let (a, b) = (a.min(b), a.max(b));
            if a != b {
                let ra = line_range(text, &starts, a);
                let rb = line_range(text, &starts, b);
                let mut out = text[..ra.start].to_vec();
                out.extend_from_slice(&text[rb.clone()]);
                if out.last() != Some(&b'\n') {
                    out.push(b'\n');
                }
                out.extend_from_slice(&text[ra.end..rb.start]);
                out.extend_from_slice(&text[ra]);
                out.extend_from_slice(&text[rb.end..]);
                *text = out;
            }
            "lines swapped"
        }
        4 => {
            let at = pick(rng, text.len() + 1);
            let j = junk(rng);
            text.splice(at..at, j);
            "junk inserted"
        }
        5 => {
            // The first digit run after a random offset.
            let from = pick(rng, text.len());
            if let Some(i) = text[from..].iter().position(u8::is_ascii_digit) {
                let i = from + i;
                let len = text[i..]
                    .iter()
                    .position(|b| !(b.is_ascii_digit() || *b == b'.'))
                    .unwrap_or(text.len() - i);
                let n = number_text(rng);
                text.splice(i..i + len, n.into_bytes());
            }
            "number replaced"
        }
        6 => {
            let mut out = Vec::with_capacity(text.len() + starts.len());
            for &b in text.iter() {
                if b == b'\n' {
                    out.push(b'\r');
                }
                out.push(b);
            }
            *text = out;
            "CRLF line ends"
        }
        _ => {
            let at = pick(rng, text.len());
            text[at] ^= 1 << pick(rng, 8);
            "byte flipped"
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng as _;

    #[test]
    fn raw_edits_keep_every_byte_range_in_bounds() {
        let mut rng = Rng::seed_from_u64(7);
        for i in 0..2000 {
            let mut text = match i % 3 {
                0 => Vec::new(),
                1 => b"a = 1\nb = [2, 3]\n".to_vec(),
                _ => b"no newline 12.5".to_vec(),
            };
            for _ in 0..3 {
                raw_edit(&mut rng, &mut text);
            }
        }
    }

    #[test]
    fn edges_include_the_caps_and_their_neighbours() {
        let mut rng = Rng::seed_from_u64(1);
        let seen: Vec<f64> = (0..20_000).map(|_| float_edge(&mut rng, None)).collect();
        for x in [1e5, 1e5 + 1.0, 99_999.0, 1e5f64.next_up()] {
            assert!(seen.contains(&x), "{x}");
        }
        let ints: Vec<i64> = (0..20_000).map(|_| int_edge(&mut rng, None)).collect();
        for x in [9_999, 10_000, 10_001, i64::MAX] {
            assert!(ints.contains(&x), "{x}");
        }
    }
}
