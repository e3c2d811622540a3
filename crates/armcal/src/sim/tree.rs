//! A virtual kinematic tree measured by a virtual instrument (issue 32): what `armcal
//! simulate` makes of a tree cell, so users and tests can make tree data.

use super::{add_noise, perturbed_registry, Perturbation, Simulation, TruthRecord};
use crate::measure::{Dataset, Measurement, NoiseModel};
use crate::model::identifiability::{IdentifiabilitySettings, Measurement as Measured};
use crate::model::tree::identifiability::analyze_tree;
use crate::model::tree::kinematics::{branch_kinematics, tree_observed_pose, TreeData};
use crate::model::tree::Tree;
use crate::model::{Observed, ParameterStatus};
use crate::Error;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

/// Measures the poses `(id, q)` (every tree joint that is not coupled; the coupled ones
/// follow their couplings) on a tree perturbed from `tree`'s nominal values: the parameters
/// the tree identifies from `measured` at random configurations ([`analyze_tree`]), or
/// every parameter with `perturbation.all`, each by its kind's σ (as
/// [`super::perturbed_truth`], seed `seed`). Each pose measures every target in `targets`
/// (tree target indices; empty: every target, as an instrument that sees every branch's
/// reflector): a frame target its pose (unless `measured` is position), a point its
/// position, with `noise` (seed `seed + 0x5eed`; `None`: noise-free).
pub fn simulate_tree(
    tree: &Tree,
    measured: Measured,
    noise: Option<&NoiseModel>,
    poses: &[(String, Vec<f64>)],
    targets: &[usize],
    perturbation: &Perturbation,
    seed: u64,
) -> Result<Simulation, Error> {
    if let Some(&t) = targets.iter().find(|&&t| t >= tree.targets.len()) {
        return Err(Error::Input(format!(
            "tree `{}` has {} targets; there is no target {t}",
            tree.name,
            tree.targets.len()
        )));
    }
    let targets: Vec<usize> = if targets.is_empty() {
        (0..tree.targets.len()).collect()
    } else {
        targets.to_vec()
    };
    let mut registry = tree.registry.clone();
    if !perturbation.all {
        let generic = analyze_tree(
            tree,
            &tree.nominal(),
            None,
            &IdentifiabilitySettings {
                measurement: measured,
                ..Default::default()
            },
        )?;
        for i in 0..registry.len() {
            let free = generic.identifiable.contains(&registry.get(i).name);
            registry.set_status(
                i,
                if free {
                    ParameterStatus::Free
                } else {
                    ParameterStatus::Fixed
                },
            );
        }
    }
    let truth = perturbed_registry(&registry, perturbation, seed);
    let mut rng = ChaCha8Rng::seed_from_u64(seed.wrapping_add(0x5eed));
    let unit_normal = Normal::new(0.0, 1.0).expect("valid normal");
    let mut data = Dataset {
        source: format!("simulation (seed {seed})"),
        ..Default::default()
    };
    let mut fk = TreeData::new(tree);
    for (id, q) in poses {
        if q.len() != tree.dof() || q.iter().any(|x| !x.is_finite()) {
            return Err(Error::Input(format!(
                "pose `{id}`: tree `{}` has {} joints; the pose has {} values or a non-finite one",
                tree.name,
                tree.dof(),
                q.len()
            )));
        }
        let config = data.push_configuration(id.clone(), q.clone());
        for &t in &targets {
            let (_, b, k) = tree.targets[t];
            branch_kinematics(tree, &mut fk, b, &truth, q);
            let pose = tree_observed_pose(tree, &fk, t);
            let frame = tree.branches[b].model.target_is_frame(k) && measured != Measured::Position;
            let mut m = Measurement::simulated(config, Observed::Target(t), pose, frame);
            if let Some(noise) = noise {
                add_noise(&mut m, noise, &mut || unit_normal.sample(&mut rng))?;
            }
            data.measurements.push(m);
        }
    }
    Ok(Simulation {
        data,
        truth: TruthRecord::of_registry(&tree.name, &tree.registry, &truth, seed),
    })
}
