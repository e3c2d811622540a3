//! Values `g(q)` and exact joint gradients of a [`ConstraintSet`] at a configuration (see
//! the [module documentation](super) for the formulas), and which constraints do not
//! depend on the configuration.

use super::*;
use crate::model::fixed_kinematics::fixed_forward_kinematics;

/// A pose read back from a design CSV (6 decimals of a degree, ±5e-7° = 8.7e-9 rad) may sit
/// that much inside the joint margin it was planned on; 1e-7 rad (6e-6°) covers it. It
/// applies to the margin only: without one the bounds are the joint limits, checked exactly.
pub const JOINT_MARGIN_TOLERANCE: f64 = 1e-7;

impl ConstraintSet {
    /// The least value constraint `i` must keep: the clearance for a distance, 0 for the
    /// incidence and for a distance that is the same at every configuration and below the
    /// clearance (exempt, see the module documentation).
    pub fn required(&self, i: usize) -> f64 {
        self.required[i]
    }

    /// Whether constraint `i` has the same value at 16 configurations spread over the joint
    /// ranges (`constraint_ranges` in `evaluate.rs`): constant, or flat where sampled.
    pub fn is_constant(&self, i: usize) -> bool {
        self.constant[i]
    }

    /// The joint bounds a configuration must keep (internal units): the limits, revolute
    /// joints shrunk by the joint margin.
    pub fn joint_bounds(&self) -> (&[f64], &[f64]) {
        (&self.lower, &self.upper)
    }

    /// Evaluates every constraint at parameters `params` (internal units, the model's full
    /// parameter vector) and joints `q`: `values[i] = g_i(q)` (≥ 0 is feasible) and, if given,
    /// `jacobian[i · dof + j] = ∂g_i/∂q_j` (row major, `len × dof`). Allocates nothing.
    ///
    /// # Panics
    /// If `params`, `q`, `values` or `jacobian` have the wrong length.
    pub fn evaluate(
        &self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
    ) {
        self.check_lengths(params, q, values, jacobian.as_deref());
        self.place(ws, params, q);
        let dof = self.dof();
        for (row, value) in values.iter_mut().enumerate() {
            let grad = jacobian
                .as_deref_mut()
                .map(|jac| &mut jac[row * dof..(row + 1) * dof]);
            *value = self.evaluate_row(ws, row, grad);
        }
    }

    /// Like [`ConstraintSet::evaluate`], but only the constraints listed in `rows`: their
    /// values (and Jacobian rows) are written at their own index of the full-length `values`
    /// (and `jacobian`); the other entries are left as they are. One forward kinematics plus
    /// the listed constraints: the cost of a projection that knows which constraints can be
    /// near their boundary.
    ///
    /// # Panics
    /// If a length is wrong or a row is out of range.
    pub fn evaluate_rows(
        &self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
        rows: &[usize],
        values: &mut [f64],
        mut jacobian: Option<&mut [f64]>,
    ) {
        self.check_lengths(params, q, values, jacobian.as_deref());
        self.place(ws, params, q);
        let dof = self.dof();
        for &row in rows {
            let grad = jacobian
                .as_deref_mut()
                .map(|jac| &mut jac[row * dof..(row + 1) * dof]);
            values[row] = self.evaluate_row(ws, row, grad);
        }
    }

    fn check_lengths(&self, params: &[f64], q: &[f64], values: &[f64], jac: Option<&[f64]>) {
        assert_eq!(params.len(), self.model.param_count(), "parameter count");
        assert_eq!(q.len(), self.dof(), "joint count");
        assert_eq!(values.len(), self.len(), "values length");
        if let Some(jac) = jac {
            assert_eq!(
                jac.len(),
                self.len() * self.dof(),
                "jacobian length (len × dof)"
            );
        }
    }

