//! Reading an exported controller back ([`read`], `check`): the JSON is read with the path of
//! every part, and then every part is checked against the format's rules and the others, also the
//! parts the executor does not use, so that a file is accepted only if it describes a model and
//! a controller that can be built again (docs/formats.md lists the rules).
//!
//! Every problem is one [`Problem`] located by its JSON path (`$.modes[1].codes`, a table's
//! entry by its index), and all those found are reported in the order of the file's parts (the
//! first [`DEFAULT_LIMIT`]); the parts that depend on one that failed (the tables on the arena,
//! say) are not checked. A file whose JSON does not read, or of another format or version, has
//! that one error. Messages quote the file briefly ([`brief`]). Cost: linear in the file, plus
//! building its arena and one look-up in the arena's edges per table entry.

use std::collections::{HashMap, HashSet};

use bit_set::BitSet;
use std::fmt;

use thiserror::Error;

use super::adversary::{EntryError, EntryPart, Weight, WeightTable};
use super::export::{
    ArenaSource, AutomatonTable, Believed, CertificateTables, Choice, ControllerFile, Entries,
    FORMAT, MAX_MASKED_EDGES, Ranks, Scope, SigmaLRule, Table,
};
use crate::arena::{ActionId, Arena, Owner, StateId};
use crate::diagnostic::{DEFAULT_LIMIT, Diagnostic, brief, brief_quotes};
use crate::game::{MAX_TASKS, PayoffError, SubsetPayoffs, TaskSet};
use crate::position::Position;

/// Why a text is not a controller file this version reads.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum ControllerError {
    /// The text is not JSON: its first syntax error, at its line and column.
    #[error("{0}")]
    Syntax(Diagnostic),
    /// The JSON breaks the format's rules: each problem at its JSON path.
    #[error("{0}")]
    Invalid(Problems),
}

impl ControllerError {
    /// The problems of [`ControllerError::Invalid`] (none for a syntax error).
    pub fn problems(&self) -> &[Problem] {
        match self {
            ControllerError::Syntax(_) => &[],
            ControllerError::Invalid(problems) => &problems.kept,
        }
    }
}

/// One problem of a file: where (a JSON path) and what.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problem {
    /// The part, as a JSON path (`$.modes[1].codes`).
    pub path: String,
    /// What is wrong, one line.
    pub message: String,
}

impl fmt::Display for Problem {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}: {}", self.path, self.message)
    }
}

/// The problems found in a file: at least one, in the order of the file's parts, at most
/// [`DEFAULT_LIMIT`], and how many there were in all.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Problems {
    kept: Vec<Problem>,
    total: usize,
}

impl Problems {
    /// How many problems were found, kept or not.
    pub fn total(&self) -> usize {
        self.total
    }
}

/// One problem per line, then `N more problems not shown` if some were not kept.
impl fmt::Display for Problems {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        for (i, problem) in self.kept.iter().enumerate() {
            if i > 0 {
                f.write_str("\n")?;
            }
            write!(f, "{problem}")?;
        }
        let omitted = self.total - self.kept.len();
        if omitted > 0 {
            let plural = if omitted == 1 { "" } else { "s" };
            write!(f, "\n{omitted} more problem{plural} not shown")?;
        }
        Ok(())
    }
}

/// Gathers problems in the order they are found.
#[derive(Default)]
struct Found {
    kept: Vec<Problem>,
    total: usize,
}

impl Found {
    fn add(&mut self, path: impl Into<String>, message: impl fmt::Display) {
        self.total += 1;
        if self.kept.len() < DEFAULT_LIMIT {
            self.kept.push(Problem {
                path: path.into(),
                message: message.to_string(),
            });
        }
    }

    fn is_empty(&self) -> bool {
        self.total == 0
    }

    /// The error, once a problem was found.
    fn failed(self) -> ControllerError {
        debug_assert!(!self.is_empty());
        ControllerError::Invalid(Problems {
            kept: self.kept,
            total: self.total,
        })
    }
}

/// One problem, as the error.
fn invalid(path: impl Into<String>, message: impl fmt::Display) -> ControllerError {
    let mut found = Found::default();
    found.add(path, message);
    found.failed()
}

