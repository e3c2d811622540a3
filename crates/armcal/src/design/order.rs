//! Ordering a design to shorten robot travel: the time to move between two configurations
//! is taken as the largest joint displacement (all joints move together), and the tour is
//! built by nearest neighbour from the first pose and improved by 2-opt.

/// Travel cost between two configurations: `max_j |a_j − b_j|`.
pub fn travel(a: &[f64], b: &[f64]) -> f64 {
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

/// A permutation of `qs` (open path, starting at the first configuration) with shorter
/// travel.
pub fn order_for_travel(qs: &[Vec<f64>]) -> Vec<usize> {
    let n = qs.len();
    if n < 3 {
        return (0..n).collect();
    }
    let mut order = vec![0];
    let mut used = vec![false; n];
    used[0] = true;
    for _ in 1..n {
        let last = *order.last().expect("non-empty");
        let next = (0..n)
            .filter(|&j| !used[j])
            .min_by(|&a, &b| travel(&qs[last], &qs[a]).total_cmp(&travel(&qs[last], &qs[b])))
            .expect("unused remain");
        used[next] = true;
        order.push(next);
    }
    // 2-opt on the open path.
    let mut improved = true;
    while improved {
        improved = false;
        for i in 0..n - 2 {
            for j in i + 2..n {
                let a = travel(&qs[order[i]], &qs[order[i + 1]]);
                let b = if j + 1 < n {
                    travel(&qs[order[j]], &qs[order[j + 1]])
                } else {
                    0.0
                };
                let c = travel(&qs[order[i]], &qs[order[j]]);
                let d = if j + 1 < n {
                    travel(&qs[order[i + 1]], &qs[order[j + 1]])
                } else {
                    0.0
                };
                if c + d < a + b - 1e-12 {
                    order[i + 1..=j].reverse();
                    improved = true;
                }
            }
        }
    }
    order
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Total travel of a sequence.
    fn path_length(qs: &[Vec<f64>]) -> f64 {
        qs.windows(2).map(|w| travel(&w[0], &w[1])).sum()
    }

    #[test]
    fn ordering_never_lengthens_the_path() {
        let qs: Vec<Vec<f64>> = (0..30)
            .map(|i| vec![((i * 7919) % 31) as f64, ((i * 104729) % 17) as f64])
            .collect();
        let order = order_for_travel(&qs);
        let mut sorted = order.clone();
        sorted.sort();
        assert_eq!(sorted, (0..30).collect::<Vec<_>>());
        let reordered: Vec<Vec<f64>> = order.iter().map(|&i| qs[i].clone()).collect();
        assert!(path_length(&reordered) < path_length(&qs));
    }
}