    /// Forward kinematics (frames, targets and joint twists: all the constraints read) and
    /// the world endpoints of every robot capsule at `q`; nothing when `ws` already holds
    /// them for exactly (bitwise) these `params` and `q` (a projection evaluates the values,
    /// then the Jacobian rows of the violated constraints, at one configuration).
    fn place(&self, ws: &mut ConstraintWorkspace, params: &[f64], q: &[f64]) {
        let same = |a: &[f64], b: &[f64]| a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits());
        let placed = &ws.placed;
        if placed.len() == params.len() + q.len()
            && same(&placed[params.len()..], q)
            && same(&placed[..params.len()], params)
        {
            return;
        }
        fixed_forward_kinematics(&self.model, &mut ws.fixed, &mut ws.data, params, q);
        for (c, ends) in self.capsules.iter().zip(ws.ends.iter_mut()) {
            *ends = c.place(&ws.data);
        }
        ws.placed.clear();
        ws.placed.extend_from_slice(params);
        ws.placed.extend_from_slice(q);
    }

    /// Value (and gradient) of constraint `row` at the configuration [`Self::place`]d in `ws`.
    #[inline]
    fn evaluate_row(&self, ws: &ConstraintWorkspace, row: usize, grad: Option<&mut [f64]>) -> f64 {
        let data = &ws.data;
        let ends = &ws.ends;
        let refl = match self.reflector {
            Reflector::Target(k) => &data.targets[k],
            Reflector::Tool => data.tool(),
        };
        let p = refl.trans;
        let tracker = data.instrument.trans;
        let twists = &data.joint_twists;
        match self.items[row] {
            Item::Incidence => {
                let z = refl.rot.column(2).into_owned();
                let beam = tracker - p;
                let len = beam.norm();
                let g = beam / len;
                let cos_b = z.dot(&g);
                if let Some(grad) = grad {
                    let perp = z - g * cos_b;
                    for (gj, tw) in grad.iter_mut().zip(twists) {
                        let dp = tw.point_velocity(&p);
                        *gj = tw.w.cross(&z).dot(&g) - perp.dot(&dp) / len;
                    }
                }
                cos_b - self.cos_max
            }
            Item::Pair { i, j } => {
                let (ci, cj) = (&self.capsules[i], &self.capsules[j]);
                let sd = segment_distance(&ends[i][0], &ends[i][1], &ends[j][0], &ends[j][1]);
                if let Some(grad) = grad {
                    two_point_gradient(
                        grad, twists, &sd.normal, &sd.p, ci.joints, &sd.q, cj.joints,
                    );
                }
                sd.distance - ci.radius - cj.radius
            }
            Item::Obstacle { i, o } => {
                let (ci, ob) = (&self.capsules[i], &self.obstacles[o]);
                let sd = segment_distance(&ends[i][0], &ends[i][1], &ob.a, &ob.b);
                if let Some(grad) = grad {
                    two_point_gradient(grad, twists, &sd.normal, &sd.p, ci.joints, &sd.q, 0);
                }
                sd.distance - ci.radius - ob.radius
            }
            Item::Box { i, b } => {
                let ci = &self.capsules[i];
                let sd = segment_box_distance(&ends[i][0], &ends[i][1], &self.boxes[b]);
                if let Some(grad) = grad {
                    two_point_gradient(grad, twists, &sd.normal, &sd.p, ci.joints, &sd.p, 0);
                }
                sd.distance - ci.radius
            }
            Item::HalfSpace { i, end, h } => {
                let (ci, hs) = (&self.capsules[i], &self.half_spaces[h]);
                let x = ends[i][end];
                if let Some(grad) = grad {
                    two_point_gradient(grad, twists, &hs.normal, &x, ci.joints, &x, 0);
                }
                hs.normal.dot(&x) - ci.radius - hs.offset
            }
            Item::BeamRobot { i } => {
                let ci = &self.capsules[i];
                let sd = segment_distance(&p, &tracker, &ends[i][0], &ends[i][1]);
                if let Some(grad) = grad {
                    beam_gradient(grad, twists, &sd.normal, sd.s, &p, &sd.q, ci.joints);
                }
                sd.distance - self.beam_radius - ci.radius
            }
            Item::BeamObstacle { o } => {
                let ob = &self.obstacles[o];
                let sd = segment_distance(&p, &tracker, &ob.a, &ob.b);
                if let Some(grad) = grad {
                    beam_gradient(grad, twists, &sd.normal, sd.s, &p, &sd.q, 0);
                }
                sd.distance - self.beam_radius - ob.radius
            }
            Item::BeamBox { b } => {
                let sd = segment_box_distance(&p, &tracker, &self.boxes[b]);
                if let Some(grad) = grad {
                    beam_gradient(grad, twists, &sd.normal, sd.s, &p, &sd.p, 0);
                }
                sd.distance - self.beam_radius
            }
        }
    }

    /// The incidence angle β (rad) of an incidence constraint value `v = cos β − cos β_max`
    /// (paper eq. 4).
    pub fn incidence_angle(&self, v: f64) -> f64 {
        (v + self.cos_max).clamp(-1.0, 1.0).acos()
    }

    /// The cell's incidence limit β_max (rad), if the set checks the incidence.
    pub fn max_incidence(&self) -> Option<f64> {
        (self.count(ConstraintKind::Incidence) > 0).then(|| self.cos_max.acos())
    }

    /// Whether `q` lies within the joint bounds (inclusive; the limits shrunk by the joint
    /// margin, see [`ConstraintSet::joint_bounds`], less `JOINT_MARGIN_TOLERANCE`).
    pub fn within_limits(&self, q: &[f64]) -> bool {
        let tol = self.joint_tolerance;
        q.iter()
            .zip(self.lower.iter().zip(&self.upper))
            .all(|(v, (lo, hi))| *v >= *lo - tol && *v <= *hi + tol)
    }

    /// The smallest of `values` (one per constraint) with its index, name and kind; `None`
    /// for an empty set.
    pub fn min_margin<'a>(&'a self, values: &[f64]) -> Option<Margin<'a>> {
        let (index, value) = values
            .iter()
            .copied()
            .enumerate()
            .min_by(|a, b| a.1.total_cmp(&b.1))?;
        Some(Margin {
            index,
            value,
            name: &self.names[index],
            kind: self.items[index].kind(),
        })
    }

    /// Evaluates the constraints at `q` (into `ws.values`) and returns the smallest.
    pub fn min_margin_at<'a>(
        &'a self,
        ws: &mut ConstraintWorkspace,
        params: &[f64],
        q: &[f64],
    ) -> Option<Margin<'a>> {
        let mut values = std::mem::take(&mut ws.values);
        self.evaluate(ws, params, q, &mut values, None);
        ws.values = values;
        self.min_margin(&ws.values)
    }

    /// `q` within the joint bounds and every constraint at least its
    /// [`ConstraintSet::required`] value (paper eq. 24b, with the cell's clearance). Stops at the
    /// first violated constraint (random draws are mostly rejected by one of the first few),
    /// so `ws.values` is not filled; use [`ConstraintSet::min_margin_at`] for the values.
    pub fn feasible(&self, ws: &mut ConstraintWorkspace, params: &[f64], q: &[f64]) -> bool {
        if !self.within_limits(q) {
            return false;
        }
        assert_eq!(params.len(), self.model.param_count(), "parameter count");
        assert_eq!(q.len(), self.dof(), "joint count");
        self.place(ws, params, q);
        (0..self.len()).all(|row| self.evaluate_row(ws, row, None) >= self.required[row])
    }
}

