//! ISO 9283 position accuracy AP and position repeatability RP (ISO 9283:1998 §7.2; book
//! ch. 7) from repeated measurements of one commanded pose.

use nalgebra::Vector3;
use serde::{Deserialize, Serialize};

/// Position repeatability of `n` attained positions of one commanded pose:
/// barycentre x̄, distances `l_j = |x_j − x̄|`, `l̄ = mean l_j`,
/// `S_l = √(Σ(l_j − l̄)²/(n − 1))`, and `RP = l̄ + 3 S_l`.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Repeatability {
    /// Number of attained positions `n`.
    pub n: usize,
    /// Barycentre x̄ of the attained positions (mm, measurement frame).
    pub barycentre: Vector3<f64>,
    /// Mean distance l̄ of the positions from the barycentre (mm).
    pub mean_distance: f64,
    /// Sample standard deviation S_l of those distances, with `n − 1` (mm).
    pub std_distance: f64,
    /// RP = l̄ + 3 S_l (mm).
    pub rp: f64,
}

/// ISO 9283 RP. `None` for fewer than two positions.
pub fn position_repeatability(points: &[Vector3<f64>]) -> Option<Repeatability> {
    let n = points.len();
    if n < 2 {
        return None;
    }
    let bary = points.iter().fold(Vector3::zeros(), |a, p| a + p) / n as f64;
    let l: Vec<f64> = points.iter().map(|p| (p - bary).norm()).collect();
    let mean = l.iter().sum::<f64>() / n as f64;
    let s = (l.iter().map(|x| (x - mean).powi(2)).sum::<f64>() / (n as f64 - 1.0)).sqrt();
    Some(Repeatability {
        n,
        barycentre: bary,
        mean_distance: mean,
        std_distance: s,
        rp: mean + 3.0 * s,
    })
}

/// Position accuracy: `AP = |x̄ − x_c|` with components, between the barycentre of the
/// attained positions and the commanded position.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Accuracy {
    /// AP = |x̄ − x_c| (mm).
    pub ap: f64,
    /// x component of x̄ − x_c (mm).
    pub apx: f64,
    /// y component of x̄ − x_c (mm).
    pub apy: f64,
    /// z component of x̄ − x_c (mm).
    pub apz: f64,
}

/// ISO 9283 AP. `None` without positions.
pub fn position_accuracy(commanded: &Vector3<f64>, attained: &[Vector3<f64>]) -> Option<Accuracy> {
    if attained.is_empty() {
        return None;
    }
    let bary = attained.iter().fold(Vector3::zeros(), |a, p| a + p) / attained.len() as f64;
    let d = bary - commanded;
    Some(Accuracy {
        ap: d.norm(),
        apx: d[0],
        apy: d[1],
        apz: d[2],
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeatability_of_a_known_spread() {
        // Four points on a circle of radius 1 around (1, 2, 3): l̄ = 1, S_l = 0, RP = 1.
        let c = Vector3::new(1.0, 2.0, 3.0);
        let pts: Vec<_> = [(1.0, 0.0), (0.0, 1.0), (-1.0, 0.0), (0.0, -1.0)]
            .iter()
            .map(|&(x, y)| c + Vector3::new(x, y, 0.0))
            .collect();
        let r = position_repeatability(&pts).unwrap();
        assert!((r.rp - 1.0).abs() < 1e-12 && (r.barycentre - c).norm() < 1e-12);
        let a = position_accuracy(&Vector3::new(1.0, 2.0, 2.5), &pts).unwrap();
        assert!((a.ap - 0.5).abs() < 1e-12 && (a.apz - 0.5).abs() < 1e-12);
        assert!(position_repeatability(&pts[..1]).is_none());
    }
}