/// Reads a controller file's JSON: its syntax (located by line and column), its format and
/// version (a file of version 1 is refused with a request to export it again), and the type of
/// every part (located by its JSON path). The parts are checked against each other by
/// `check`.
pub fn read(text: &str) -> Result<ControllerFile, ControllerError> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| ControllerError::Syntax(syntax_error(text, &e)))?;
    if let Some(format) = value.get("format") {
        check_format(format.as_str().unwrap_or_default(), format)?;
    }
    serde_path_to_error::deserialize(value).map_err(|error| {
        let message = brief_quotes(&error.inner().to_string());
        invalid(json_path(error.path()), message)
    })
}

/// The format of a file that declares `format` (`value` as written), if it is not [`FORMAT`].
fn check_format(format: &str, value: &serde_json::Value) -> Result<(), ControllerError> {
    match format {
        FORMAT => Ok(()),
        "hypersynth-controller/1" => Err(invalid(
            "$.format",
            format!(
                "a file of version 1 of the format, which this version of hypersynth no longer \
                 reads (it reads \"{FORMAT}\", which also holds the model's rules): export the \
                 controller again"
            ),
        )),
        _ => Err(invalid(
            "$.format",
            format!("expected \"{FORMAT}\", found {}", brief(value)),
        )),
    }
}

/// A JSON syntax error at its line and column (the column in characters, as positions count).
fn syntax_error(text: &str, error: &serde_json::Error) -> Diagnostic {
    let shown = error.to_string();
    let suffix = format!(" at line {} column {}", error.line(), error.column());
    let message = shown.strip_suffix(&suffix).unwrap_or(&shown);
    let line = text
        .lines()
        .nth(error.line().saturating_sub(1))
        .unwrap_or("");
    let mut byte = error.column().saturating_sub(1).min(line.len());
    while !line.is_char_boundary(byte) {
        byte -= 1;
    }
    let position = Position {
        line: error.line(),
        column: line[..byte].chars().count() + 1,
    };
    Diagnostic::new(position, brief_quotes(message))
}

/// `$` and the path's parts: `.name` for an object's member, `[i]` for an array's item.
fn json_path(path: &serde_path_to_error::Path) -> String {
    use serde_path_to_error::Segment;
    let mut out = String::from("$");
    for segment in path.iter() {
        match segment {
            Segment::Seq { index } => out.push_str(&format!("[{index}]")),
            Segment::Map { key } => out.push_str(&format!(".{}", brief(key))),
            Segment::Enum { variant } => out.push_str(&format!(".{}", brief(variant))),
            Segment::Unknown => out.push_str(".?"),
        }
    }
    out
}

/// A file checked, with what running it needs: the arena built, the tables decoded and the
/// names resolved.
pub(crate) struct Checked {
    pub(crate) file: ControllerFile,
    pub(crate) arena: Arena,
    pub(crate) ranks: Ranks,
    /// The arena's label id → the file's letter.
    pub(crate) letters: Vec<usize>,
    /// Automata tuple → its index.
    pub(crate) tuples: HashMap<Vec<u32>, usize>,
    /// Set (mask) → its mode's table, decoded.
    pub(crate) modes: Vec<Option<Entries>>,
    /// The adversary table, decoded.
    pub(crate) adversary: Entries,
    /// Per choice, the arena action of a move.
    pub(crate) moves: Vec<Option<ActionId>>,
    /// The certificate's tables, decoded, when the file has one.
    pub(crate) certificate: Option<CertificateEntries>,
}

/// A certificate's tables, decoded: the values of the states that carry one, in the checker's
/// order (docs/semantics.md §9.4), each a non-negative finite double.
pub(crate) struct CertificateEntries {
    /// x at the states of D_L that carry one.
    pub(crate) lower: Vec<f64>,
    /// y at the states of D_U that carry one.
    pub(crate) upper: Vec<f64>,
}

