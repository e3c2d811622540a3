//! Decimation of per-measurement plots: a figure of 10⁵ measurements would be tens of MB
//! of SVG that no screen can show. [`envelope`] keeps, for each of consecutive equal groups
//! of points, the one with the smallest and the one with the largest value (the "min–max"
//! decimation of time-series plotting), so the outline of the plot, every extreme and
//! every isolated spike stay; the choice depends only on the data (deterministic).

/// At most this many points are drawn per series of a per-measurement figure.
pub const MAX_POINTS: usize = 2000;

/// The points of `points` (in order) a plot of at most `max` points draws: all of them if
/// there are at most `max`, otherwise the smallest and largest `y` of each of `max / 2`
/// consecutive groups, in their original order (the global minimum and maximum among
/// them).
pub fn envelope(points: &[(f64, f64)], max: usize) -> Vec<(f64, f64)> {
    let groups = (max / 2).max(1);
    if points.len() <= max.max(1) {
        return points.to_vec();
    }
    let mut kept = Vec::with_capacity(2 * groups);
    for g in 0..groups {
        let (lo, hi) = (g * points.len() / groups, (g + 1) * points.len() / groups);
        let group = &points[lo..hi];
        let (mut imin, mut imax) = (0, 0);
        for (i, p) in group.iter().enumerate() {
            if p.1 < group[imin].1 {
                imin = i;
            }
            if p.1 > group[imax].1 {
                imax = i;
            }
        }
        kept.push(group[imin.min(imax)]);
        if imin != imax {
            kept.push(group[imin.max(imax)]);
        }
    }
    kept
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn envelope_keeps_extremes_spikes_and_order() {
        let n = 100_000;
        let mut pts: Vec<(f64, f64)> = (0..n)
            .map(|i| (i as f64, ((i * 7919) % 1000) as f64 / 1000.0))
            .collect();
        pts[31_415].1 = 50.0; // a spike
        pts[77_777].1 = -20.0; // a dip
        let kept = envelope(&pts, MAX_POINTS);
        assert!(kept.len() <= MAX_POINTS);
        assert!(kept.contains(&pts[31_415]) && kept.contains(&pts[77_777]));
        assert!(kept.windows(2).all(|w| w[0].0 < w[1].0), "in order");
        // Every group's range is kept: each drawn value lies within the data's range and
        // the y range of the plot is the data's.
        let ymax = kept.iter().map(|p| p.1).fold(f64::MIN, f64::max);
        let ymin = kept.iter().map(|p| p.1).fold(f64::MAX, f64::min);
        assert_eq!((ymin, ymax), (-20.0, 50.0));
        assert_eq!(envelope(&pts[..10], MAX_POINTS), pts[..10].to_vec());
    }
}
