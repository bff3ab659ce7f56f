//! The text report: one layout for both vocabularies, read from the report's data and its
//! [`Presentation`]'s words and [`Layout`].

use std::fmt;

use super::games::{ArenaSummary, AutomatonSummary, Games};
use super::synthesis::{InitialDecision, RobustSummary, SolverSummary, Synthesis, moves, number};
use crate::game::{Engine, States, TaskSet, WinLabel, label_text};
use crate::opportunistic::build::MdpSizes;
use crate::opportunistic::controller::Explanation;
use crate::opportunistic::presentation::{Layout, Presentation};

/// The whole text report: the games, then the MDP stage when there is one.
pub(super) fn write(
    f: &mut fmt::Formatter<'_>,
    p: &Presentation,
    games: &Games,
    synthesis: Option<&Synthesis>,
) -> fmt::Result {
    write_games(f, p, games)?;
    match synthesis {
        Some(synthesis) => write_synthesis(f, p, games, synthesis),
        None => Ok(()),
    }
}

/// A set of sub-tasks as the general form's lines write it: `{A,B}`.
fn set_text(set: &[String]) -> String {
    format!("{{{}}}", set.join(","))
}

/// The paper's win-label of h0, read from whether h0 is in each task's region.
fn initial_win_label(games: &Games) -> WinLabel {
    let realizable = |i: usize| games.regions.get(i).is_some_and(|r| r.realizable);
    WinLabel::new(realizable(0), realizable(1), realizable(2))
}

fn write_games(f: &mut fmt::Formatter<'_>, p: &Presentation, g: &Games) -> fmt::Result {
    let layout: &Layout = p.layout();
    write_arena(f, &g.arena)?;
    if let Some(phi) = p.whole_task() {
        writeln!(f, "phi            {phi}")?;
    }
    for (i, task) in g.tasks.iter().enumerate() {
        write_automaton(f, &p.task_title(i), &task.automaton)?;
    }
    let k = g.tasks.len();
    if layout.states_belief {
        let believed = &g.believed;
        match (&believed.tasks, &believed.automaton) {
            (Some(tasks), _) => writeln!(
                f,
                "believed psi   {}\n               the conjunction of {}: Win(psi) = Win({})",
                believed.formula,
                set_text(tasks),
                set_text(tasks)
            )?,
            (None, Some(dfa)) => write_automaton(f, "believed psi", dfa)?,
            (None, None) => writeln!(f, "believed psi   {}", believed.formula)?,
        }
        let payoffs: Vec<String> = TaskSet::non_empty(k)
            .zip(&g.payoffs)
            .map(|(set, p_set)| format!("{} = {}", p.payoff_name(set), p_set.payoff))
            .collect();
        writeln!(f, "payoffs        {}", payoffs.join(", "))?;
    }
    write_product(f, g.states, g.engine, g.product_states, g.product_edges)?;
    let regions: Vec<String> = TaskSet::non_empty(k)
        .zip(&g.regions)
        .map(|(set, region)| format!("|Win{}| = {}", p.region_name(set), region.states))
        .collect();
    writeln!(f, "winning        {}", regions.join(", "))?;
    if layout.states_belief {
        writeln!(f, "               |Win(psi)| = {}", g.believed_region)?;
    }
    writeln!(f)?;
    let rows = p.partition(&g.classes);
    let (heading, least) = layout.partition_heading;
    let label_width = rows
        .iter()
        .map(|row| row.text.chars().count())
        .chain([heading.len(), least])
        .max()
        .unwrap_or(0);
    let width = g.product_states.to_string().len().max("adversary".len());
    writeln!(
        f,
        "{heading:<label_width$} {:>width$} {:>width$} {:>width$}",
        "robot", "adversary", "total"
    )?;
    for row in &rows {
        let note = if row.possible { "" } else { "  (impossible)" };
        writeln!(
            f,
            "{:<label_width$} {:>width$} {:>width$} {:>width$}{note}",
            row.text, row.counts.robot, row.counts.adversary, row.counts.total
        )?;
    }
    writeln!(f)?;
    let i = &g.initial;
    if layout.win_labels {
        writeln!(f, "initial state  {}  {}", i.state, initial_win_label(g))?;
        let verdict = |set: TaskSet| match g.regions[set.0 as usize - 1].initial_rank {
            Some(rank) => format!("{}: yes (rank {rank})", p.set_name(set)),
            None => format!("{}: no", p.set_name(set)),
        };
        let all = TaskSet::all(k);
        let verdicts: Vec<String> = std::iter::once(all)
            .chain(TaskSet::non_empty(k).filter(|&set| set != all))
            .map(verdict)
            .collect();
        writeln!(f, "realizable     {}", verdicts.join(", "))?;
    } else {
        let settles = i
            .settles_for
            .as_ref()
            .map_or("nothing".to_string(), |set| set_text(set));
        writeln!(
            f,
            "initial state  {}  {}\n               guarantee {} (settles for {settles})",
            i.state,
            label_text(&i.maximal, i.psi),
            i.guarantee
        )?;
    }
    if layout.states_belief && !g.missing_propositions.is_empty() {
        writeln!(
            f,
            "always false   {} (carried by no arena state)",
            g.missing_propositions.join(", ")
        )?;
    }
    Ok(())
}