/// `∂/∂q_j` of a distance whose closest points `P` (moved by joints `0..jp`) and `Q` (moved by
/// joints `0..jq`) separate along the unit vector `n`: `n · (Ṗ_j − Q̇_j)`.
#[inline]
fn two_point_gradient(
    grad: &mut [f64],
    twists: &[Twist<f64>],
    n: &Vector3<f64>,
    p: &Vector3<f64>,
    jp: usize,
    q: &Vector3<f64>,
    jq: usize,
) {
    for (j, (gj, tw)) in grad.iter_mut().zip(twists).enumerate() {
        let mut v = 0.0;
        if j < jp {
            v += n.dot(&tw.point_velocity(p));
        }
        if j < jq {
            v -= n.dot(&tw.point_velocity(q));
        }
        *gj = v;
    }
}

/// Gradient of the beam–capsule distance: the beam's closest point `(1 − s) p + s t` moves
/// with `(1 − s) ṗ` (the tracker origin `t` is fixed), the capsule's `Q` with joints `0..jq`.
#[inline]
fn beam_gradient(
    grad: &mut [f64],
    twists: &[Twist<f64>],
    n: &Vector3<f64>,
    s: f64,
    p: &Vector3<f64>,
    q: &Vector3<f64>,
    jq: usize,
) {
    for (j, (gj, tw)) in grad.iter_mut().zip(twists).enumerate() {
        let mut v = (1.0 - s) * n.dot(&tw.point_velocity(p));
        if j < jq {
            v -= n.dot(&tw.point_velocity(q));
        }
        *gj = v;
    }
}

/// The range `(min, max)` of every constraint of `set` over `samples` configurations spread
/// over the joint ranges (mid-range and a fixed low-discrepancy sequence: the fractional parts
/// of `0.5 + k·√(j + 2)` for joint j), at the nominal parameters. A constraint whose range is
/// below 1e-9 does not depend on q there — a KUKA base column on joint 1 standing on the
/// floor, a point on the joint-1 axis against the wall — or is flat over the sampled region:
/// the distance from a point on a joint axis to a capsule turning about that axis stays the
/// same until another point of the capsule comes closest (the paper robot's upper arm and
/// forearm at 16 samples), so 16 samples flag such a constraint and 256 rarely do.
pub(super) fn constraint_ranges(set: &ConstraintSet, samples: usize) -> Vec<(f64, f64)> {
    let (lower, upper) = set.model.joint_limits();
    let params = set.model.nominal();
    let mut ws = set.workspace();
    let m = set.len();
    let mut range = vec![(f64::INFINITY, f64::NEG_INFINITY); m];
    let mut values = vec![0.0; m];
    let mut q = vec![0.0; lower.len()];
    for k in 0..samples {
        spread_configuration(&lower, &upper, k, &mut q);
        set.evaluate(&mut ws, &params, &q, &mut values, None);
        for (r, v) in range.iter_mut().zip(&values) {
            *r = (r.0.min(*v), r.1.max(*v));
        }
    }
    range
}

