mod case_study;
mod hypergame_hand;
mod hypergame_props;