/// Checks every part of `file` against the format's rules and the other parts (see the module
/// documentation and docs/formats.md); all problems found, located by their JSON paths.
pub(crate) fn check(file: ControllerFile) -> Result<Checked, ControllerError> {
    let mut found = Found::default();
    if file.format != FORMAT {
        let value = serde_json::Value::String(file.format.clone());
        check_format(&file.format, &value)?;
    }
    let k = file.tasks.len();
    let tasks_fit = (1..=MAX_TASKS).contains(&k);
    if !tasks_fit {
        found.add(
            "$.tasks",
            format!("{k} sub-tasks, where 1 to {MAX_TASKS} are expected"),
        );
    }
    let mut names = HashSet::new();
    for (i, name) in file.tasks.iter().enumerate() {
        if !names.insert(name) {
            found.add(
                format!("$.tasks[{i}]"),
                format_args!("`{}` names two sub-tasks", brief(name)),
            );
        }
    }
    if let Some(fixed) = file.form.fixed_tasks().filter(|&fixed| fixed != k) {
        found.add(
            "$.form",
            format!(
                "the {} form has exactly {fixed} sub-tasks",
                file.form.name()
            ),
        );
    }
    let sets = if tasks_fit { 1usize << k } else { 0 };
    let psi_automaton = check_believed(&file.believed, k, sets, &mut found);
    let largest = check_payoffs(&file, sets, &mut found);
    let g = file.discount;
    if !(g > 0.0 && g <= 1.0) {
        found.add(
            "$.discount",
            format!("{g} is not a discount: expected 0 < g <= 1"),
        );
    }
    if let SigmaLRule::Weights(weights) = &file.sigma_l {
        for (i, weight) in weights.iter().enumerate() {
            let w = weight.weight;
            if !(w.is_finite() && w > 0.0) {
                found.add(
                    format!("$.sigma_l.weights[{i}].weight"),
                    format!("{w} is not a weight: expected a finite number > 0"),
                );
            }
        }
    }
    if let SigmaLRule::Learnt { delta, counts } = &file.sigma_l {
        if !(*delta > 0.0 && *delta < 1.0) {
            found.add(
                "$.sigma_l.learnt.delta",
                format!("{delta} is not a confidence parameter: expected 0 < delta < 1"),
            );
        }
        if let Some(i) = counts.iter().position(|c| c.count == 0) {
            found.add(
                format!("$.sigma_l.learnt.counts[{i}].count"),
                "0 is not a count of observations: expected a whole number > 0 (unlisted \
                 pairs count 0)",
            );
        }
    }
    let [lower, upper] = file.value;
    let top = largest.unwrap_or(f64::INFINITY);
    if !(lower >= 0.0 && lower <= upper && upper <= top && upper.is_finite()) {
        let most = largest.map_or(String::new(), |r| format!(", {r}]"));
        let within = largest.map_or(" finite".to_string(), |_| format!(" within [0{most}"));
        found.add(
            "$.value",
            format!(
                "[{lower}, {upper}] are not bounds on a value: expected lower <= upper,{within}"
            ),
        );
    }
    let arena = match build_arena(&file.arena) {
        Ok(arena) => Some(arena),
        Err((path, message)) => {
            found.add(path, message);
            None
        }
    };
    if let (Some(arena), SigmaLRule::Weights(weights)) = (&arena, &file.sigma_l)
        && weights
            .iter()
            .all(|w| w.weight.is_finite() && w.weight > 0.0)
    {
        check_weights(arena, weights, "weights", &mut found);
    }
    if let (Some(arena), SigmaLRule::Learnt { counts, .. }) = (&arena, &file.sigma_l) {
        let as_weights: Vec<Weight> = counts
            .iter()
            .map(|c| Weight {
                state: c.state.clone(),
                action: c.action.clone(),
                weight: f64::from(c.count.max(1)),
            })
            .collect();
        check_weights(arena, &as_weights, "learnt.counts", &mut found);
    }
    let letters = arena
        .as_ref()
        .and_then(|arena| check_labels(arena, &file.labels, &mut found));
    let automata = file.automata.len();
    let expected = k + usize::from(psi_automaton);
    if tasks_fit && automata != expected {
        found.add(
            "$.automata",
            format!("{automata} automata, where the sub-tasks and psi have {expected}"),
        );
    }
    for (i, automaton) in file.automata.iter().enumerate() {
        let name = match i.cmp(&k) {
            std::cmp::Ordering::Less => Some(file.tasks[i].as_str()),
            std::cmp::Ordering::Equal if psi_automaton => Some("psi"),
            _ => None,
        };
        check_automaton(i, automaton, name, file.labels.len(), &mut found);
    }
    let tuples = check_tuples(&file, &mut found);
    let mut modes_of = HashSet::new();
    for (m, mode) in file.modes.iter().enumerate() {
        let set = mode.set;
        if set as usize >= sets || !modes_of.insert(set) {
            found.add(
                format!("$.modes[{m}].set"),
                format!("set {set} is repeated or no set of the sub-tasks"),
            );
        }
    }
    if !modes_of.contains(&0) {
        found.add("$.modes", "the uncommitted mode (set 0) is missing");
    }
    let moves = check_choices(&file, arena.as_ref(), sets, &modes_of, &mut found);
    if !found.is_empty() {
        return Err(found.failed());
    }
    // Every part reads: the tables, against the arena, the tuples and the choices.
    let arena = arena.expect("an arena without problems");
    let ranks = Ranks::new(&arena);
    let tables = Tables::new(&arena, &ranks, file.tuples.len());
    let mut modes: Vec<Option<Entries>> = vec![None; sets];
    for (m, mode) in file.modes.iter().enumerate() {
        match tables.mode(&format!("$.modes[{m}]"), mode, &file, &moves) {
            Ok(entries) => modes[mode.set as usize] = Some(entries),
            Err((path, message)) => found.add(path, message),
        }
    }
    let adversary = tables
        .adversary(&file.adversary)
        .map_err(|(path, message)| found.add(path, message))
        .ok();
    let certificate = file.certificate.as_ref().and_then(|certificate| {
        tables
            .certificate(certificate)
            .map_err(|(path, message)| found.add(path, message))
            .ok()
    });
    if !found.is_empty() {
        return Err(found.failed());
    }
    let checked = Checked {
        file,
        arena,
        ranks,
        letters: letters.expect("labels without problems"),
        tuples: tuples.expect("tuples without problems"),
        modes,
        adversary: adversary.expect("an adversary table without problems"),
        moves,
        certificate,
    };
    if checked.file.scope == Scope::All
        && let Some((path, message)) = uncovered(&checked)
    {
        return Err(invalid(path, message));
    }
    Ok(checked)
}

