//! Forward kinematics at fixed parameters for what moves with the joints only: the pose of
//! every frame and target, and the world twist and axis point of every joint. Each run of
//! factors without a joint is multiplied out once per parameter vector, so an evaluation
//! costs one pose product per run and one factor per joint, where [`forward_kinematics`]
//! applies every factor and records every parameter's twist. The planner's constraints
//! (incidence, capsule distances and their joint gradients) need nothing more, and are
//! evaluated at the nominal parameters for every configuration the design visits.

use crate::model::chain::{Model, Step};
use crate::model::kinematics::{apply_step, forward_kinematics, Data};
use crate::model::pose::Pose;

/// One operation of a compiled step list.
#[derive(Clone, Debug)]
enum Op {
    /// Multiply by a constant pose (a run of factors without a joint).
    Fixed(Pose<f64>),
    /// Apply the factor of this index in the list (it has a joint).
    Joint(usize),
    /// The chain frame of this link is complete: record it.
    Frame(usize),
}

/// The model's step lists compiled at one parameter vector and station (rebuilt when
/// either changes), with a scratch [`Data`] for building.
#[derive(Clone, Debug)]
pub struct FixedKinematics {
    /// Bits of the parameters and the station the compilation holds; empty before the
    /// first.
    key: Vec<u64>,
    station: usize,
    instrument: Pose<f64>,
    chain: Vec<Op>,
    targets: Vec<Vec<Op>>,
    scratch: Data<f64>,
}

impl FixedKinematics {
    /// Empty buffers for `model` (compiled on first use).
    pub fn new(model: &Model) -> Self {
        FixedKinematics {
            key: Vec::new(),
            station: 0,
            instrument: Pose::identity(),
            chain: Vec::new(),
            targets: vec![Vec::new(); model.targets.len()],
            scratch: Data::without_corrections(model),
        }
    }

    /// Compiles the step lists at `params` and `station` unless they are the ones held.
    fn prepare(&mut self, model: &Model, params: &[f64], station: usize) {
        let same = self.station == station
            && self.key.len() == params.len()
            && self.key.iter().zip(params).all(|(k, p)| *k == p.to_bits());
        if same {
            return;
        }
        self.key.clear();
        self.key.extend(params.iter().map(|p| p.to_bits()));
        self.station = station;
        // The instrument pose does not depend on q: the full pass at q = 0 gives it.
        self.scratch.station = station;
        forward_kinematics(model, &mut self.scratch, params, &vec![0.0; model.dof()]);
        self.instrument = self.scratch.instrument;
        let ends = &model.chain_step_end;
        self.chain = compile(&model.chain_steps, params, &mut self.scratch, |i| {
            (0..ends.len()).filter(move |&l| ends[l] == i)
        });
        for (ops, steps) in self.targets.iter_mut().zip(&model.target_steps) {
            *ops = compile(steps, params, &mut self.scratch, |_| 0..0);
        }
    }
}

/// The operations of `steps`: runs of joint-free factors multiplied out, joint factors kept,
/// and a frame record after step `i` for every link `frames_after(i + 1)` lists (the
/// records at 0, before any step, come first).
fn compile<I: Iterator<Item = usize>>(
    steps: &[Step],
    params: &[f64],
    scratch: &mut Data<f64>,
    frames_after: impl Fn(usize) -> I,
) -> Vec<Op> {
    let mut ops: Vec<Op> = frames_after(0).map(Op::Frame).collect();
    let mut run: Option<Pose<f64>> = None;
    for (i, step) in steps.iter().enumerate() {
        let joint = match step {
            Step::Elementary { joint, .. } | Step::Screw { joint, .. } => joint.is_some(),
        };
        if joint {
            ops.extend(run.take().map(Op::Fixed));
            ops.push(Op::Joint(i));
        } else {
            let pose = run.get_or_insert_with(Pose::identity);
            apply_step(step, pose, params, &[], scratch);
        }
        let mut frames = frames_after(i + 1).peekable();
        if frames.peek().is_some() {
            ops.extend(run.take().map(Op::Fixed));
            ops.extend(frames.map(Op::Frame));
        }
    }
    ops.extend(run.take().map(Op::Fixed));
    ops
}

/// Applies compiled operations to `pose`, recording frames and joint twists in `data`.
fn run(
    ops: &[Op],
    steps: &[Step],
    pose: &mut Pose<f64>,
    params: &[f64],
    q: &[f64],
    data: &mut Data<f64>,
) {
    for op in ops {
        match op {
            Op::Fixed(p) => *pose = pose.compose(p),
            Op::Joint(i) => apply_step(&steps[*i], pose, params, q, data),
            Op::Frame(l) => data.frames[*l] = *pose,
        }
    }
}

/// Fills `data`'s instrument pose, chain frames, targets, joint twists and joint points at
/// parameters `params` and joints `q` (at `data.station`), as [`forward_kinematics`] does;
/// the parameter twists and rates are NOT computed (they keep stale values). A model with
/// joint corrections (compliance, periodic errors) takes the full [`forward_kinematics`].
pub fn fixed_forward_kinematics(
    model: &Model,
    fixed: &mut FixedKinematics,
    data: &mut Data<f64>,
    params: &[f64],
    q: &[f64],
) {
    if data.corrections.is_some() {
        forward_kinematics(model, data, params, q);
        return;
    }
    fixed.prepare(model, params, data.station);
    data.instrument = fixed.instrument;
    let mut pose = Pose::identity();
    run(&fixed.chain, &model.chain_steps, &mut pose, params, q, data);
    let tool = *data.tool();
    for (k, (ops, steps)) in fixed.targets.iter().zip(&model.target_steps).enumerate() {
        let mut pose = tool;
        run(ops, steps, &mut pose, params, q, data);
        data.targets[k] = pose;
    }
}
