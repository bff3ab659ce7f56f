#!/bin/sh
# Builds fuzz/corpus/<target>/ from the repository's fixtures and fuzz/seeds/<target>/:
# the 300 formulas and Spot automata of tests/fixtures/spot, the HOA snapshots, and the
# bundled case study's arena. libFuzzer adds what it finds to these directories (ignored by git).
set -eu
cd "$(dirname "$0")"
root=..
for target in ltl hoa arena map weights observations pipeline; do
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
# The README's example arena: the first text block after "## Arena format".
awk '/^## Arena format/ {section = 1} section && /^```text/ {inside = 1; next}
     inside && /^```/ {exit} inside {print}' "$root/README.md" > corpus/arena/readme.arena
echo "corpus: $(ls corpus/ltl | wc -l) ltl, $(ls corpus/hoa | wc -l) hoa, $(ls corpus/arena | wc -l) arena, $(ls corpus/map | wc -l) map, $(ls corpus/weights | wc -l) weights, $(ls corpus/observations | wc -l) observations, $(ls corpus/pipeline | wc -l) pipeline"