/// For a file of scope `all`: the first place a play can reach that the file does not decide
/// at, if any, as (JSON path, message). A play is any walk of the product from h0 (the arena's
/// initial state, the automata stepped by the labels of the states entered), whoever moves:
/// each robot state it reaches needs a choice of the uncommitted mode; and from each robot state
/// where that choice commits to a set, each robot state the set's reactive moves reach, with
/// the adversary making any move, needs a move of the set's mode unless the set holds there.
/// Linear in the product states reached, times the modes.
fn uncovered(checked: &Checked) -> Option<(String, String)> {
    let (file, arena) = (&checked.file, &checked.arena);
    let count = file.tuples.len();
    let letters = file.labels.len();
    let mode_path = |set: u8| {
        let m = file.modes.iter().position(|mode| mode.set == set);
        format!("$.modes[{}].codes", m.unwrap_or_default())
    };
    let letter = |s: StateId| checked.letters[arena.label_id(s) as usize];
    // The tuple after reading `letter` from `automata` (the initial states: `None`), by index.
    let stepped = |automata: Option<&[u32]>, letter: usize| -> Result<usize, String> {
        let next: Vec<u32> = file
            .automata
            .iter()
            .enumerate()
            .map(|(i, a)| a.step[automata.map_or(a.initial, |q| q[i]) as usize][letter])
            .collect();
        checked.tuples.get(&next).copied().ok_or_else(|| {
            format!(
                "scope `all`, but the automata tuple {next:?}, which a play reaches, is missing"
            )
        })
    };
    // Tuple × letter → the next tuple, computed once each.
    let mut next: Vec<Option<usize>> = vec![None; count * letters];
    let initial = arena.initial();
    let start = match stepped(None, letter(initial)) {
        Ok(t) => t,
        Err(message) => return Some(("$.tuples".to_string(), message)),
    };
    // The search over (state, tuple, mode).
    let mut seen: Vec<Option<BitSet>> = vec![None; checked.modes.len()];
    let mut stack = vec![(initial, start, 0u8)];
    while let Some((s, t, mode)) = stack.pop() {
        let visited = seen[mode as usize]
            .get_or_insert_with(|| BitSet::with_capacity(arena.num_states() * count));
        if !visited.insert(s.index() * count + t) {
            continue;
        }
        let automata = &file.tuples[t];
        let missing = |what: &str| {
            format!(
                "scope `all`, but no {what} at `{}` with the automata at {automata:?}, which a \
                 play can reach",
                brief(arena.name(s))
            )
        };
        let entry = checked.ranks.of(s) * count + t;
        let successors: Vec<StateId> = match arena.owner(s) {
            Owner::Adversary => arena.edges(s).map(|(_, to)| to).collect(),
            Owner::Robot if mode == 0 => {
                let Some(choice) = checked.modes[0].as_ref().and_then(|m| m.get(entry)) else {
                    return Some((mode_path(0), missing("choice")));
                };
                if let Choice::Commit(set) | Choice::Stop(set) = file.choices[choice as usize] {
                    stack.push((s, t, set));
                }
                // Any robot move: the robot may slip.
                arena.edges(s).map(|(_, to)| to).collect()
            }
            Owner::Robot => {
                let holds = TaskSet(mode)
                    .iter()
                    .all(|i| file.automata[i].finals.contains(&automata[i]));
                if holds {
                    continue;
                }
                let table = checked.modes[mode as usize].as_ref();
                let Some(choice) = table.and_then(|m| m.get(entry)) else {
                    return Some((mode_path(mode), missing("reactive move")));
                };
                let action = checked.moves[choice as usize].expect("a committed mode moves");
                arena.successor(s, action).into_iter().collect()
            }
        };
        for to in successors {
            let l = letter(to);
            let u = match next[t * letters + l] {
                Some(u) => u,
                None => match stepped(Some(automata), l) {
                    Ok(u) => *next[t * letters + l].insert(u),
                    Err(message) => return Some(("$.tuples".to_string(), message)),
                },
            };
            stack.push((to, u, mode));
        }
    }
    None
}

