//! Axis ranges, tick positions and labels, and clipping of geometry to the plotted rectangle.
//!
//! Ticks are computed here (not by plotters) so that their labels are known before drawing: the
//! label area is sized from them and the same data always gives the same text.

/// Pads a degenerate (zero-width) range so that it can be drawn: `[v - p, v + p]` with
/// `p = 10 %` of `|v|`, or `1` when `v` is zero.
pub(crate) fn pad_degenerate(lo: f64, hi: f64) -> (f64, f64) {
    let (lo, hi) = if lo <= hi { (lo, hi) } else { (hi, lo) };
    let scale = lo.abs().max(hi.abs());
    if hi - lo > scale * 1e-9 && hi - lo > f64::MIN_POSITIVE {
        return (lo, hi);
    }
    let mid = 0.5 * (lo + hi);
    let pad = if mid.abs() > 1e-12 {
        0.1 * mid.abs()
    } else {
        1.0
    };
    (mid - pad, mid + pad)
}

/// Widens `[lo, hi]` by `frac` of its width on both sides (after padding a degenerate range).
pub(crate) fn with_margin(lo: f64, hi: f64, frac: f64) -> (f64, f64) {
    let (lo, hi) = pad_degenerate(lo, hi);
    let m = frac * (hi - lo);
    (lo - m, hi + m)
}

/// Minimum and maximum of the finite values, if any.
pub(crate) fn finite_extent(values: impl IntoIterator<Item = f64>) -> Option<(f64, f64)> {
    values
        .into_iter()
        .filter(|v| v.is_finite())
        .fold(None, |acc, v| match acc {
            None => Some((v, v)),
            Some((lo, hi)) => Some((lo.min(v), hi.max(v))),
        })
}

/// One axis: its drawn range, tick positions and the number of decimals of the tick labels.
#[derive(Clone, Debug)]
pub(crate) struct Axis {
    pub(crate) lo: f64,
    pub(crate) hi: f64,
    pub(crate) ticks: Vec<f64>,
    pub(crate) decimals: usize,
}

impl Axis {
    /// An axis over `[lo, hi]` (padded if degenerate) with about `target` "nice" ticks
    /// (steps of 1, 2, 2.5 or 5 times a power of ten).
    pub(crate) fn new(lo: f64, hi: f64, target: usize) -> Self {
        let (lo, hi) = pad_degenerate(lo, hi);
        let raw = (hi - lo) / target.max(1) as f64;
        let exp = raw.log10().floor();
        let mag = 10f64.powf(exp);
        let norm = raw / mag;
        // A little tolerance so that a range widened by pixel rounding keeps its natural step.
        let norm = norm / (1.0 + 1e-6);
        let (mult, extra) = if norm <= 1.0 {
            (1.0, 0)
        } else if norm <= 2.0 {
            (2.0, 0)
        } else if norm <= 2.5 {
            (2.5, 1)
        } else if norm <= 5.0 {
            (5.0, 0)
        } else {
            (10.0, 0)
        };
        let step = mult * mag;
        let decimals = (extra - exp as i64 - i64::from(mult >= 10.0)).clamp(0, 12) as usize;
        let k0 = (lo / step - 1e-9).ceil() as i64;
        let k1 = (hi / step + 1e-9).floor() as i64;
        let ticks = (k0..=k1)
            .take(200)
            .map(|k| {
                let v = k as f64 * step;
                if v.abs() < step * 1e-9 { 0.0 } else { v }
            })
            .collect();
        Self {
            lo,
            hi,
            ticks,
            decimals,
        }
    }

    /// An axis whose ticks are the given positions (used for categories).
    pub(crate) fn with_ticks(lo: f64, hi: f64, ticks: Vec<f64>) -> Self {
        Self {
            lo,
            hi,
            ticks,
            decimals: 0,
        }
    }

    pub(crate) fn label(&self, v: f64) -> String {
        format_number(v, self.decimals)
    }

    pub(crate) fn contains(&self, v: f64) -> bool {
        v >= self.lo && v <= self.hi
    }
}

