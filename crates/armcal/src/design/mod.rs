//! Optimal measurement-pose design (paper §2–3): choose the N configurations that make the
//! calibrated robot most precise where it works (the KPI method), or that optimise a classic
//! criterion of the parameter covariance.

pub(crate) mod assess;
pub mod baselines;
pub mod bound;
pub(crate) mod cell_constraints;
pub(crate) mod criteria;
pub mod exchange;
pub(crate) mod information;
pub(crate) mod objective;
pub(crate) mod order;
pub(crate) mod plan;
pub(crate) mod record;
pub mod refine;
pub mod selection;
pub(crate) mod small_cholesky;
pub(crate) mod user_pool;

// The planner's parts, one path each (the calls and records are root items: `armcal::plan`,
// `armcal::PlanSettings`, `armcal::DesignRecord`, …).
pub use cell_constraints::{ConstraintKind, ConstraintSet, ConstraintSettings};
pub(crate) use criteria::Criterion;
pub use criteria::SMOOTH_MAX_P;
pub use information::{DesignModel, InformationWorkspace};
pub use objective::DesignObjective;
pub use plan::{constraint_set, CellConstraints, EXCHANGE_TOLERANCE_BEFORE_REFINEMENT};
pub use record::kind_margins;
pub(crate) use record::DesignRecord;
pub use user_pool::plan_from_pool;
