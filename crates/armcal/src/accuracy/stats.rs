//! Summary statistics of absolute errors: count, mean, RMS, maximum, 95th percentile. The
//! figures of every accuracy statement (held-out validation, TCP errors, accuracy reports).

use serde::{Deserialize, Serialize};

/// Summary statistics of absolute errors (mm).
#[derive(Clone, Debug, Default, Serialize, Deserialize)]
pub struct ErrorStats {
    /// Number of values.
    pub count: usize,
    /// Mean of |e| (mm).
    pub mean: f64,
    /// Root mean square √(Σe²/n) (mm).
    pub rms: f64,
    /// Largest |e| (mm).
    pub max: f64,
    /// 95th percentile of |e|, linear interpolation between order statistics (mm).
    pub p95: f64,
}

impl ErrorStats {
    /// Statistics of the absolute values of `values`; all zero for an empty slice.
    pub fn of(values: &[f64]) -> ErrorStats {
        if values.is_empty() {
            return ErrorStats::default();
        }
        let mut v: Vec<f64> = values.iter().map(|x| x.abs()).collect();
        v.sort_by(f64::total_cmp);
        let n = v.len() as f64;
        // 95th percentile by linear interpolation between order statistics.
        let pos = 0.95 * (n - 1.0);
        let (lo, hi) = (pos.floor() as usize, pos.ceil() as usize);
        let p95 = v[lo] + (v[hi] - v[lo]) * (pos - lo as f64);
        ErrorStats {
            count: v.len(),
            mean: v.iter().sum::<f64>() / n,
            rms: (v.iter().map(|x| x * x).sum::<f64>() / n).sqrt(),
            max: v[v.len() - 1],
            p95,
        }
    }
}