/// `v` with `decimals` decimals, never printing `-0`.
pub(crate) fn format_number(v: f64, decimals: usize) -> String {
    let s = format!("{v:.decimals$}");
    if s.starts_with('-') && s[1..].chars().all(|c| c == '0' || c == '.') {
        s[1..].to_string()
    } else {
        s
    }
}

/// An axis-aligned rectangle in data coordinates.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Rect {
    pub(crate) x0: f64,
    pub(crate) x1: f64,
    pub(crate) y0: f64,
    pub(crate) y1: f64,
}

impl Rect {
    pub(crate) fn of(x: &Axis, y: &Axis) -> Self {
        Self {
            x0: x.lo,
            x1: x.hi,
            y0: y.lo,
            y1: y.hi,
        }
    }

    pub(crate) fn contains(&self, p: (f64, f64)) -> bool {
        p.0 >= self.x0 && p.0 <= self.x1 && p.1 >= self.y0 && p.1 <= self.y1
    }
}

/// Liang–Barsky: the part of segment `a`–`b` inside `r`, if any.
pub(crate) fn clip_segment(
    a: (f64, f64),
    b: (f64, f64),
    r: &Rect,
) -> Option<((f64, f64), (f64, f64))> {
    let (dx, dy) = (b.0 - a.0, b.1 - a.1);
    let mut t0 = 0.0f64;
    let mut t1 = 1.0f64;
    for (p, q) in [
        (-dx, a.0 - r.x0),
        (dx, r.x1 - a.0),
        (-dy, a.1 - r.y0),
        (dy, r.y1 - a.1),
    ] {
        if p == 0.0 {
            if q < 0.0 {
                return None;
            }
        } else {
            let t = q / p;
            if p < 0.0 {
                t0 = t0.max(t);
            } else {
                t1 = t1.min(t);
            }
            if t0 > t1 {
                return None;
            }
        }
    }
    Some((
        (a.0 + t0 * dx, a.1 + t0 * dy),
        (a.0 + t1 * dx, a.1 + t1 * dy),
    ))
}

/// Splits a polyline into the runs that lie inside `r`, breaking it at non-finite vertices.
/// Returns the runs and the number of non-finite vertices skipped.
pub(crate) fn clip_polyline(points: &[(f64, f64)], r: &Rect) -> (Vec<Vec<(f64, f64)>>, usize) {
    let mut runs: Vec<Vec<(f64, f64)>> = Vec::new();
    let mut current: Vec<(f64, f64)> = Vec::new();
    let mut skipped = 0;
    let mut prev: Option<(f64, f64)> = None;
    let flush = |current: &mut Vec<(f64, f64)>, runs: &mut Vec<Vec<(f64, f64)>>| {
        if !current.is_empty() {
            runs.push(std::mem::take(current));
        }
    };
    for &p in points {
        if !(p.0.is_finite() && p.1.is_finite()) {
            skipped += 1;
            flush(&mut current, &mut runs);
            prev = None;
            continue;
        }
        match prev {
            None => {
                if r.contains(p) {
                    current.push(p);
                }
            }
            Some(q) => match clip_segment(q, p, r) {
                Some((c0, c1)) => {
                    if current.last() != Some(&c0) {
                        flush(&mut current, &mut runs);
                        current.push(c0);
                    }
                    current.push(c1);
                    if c1 != p {
                        flush(&mut current, &mut runs);
                    }
                }
                None => flush(&mut current, &mut runs),
            },
        }
        prev = Some(p);
    }
    flush(&mut current, &mut runs);
    (runs, skipped)
}

