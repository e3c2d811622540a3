//! Forward kinematics with the world twist of every parameter and joint (book §2.4–2.5:
//! the differential change of the end pose caused by a change in one link parameter is a
//! differential transformation about that parameter's axis). One pass over the chain gives
//! the pose of every frame and all the data the analytic Jacobians need.

use crate::model::chain::{Model, Step};
use crate::model::joint_correction::CorrectionData;
use crate::model::link::Motion;
use crate::model::pose::{rot_axis, Pose, Twist};
use crate::Error;
use nalgebra::{convert, RealField, Vector3};

/// Reusable buffers for one evaluation of a [`Model`] (pinocchio's `Data`). Generic over
/// the scalar so dual numbers can flow through the same code.
#[derive(Clone, Debug)]
pub struct Data<T: RealField + Copy> {
    /// The station whose instrument pose [`forward_kinematics`] takes (an index into
    /// [`Model::stations`]; 0 by default, and the only one without stations).
    pub station: usize,
    /// The payload the robot carries (an index into [`Model::payloads`]; `None` by default):
    /// with compliance, its gravity torque deflects the joints
    /// ([`crate::model::compliance`]).
    pub payload: Option<usize>,
    /// Pose of the instrument frame in the world (at `station`).
    pub instrument: Pose<T>,
    /// World pose at the end of each chain link (base, links, tool).
    pub frames: Vec<Pose<T>>,
    /// World pose of each target.
    pub targets: Vec<Pose<T>>,
    /// For every parameter, the world-frame twist caused by a unit change of it.
    pub param_twists: Vec<Twist<T>>,
    /// For every joint, the world-frame twist caused by a unit change of its variable.
    pub joint_twists: Vec<Twist<T>>,
    /// For every parameter, the derivative of its world twist w.r.t. the angle (or
    /// displacement) φ of its own factor. Only zero-reference screws have one (their
    /// axis-direction and axis-point twists turn with φ, see `apply_screw`); every other
    /// parameter's twist is taken before its factor acts and its entry stays zero.
    pub param_twist_rates: Vec<Twist<T>>,
    /// For every joint, the point where the chain reaches its axis (the frame origin before a
    /// DH/MDH joint factor, a zero-reference screw's axis point), world frame (mm): where
    /// [`crate::model::compliance`] puts its point masses.
    pub joint_points: Vec<Vector3<T>>,
    /// The joint-space corrections (compliance, periodic errors;
    /// `crate::model::joint_correction`) and the corrected joints; `None` without them.
    /// `joint_twists` are then the twists of the corrected joints `q + Δq`.
    pub corrections: Option<Box<CorrectionData<T>>>,
    /// Per parameter of a constant elementary rotation (no joint): the parameter value (its
    /// bits) and the sine and cosine last computed for it. A model evaluated at fixed
    /// parameters (the planner, every row of one identification iteration) then computes
    /// the sines and cosines of its joints only; a changed value is recomputed.
    rotation_memo: Vec<Option<(u64, T, T)>>,
}

impl<T: RealField + Copy> Data<T> {
    /// Buffers sized for `model`, every pose the identity and every twist zero.
    pub fn new(model: &Model) -> Self {
        let mut data = Self::without_corrections(model);
        data.corrections = CorrectionData::new(model).map(Box::new);
        data
    }

    /// Buffers for the chain alone, with no joint corrections (the compliance's lever pass).
    pub(crate) fn without_corrections(model: &Model) -> Self {
        Data {
            station: 0,
            payload: None,
            instrument: Pose::identity(),
            frames: vec![Pose::identity(); model.links.len()],
            targets: vec![Pose::identity(); model.targets.len()],
            param_twists: vec![Twist::zero(); model.param_count()],
            joint_twists: vec![Twist::zero(); model.dof()],
            param_twist_rates: vec![Twist::zero(); model.param_count()],
            joint_points: vec![Vector3::zeros(); model.dof()],
            corrections: None,
            rotation_memo: vec![None; model.param_count()],
        }
    }

    /// World pose of the tool frame (the end of the chain).
    pub fn tool(&self) -> &Pose<T> {
        self.frames.last().expect("a model has at least one link")
    }
}

