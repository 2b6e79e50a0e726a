//! Size limits of the path engine, checked before anything is allocated so
//! that an absurd request is an error, never an abort.

/// Most points of one continuation path (`max_points`): each holds its
/// state, so 10⁵ points of 4096 unknowns are 3.3 GB; a path that needs more
/// is better cut into pieces.
pub const MAX_PATH_POINTS: usize = 100_000;

/// `None` when `max_points` fits [`MAX_PATH_POINTS`], otherwise the reason.
pub fn path_points_error(max_points: usize) -> Option<String> {
    (max_points > MAX_PATH_POINTS).then(|| {
        format!("max_points = {max_points} exceeds the limit of {MAX_PATH_POINTS} points per path")
    })
}
