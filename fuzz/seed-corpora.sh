#!/bin/sh
# Builds fuzz/corpus/<target>/ from the repository's fixtures and fuzz/seeds/<target>/:
# the 300 formulas and Spot automata of tests/fixtures/spot, the HOA snapshots, the bundled
# case study's arena, and the controllers the bundled examples export, each followed by the
# start of a play as the `controller` target reads it (written by the hypersynth command
# $HYPERSYNTH, or by one built here). libFuzzer adds what it finds to these directories
# (ignored by git).
set -eu
cd "$(dirname "$0")"
root=..
for target in ltl hoa arena map weights observations pipeline controller; do
    mkdir -p "corpus/$target"
    cp seeds/"$target"/* "corpus/$target/"
done
n=0
while IFS= read -r formula; do
    n=$((n + 1))
    printf '%s' "$formula" > "corpus/ltl/fixture-$n.ltl"
done < "$root/tests/fixtures/spot/formulas.ltl"
cp "$root"/tests/fixtures/spot/hoa/*.hoa \
    "$root"/crates/hypersynth/tests/automata/hoa/snapshots/*.hoa corpus/hoa/
cp "$root/specs/case-study/arena.txt" corpus/arena/case-study.arena
# The documented example arena: the first text block after "## Arena format" in docs/formats.md.
awk '/^## Arena format/ {section = 1} section && /^```text/ {inside = 1; next}
     inside && /^```/ {exit} inside {print}' "$root/docs/formats.md" > corpus/arena/formats.arena
# The examples' controllers from their maps (their arena texts are longer than the 8 KiB
# inputs scripts/fuzz-all allows).
if [ -z "${HYPERSYNTH:-}" ]; then
    cargo build --quiet --manifest-path "$root/Cargo.toml"
    HYPERSYNTH=$(cargo metadata --format-version 1 --no-deps --manifest-path "$root/Cargo.toml" |
        sed -n 's/.*"target_directory":"\([^"]*\)".*/\1/p')/debug/hypersynth
fi
export_controller() { # name, options... (the map last)
    name=$1
    shift
    "$HYPERSYNTH" -q "$@" --export-controller "corpus/controller/$name" >/dev/null
    printf '((0,2),(4,2),0)\n((0,3),(4,2),1)\n((0,3),(4,1),0)\n((0,4),(4,1),1)\n' \
        >>"corpus/controller/$name"
}
specs=$root/specs
export_controller case-study --phi '(!O U A) & (!O U B)' --psi '!O U A' "$specs/case-study/map.txt"
export_controller case-study-uniform --phi '(!O U A) & (!O U B)' --psi '!O U A' \
    --discount 0.99 --sigma-l uniform "$specs/case-study/map.txt"
export_controller decoy --task 'A=!O U A' --task 'B=!O U B' --payoff A=200 --payoff B=100 \
    --believed 'F C' --discount 0.95 "$specs/decoy/map.txt"
export_controller three-tasks --task 'A=!O U A' --task 'B=!O U B' --task 'C=F C' \
    --payoff A=200 --payoff B=100 --payoff C=50 --payoff A,B,C=500 --believed '!O U A' \
    --risk strict --sigma-l uniform "$specs/decoy/map.txt"
export_controller learnt --phi '(!O U A) & (!O U B)' --psi '!O U A' --discount 0.99 \
    --observations "$specs/learnt/runs.txt" "$specs/case-study/map.txt"
echo "corpus: $(ls corpus/ltl | wc -l) ltl, $(ls corpus/hoa | wc -l) hoa, $(ls corpus/arena | wc -l) arena, $(ls corpus/map | wc -l) map, $(ls corpus/weights | wc -l) weights, $(ls corpus/observations | wc -l) observations, $(ls corpus/pipeline | wc -l) pipeline, $(ls corpus/controller | wc -l) controller"
