//! Sampling of joint configurations: seeded, uniform within the joint limits. Used to
//! build design candidate pools, identifiability analyses, simulations and tests.

use crate::model::chain::Model;
use crate::model::link::Joint;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Uniform random configurations within the joint limits (seeded).
pub fn random_configurations(model: &Model, n: usize, seed: u64) -> Vec<Vec<f64>> {
    random_joint_values(&model.joints, n, seed)
}

/// Uniform random values of `joints` within their limits (seeded): `n` configurations
/// (a tree's joints, [`crate::model::tree::Tree::joints`], as a chain's).
pub(crate) fn random_joint_values(joints: &[Joint], n: usize, seed: u64) -> Vec<Vec<f64>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| {
            joints
                .iter()
                .map(|j| {
                    if j.upper > j.lower {
                        rng.random_range(j.lower..j.upper)
                    } else {
                        j.lower
                    }
                })
                .collect()
        })
        .collect()
}