/// The MDP stage's part, after the games.
fn write_synthesis(
    f: &mut fmt::Formatter<'_>,
    p: &Presentation,
    g: &Games,
    s: &Synthesis,
) -> fmt::Result {
    let layout = p.layout();
    let settings = &s.settings;
    writeln!(f)?;
    writeln!(
        f,
        "adversary      sigma_W {}; sigma_L {} (seed {})",
        layout.sigma_w, settings.sigma_l, settings.seed
    )?;
    if layout.states_guarantees {
        writeln!(
            f,
            "settings       risk {}; discount {}",
            settings.risk.name(),
            settings.discount
        )?;
    } else {
        let payoffs: Vec<String> = TaskSet::non_empty(g.tasks.len())
            .zip(&g.payoffs)
            .map(|(set, payoff)| format!("{} = {}", p.payoff_name(set), payoff.payoff))
            .collect();
        writeln!(
            f,
            "payoffs        {}; discount {}",
            payoffs.join(", "),
            settings.discount
        )?;
    }
    let m = &s.mdp;
    write!(
        f,
        "MDP            {} decision nodes (robot states): {} absorbing, {} with an opportunity, {} without ({} stuck)",
        m.robot_states, m.absorbing, m.with_opportunity, m.without_opportunity, m.stuck
    )?;
    match m.above_guarantee {
        Some(above) => writeln!(f, "; {above} worth more than their guarantee")?,
        None => writeln!(f)?,
    }
    write_model_and_solver(f, m, &s.solver, settings.epsilon)?;
    write_value(f, &s.decision, &action_text(layout, &s.decision))?;
    let outcomes: Vec<(String, u32)> = s.simulation.as_ref().map_or(Vec::new(), |sim| {
        sim.endings(p)
            .into_iter()
            .map(|(ending, count)| (p.ending(ending), count))
            .collect()
    });
    let trace_outcome = s
        .trace
        .as_ref()
        .map_or(String::new(), |trace| p.ending(trace.ending));
    write_details(f, s, &outcomes, &trace_outcome)
}

/// The controller's first decision at h0 in words.
fn action_text(layout: &Layout, d: &InitialDecision) -> String {
    let commits = d.commits_to.as_ref().filter(|_| layout.states_guarantees);
    match (&d.action, commits, d.adversary_first) {
        (Some(action), Some(set), _) => format!("{action}, committing to {}", set_text(set)),
        (Some(action), None, _) => action.clone(),
        (None, Some(set), _) => format!("none (absorbing: commits to {})", set_text(set)),
        (None, None, true) => "none (the adversary moves first)".to_string(),
        (None, None, false) if layout.states_guarantees => "none (nothing to gain)".to_string(),
        (None, None, false) => "none (absorbing)".to_string(),
    }
}

