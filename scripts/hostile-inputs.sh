#!/bin/sh
# Times the inputs of issue 15 (and a few like them) on a hypersynth binary: wall time, CPU
# time (user + system, the fairer figure on a busy machine), peak memory (GNU time) and the
# outcome, each run cut off after LIMIT seconds. For the record only:
# crates/hypersynth/tests/hostile_inputs.rs checks the outcomes with counted limits, without a clock.
#
#   scripts/hostile-inputs.sh [BINARY] [LIMIT]     (default target/release/hypersynth, 60)
set -eu
binary=${1:-target/release/hypersynth}
limit=${2:-60}
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT

python3 - "$dir" <<'PY'
import sys
d = sys.argv[1]
def write(name, text):
    with open(f"{d}/{name}", "w") as f:
        f.write(text)
write("window.ltl", "F(a & XXXXXXXXXXXXXXXXXXXXXXb)")
write("release.ltl", "!a M (((a & ((!c & !XXXXXXXXXXXXXXXXXX(!c & d))))) U !b)")
for n in (300, 500, 1000, 3000):
    write(f"until{n}.ltl", " U ".join(f"a{i % 5}" for i in range(n)))
write("nextdisj24.ltl", "F(" + " | ".join(f"(p{i} & X q{i})" for i in range(24)) + ")")
write("eventually10.ltl", " & ".join(f"F p{i}" for i in range(10)))
write("eventually16.ltl", " & ".join(f"F p{i}" for i in range(16)))
write("untils12.ltl", " & ".join(f"(a{i} U b{i})" for i in range(12)))
def pairs(k):
    names = " ".join(f'"p{i}"' for i in range(2 * k))
    label = "&".join(f"({2 * i}|{2 * i + 1})" for i in range(k))
    return (f"HOA: v1\nStates: 2\nStart: 0\nAP: {2 * k} {names}\nAcceptance: 1 Inf(0)\n"
            f"--BODY--\nState: 0\n[{label}] 1\nState: 1 {{0}}\n[t] 1\n--END--\n")
write("pairs16.hoa", pairs(16))
write("pairs20.hoa", pairs(20))
names = " ".join(f'"p{i}"' for i in range(12))
edges = "".join(f"{i % 2}\n" for i in range(4096))
write("implicit4096.hoa", f"HOA: v1\nStates: 2\nStart: 0\nAP: 12 {names}\nAcceptance: 1 Inf(0)\n"
      f"--BODY--\nState: 0\n{edges}State: 1 {{0}}\n[t] 1\n--END--\n")
labels = " ".join(f"p{i}" for i in range(10 ** 6))
write("label1e6.arena", f"initial s\nstate s robot {{{labels}}}\n")
lines = ["initial s0", "state s0 robot {}", "state s1 adversary {}"]
for i in range(100_000):
    lines += [f"edge s0 x{i} s1", f"edge s1 x{i} s0"]
write("alternating100k.arena", "\n".join(lines) + "\n")
PY

run() {
    name=$1
    shift
    status=0
    /usr/bin/time -f "%e %U %S %M" -o "$dir/time" timeout "$limit" "$@" >"$dir/out" 2>"$dir/err" \
        || status=$?
    # GNU time puts "Command exited with non-zero status N" first when the command fails.
    read -r seconds user system kilobytes <<TIME
$(tail -n 1 "$dir/time")
TIME
    case $status in
        0) outcome=answer ;;
        124) outcome="cut off at $limit s" ;;
        *) outcome="error: $(grep -m1 'error' "$dir/err" | cut -c1-110)" ;;
    esac
    cpu=$(echo "$user + $system" | bc)
    printf '%-22s %7s s wall %7s s CPU %6s MB  %s\n' "$name" "$seconds" "$cpu" \
        "$((kilobytes / 1024))" "$outcome"
}

translate() {
    run "$1" "$binary" translate --translator builtin -q "$(cat "$dir/$1")"
}
for formula in window.ltl release.ltl until300.ltl until500.ltl until1000.ltl until3000.ltl \
    nextdisj24.ltl eventually10.ltl eventually16.ltl untils12.ltl; do
    translate "$formula"
done
for file in pairs16.hoa pairs20.hoa implicit4096.hoa; do
    run "$file" "$binary" hoa "$dir/$file"
done
for file in label1e6.arena alternating100k.arena; do
    run "$file" "$binary" arena "$dir/$file"
done
