//! ISO 9283 pose accuracy and repeatability from repeated approaches.
//!
//! A virtual robot approaches five poses 30 times each; its tool lands with a small random
//! scatter around where its true (perturbed) kinematics put it. ISO 9283 §7.2.1 position
//! accuracy AP_P is the distance of the barycentre of the attained positions from the
//! commanded position, and §7.2.2 repeatability RP_l = l̄ + 3 S_l.
//!
//! Run: `cargo run --release -p armcal --example accuracy_iso9283`
//! (the same figures as `armcal accuracy`; guide: "Accuracy (ISO 9283)").

use armcal::model::{random_configurations, tool_pose};
use armcal::nalgebra::Vector3;
use armcal::{perturbed_truth, position_accuracy, position_repeatability, Perturbation};
use rand::SeedableRng;
use rand_distr::{Distribution, Normal};

fn main() -> armcal::Result<()> {
    let cell = armcal::cell::builtin::paper_cell()?;
    let model = &cell.model;
    let nominal = model.nominal();
    let truth = perturbed_truth(model, &Perturbation::default(), 21);
    // Repeatability scatter of the virtual robot: 20 µm per axis.
    let scatter = Normal::new(0.0, 0.020).expect("a valid σ");
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    for (k, q) in random_configurations(model, 5, 9).iter().enumerate() {
        let commanded = tool_pose(model, &nominal, q).trans;
        let attained_mean = tool_pose(model, &truth, q).trans;
        let attained: Vec<Vector3<f64>> = (0..30)
            .map(|_| attained_mean + Vector3::from_fn(|_, _| scatter.sample(&mut rng)))
            .collect();
        let (Some(ap), Some(rp)) = (
            position_accuracy(&commanded, &attained),
            position_repeatability(&attained),
        ) else {
            continue;
        };
        println!(
            "pose P{}: AP_P {:.3} mm, RP_l {:.4} mm",
            k + 1,
            ap.ap,
            rp.rp
        );
    }
    Ok(())
}