/// A task's line and its DFA's line.
fn write_automaton(f: &mut fmt::Formatter<'_>, title: &str, dfa: &AutomatonSummary) -> fmt::Result {
    writeln!(
        f,
        "{title:<14} {}\n               DFA: {}, {} ({}); {} reachable by arena labels",
        dfa.formula,
        counted(dfa.states, "state", "states"),
        counted(dfa.edges, "edge", "edges"),
        dfa.translator,
        dfa.enumerated_states
    )
}

/// `n` and the noun that agrees with it: `1 state`, `2 states`.
pub fn counted(n: usize, singular: &str, plural: &str) -> String {
    format!("{n} {}", if n == 1 { singular } else { plural })
}

/// The product's size line.
fn write_product(
    f: &mut fmt::Formatter<'_>,
    states: States,
    engine: Engine,
    product_states: usize,
    product_edges: usize,
) -> fmt::Result {
    let states = match states {
        States::Full => "full",
        States::Reachable => "reachable from h0",
    };
    writeln!(
        f,
        "product        {product_states} states, {product_edges} edges ({states}; {} engine)",
        engine.name()
    )
}

/// The arena's size line.
fn write_arena(f: &mut fmt::Formatter<'_>, a: &ArenaSummary) -> fmt::Result {
    writeln!(
        f,
        "arena          {} states ({} robot, {} adversary), {} transitions",
        a.states, a.robot_states, a.adversary_states, a.transitions
    )
}

/// The MDP line's continuation and the solver's line: the MDP's own size (chance nodes,
/// states, choices, transitions) and the solver's figures.
fn write_model_and_solver(
    f: &mut fmt::Formatter<'_>,
    m: &MdpSizes,
    solver: &SolverSummary,
    epsilon: f64,
) -> fmt::Result {
    writeln!(
        f,
        "               {} chance nodes (adversary states); {} states, {} choices, {} \
         transitions",
        m.chance_nodes, m.states, m.choices, m.transitions
    )?;
    writeln!(
        f,
        "solver         {} iterations, gap {:.1e} (epsilon {epsilon:e}), {} end components collapsed",
        solver.iterations, solver.gap, solver.end_components
    )
}

/// The value of h0 and the controller's line, `action` as the form words it.
fn write_value(f: &mut fmt::Formatter<'_>, d: &InitialDecision, action: &str) -> fmt::Result {
    writeln!(
        f,
        "value of h0    {} (upper bound {}), expected {} robot moves; action {action}",
        number(d.value),
        number(d.value_upper),
        moves(d.expected_moves)
    )?;
    writeln!(
        f,
        "controller     collects {} (upper bound {}), evaluated as a Markov chain",
        number(d.policy_value),
        number(d.policy_value_upper)
    )
}

/// The optional parts after the value: the decision table, the simulation (its outcome lines
/// as the form names them) and the trace (with its outcome as the form names it).
fn write_details(
    f: &mut fmt::Formatter<'_>,
    synthesis: &Synthesis,
    outcomes: &[(String, u32)],
    trace_outcome: &str,
) -> fmt::Result {
    if let Some(robust) = &synthesis.robust {
        write_robust(f, robust)?;
    }
    if let Some(table) = &synthesis.explanation {
        write_explanation(f, table)?;
    }
    if let Some(sim) = &synthesis.simulation {
        let options = sim.options;
        writeln!(f)?;
        writeln!(
            f,
            "simulation     {} runs, seed {}, at most {} steps",
            options.runs, options.seed, options.max_steps
        )?;
        for (outcome, count) in outcomes {
            writeln!(
                f,
                "  {outcome:<16} {count:>8}  {:>6.2}%",
                100.0 * f64::from(*count) / f64::from(options.runs.max(1))
            )?;
        }
        writeln!(
            f,
            "  mean payoff      {:.4}  95% CI [{:.4}, {:.4}]  (value of h0 {:.4})",
            sim.mean_payoff, sim.ci_low, sim.ci_high, synthesis.decision.value
        )?;
    }
    if let Some(trace) = &synthesis.trace {
        writeln!(f)?;
        writeln!(f, "trace")?;
        for (i, step) in trace.steps.iter().enumerate() {
            let committed = step
                .committed
                .as_ref()
                .map_or(String::new(), |t| format!("  [{t}]"));
            writeln!(
                f,
                "  {i:>4}  {}  {}  {}{committed}",
                step.state,
                step.label,
                step.action.as_deref().unwrap_or("-")
            )?;
        }
        writeln!(
            f,
            "  outcome {trace_outcome}, payoff {}",
            number(trace.payoff)
        )?;
    }
    Ok(())
}

