//! What became of a variant: one status for its whole life, from the balance search's verdict
//! to the study's.
//!
//! The balance search ends a variant [`Status::Balanced`] (verified physical parameters exist)
//! or with one of its final verdicts ([`Status::Degenerate`], [`Status::Unrealizable`],
//! [`Status::Infeasible`], [`Status::Undecided`]); the optimiser turns a balanced variant into
//! [`Status::Feasible`], [`Status::Discarded`] or [`Status::Undecided`]. The shard files and
//! results.json record the same values, so no stage translates between enums and a new status
//! is a compile error wherever one is matched.

use serde::{Deserialize, Serialize};

/// What became of a variant (serialised in lower case: `"feasible"`, …).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Balanced, optimised within bounds and re-evaluated: ranked.
    Feasible,
    /// Balanced, but the optimiser proved that no parameters satisfy the bounds and peak
    /// limits (paper Proc-6), or the optimised parameters were verified to violate a peak
    /// limit over all tasks.
    Discarded,
    /// Balanced in lifted parameters, but no physical parameters exist: a certificate is given
    /// (a mass or stiffness forced to zero or below, no positive solution, an impossible
    /// rank-one spring).
    Unrealizable,
    /// Verified physical parameters exist, but some element can only idle: it contributes no
    /// energy in any balancing solution (a spring anchored on a joint axis, a counterweight on
    /// a fixed point). Really a smaller variant plus idle parts; not optimised.
    Degenerate,
    /// Not decided: a floating-point test was ambiguous, or a search found neither parameters
    /// nor a proof that none exist (the reason says which). Never a verdict.
    Undecided,
    /// `A_S x = −b` has no solution: no parameters balance this variant.
    Infeasible,
    /// The balance search's verdict before the optimisation: verified physical parameters
    /// exist and every element carries part of the load. The optimiser decides what follows.
    Balanced,
}

impl Status {
    /// The verdicts the balance search gives, in the order of its counts.
    pub const SEARCH_VERDICTS: [Status; 5] = [
        Status::Balanced,
        Status::Degenerate,
        Status::Unrealizable,
        Status::Infeasible,
        Status::Undecided,
    ];

    /// The verdicts a finished study gives, in the order of the results' counts table.
    pub const STUDY_VERDICTS: [Status; 6] = [
        Status::Feasible,
        Status::Discarded,
        Status::Unrealizable,
        Status::Degenerate,
        Status::Undecided,
        Status::Infeasible,
    ];

    /// The machine name used in JSON and CSV.
    pub fn name(self) -> &'static str {
        match self {
            Status::Feasible => "feasible",
            Status::Discarded => "discarded",
            Status::Unrealizable => "unrealizable",
            Status::Degenerate => "degenerate",
            Status::Undecided => "undecided",
            Status::Infeasible => "infeasible",
            Status::Balanced => "balanced",
        }
    }

    /// One line for the counts table.
    pub fn meaning(self) -> &'static str {
        match self {
            Status::Feasible => "balanced exactly, parameters within bounds; ranked",
            Status::Discarded => "balanced, but no parameters satisfy the bounds and peak limits",
            Status::Unrealizable => "balanced in lifted parameters, no physical parameters exist",
            Status::Degenerate => "realizable, but an element can only idle (a smaller variant)",
            Status::Undecided => "the search or optimiser could not decide",
            Status::Infeasible => "no parameters balance the mechanism",
            Status::Balanced => "balanced exactly with verified parameters; not yet optimised",
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The JSON name is `name()`, and every status is among the search's or the study's
    /// verdicts, each list without repeats.
    #[test]
    fn names_are_the_documents_and_every_status_is_a_verdict() {
        let all = [
            Status::Feasible,
            Status::Discarded,
            Status::Unrealizable,
            Status::Degenerate,
            Status::Undecided,
            Status::Infeasible,
            Status::Balanced,
        ];
        for s in all {
            assert_eq!(
                serde_json::to_string(&s).unwrap(),
                format!("\"{}\"", s.name())
            );
            let back: Status = serde_json::from_str(&format!("\"{}\"", s.name())).unwrap();
            assert_eq!(back, s);
            assert!(Status::SEARCH_VERDICTS.contains(&s) || Status::STUDY_VERDICTS.contains(&s));
            assert!(!s.meaning().is_empty());
        }
        let mut names: Vec<_> = all.iter().map(|s| s.name()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), all.len());
        // Each meaning is its own line of the counts table and says what the status is.
        let mut meanings: Vec<_> = all.iter().map(|s| s.meaning()).collect();
        meanings.sort();
        meanings.dedup();
        assert_eq!(meanings.len(), all.len());
        assert!(Status::Feasible.meaning().contains("ranked"));
        assert!(
            Status::Infeasible
                .meaning()
                .contains("no parameters balance")
        );
        assert!(Status::Balanced.meaning().contains("not yet optimised"));
        // Only the optimiser turns a balanced variant into a ranked one.
        assert!(!Status::STUDY_VERDICTS.contains(&Status::Balanced));
        assert!(!Status::SEARCH_VERDICTS.contains(&Status::Feasible));
        assert!(!Status::SEARCH_VERDICTS.contains(&Status::Discarded));
    }
}
