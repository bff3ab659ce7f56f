//! Splitting the robot's task `phi` into `phi1` (what the adversary believes, `psi`) and `phi2`.
//!
//! Conjunctions are compared as sets of top-level conjuncts (the parser keeps `&` flat and n-ary;
//! formulas are compared structurally, ignoring spans, so `a & b` and `b & a` split alike, and
//! `(a & b) & c` has the three conjuncts `a`, `b`, `c`):
//! - every conjunct of `psi` must be a conjunct of `phi`; then `phi1 = psi` as written;
//! - without an explicit `phi2`, it is the conjunction of the other conjuncts of `phi`, in
//!   `phi`'s order, repeated ones once; `true` when `psi` covers all of `phi`;
//! - with an explicit `phi2`, every conjunct of `phi2` must be a conjunct of `phi`, and every
//!   conjunct of `phi` one of `psi` or of `phi2`, so that `phi = phi1 & phi2` as sets of
//!   conjuncts (overlap between `psi` and `phi2` is allowed: it changes nothing semantically).

use super::sets::{MAX_TASKS, TaskSet};
use crate::ltl::{Formula, FormulaKind, NaryOp, Span};

/// The three formulas of a hypergame.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct TaskSplit {
    /// The robot's task as given.
    pub phi: Formula,
    /// `psi` as written: the conjuncts the adversary believes are the whole task.
    pub phi1: Formula,
    /// The other conjuncts of `phi` (or `phi2` as given); `true` when `psi` covers all of `phi`.
    pub phi2: Formula,
}

/// Which formula an error points into.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Operand {
    /// The robot's task (`--phi`).
    Phi,
    /// The adversary's belief (`--psi`).
    Psi,
    /// The rest of the task, when given explicitly (`--phi2`).
    Phi2,
}

/// Why `phi`, `psi` (and `phi2`) do not form a hypergame; each error points at the offending
/// conjunct (its span in the text of [`SplitError::operand`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum SplitError {
    #[error(
        "this conjunct of psi is not a conjunct of phi (psi must be a part of phi's conjunction)"
    )]
    /// A conjunct of `psi` (its span in `psi`) is not a conjunct of `phi`.
    PsiNotInPhi(Span),
    /// A conjunct of `phi2` (its span in `phi2`) is not a conjunct of `phi`.
    #[error("this conjunct of phi2 is not a conjunct of phi")]
    Phi2NotInPhi(Span),
    /// A conjunct of `phi` (its span in `phi`) is a conjunct of neither `psi` nor `phi2`.
    #[error("this conjunct of phi is in neither psi nor phi2")]
    PhiNotCovered(Span),
}

impl SplitError {
    /// The formula whose text [`Self::span`] indexes.
    pub fn operand(&self) -> Operand {
        match self {
            SplitError::PsiNotInPhi(_) => Operand::Psi,
            SplitError::Phi2NotInPhi(_) => Operand::Phi2,
            SplitError::PhiNotCovered(_) => Operand::Phi,
        }
    }

    /// The span of the offending conjunct (of its main operator for operator nodes).
    pub fn span(&self) -> Span {
        match self {
            SplitError::PsiNotInPhi(span)
            | SplitError::Phi2NotInPhi(span)
            | SplitError::PhiNotCovered(span) => *span,
        }
    }
}

/// Splits `phi` by `psi` (and checks an explicit `phi2`), see the module documentation.
pub fn split_task(
    phi: &Formula,
    psi: &Formula,
    phi2: Option<&Formula>,
) -> Result<TaskSplit, SplitError> {
    let phi_conjuncts = conjuncts(phi);
    let psi_conjuncts = conjuncts(psi);
    if let Some(missing) = psi_conjuncts.iter().find(|c| !phi_conjuncts.contains(c)) {
        return Err(SplitError::PsiNotInPhi(missing.span));
    }
    let phi2 = match phi2 {
        Some(phi2) => {
            let phi2_conjuncts = conjuncts(phi2);
            if let Some(extra) = phi2_conjuncts.iter().find(|c| !phi_conjuncts.contains(c)) {
                return Err(SplitError::Phi2NotInPhi(extra.span));
            }
            if let Some(uncovered) = phi_conjuncts
                .iter()
                .find(|c| !psi_conjuncts.contains(c) && !phi2_conjuncts.contains(c))
            {
                return Err(SplitError::PhiNotCovered(uncovered.span));
            }
            phi2.clone()
        }
        None => {
            let mut rest: Vec<Formula> = Vec::new();
            for conjunct in phi_conjuncts {
                if !psi_conjuncts.contains(&conjunct) && !rest.contains(conjunct) {
                    rest.push(conjunct.clone());
                }
            }
            conjunction(rest)
        }
    };
    Ok(TaskSplit {
        phi: phi.clone(),
        phi1: psi.clone(),
        phi2,
    })
}

/// The set of sub-tasks whose conjunction is `psi` (docs/semantics.md §8), if any: psi's top-level
/// conjuncts, compared structurally as a set, are exactly the union of those of the sub-tasks
/// in the set (the sub-tasks all of whose conjuncts are psi's). Bit i stands for `tasks[i]`;
/// a sub-task without a formula (read from a HOA file) never matches.
pub fn match_belief(tasks: &[Option<&Formula>], psi: &Formula) -> Option<TaskSet> {
    let wanted = conjuncts(psi);
    let mut mask = 0u8;
    let mut covered: Vec<&Formula> = Vec::new();
    for (i, task) in tasks.iter().enumerate().take(MAX_TASKS) {
        let Some(task) = task else { continue };
        let parts = conjuncts(task);
        if parts.iter().all(|c| wanted.contains(c)) {
            mask |= 1 << i;
            covered.extend(parts);
        }
    }
    (mask != 0 && wanted.iter().all(|c| covered.contains(c))).then_some(TaskSet(mask))
}