/// Checks `believed` against `k` sub-tasks (`sets` of them); whether psi has its own
/// automaton.
fn check_believed(believed: &Believed, k: usize, sets: usize, found: &mut Found) -> bool {
    match (believed.set, believed.automaton) {
        (Some(set), None) => {
            if set == 0 || set as usize >= sets {
                found.add(
                    "$.believed.set",
                    format!("{set} is no non-empty set of the {k} sub-tasks"),
                );
            }
            false
        }
        (None, Some(automaton)) => {
            if automaton as usize != k {
                found.add(
                    "$.believed.automaton",
                    format!(
                        "psi's automaton is the one after the sub-tasks', {k}, not {automaton}"
                    ),
                );
            }
            true
        }
        _ => {
            found.add(
                "$.believed",
                "expected exactly one of `set` (psi is a conjunction of sub-tasks) and \
                 `automaton` (psi has its own)",
            );
            false
        }
    }
}

/// Checks the payoffs of the `sets` sets: finite, >= 0, 0 for the empty set, monotone;
/// the largest, when they are.
fn check_payoffs(file: &ControllerFile, sets: usize, found: &mut Found) -> Option<f64> {
    let payoffs = &file.payoffs;
    if sets == 0 {
        return None;
    }
    if payoffs.len() != sets {
        found.add(
            "$.payoffs",
            format!(
                "{} payoffs, where {} sub-tasks have {sets} sets",
                payoffs.len(),
                file.tasks.len()
            ),
        );
        return None;
    }
    let before = found.total;
    for (mask, &r) in payoffs.iter().enumerate() {
        if !(r.is_finite() && r >= 0.0) {
            found.add(
                format!("$.payoffs[{mask}]"),
                format!("{r} is not a payoff: expected a finite number >= 0"),
            );
        }
    }
    if payoffs[0] != 0.0 {
        found.add("$.payoffs[0]", "the empty set's payoff is 0");
    }
    if found.total > before {
        return None;
    }
    let k = file.tasks.len();
    let singles: Vec<f64> = (0..k).map(|i| payoffs[1 << i]).collect();
    let others: Vec<(TaskSet, f64)> = (1..sets)
        .filter(|mask: &usize| !mask.is_power_of_two())
        .map(|mask| (TaskSet(mask as u8), payoffs[mask]))
        .collect();
    let names: Vec<String> = file.tasks.iter().map(|n| brief(n).to_string()).collect();
    match SubsetPayoffs::new(&singles, &others, &names) {
        Ok(payoffs) => Some(payoffs.all()),
        Err(error) => {
            let mask = match &error {
                PayoffError::NotMonotone { smaller, .. } => smaller.0 as usize,
                PayoffError::Invalid { set, .. } => set.0 as usize,
                _ => 0,
            };
            found.add(format!("$.payoffs[{mask}]"), error);
            None
        }
    }
}

/// The arena of the file, or the path and message of its first error.
fn build_arena(source: &ArenaSource) -> Result<Arena, (String, String)> {
    match source {
        ArenaSource::Map(text) => {
            let path = "$.arena.map".to_string();
            let map = crate::arena::map::parse(text)
                .map_err(|e| (path.clone(), e.first().to_string()))?;
            map.build_without_display_names()
                .map_err(|e| (path, e.to_string()))
        }
        ArenaSource::Text(text) => crate::arena::parse(text)
            .map(|parsed| parsed.arena)
            .map_err(|e| ("$.arena.text".to_string(), e.first().to_string())),
    }
}