/// The `k`-th of the spread configurations within `lower`, `upper` (a Kronecker sequence:
/// joint j at the fractional part of `0.5 + k √(j + 2)` of its range).
fn spread_configuration(lower: &[f64], upper: &[f64], k: usize, q: &mut [f64]) {
    for (j, x) in q.iter_mut().enumerate() {
        let t = (0.5 + k as f64 * (j as f64 + 2.0).sqrt()).fract();
        *x = lower[j] + t * (upper[j] - lower[j]);
    }
}

/// Leaves out the robot capsule pairs that overlap at every one of `samples` spread
/// configurations (those of [`constraint_ranges`]), and the robot–obstacle and robot–half-space
/// constraints that keep one negative value at all of them, keeping their names in
/// `set.pairs_in_contact` (see the module documentation: bodies in contact by construction).
/// Only the constraints not yet seen apart (or changing) are evaluated, and the sampling
/// stops when none is left: a few configurations for a robot without such a pair.
pub(super) fn drop_pairs_in_contact(set: &mut ConstraintSet, samples: usize) {
    let constant_only = |i: usize| {
        matches!(
            set.items[i],
            Item::Obstacle { .. } | Item::Box { .. } | Item::HalfSpace { .. }
        )
    };
    let mut touching: Vec<bool> = (0..set.len())
        .map(|i| set.kind(i) == ConstraintKind::SelfCollision || constant_only(i))
        .collect();
    let constant: Vec<bool> = (0..set.len()).map(constant_only).collect();
    let (lower, upper) = set.model.joint_limits();
    let params = set.model.nominal();
    let mut ws = set.workspace();
    let mut values = vec![0.0; set.len()];
    let mut first = vec![f64::NAN; set.len()];
    let mut q = vec![0.0; lower.len()];
    let mut rows: Vec<usize> = (0..set.len()).filter(|&i| touching[i]).collect();
    for k in 0..samples {
        if rows.is_empty() {
            break;
        }
        spread_configuration(&lower, &upper, k, &mut q);
        set.evaluate_rows(&mut ws, &params, &q, &rows, &mut values, None);
        for &i in &rows {
            if k == 0 {
                first[i] = values[i];
            }
            touching[i] = values[i] < 0.0 && (!constant[i] || (values[i] - first[i]).abs() < 1e-9);
        }
        rows.retain(|&i| touching[i]);
    }
    let mut keep = touching.iter().map(|t| !t);
    set.items.retain(|_| keep.next().unwrap_or(true));
    let names = std::mem::take(&mut set.names);
    for (name, touching) in names.into_iter().zip(&touching) {
        match touching {
            true => set.pairs_in_contact.push(name),
            false => set.names.push(name),
        }
    }
    let n = set.items.len();
    set.required.truncate(n);
    set.constant.truncate(n);
}

impl ConstraintSet {
    /// Robot capsule pairs not checked because they overlap at every sampled configuration,
    /// and robot–obstacle constraints left out because they keep one negative value there (a
    /// capsule from the base origin on the floor); names as [`ConstraintSet::names`].
    pub fn pairs_in_contact(&self) -> &[String] {
        &self.pairs_in_contact
    }

    /// Number of constraints of one kind.
    pub fn count(&self, kind: ConstraintKind) -> usize {
        self.items.iter().filter(|it| it.kind() == kind).count()
    }

    /// Buffers for [`ConstraintSet::evaluate`].
    pub fn workspace(&self) -> ConstraintWorkspace {
        ConstraintWorkspace::new(self)
    }
}

/// Whether a range of [`constraint_ranges`] is constant (within 1e-9).
pub(super) fn is_flat(range: (f64, f64)) -> bool {
    range.1 - range.0 < 1e-9
}

impl ConstraintWorkspace {
    pub(crate) fn new(set: &ConstraintSet) -> Self {
        ConstraintWorkspace {
            data: Data::new(&set.model),
            fixed: FixedKinematics::new(&set.model),
            ends: vec![[Vector3::zeros(); 2]; set.capsules.len()],
            placed: Vec::new(),
            values: vec![0.0; set.len()],
        }
    }
}
