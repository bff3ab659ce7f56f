//! From co-safe LTL to a minimal complete DFA: the `Translator` trait, the built-in translation
//! and the one that runs Spot's `ltl2tgba`.