/// Checks sigma_L's weights (or a learnt sigma_L's counts, as weights) against the arena, as
/// a weight table is checked; errors are placed in `$.sigma_l.LIST`.
fn check_weights(arena: &Arena, weights: &[Weight], list: &str, found: &mut Found) {
    let mut table = WeightTable::new();
    for weight in weights {
        table.add(weight.state.clone(), weight.action.clone(), weight.weight);
    }
    let Err(errors) = table.check(arena) else {
        return;
    };
    for error in errors.as_slice() {
        let part = match error.part {
            EntryPart::State => "state",
            EntryPart::Action => "action",
            EntryPart::Weight => "weight",
        };
        let path = format!("$.sigma_l.{list}[{}].{part}", error.entry);
        match &error.error {
            EntryError::Duplicate { first, .. } => found.add(
                path,
                format_args!("{} (first at $.sigma_l.{list}[{first}])", error.error),
            ),
            other => found.add(path, other),
        }
    }
}

/// Checks the file's labels against the arena's: each a set of its propositions, all
/// distinct, one per label of the arena. The arena's label id → the file's letter, when they
/// are.
fn check_labels(arena: &Arena, labels: &[Vec<String>], found: &mut Found) -> Option<Vec<usize>> {
    let before = found.total;
    let mut letters: HashMap<Vec<&str>, usize> = HashMap::new();
    for (l, label) in labels.iter().enumerate() {
        let path = format!("$.labels[{l}]");
        let mut names: Vec<&str> = label.iter().map(String::as_str).collect();
        names.sort_unstable();
        if let Some(p) = names.iter().find(|p| arena.find_proposition(p).is_none()) {
            found.add(
                &path,
                format_args!("`{}` is no proposition of the arena", brief(p)),
            );
        } else if names.windows(2).any(|w| w[0] == w[1]) {
            found.add(&path, "a proposition is named twice");
        } else if let Some(first) = letters.insert(names, l) {
            found.add(&path, format_args!("the same letter as labels[{first}]"));
        }
    }
    let mut map = Vec::with_capacity(arena.labels().len());
    for label in arena.labels() {
        let mut names: Vec<&str> = label
            .iter()
            .map(|p| arena.propositions()[p].as_str())
            .collect();
        names.sort_unstable();
        match letters.get(&names) {
            Some(&l) => map.push(l),
            None => {
                found.add(
                    "$.labels",
                    format_args!(
                        "the arena's label {{{}}} is missing",
                        brief(names.join(" "))
                    ),
                );
                return None;
            }
        }
    }
    if labels.len() != arena.labels().len() && found.total == before {
        found.add(
            "$.labels",
            format!(
                "{} labels, where the arena has {}",
                labels.len(),
                arena.labels().len()
            ),
        );
    }
    (found.total == before).then_some(map)
}

/// Checks automaton `i`: named `name` (a sub-task's, or `psi`), a complete table over
/// `letters` letters, its states in range.
fn check_automaton(
    i: usize,
    automaton: &AutomatonTable,
    name: Option<&str>,
    letters: usize,
    found: &mut Found,
) {
    let path = format!("$.automata[{i}]");
    if let Some(name) = name
        && automaton.name != name
    {
        found.add(
            format!("{path}.name"),
            format_args!(
                "expected `{}`, found `{}`",
                brief(name),
                brief(&automaton.name)
            ),
        );
    }
    let n = automaton.step.len();
    if n == 0 {
        found.add(
            format!("{path}.step"),
            "an automaton has at least one state",
        );
        return;
    }
    if automaton.initial as usize >= n {
        found.add(
            format!("{path}.initial"),
            format!("{} is no state of the {n}", automaton.initial),
        );
    }
    let mut finals = HashSet::new();
    for (f, &q) in automaton.finals.iter().enumerate() {
        if q as usize >= n || !finals.insert(q) {
            found.add(
                format!("{path}.finals[{f}]"),
                format!("{q} is repeated or no state of the {n}"),
            );
        }
    }
    for (q, row) in automaton.step.iter().enumerate() {
        if row.len() != letters {
            found.add(
                format!("{path}.step[{q}]"),
                format!("{} entries, where there are {letters} labels", row.len()),
            );
        } else if let Some(l) = row.iter().position(|&t| t as usize >= n) {
            found.add(
                format!("{path}.step[{q}][{l}]"),
                format!("{} is no state of the {n}", row[l]),
            );
        }
    }
}

