//! [`StraightLine`]: the paper's baseline 1 ("no hierarchical guidance", Sec. IV-D) — the straight
//! segment from the start toward the goal, truncated to the distance the vehicle covers in the horizon.

use std::time::Instant;

use trust_core::{
    GuidePath, PathFrontend, PathQuery, PlanError, Rng, Scene, SearchResult, SearchStats,
};

use crate::prm::check_or_trivial_answer;

/// Baseline 1 as a [`PathFrontend`] (`"straight-line"`): one path `[start, end]` where `end` is the goal
/// if it lies within `T_h·v_max`, else the point at that distance toward the goal (which lies on the
/// goal guidance surface of DEV-PRM). Obstacles are deliberately ignored: the trajectory backend must
/// find its way from this initial guess alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct StraightLine;

/// The end of the straight guide (defined in `trust-core`, shared with the manager's fallback
/// guide).
pub use trust_core::straight_end;

impl PathFrontend for StraightLine {
    fn name(&self) -> &str {
        "straight-line"
    }

    fn search(
        &self,
        query: &PathQuery,
        scene: &Scene<'_>,
        _rng: &mut Rng,
    ) -> Result<SearchResult, PlanError> {
        let since = Instant::now();
        if let Some(answer) = check_or_trivial_answer(query, scene, since)? {
            return Ok(answer);
        }
        let start = query.start.p;
        let reach = query.horizon_s * query.limits.v_max;
        let end = straight_end(&start, &query.goal, reach);
        Ok(SearchResult {
            paths: vec![GuidePath::new(vec![start, end])?],
            stats: SearchStats {
                elapsed: since.elapsed(),
                ..SearchStats::default()
            },
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use trust_core::Vec3;

    #[test]
    fn truncates_to_the_reach() {
        let s = Vec3::zeros();
        let g = Vec3::new(30.0, 40.0, 0.0);
        assert_relative_eq!(straight_end(&s, &g, 10.0), Vec3::new(6.0, 8.0, 0.0));
        assert_eq!(straight_end(&s, &g, 100.0), g);
        assert_eq!(straight_end(&s, &s, 10.0), s);
    }
}
