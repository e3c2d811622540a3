//! The ids of new poses ([`next_pose_ids`]).

/// `n` new pose ids that continue `taken` (the ids of the poses already measured): on from
/// the largest whole-number id (`61`, `62`, … after `1` … `60`), or from `taken.len()` when
/// that is larger (ids that are not numbers), never an id already taken.
pub fn next_pose_ids(taken: &[String], n: usize) -> Vec<String> {
    let largest = taken
        .iter()
        .filter_map(|id| id.parse::<u64>().ok())
        .max()
        .unwrap_or(0)
        .max(taken.len() as u64);
    (largest + 1..)
        .map(|k| k.to_string())
        .filter(|id| !taken.contains(id))
        .take(n)
        .collect()
}