/// The top-level conjuncts of `formula` (itself if it is not a conjunction).
fn conjuncts(formula: &Formula) -> Vec<&Formula> {
    match &formula.kind {
        FormulaKind::Nary(NaryOp::And, operands) => operands.iter().collect(),
        _ => vec![formula],
    }
}

/// `true` for no formula, the formula for one, their flat conjunction otherwise.
fn conjunction(mut formulas: Vec<Formula>) -> Formula {
    let kind = match formulas.len() {
        0 => FormulaKind::Const(true),
        1 => return formulas.remove(0),
        _ => FormulaKind::Nary(NaryOp::And, formulas),
    };
    Formula {
        kind,
        span: Span::default(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ltl::BinaryOp;

    fn at(kind: FormulaKind, start: usize) -> Formula {
        Formula {
            kind,
            span: Span {
                start,
                end: start + 1,
            },
        }
    }

    fn atom(name: &str, start: usize) -> Formula {
        at(FormulaKind::Atom(name.into()), start)
    }

    /// `!O U target`, with its `U` at `start`.
    fn reach(target: &str, start: usize) -> Formula {
        let not_o = at(
            FormulaKind::Unary(crate::ltl::UnaryOp::Not, Box::new(atom("O", start))),
            start,
        );
        at(
            FormulaKind::Binary(
                BinaryOp::Until,
                Box::new(not_o),
                Box::new(atom(target, start)),
            ),
            start,
        )
    }

    fn and(operands: Vec<Formula>, start: usize) -> Formula {
        at(FormulaKind::Nary(NaryOp::And, operands), start)
    }

    #[test]
    fn psi_is_phi1_and_the_rest_of_phi_is_phi2() {
        // phi = (!O U A) & (!O U B) & c, psi = (!O U A) written elsewhere (other spans).
        let phi = and(vec![reach("A", 3), reach("B", 15), atom("c", 22)], 9);
        let split = split_task(&phi, &reach("A", 40), None).unwrap();
        assert_eq!(split.phi1, reach("A", 0));
        assert_eq!(split.phi2, and(vec![reach("B", 0), atom("c", 0)], 0));
        assert_eq!(split.phi, phi);
        // psi as a conjunction in another order takes both conjuncts.
        let psi = and(vec![atom("c", 0), reach("A", 0)], 0);
        assert_eq!(split_task(&phi, &psi, None).unwrap().phi2, reach("B", 0));
        // psi = phi leaves phi2 = true.
        assert_eq!(
            split_task(&phi, &phi, None).unwrap().phi2.kind,
            FormulaKind::Const(true)
        );
    }

    #[test]
    fn a_psi_conjunct_outside_phi_is_located() {
        let phi = and(vec![reach("A", 3), reach("B", 15)], 9);
        let psi = and(vec![reach("A", 3), reach("C", 17)], 9);
        let error = split_task(&phi, &psi, None).unwrap_err();
        assert_eq!(error, SplitError::PsiNotInPhi(Span { start: 17, end: 18 }));
        assert_eq!(error.operand(), Operand::Psi);
        // A formula that is not a conjunction is its only conjunct.
        let error = split_task(&reach("A", 3), &reach("B", 7), None).unwrap_err();
        assert_eq!(error.span(), Span { start: 7, end: 8 });
    }

    #[test]
    fn a_belief_matches_the_sub_tasks_whose_conjuncts_it_has() {
        let (a, b, c) = (reach("A", 0), reach("B", 7), atom("c", 14));
        let tasks = [Some(&a), Some(&b), Some(&c)];
        assert_eq!(match_belief(&tasks, &reach("A", 30)), Some(TaskSet(0b001)));
        let psi = and(vec![atom("c", 2), reach("A", 5)], 3);
        assert_eq!(match_belief(&tasks, &psi), Some(TaskSet(0b101)));
        // A conjunct of no sub-task: psi gets its own automaton.
        let psi = and(vec![reach("A", 2), atom("d", 5)], 3);
        assert_eq!(match_belief(&tasks, &psi), None);
        assert_eq!(match_belief(&tasks, &atom("d", 0)), None);
        // A sub-task that is itself a conjunction matches only as a whole.
        let (ab, c) = (and(vec![atom("a", 0), atom("b", 4)], 2), atom("c", 0));
        let tasks = [Some(&ab), Some(&c), None];
        assert_eq!(match_belief(&tasks, &atom("a", 0)), None);
    }

    #[test]
    fn an_explicit_phi2_must_complete_psi_to_phi() {
        let phi = and(vec![reach("A", 3), reach("B", 15), atom("c", 22)], 9);
        let psi = reach("A", 0);
        let phi2 = and(vec![atom("c", 1), reach("B", 5)], 3);
        assert_eq!(
            split_task(&phi, &psi, Some(&phi2)).unwrap().phi2,
            phi2.clone()
        );
        assert_eq!(
            split_task(&phi, &psi, Some(&reach("B", 4))),
            Err(SplitError::PhiNotCovered(Span { start: 22, end: 23 }))
        );
        let too_much = and(vec![atom("c", 1), reach("B", 5), atom("d", 11)], 3);
        assert_eq!(
            split_task(&phi, &psi, Some(&too_much)),
            Err(SplitError::Phi2NotInPhi(Span { start: 11, end: 12 }))
        );
    }
}
