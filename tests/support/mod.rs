//! Helpers shared by the translation tests.

use hypersynth::automata::{Dfa, DfaState};

/// `None` when the two DFAs have the same propositions, states, finality and edges (targets
/// equal, guards equivalent), otherwise the first difference.
pub fn structural_difference(x: &Dfa, y: &Dfa) -> Option<String> {
    if x.aps() != y.aps() || x.num_states() != y.num_states() || x.initial() != y.initial() {
        return Some(format!(
            "{:?}, {} states, start {} vs {:?}, {} states, start {}",
            x.aps(),
            x.num_states(),
            x.initial(),
            y.aps(),
            y.num_states(),
            y.initial()
        ));
    }
    for q in 0..x.num_states() as DfaState {
        let (ex, ey): (Vec<_>, Vec<_>) = (x.edges(q).collect(), y.edges(q).collect());
        let same = x.is_final(q) == y.is_final(q)
            && ex.len() == ey.len()
            && ex
                .iter()
                .zip(&ey)
                .all(|((gx, tx), (gy, ty))| tx == ty && gx.equivalent(gy));
        if !same {
            return Some(format!("state {q} differs"));
        }
    }
    None
}
