//! The vocabulary every solver shares: how it ended ([`Status`]). Identification returns it
//! as is, the design refinement returns it with its own record wording
//! ([`crate::design::refine::RefineResult::describe`]), and inverse kinematics keeps a
//! domain status ([`crate::compensate::IkStatus`]) that maps onto it
//! ([`crate::compensate::IkStatus::status`]). Control flow tests variants, never text.

use serde::{Deserialize, Serialize};

/// How a solver ended, with the criterion or reason.
///
/// Serialized with the tag `status` in kebab-case (`{"status":"converged","criterion":…}`);
/// [`Status::IterationLimit`] keeps the estimate files' name `max-iterations`.
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "kebab-case")]
pub enum Status {
    /// A convergence criterion was met; `criterion` says which (empty: the solver's own
    /// tolerance, nothing more to say).
    Converged {
        /// Which criterion was met (e.g. step or gradient tolerance); may be empty.
        criterion: String,
    },
    /// The iteration limit was reached before convergence.
    #[serde(rename = "max-iterations")]
    IterationLimit,
    /// The time limit was reached before convergence.
    TimeLimit,
    /// No step makes progress any more, away from a proven optimum (a failed line search, a
    /// singular configuration).
    Stalled {
        /// Why no step progresses.
        reason: String,
    },
    /// The constraints (joint limits, reach) admit no solution.
    Infeasible {
        /// Which constraint cannot be met.
        reason: String,
    },
    /// The iteration failed (non-finite values, or no step reduces the cost).
    Diverged {
        /// What failed.
        reason: String,
    },
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Status::Converged { criterion } if criterion.is_empty() => f.write_str("converged"),
            Status::Converged { criterion } => write!(f, "converged ({criterion})"),
            Status::IterationLimit => f.write_str("stopped at the iteration limit"),
            Status::TimeLimit => f.write_str("stopped at the time limit"),
            Status::Stalled { reason } => write!(f, "stalled: {reason}"),
            Status::Infeasible { reason } => write!(f, "infeasible: {reason}"),
            Status::Diverged { reason } => write!(f, "diverged: {reason}"),
        }
    }
}

impl Status {
    /// Whether a convergence criterion was met.
    pub fn is_converged(&self) -> bool {
        matches!(self, Status::Converged { .. })
    }
}

#[cfg(test)]
mod tests {
    use super::Status;

    /// The estimate files' names and the printed words are those of the statuses before
    /// the shared vocabulary.
    #[test]
    fn files_and_words_keep_their_names() {
        let json = |s: &Status| serde_json::to_string(s).unwrap();
        let converged = Status::Converged {
            criterion: "gradient".into(),
        };
        assert_eq!(
            json(&converged),
            r#"{"status":"converged","criterion":"gradient"}"#
        );
        assert_eq!(
            json(&Status::IterationLimit),
            r#"{"status":"max-iterations"}"#
        );
        let back: Status = serde_json::from_str(r#"{"status":"max-iterations"}"#).unwrap();
        assert_eq!(back, Status::IterationLimit);
        assert_eq!(converged.to_string(), "converged (gradient)");
        assert_eq!(
            Status::IterationLimit.to_string(),
            "stopped at the iteration limit"
        );
        let diverged = Status::Diverged {
            reason: "NaN".into(),
        };
        assert_eq!(diverged.to_string(), "diverged: NaN");
    }
}
