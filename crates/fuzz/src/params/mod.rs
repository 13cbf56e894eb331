//! Parameter structs at their edges, one module per crate: every numeric field of a params struct
//! (and every scalar argument of a constructor) set to an edge value — 0, −0, negative, tiny,
//! huge, NaN, ±∞, `usize::MAX`, `1 << 40`, just above a cap — one field at a time and in pairs,
//! then the struct used as a caller would. Oracles, on top of the harness's own (no panic, no hang,
//! no slow call):
//!
//! * **culprit**: an error for an edited struct must name one of the edited fields (field paths
//!   such as `devprm.surface_offset`); an accepted struct must not make the call that uses it fail
//!   with an error naming something else;
//! * **readable**: no error message carries a run of more than 17 digits (a 31-digit integer);
//! * **finite**: every output of an accepted call is finite;
//! * crate-specific answers (`segment_clear` at clearance 0, in [`geometry`]).
//!
//! To add a crate, add a module with `pub fn apis() -> Vec<Api>` built from [`Fields`] and
//! [`judge`], and append it in [`apis`].

pub mod geometry;
pub mod lbfgs;
pub mod predict;
pub mod topo;

use crate::apis::{Api, Outcome};
use crate::inputs::Gen;

/// Every parameter-edge API of every crate.
pub fn apis() -> Vec<Api> {
    let mut v = Vec::new();
    v.extend(lbfgs::apis());
    v.extend(geometry::apis());
    v.extend(predict::apis());
    v.extend(topo::apis());
    v
}

/// Float edges: the harness's special values plus values just outside and at the scale policy's
/// ends.
pub const FLOAT_EDGES: [f64; 36] = [
    f64::NAN,
    f64::INFINITY,
    f64::NEG_INFINITY,
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    f64::MIN_POSITIVE,
    1e-300,
    1e-12,
    1e-10,
    1e-9,
    1e-6,
    1e-3,
    0.5,
    1.0,
    -1.0,
    -1e-9,
    2.0,
    100.0,
    1e4,
    1.00001e4,
    1e5,
    1e6,
    1.000001e6,
    6e5,
    1e7,
    1.0000001e7,
    1e8,
    1e10,
    1e155,
    1e300,
    -1e300,
    f64::MAX,
    f64::MIN,
    -1e6,
];

/// Count edges: empty, one, small, at and above the caps, `1 << 40`, `usize::MAX`.
pub const COUNT_EDGES: [usize; 16] = [
    0,
    1,
    2,
    3,
    8,
    64,
    65,
    1024,
    1025,
    10_000,
    10_001,
    100_000,
    100_001,
    1 << 40,
    usize::MAX / 2,
    usize::MAX,
];

/// A settable field of a params struct `T`: its name as error messages spell it, and a setter.
pub enum Field<T> {
    /// An `f64` field (or one component of a vector field).
    Float(&'static str, fn(&mut T, f64)),
    /// A `usize` field.
    Count(&'static str, fn(&mut T, usize)),
}

/// The fields of one params struct.
pub struct Fields<T: 'static>(pub &'static [Field<T>]);

impl<T> Fields<T> {
    /// Edits one field (two, 30 % of the time) of `base` to edge values (sometimes a random
    /// ordinary value for the second one); returns the struct and the edited names.
    pub fn edit(&self, g: &mut Gen, mut base: T) -> (T, Vec<&'static str>) {
        let mut names = Vec::new();
        let n = if g.chance(0.3) { 2 } else { 1 };
        for _ in 0..n {
            let f = &self.0[g.index(self.0.len())];
            match f {
                Field::Float(name, set) => {
                    let x = if g.chance(0.8) {
                        FLOAT_EDGES[g.index(FLOAT_EDGES.len())]
                    } else {
                        g.num(0.0, 10.0)
                    };
                    set(&mut base, x);
                    names.push(*name);
                }
                Field::Count(name, set) => {
                    let x = if g.chance(0.8) {
                        COUNT_EDGES[g.index(COUNT_EDGES.len())]
                    } else {
                        g.count(100)
                    };
                    set(&mut base, x);
                    names.push(*name);
                }
            }
        }
        (base, names)
    }
}

/// Longest run of significant decimal digits in `s` (leading zeros of a run do not count, so
/// `0.000006661117722360797`, a shortest round-trip f64, has 16).
pub fn longest_digit_run(s: &str) -> usize {
    s.split(|c: char| !c.is_ascii_digit())
        .map(|run| run.trim_start_matches('0').len())
        .max()
        .unwrap_or(0)
}

/// The readable and culprit oracles on an error message: `Some(Wrong)` if it has a run of more
/// than 17 digits, or names none of `culprits` (when any are given).
pub fn judge_error(msg: &str, culprits: &[&str]) -> Option<Outcome> {
    if longest_digit_run(msg) > 17 {
        return Some(Outcome::Wrong(format!("unreadable number in: {msg}")));
    }
    if !culprits.is_empty() && !culprits.iter().any(|c| msg.contains(c)) {
        return Some(Outcome::Wrong(format!(
            "error names none of the edited fields {culprits:?}: {msg}"
        )));
    }
    None
}

/// Judges a validation result: an error must be readable and name an edited field.
pub fn judge<E: std::fmt::Display>(r: &Result<(), E>, culprits: &[&str]) -> Option<Outcome> {
    match r {
        Ok(()) => None,
        Err(e) => Some(judge_error(&e.to_string(), culprits).unwrap_or(Outcome::Err)),
    }
}

/// Judges the error of a call made with an *accepted* struct: it must be readable and, since the
/// rest of the call's inputs are valid, name one of the edited fields (else the struct accepted
/// a value that breaks the call: a wrong answer).
pub fn judge_use<E: std::fmt::Display>(e: &E, culprits: &[&str]) -> Outcome {
    let msg = e.to_string();
    judge_error(&msg, culprits).unwrap_or(Outcome::Err)
}