/// Sutherland–Hodgman: the part of a polygon inside `r` (empty if none).
pub(crate) fn clip_polygon(poly: &[(f64, f64)], r: &Rect) -> Vec<(f64, f64)> {
    type Inside = fn(&Rect, (f64, f64)) -> bool;
    type Cut = fn(&Rect, (f64, f64), (f64, f64)) -> (f64, f64);
    let edges: [(Inside, Cut); 4] = [
        (
            |r, p| p.0 >= r.x0,
            |r, a, b| (r.x0, a.1 + (b.1 - a.1) * (r.x0 - a.0) / (b.0 - a.0)),
        ),
        (
            |r, p| p.0 <= r.x1,
            |r, a, b| (r.x1, a.1 + (b.1 - a.1) * (r.x1 - a.0) / (b.0 - a.0)),
        ),
        (
            |r, p| p.1 >= r.y0,
            |r, a, b| (a.0 + (b.0 - a.0) * (r.y0 - a.1) / (b.1 - a.1), r.y0),
        ),
        (
            |r, p| p.1 <= r.y1,
            |r, a, b| (a.0 + (b.0 - a.0) * (r.y1 - a.1) / (b.1 - a.1), r.y1),
        ),
    ];
    let mut out: Vec<(f64, f64)> = poly.to_vec();
    for (inside, cut) in edges {
        if out.is_empty() {
            break;
        }
        let input = std::mem::take(&mut out);
        let mut prev = input[input.len() - 1];
        for &cur in &input {
            let (pi, ci) = (inside(r, prev), inside(r, cur));
            if ci {
                if !pi {
                    out.push(cut(r, prev, cur));
                }
                out.push(cur);
            } else if pi {
                out.push(cut(r, prev, cur));
            }
            prev = cur;
        }
    }
    out
}

/// A circle as a polygon with `n` vertices.
pub(crate) fn circle_polygon(c: (f64, f64), radius: f64, n: usize) -> Vec<(f64, f64)> {
    (0..n)
        .map(|i| {
            let a = std::f64::consts::TAU * i as f64 / n as f64;
            (c.0 + radius * a.cos(), c.1 + radius * a.sin())
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn degenerate_ranges_are_padded_and_ordered() {
        assert_eq!(pad_degenerate(0.0, 0.0), (-1.0, 1.0));
        let (lo, hi) = pad_degenerate(5.0, 5.0);
        assert!((lo - 4.5).abs() < 1e-12 && (hi - 5.5).abs() < 1e-12);
        assert_eq!(pad_degenerate(3.0, 1.0), (1.0, 3.0));
    }

    #[test]
    fn ticks_are_nice_and_inside() {
        let a = Axis::new(0.0, 250.0, 8);
        assert_eq!(a.ticks.first().copied(), Some(0.0));
        assert_eq!(a.ticks.last().copied(), Some(250.0));
        assert!(a.ticks.iter().all(|t| a.contains(*t)));
        assert_eq!(a.decimals, 0);
        let b = Axis::new(-0.013, 0.021, 5);
        assert!(b.ticks.len() >= 3 && b.decimals >= 2, "{b:?}");
        assert!(b.ticks.iter().all(|t| b.label(*t) != "-0.000"));
        let c = Axis::new(0.0, 1.0, 2);
        assert_eq!(
            c.ticks.iter().map(|t| c.label(*t)).collect::<Vec<_>>(),
            ["0.0", "0.5", "1.0"]
        );
    }

    #[test]
    fn negative_zero_is_printed_as_zero() {
        assert_eq!(format_number(-0.0001, 2), "0.00");
        assert_eq!(format_number(-1.5, 1), "-1.5");
    }

    #[test]
    fn polylines_are_clipped_and_broken_at_nan() {
        let r = Rect {
            x0: 0.0,
            x1: 10.0,
            y0: 0.0,
            y1: 10.0,
        };
        let (runs, skipped) = clip_polyline(
            &[
                (-5.0, 5.0),
                (5.0, 5.0),
                (f64::NAN, 1.0),
                (1.0, 1.0),
                (2.0, 2.0),
                (20.0, 2.0),
            ],
            &r,
        );
        assert_eq!(skipped, 1);
        assert_eq!(
            runs,
            vec![
                vec![(0.0, 5.0), (5.0, 5.0)],
                vec![(1.0, 1.0), (2.0, 2.0), (10.0, 2.0)]
            ]
        );
    }

    #[test]
    fn polygons_are_clipped_to_the_rectangle() {
        let r = Rect {
            x0: 0.0,
            x1: 1.0,
            y0: 0.0,
            y1: 1.0,
        };
        let clipped = clip_polygon(&[(-1.0, -1.0), (0.5, -1.0), (0.5, 0.5), (-1.0, 0.5)], &r);
        assert!(clipped.iter().all(|p| r.contains(*p)));
        assert!(clip_polygon(&[(2.0, 2.0), (3.0, 2.0), (3.0, 3.0)], &r).is_empty());
    }
}
