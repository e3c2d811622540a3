//! Optimal measurement-pose design (paper §2–3): choose the N configurations that make the
//! calibrated robot most precise where it works (the KPI method), or that optimise a classic
//! criterion of the parameter covariance.

pub mod assess;
pub mod baselines;
pub mod bound;
pub mod cell_constraints;
pub mod criteria;
pub mod exchange;
pub mod information;
pub mod objective;
pub(crate) mod order;
pub mod plan;
pub mod record;
pub mod refine;
pub mod selection;
pub(crate) mod small_cholesky;
pub mod user_pool;

pub use cell_constraints::{ConstraintKind, ConstraintSet, ConstraintSettings};
pub use criteria::Criterion;
pub use information::{DesignModel, InformationWorkspace};
pub use objective::DesignObjective;
pub use record::DesignRecord;