/// Evaluates the model at parameters `params` (internal units) and joints `q`, filling
/// `data` with every frame pose and every parameter and joint twist. A model with joint
/// corrections (`crate::model::joint_correction`: compliance, periodic errors) first
/// computes them at `q`, then evaluates the chain at the corrected joints `q + Δq`.
/// Allocates nothing.
pub fn forward_kinematics<T: RealField + Copy>(
    model: &Model,
    data: &mut Data<T>,
    params: &[f64],
    q: &[T],
) {
    debug_assert_eq!(params.len(), model.param_count());
    debug_assert_eq!(q.len(), model.dof());
    match data.corrections.take() {
        Some(mut state) => {
            state.evaluate(model, params, q, data.payload);
            chain_pass(model, data, params, &state.q);
            state.set_twists(
                model,
                &mut data.param_twists,
                &data.joint_twists,
                &mut data.param_twist_rates,
            );
            data.corrections = Some(state);
        }
        None => chain_pass(model, data, params, q),
    }
}

/// One pass over instrument, chain and targets at joints `q` (no joint corrections).
fn chain_pass<T: RealField + Copy>(model: &Model, data: &mut Data<T>, params: &[f64], q: &[T]) {
    let mut pose = Pose::identity();
    let steps = match model.station_steps.get(data.station) {
        Some(steps) => {
            // only this station's instrument parameters move what it measures
            for l in &model.stations {
                let first = l.first_param;
                data.param_twists[first..first + l.param_count()].fill(Twist::zero());
            }
            steps
        }
        None => &model.instrument_steps,
    };
    for step in steps {
        apply_step(step, &mut pose, params, q, data);
    }
    data.instrument = pose;

    let mut pose = Pose::identity();
    let mut link = 0;
    for (i, step) in model.chain_steps.iter().enumerate() {
        apply_step(step, &mut pose, params, q, data);
        while link < model.chain_step_end.len() && model.chain_step_end[link] == i + 1 {
            data.frames[link] = pose;
            link += 1;
        }
    }
    // Links without steps cannot exist (every convention has at least one field), but keep
    // the frames consistent anyway.
    while link < model.chain_step_end.len() {
        data.frames[link] = pose;
        link += 1;
    }
    let tool = pose;
    for (k, steps) in model.target_steps.iter().enumerate() {
        let mut pose = tool;
        for step in steps {
            apply_step(step, &mut pose, params, q, data);
        }
        data.targets[k] = pose;
    }
}

/// Convenience: world pose of the tool frame at `q` with the given parameters.
pub fn tool_pose(model: &Model, params: &[f64], q: &[f64]) -> Pose<f64> {
    let mut data = Data::new(model);
    forward_kinematics(model, &mut data, params, q);
    *data.tool()
}

/// The tool frame's world pose at every configuration of `configurations` (internal units:
/// rad, mm) with the parameters `params`, as 4×4 homogeneous matrices (translation in mm):
/// `T(q) = B · ∏ A_i(q_i) · E`, base, links and tool multiplied out (book ch. 2; the chain
/// of [`forward_kinematics`], the pose [`tool_pose`] gives). A row of
/// the wrong length or with a non-finite value is an error naming the row (1-based); joint
/// limits are not checked (the pose is defined anywhere).
///
/// ```
/// let cell = armcal::cell::builtin::paper_cell()?;
/// let model = &cell.model;
/// let q = vec![0.1, -0.2, 0.3, 0.0, 0.4, 0.0];
/// let t = armcal::fk(model, &model.nominal(), &[q.clone(), q])?;
/// assert_eq!(t.len(), 2);
/// assert_eq!(t[0], t[1]);
/// let p = armcal::model::tool_pose(model, &model.nominal(), &[0.1, -0.2, 0.3, 0.0, 0.4, 0.0]);
/// assert_eq!(t[0].fixed_view::<3, 1>(0, 3), p.trans);
/// assert_eq!(t[0][(3, 3)], 1.0);
/// let e = armcal::fk(model, &model.nominal(), &[vec![0.0; 5]]).unwrap_err();
/// assert!(e.to_string().starts_with("configuration 1:"), "{e}");
/// # Ok::<(), armcal::Error>(())
/// ```
pub fn fk(
    model: &Model,
    params: &[f64],
    configurations: &[Vec<f64>],
) -> Result<Vec<nalgebra::Matrix4<f64>>, Error> {
    if params.len() != model.registry.len() {
        return Err(Error::Input(format!(
            "model `{}` has {} parameters, got {}",
            model.name,
            model.registry.len(),
            params.len()
        )));
    }
    let mut data = Data::new(model);
    configurations
        .iter()
        .enumerate()
        .map(|(i, q)| {
            if q.len() != model.dof() || q.iter().any(|v| !v.is_finite()) {
                return Err(Error::Input(format!(
                    "configuration {}: {} finite joint values expected (rad, mm), got {:?}",
                    i + 1,
                    model.dof(),
                    q
                )));
            }
            forward_kinematics(model, &mut data, params, q);
            Ok(nalgebra::Matrix4::from(data.tool().to_matrix()).transpose())
        })
        .collect()
}

