//! The split of a data set into the configurations a fit uses and those it is validated
//! on (a seeded random holdout, or the user's own test file).

use super::held_out::held_out_errors;
use super::{
    frames_only_fit, holdout_split, residuals, AxisErrors, HeldOutAxes, HeldOutOrientation,
    IdentifySettings, Problem, Validation,
};
use crate::accuracy::ErrorStats;
use crate::measure::Dataset;
use crate::model::Model;
use crate::Error;

/// The data a fit uses and the data it is validated on: `opts.holdout` of the
/// configurations held out at random (seeded), or the whole data fitted and validated on
/// `opts.test`, or no validation. A fraction outside [0, 1), or both a fraction and test
/// data, is an error.
pub(super) struct Split<'d> {
    /// The data fitted: the whole data set (borrowed, not copied) or a training subset.
    pub(super) train: std::borrow::Cow<'d, Dataset>,
    /// Index in the data file of each training configuration.
    pub(super) train_configs: Vec<usize>,
    /// Validation data and what it is.
    pub(super) test: Option<(std::borrow::Cow<'d, Dataset>, String)>,
}

/// [`holdout_split`] of each station's configurations (in file order) with the same seed:
/// every station holds out what a fit of its data alone would (the whole data set without
/// stations).
fn holdout_split_by_station(data: &Dataset, fraction: f64, seed: u64) -> (Vec<usize>, Vec<usize>) {
    let (mut train, mut test) = (Vec::new(), Vec::new());
    for s in 0..data.stations.len().max(1) {
        let configs: Vec<usize> = (0..data.configurations.len())
            .filter(|&c| data.station_of(c) == s)
            .collect();
        let (tr, te) = holdout_split(configs.len(), fraction, seed);
        train.extend(tr.into_iter().map(|i| configs[i]));
        test.extend(te.into_iter().map(|i| configs[i]));
    }
    train.sort_unstable();
    test.sort_unstable();
    (train, test)
}

impl<'d> Split<'d> {
    pub(super) fn of(data: &'d Dataset, opts: &'d IdentifySettings) -> Result<Split<'d>, Error> {
        let h = opts.holdout;
        if !(0.0..1.0).contains(&h) {
            return Err(Error::Input(format!(
                "the holdout fraction {h} must be in [0, 1) (0: no held-out validation)"
            )));
        }
        let all: Vec<usize> = (0..data.configurations.len()).collect();
        match (&opts.test, h > 0.0) {
            (Some(_), true) => Err(Error::Input(
                "give either a holdout fraction or test data for validation, not both".into(),
            )),
            (Some(test), false) => Ok(Split {
                train: std::borrow::Cow::Borrowed(data),
                train_configs: all,
                test: Some((std::borrow::Cow::Borrowed(test), test.source.clone())),
            }),
            (None, true) => {
                let (train, test) = holdout_split_by_station(data, h, opts.seed);
                if test.is_empty() {
                    return Err(Error::Input(format!(
                        "the holdout fraction {h} of {} configurations holds out none; hold out a larger fraction",
                        all.len()
                    )));
                }
                Ok(Split {
                    train: std::borrow::Cow::Owned(data.subset(&train)),
                    train_configs: train,
                    test: Some((
                        std::borrow::Cow::Owned(data.subset(&test)),
                        format!(
                            "{} of the {} configurations of {} held out at random (seed {})",
                            test.len(),
                            all.len(),
                            data.source,
                            opts.seed
                        ),
                    )),
                })
            }
            (None, false) => Ok(Split {
                train: std::borrow::Cow::Borrowed(data),
                train_configs: all,
                test: None,
            }),
        }
    }

    /// Validation of the fit `calibrated` of `model` on the test data (`None` without).
    pub(super) fn validate(
        &self,
        model: &Model,
        calibrated: &[f64],
        opts: &IdentifySettings,
        noise: &crate::measure::NoiseModel,
    ) -> Result<Option<Validation>, Error> {
        let Some((test, source)) = &self.test else {
            return Ok(None);
        };
        let frames = frames_only_fit(model, &self.train, noise, opts)?;
        let eval = Problem::new(model, test, noise)?;
        let mut ws = eval.workspace();
        let orientation = |ws: &mut super::problem::Workspace, params: &[f64]| {
            residuals::orientation_stats(&eval, ws, params)
        };
        let orientation = match (
            orientation(&mut ws, &model.nominal()),
            orientation(&mut ws, &frames),
            orientation(&mut ws, calibrated),
        ) {
            (Some(nominal), Some(frames_only), Some(calibrated)) => Some(HeldOutOrientation {
                nominal,
                frames_only,
                calibrated,
            }),
            _ => None,
        };
        let mut axes = |params: &[f64]| {
            let xyz: Vec<[f64; 3]> = residuals::position_components(&eval, &mut ws, params)
                .into_iter()
                .flatten()
                .collect();
            AxisErrors::of(&xyz)
        };
        let per_axis = HeldOutAxes {
            nominal: axes(&model.nominal()),
            frames_only: axes(&frames),
            calibrated: axes(calibrated),
        };
        let position = eval.errors(&mut ws, calibrated);
        let errors = held_out_errors(
            test,
            &position,
            &eval.orientation_errors(&mut ws, calibrated),
        );
        Ok(Some(Validation {
            errors,
            per_axis: Some(per_axis),
            orientation,
            test_data: source.clone(),
            train_configurations: self.train.configurations.len(),
            test_configurations: test.configurations.len(),
            train_ids: self.train.config_ids.clone(),
            test_ids: test.config_ids.clone(),
            nominal: ErrorStats::of(&eval.errors(&mut ws, &model.nominal())),
            frames_only: ErrorStats::of(&eval.errors(&mut ws, &frames)),
            calibrated: ErrorStats::of(&position),
        }))
    }
}