/// Checks the tuples: one state of each automaton, all distinct. Tuple → index, when they are.
fn check_tuples(file: &ControllerFile, found: &mut Found) -> Option<HashMap<Vec<u32>, usize>> {
    let before = found.total;
    let mut tuples = HashMap::with_capacity(file.tuples.len());
    for (t, tuple) in file.tuples.iter().enumerate() {
        let fits = tuple.len() == file.automata.len()
            && tuple
                .iter()
                .zip(&file.automata)
                .all(|(&q, a)| (q as usize) < a.step.len());
        if !fits {
            found.add(
                format!("$.tuples[{t}]"),
                format!(
                    "not one state of each of the {} automata",
                    file.automata.len()
                ),
            );
        } else if let Some(first) = tuples.insert(tuple.clone(), t) {
            found.add(
                format!("$.tuples[{t}]"),
                format!("the same tuple as tuples[{first}]"),
            );
        }
    }
    (found.total == before).then_some(tuples)
}

/// Checks the choices: moves name arena actions, commitments name non-empty sets of the
/// sub-tasks that have a mode. Per choice, the action of a move.
fn check_choices(
    file: &ControllerFile,
    arena: Option<&Arena>,
    sets: usize,
    modes: &HashSet<u8>,
    found: &mut Found,
) -> Vec<Option<ActionId>> {
    let mut moves = Vec::with_capacity(file.choices.len());
    for (c, choice) in file.choices.iter().enumerate() {
        let path = format!("$.choices[{c}]");
        moves.push(match choice {
            Choice::Move(name) => {
                let action = arena.map(|arena| arena.find_action(name));
                if action == Some(None) {
                    found.add(
                        format!("{path}.move"),
                        format_args!("`{}` is no action of the arena", brief(name)),
                    );
                }
                action.flatten()
            }
            Choice::Stop(set) | Choice::Commit(set) => {
                let verb = if matches!(choice, Choice::Stop(_)) {
                    "stop"
                } else {
                    "commit"
                };
                if *set == 0 || *set as usize >= sets {
                    found.add(
                        format!("{path}.{verb}"),
                        format!("{set} is no non-empty set of the sub-tasks"),
                    );
                } else if !modes.contains(set) {
                    found.add(
                        format!("{path}.{verb}"),
                        format!("set {set} has no mode to play once committed to"),
                    );
                }
                None
            }
            Choice::GiveUp => None,
        });
    }
    moves
}

/// The arena's states by owner and rank, for the tables' rows.
struct Tables<'a> {
    arena: &'a Arena,
    robot: Vec<StateId>,
    adversary: Vec<StateId>,
    tuples: usize,
}