#[inline]
fn lift<T: RealField + Copy>(x: f64) -> T {
    convert(x)
}

/// Multiplies `pose` by one elementary factor or screw and records the twists of the
/// factor's parameter(s) and joint.
#[inline]
pub(crate) fn apply_step<T: RealField + Copy>(
    step: &Step,
    pose: &mut Pose<T>,
    params: &[f64],
    q: &[T],
    data: &mut Data<T>,
) {
    match step {
        Step::Elementary {
            motion,
            param,
            joint,
            axis,
        } => {
            let mut value: T = lift(params[*param]);
            if let Some(j) = joint {
                value += q[*j];
            }
            let world_axis = match motion {
                Motion::Rx | Motion::Tx => pose.rot.column(0).into_owned(),
                Motion::Ry | Motion::Ty => pose.rot.column(1).into_owned(),
                Motion::Rz | Motion::Tz => pose.rot.column(2).into_owned(),
                Motion::RotAxis | Motion::TransAxis => pose.rot * axis.map(lift::<T>),
            };
            let twist = match motion {
                Motion::Rx | Motion::Ry | Motion::Rz | Motion::RotAxis => Twist {
                    w: world_axis,
                    v: pose.trans.cross(&world_axis),
                },
                _ => Twist {
                    w: Vector3::zeros(),
                    v: world_axis,
                },
            };
            data.param_twists[*param] = twist;
            if let Some(j) = joint {
                data.joint_twists[*j] = twist;
                data.joint_points[*j] = pose.trans;
            }
            let mut sin_cos = || match joint {
                Some(_) => value.sin_cos(),
                None => memoized_sin_cos(&mut data.rotation_memo[*param], params[*param], value),
            };
            match motion {
                Motion::Rx => rotate_columns(pose, 1, 2, sin_cos()),
                Motion::Ry => rotate_columns(pose, 2, 0, sin_cos()),
                Motion::Rz => rotate_columns(pose, 0, 1, sin_cos()),
                Motion::RotAxis => pose.rot *= rot_axis(&axis.map(lift::<T>), value),
                _ => pose.trans += world_axis * value,
            }
        }
        Step::Screw {
            first,
            joint,
            prismatic,
        } => apply_screw(*first, *joint, *prismatic, pose, params, q, data),
    }
}

/// `(sin, cos)` of the constant angle `value` (= `key` lifted), from `memo` when it holds
/// them for `key`, else computed and kept.
#[inline]
fn memoized_sin_cos<T: RealField + Copy>(
    memo: &mut Option<(u64, T, T)>,
    key: f64,
    value: T,
) -> (T, T) {
    let bits = key.to_bits();
    match *memo {
        Some((k, s, c)) if k == bits => (s, c),
        _ => {
            let (s, c) = value.sin_cos();
            *memo = Some((bits, s, c));
            (s, c)
        }
    }
}

/// Right-multiplies the rotation by an elementary rotation of angle θ given as
/// `(sin θ, cos θ)`: columns `a`, `b` turn in their plane (`Rx`: y,z; `Ry`: z,x; `Rz`: x,y).
#[inline]
fn rotate_columns<T: RealField + Copy>(pose: &mut Pose<T>, a: usize, b: usize, (s, c): (T, T)) {
    let ca = pose.rot.column(a).into_owned();
    let cb = pose.rot.column(b).into_owned();
    pose.rot.set_column(a, &(ca * c + cb * s));
    pose.rot.set_column(b, &(cb * c - ca * s));
}