/// The robust stage's block: what was learnt, both values of h0, the decision table at h0
/// with both, and the robust controller's simulation.
fn write_robust(f: &mut fmt::Formatter<'_>, r: &RobustSummary) -> fmt::Result {
    writeln!(f)?;
    writeln!(
        f,
        "learnt         sigma_L from {}: {} runs, {} observations counted ({} steps of sigma_W, {} misfits)",
        r.observations, r.runs, r.counted, r.sigma_w_steps, r.misfits
    )?;
    writeln!(
        f,
        "               delta {} over {} (state, action) pairs; {} of {} sigma_L states never observed",
        r.delta, r.pairs, r.never_observed, r.sigma_l_states
    )?;
    let action = |a: &Option<String>| a.clone().unwrap_or_else(|| "none".to_string());
    writeln!(
        f,
        "robust value   {} (upper bound {}), action {}; against the worst case the controller collects {}",
        number(r.value),
        number(r.value_upper),
        action(&r.action),
        number(r.worst_case_value)
    )?;
    writeln!(
        f,
        "nominal value  {} (upper bound {}), action {}",
        number(r.nominal_value),
        number(r.nominal_value_upper),
        action(&r.nominal_action)
    )?;
    if !r.choices.is_empty() {
        writeln!(f, "  {:<12} {:>12} {:>12}", "action", "robust", "nominal")?;
        for row in &r.choices {
            writeln!(
                f,
                "  {:<12} {:>12} {:>12}",
                row.action,
                number(row.robust),
                number(row.nominal)
            )?;
        }
    }
    if let Some(sim) = &r.simulation {
        writeln!(
            f,
            "  robust controller against sigma_L of the options: {} runs, mean payoff {:.4}  95% CI [{:.4}, {:.4}]",
            sim.runs, sim.mean_payoff, sim.ci_low, sim.ci_high
        )?;
    }
    if !r.learning_curve.is_empty() {
        writeln!(f)?;
        writeln!(
            f,
            "learning curve the values of h0 learnt from the first runs only (delta {})",
            r.delta
        )?;
        writeln!(
            f,
            "  {:>8} {:>12} {:>14} {:>12} {:>12}",
            "runs", "observations", "never observed", "robust", "nominal"
        )?;
        for point in &r.learning_curve {
            writeln!(
                f,
                "  {:>8} {:>12} {:>14} {:>12.4} {:>12.4}",
                point.runs, point.counted, point.never_observed, point.value, point.nominal_value
            )?;
        }
    }
    Ok(())
}

/// The decision table: per action, its value and its possible next states.
fn write_explanation(f: &mut fmt::Formatter<'_>, table: &Explanation) -> fmt::Result {
    writeln!(f)?;
    writeln!(
        f,
        "decision table of {}  {}  value {}, expected {} robot moves",
        table.state,
        table.label,
        number(table.value),
        moves(table.expected_moves)
    )?;
    if table.actions.is_empty() {
        writeln!(
            f,
            "  no decision: the state is absorbing or an adversary state"
        )?;
    }
    for row in &table.actions {
        writeln!(
            f,
            "  {:<6} value {}, expected {} robot moves",
            row.action,
            number(row.value),
            moves(row.expected_moves)
        )?;
        for outcome in &row.outcomes {
            writeln!(
                f,
                "         {:<24} {}  p = {}  value {}",
                outcome.state,
                outcome.label,
                number(outcome.probability),
                number(outcome.value)
            )?;
        }
    }
    writeln!(f, "  chosen: {}", table.chosen.as_deref().unwrap_or("-"))
}
