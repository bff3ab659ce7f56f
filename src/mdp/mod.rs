//! The hypergame MDP: adversary models, construction, certified value iteration and the
//! opportunistic policy.
