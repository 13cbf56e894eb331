//! `TopoPathSelect` (Algorithm 2): drop paths equivalent to a shorter one, then keep the shortest and
//! every path not longer than `length_ratio` times it, up to a count (Fast-Planner's
//! `pruneEquivalent` + `selectShortPaths`).

use crate::uvd::polyline_length;

/// Sorts `paths` by length (stable) and keeps a greedy representative set: a path is kept unless it is
/// `equivalent` to an already kept one. Sorting first makes each class's representative its shortest
/// member.
pub fn prune_equivalent(
    paths: Vec<Vec<trust_core::Vec3>>,
    mut equivalent: impl FnMut(&[trust_core::Vec3], &[trust_core::Vec3]) -> bool,
) -> Vec<Vec<trust_core::Vec3>> {
    let scored = by_length(paths);
    let mut kept: Vec<Vec<trust_core::Vec3>> = Vec::new();
    for (_, p) in scored {
        if !kept.iter().any(|k| equivalent(k, &p)) {
            kept.push(p);
        }
    }
    kept
}

/// The shortest path and every other path with `length / shortest < length_ratio`, shortest first, at
/// most `max_paths`. A zero-length shortest path admits only paths of zero length.
pub fn select_short_paths(
    paths: Vec<Vec<trust_core::Vec3>>,
    length_ratio: f64,
    max_paths: usize,
) -> Vec<Vec<trust_core::Vec3>> {
    let scored = by_length(paths);
    let Some(shortest) = scored.first().map(|s| s.0) else {
        return Vec::new();
    };
    scored
        .into_iter()
        .enumerate()
        .take_while(|(i, (len, _))| *i == 0 || (shortest > 0.0 && *len / shortest < length_ratio))
        .take(max_paths)
        .map(|(_, (_, p))| p)
        .collect()
}

/// [`prune_equivalent`] followed by [`select_short_paths`] with the same result, but without testing
/// paths the selection would drop anyway: the paths are taken shortest first, and the walk stops at
/// the first one at least `length_ratio` times the shortest or once `max_paths` are kept, so it asks
/// `equivalent` at most `max_paths − 1` times per path.
pub fn select_distinct_short_paths(
    paths: Vec<Vec<trust_core::Vec3>>,
    length_ratio: f64,
    max_paths: usize,
    mut equivalent: impl FnMut(&[trust_core::Vec3], &[trust_core::Vec3]) -> bool,
) -> Vec<Vec<trust_core::Vec3>> {
    let scored = by_length(paths);
    let Some(shortest) = scored.first().map(|s| s.0) else {
        return Vec::new();
    };
    let mut kept: Vec<Vec<trust_core::Vec3>> = Vec::new();
    for (i, (len, p)) in scored.into_iter().enumerate() {
        if kept.len() >= max_paths || (i > 0 && !(shortest > 0.0 && len / shortest < length_ratio))
        {
            break;
        }
        if !kept.iter().any(|k| equivalent(k, &p)) {
            kept.push(p);
        }
    }
    kept
}

/// The paths with their lengths, shortest first (a stable sort: ties keep their order).
fn by_length(paths: Vec<Vec<trust_core::Vec3>>) -> Vec<(f64, Vec<trust_core::Vec3>)> {
    let mut scored: Vec<(f64, Vec<trust_core::Vec3>)> = paths
        .into_iter()
        .map(|p| (polyline_length(&p), p))
        .collect();
    scored.sort_by(|a, b| a.0.total_cmp(&b.0));
    scored
}

#[cfg(test)]
mod tests {
    use super::*;
    use trust_core::Vec3;

    fn seg(len: f64, tag: f64) -> Vec<Vec3> {
        vec![Vec3::new(0.0, tag, 0.0), Vec3::new(len, tag, 0.0)]
    }

    #[test]
    fn keeps_the_shortest_of_each_class() {
        // Class = sign of the tag.
        let paths = vec![seg(5.0, 1.0), seg(3.0, 2.0), seg(4.0, -1.0), seg(9.0, -3.0)];
        let kept = prune_equivalent(paths, |a, b| (a[0].y > 0.0) == (b[0].y > 0.0));
        assert_eq!(kept, vec![seg(3.0, 2.0), seg(4.0, -1.0)]);
    }

    #[test]
    fn ratio_and_count_limit_the_selection() {
        let paths = vec![seg(10.0, 0.0), seg(2.0, 0.0), seg(12.0, 0.0), seg(3.0, 0.0)];
        let sel = select_short_paths(paths.clone(), 5.5, 6);
        assert_eq!(sel.len(), 3);
        assert_eq!(sel[0], seg(2.0, 0.0));
        assert_eq!(select_short_paths(paths, 5.5, 2).len(), 2);
        assert!(select_short_paths(Vec::new(), 5.5, 6).is_empty());
        let zero = vec![seg(0.0, 0.0), seg(1.0, 1.0)];
        assert_eq!(select_short_paths(zero, 5.5, 6).len(), 1);
    }

    #[test]
    fn the_fused_selection_equals_prune_then_select_and_asks_less() {
        let class = |a: &[Vec3], b: &[Vec3]| (a[0].y > 0.0) == (b[0].y > 0.0);
        let paths: Vec<Vec<Vec3>> = (0..12)
            .map(|i| {
                seg(
                    1.0 + i as f64 * 0.7,
                    if i % 3 == 0 { -1.0 } else { i as f64 },
                )
            })
            .collect();
        for (ratio, max) in [(5.5, 6), (1.5, 6), (5.5, 1), (100.0, 100)] {
            let expected = select_short_paths(prune_equivalent(paths.clone(), class), ratio, max);
            let mut asked = 0;
            let fused = select_distinct_short_paths(paths.clone(), ratio, max, |a, b| {
                asked += 1;
                class(a, b)
            });
            assert_eq!(fused, expected, "ratio {ratio}, max {max}");
            assert!(asked <= paths.len() * max);
        }
        let zero = vec![seg(0.0, 0.0), seg(1.0, 1.0)];
        assert_eq!(select_distinct_short_paths(zero, 5.5, 6, class).len(), 1);
    }
}