/// Zero-reference screw `T(p) Rot(û, φ) T(−p)`, φ = offset + q, û = u/|u| (book eq. 2.70).
/// Parameter twists in the screw's input frame:
/// - offset (and joint): `(û, p × û)`;
/// - `u_k`: `ω = sin φ dû + (1 − cos φ) û × dû`, `v = p × ω` with `dû = (e_k − û û_k)/|u|`
///   (the left Jacobian of SO(3) applied to `φ dû`);
/// - `p_k`: `(0, e_k − Rot e_k)`.
///
/// Prismatic: `T(û φ)`; offset `(0, û)`, `u_k` `(0, φ dû)`, `p` has no effect.
///
/// Their derivatives w.r.t. φ (into `param_twist_rates`): `u_k`:
/// `ω' = cos φ dû + sin φ û × dû`, `v' = p × ω'` (prismatic: `(0, dû)`); `p_k`:
/// `(0, −û × Rot e_k)`; the offset twist does not depend on φ.
fn apply_screw<T: RealField + Copy>(
    first: usize,
    joint: Option<usize>,
    prismatic: bool,
    pose: &mut Pose<T>,
    params: &[f64],
    q: &[T],
    data: &mut Data<T>,
) {
    let u = Vector3::new(params[first], params[first + 1], params[first + 2]);
    let norm = u.norm();
    let uh: Vector3<T> = (u / norm).map(lift::<T>);
    let p: Vector3<T> =
        Vector3::new(params[first + 3], params[first + 4], params[first + 5]).map(lift::<T>);
    let mut phi: T = lift(params[first + 6]);
    if let Some(j) = joint {
        phi += q[j];
    }
    let inv_norm: T = lift(1.0 / norm);
    let du = |k: usize| -> Vector3<T> {
        let mut e = Vector3::zeros();
        e[k] = T::one();
        (e - uh * uh[k]) * inv_norm
    };
    if prismatic {
        let offset = pose.adjoint(&Twist {
            w: Vector3::zeros(),
            v: uh,
        });
        data.param_twists[first + 6] = offset;
        if let Some(j) = joint {
            data.joint_twists[j] = offset;
            data.joint_points[j] = pose.transform_point(&p);
        }
        for k in 0..3 {
            let d = du(k);
            data.param_twists[first + k] = pose.adjoint(&Twist {
                w: Vector3::zeros(),
                v: d * phi,
            });
            data.param_twist_rates[first + k] = pose.adjoint(&Twist {
                w: Vector3::zeros(),
                v: d,
            });
            data.param_twists[first + 3 + k] = Twist::zero();
        }
        pose.trans += pose.rot * (uh * phi);
        return;
    }
    let rot = rot_axis(&uh, phi);
    let (s, c) = phi.sin_cos();
    let offset = pose.adjoint(&Twist {
        w: uh,
        v: p.cross(&uh),
    });
    data.param_twists[first + 6] = offset;
    if let Some(j) = joint {
        data.joint_twists[j] = offset;
        data.joint_points[j] = pose.transform_point(&p);
    }
    for k in 0..3 {
        let d = du(k);
        let w = d * s + uh.cross(&d) * (T::one() - c);
        data.param_twists[first + k] = pose.adjoint(&Twist { w, v: p.cross(&w) });
        let w_rate = d * c + uh.cross(&d) * s;
        data.param_twist_rates[first + k] = pose.adjoint(&Twist {
            w: w_rate,
            v: p.cross(&w_rate),
        });
        let mut e = Vector3::zeros();
        e[k] = T::one();
        data.param_twists[first + 3 + k] = pose.adjoint(&Twist {
            w: Vector3::zeros(),
            v: e - rot.column(k),
        });
        data.param_twist_rates[first + 3 + k] = pose.adjoint(&Twist {
            w: Vector3::zeros(),
            v: -uh.cross(&rot.column(k)),
        });
    }
    let local = Pose {
        rot,
        trans: p - rot * p,
    };
    *pose = pose.compose(&local);
}