impl<'a> Tables<'a> {
    fn new(arena: &'a Arena, ranks: &Ranks, tuples: usize) -> Tables<'a> {
        let (mut robot, mut adversary) = (
            Vec::with_capacity(ranks.robot as usize),
            Vec::with_capacity(ranks.adversary as usize),
        );
        for s in arena.states() {
            match arena.owner(s) {
                Owner::Robot => robot.push(s),
                Owner::Adversary => adversary.push(s),
            }
        }
        Tables {
            arena,
            robot,
            adversary,
            tuples,
        }
    }

    /// `table` (at `at`) decoded, with one entry per (state of `states`, tuple).
    fn decode(&self, at: &str, table: &Table, states: usize) -> Result<Entries, (String, String)> {
        if !(1..=11).contains(&table.width) {
            let message = format!(
                "{} digits per entry, where 1 to 11 are expected",
                table.width
            );
            return Err((format!("{at}.width"), message));
        }
        let path = format!("{at}.codes");
        let entries = table.decode().map_err(|message| (path.clone(), message))?;
        let rows = states.saturating_mul(self.tuples);
        if entries.len() != rows {
            let message = format!(
                "{} entries, where {states} states and {} tuples have {rows}",
                entries.len(),
                self.tuples
            );
            return Err((path, message));
        }
        Ok(entries)
    }

    /// Entry `i` of a table over the states `states`: the state and the tuple, as messages
    /// name them.
    fn entry(&self, states: &[StateId], i: usize) -> String {
        let (s, t) = (states[i / self.tuples], i % self.tuples);
        format!(
            "entry {i} (state `{}`, tuple {t})",
            brief(self.arena.name(s))
        )
    }

    /// A mode's table, decoded: every entry a choice; a move enabled at its state; a committed
    /// mode's entries moves.
    fn mode(
        &self,
        at: &str,
        mode: &super::export::Mode,
        file: &ControllerFile,
        moves: &[Option<ActionId>],
    ) -> Result<Entries, (String, String)> {
        let entries = self.decode(at, &mode.table, self.robot.len())?;
        let path = format!("{at}.codes");
        for i in 0..entries.len() {
            let Some(c) = entries.get(i) else {
                continue;
            };
            let problem = match file.choices.get(c as usize) {
                None => Some(format!("{c} is no choice of the {}", file.choices.len())),
                Some(choice) => match moves[c as usize] {
                    Some(action) => {
                        let s = self.robot[i / self.tuples];
                        self.arena.successor(s, action).is_none().then(|| {
                            format!(
                                "`{}` is not enabled there",
                                brief(self.arena.action_name(action))
                            )
                        })
                    }
                    None if mode.set != 0 => Some(format!(
                        "a committed mode only moves, not {}",
                        brief(serde_json::to_string(choice).unwrap_or_default())
                    )),
                    None => None,
                },
            };
            if let Some(problem) = problem {
                return Err((path, format!("{}: {problem}", self.entry(&self.robot, i))));
            }
        }
        Ok(entries)
    }

    /// A certificate's tables, decoded: the values non-negative finite doubles, `lower` and
    /// `upper` lists of indices of values, without absent entries.
    fn certificate(
        &self,
        certificate: &CertificateTables,
    ) -> Result<CertificateEntries, (String, String)> {
        let at = "$.certificate";
        let table = &certificate.values;
        if table.width != 11 {
            let message = format!("{} digits per value, where a double takes 11", table.width);
            return Err((format!("{at}.values.width"), message));
        }
        let path = format!("{at}.values.codes");
        let entries = table.decode().map_err(|message| (path.clone(), message))?;
        let mut values = Vec::with_capacity(entries.len());
        for i in 0..entries.len() {
            let value = entries.get(i).map(f64::from_bits);
            match value {
                Some(value) if value.is_finite() && value.is_sign_positive() => values.push(value),
                _ => {
                    let shown = value.map_or("nothing".to_string(), |v| v.to_string());
                    let message =
                        format!("value {i} is {shown}, where a finite number >= 0 is expected");
                    return Err((path, message));
                }
            }
        }
        let list = |part: &str, table: &Table| {
            let path = format!("{at}.{part}.codes");
            let entries = table.decode().map_err(|message| (path.clone(), message))?;
            (0..entries.len())
                .map(|i| match entries.get(i) {
                    Some(v) if (v as usize) < values.len() => Ok(values[v as usize]),
                    Some(_) => Err((
                        path.clone(),
                        format!("entry {i} is no index of the {} values", values.len()),
                    )),
                    None => Err((path.clone(), format!("entry {i} is absent"))),
                })
                .collect::<Result<Vec<f64>, _>>()
        };
        Ok(CertificateEntries {
            lower: list("lower", &certificate.lower)?,
            upper: list("upper", &certificate.upper)?,
        })
    }

    /// The adversary table, decoded: an entry per adversary state with moves and no other,
    /// each marking moves the state has, at least one.
    fn adversary(&self, table: &Table) -> Result<Entries, (String, String)> {
        let path = "$.adversary.codes";
        let entries = self.decode("$.adversary", table, self.adversary.len())?;
        for i in 0..entries.len() {
            let Some(entry) = entries.get(i) else {
                continue;
            };
            let s = self.adversary[i / self.tuples];
            let edges = self.arena.edges(s).len();
            let moves = entry >> 1;
            let problem = if edges == 0 {
                Some("the state has no moves, and so no entry".to_string())
            } else if edges > MAX_MASKED_EDGES {
                (moves != u64::MAX >> 1).then(|| {
                    format!(
                        "a state of more than {MAX_MASKED_EDGES} moves has every move marked possible"
                    )
                })
            } else if moves == 0 || moves >> edges != 0 {
                Some(format!(
                    "the moves marked possible are not a non-empty set of the state's {edges}"
                ))
            } else {
                None
            };
            if let Some(problem) = problem {
                let message = format!("{}: {problem}", self.entry(&self.adversary, i));
                return Err((path.to_string(), message));
            }
        }
        Ok(entries)
    }
}
