# Build, test and check hypersynth; regenerate and run the bundled case study.
CARGO ?= cargo

.PHONY: build test check

build:
	$(CARGO) build --release

# Every test: the Rust suite, then the Python package's (built in a fresh virtualenv).
test:
	$(CARGO) test
	scripts/test-python

check:
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings
	$(MAKE) test

# The case study's arena. The generator's parameters live only in gridworld.args, which this
# rule and tests/gridworld_cli.rs both read.
CASE_STUDY := specs/case-study
SOURCES := Cargo.toml Cargo.lock crates/hypersynth/Cargo.toml $(shell find src crates/hypersynth/src -name '*.rs')

.PHONY: arena-case-study
arena-case-study: $(CASE_STUDY)/arena.txt

$(CASE_STUDY)/arena.txt: $(CASE_STUDY)/gridworld.args $(SOURCES)
	$(CARGO) run --release --quiet -- gridworld $$(cat $<) -o $@

# The case study's games report, pinned by tests/games_cli.rs.
.PHONY: games-case-study
games-case-study: $(CASE_STUDY)/games.txt

$(CASE_STUDY)/games.txt: $(CASE_STUDY)/arena.txt $(SOURCES)
	$(CARGO) run --release --quiet -- --phi '(!O U A) & (!O U B)' --psi '!O U A' \
		--translator builtin --games-only $< -o $@
# The case study's opportunistic reports (the main form's default, then discounted with a
# uniform sigma_L, where N is strictly best from h0), with the decision table of h0 and a
# seeded simulation. Each report is written atomically (-o): an interrupted run leaves the old
# report, never half of a new one.
CASE_STUDY_TASKS := --phi '(!O U A) & (!O U B)' --psi '!O U A'

# The case study's pictures, drawn from its map (tests/map_cli.rs checks that the map yields
# arena.txt): the map, the win-labels at h0's automaton states and adversary cell with the
# controller's moves, and one seeded run; discounted with a uniform sigma_L, as in
# report-discounted.txt; and the explorer page (explorer.html) with the same settings. Each file
# is written atomically.
CASE_STUDY_PICTURES := --translator builtin --discount 0.99 --sigma-l uniform

# The guide's screenshot of the case study's explorer, playing the adversary (E, W, W from h0),
# in headless Chromium through the browser tests' driver (needs `npm ci` in tests/browser).
.PHONY: explorer-screenshot
explorer-screenshot: $(CASE_STUDY)/explorer.html
	node tests/browser/explorer.mjs screenshot $< $(CASE_STUDY)/explorer.png play 4,1 3,1 2,1 \
		> /dev/null

.PHONY: case-study
case-study: $(CASE_STUDY)/arena.txt
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/map.txt --games-only \
		--translator builtin --svg $(CASE_STUDY)/map.svg --picture map > /dev/null
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/map.txt \
		$(CASE_STUDY_PICTURES) --svg $(CASE_STUDY)/partition.svg --picture partition > /dev/null
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/map.txt \
		$(CASE_STUDY_PICTURES) --svg $(CASE_STUDY)/trace.svg --picture trace > /dev/null
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/map.txt \
		$(CASE_STUDY_PICTURES) --html $(CASE_STUDY)/explorer.html > /dev/null
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/arena.txt \
		--explain --simulate 10000 -o $(CASE_STUDY)/report.txt
	$(CARGO) run --release --quiet -- $(CASE_STUDY_TASKS) $(CASE_STUDY)/arena.txt \
		--discount 0.99 --sigma-l uniform --explain --simulate 10000 \
		--export-mdp $(CASE_STUDY)/mdp-discounted.drn -o $(CASE_STUDY)/report-discounted.txt

# An adversary learnt from observations (specs/learnt, docs/guide.md "An adversary learnt
# from observations"): the truth is a known non-uniform sigma_L (truth.txt, from the case
# study's arena: where IDroid believes it has lost it stays 6 times and steps south 3 times as
# often as it takes any other move), 1000 runs recorded against it (seeded), the learning curve
# from their first 1, 2, 5, ... runs (table in report.txt, picture curve.svg and curve.png), and
# the robust controller simulated against the truth beside the robust and nominal values
# (report.txt). Each file is written atomically.
LEARNT := specs/learnt
LEARNT_OPTIONS := $(CASE_STUDY_TASKS) --discount 0.99 --adversary $(LEARNT)/truth.txt

.PHONY: learnt
$(LEARNT)/truth.txt: $(CASE_STUDY)/arena.txt
	awk '/^edge/ && $$2 ~ /,1\)"$$/ { w = ($$3 == "STAY") ? 6 : ($$3 == "S") ? 3 : 1; \
		print $$2, $$3, w }' $< > $@.tmp && mv $@.tmp $@

learnt: $(CASE_STUDY)/arena.txt $(LEARNT)/truth.txt
	$(RUN) $(LEARNT_OPTIONS) --seed 1 --simulate 1000 --record $(LEARNT)/runs.txt $< \
		> /dev/null
	$(RUN) $(LEARNT_OPTIONS) --observations $(LEARNT)/runs.txt --simulate 10000 --explain \
		--learning-curve $(LEARNT)/curve.svg --learning-curve-png $(LEARNT)/curve.png \
		--dpi 96 $< -o $(LEARNT)/report.txt

# The pipeline: formula file -> one HOA file per task -> synthesis from the HOA files -> JSON
# report. Line N of the formula file (comments and blank lines aside) is task phiN. Every step
# is a file with its prerequisites, so a second `make pipeline` rebuilds nothing
# (scripts/pipeline-example shows it). The translator is `auto`: Spot's ltl2tgba when installed.
PIPELINE_TASKS := specs/pipeline/tasks.ltl
PIPELINE := target/pipeline
HYPERSYNTH := target/release/hypersynth

.PHONY: pipeline
pipeline: $(PIPELINE)/report.json

# cargo leaves the binary alone when nothing changed; touch it so make sees it as up to date.
$(HYPERSYNTH): $(SOURCES)
	$(CARGO) build --release --quiet
	touch $@

$(PIPELINE)/phi%.hoa: $(PIPELINE_TASKS) $(HYPERSYNTH)
	@mkdir -p $(@D)
	grep -v -e '^[[:space:]]*#' -e '^[[:space:]]*$$' $< | sed -n '$*p' \
		| $(HYPERSYNTH) translate -q -F - -o $@

$(PIPELINE)/report.json: $(PIPELINE)/phi1.hoa $(PIPELINE)/phi2.hoa $(CASE_STUDY)/arena.txt \
		$(HYPERSYNTH)
	$(HYPERSYNTH) -q --phi1-hoa $(PIPELINE)/phi1.hoa --phi2-hoa $(PIPELINE)/phi2.hoa \
		--format json $(CASE_STUDY)/arena.txt -o $@

# Beyond the paper (docs/guide.md "Beyond the paper"): the case study's grid with a third
# labelled cell C at (2,0). specs/decoy: the adversary believes the robot is heading for the decoy C; the
# reports compare that belief with a correctly informed adversary, at g = 1 and g = 0.95.
# specs/three-tasks: three sub-tasks with a bonus for all three, the adversary knowing one, on
# the same arena. The reports read arena.txt; the pictures are drawn from map.txt, which gives
# the same arena (tests/subtasks_cli.rs), with the reports' options at g = 1 unless named
# (tests/subtasks_render.rs checks that the committed SVGs are current). Every file is written
# atomically.
DECOY := specs/decoy
THREE := specs/three-tasks
DECOY_TASKS := --task 'A=!O U A' --task 'B=!O U B' --payoff A=200 --payoff B=100 \
	--sigma-l uniform --explain
THREE_TASKS := --task 'A=!O U A' --task 'B=!O U B' --task 'C=F C' --payoff A=200 --payoff B=100 \
	--payoff C=50 --payoff A,B,C=500 --believed '!O U A' --sigma-l uniform --explain
RUN := $(CARGO) run --release --quiet -- -q

.PHONY: decoy three-tasks
$(DECOY)/arena.txt: $(DECOY)/gridworld.args $(SOURCES)
	$(CARGO) run --release --quiet -- gridworld $$(cat $<) -o $@

decoy: $(DECOY)/arena.txt
	for g in 1 0.95; do \
		$(RUN) $(DECOY_TASKS) --believed 'F C' --discount $$g \
			$< -o $(DECOY)/report-decoy-g$$g.txt && \
		$(RUN) $(DECOY_TASKS) --believed '(!O U A) & (!O U B)' \
			--discount $$g $< -o $(DECOY)/report-informed-g$$g.txt || exit 1; \
	done
	$(RUN) $(DECOY_TASKS) --believed 'F C' $(DECOY)/map.txt --games-only \
		--svg $(DECOY)/map.svg --picture map > /dev/null
	$(RUN) $(DECOY_TASKS) --believed 'F C' $(DECOY)/map.txt \
		--svg $(DECOY)/partition-decoy.svg --picture partition > /dev/null
	$(RUN) $(DECOY_TASKS) --believed '(!O U A) & (!O U B)' $(DECOY)/map.txt \
		--svg $(DECOY)/partition-informed.svg --picture partition > /dev/null
	$(RUN) $(DECOY_TASKS) --believed 'F C' $(DECOY)/map.txt \
		--svg $(DECOY)/trace-decoy.svg --picture trace > /dev/null
	$(RUN) $(DECOY_TASKS) --believed 'F C' $(DECOY)/map.txt --html $(DECOY)/explorer.html \
		> /dev/null

three-tasks: $(DECOY)/arena.txt
	for g in 1 0.95; do for risk in paper strict; do \
		$(RUN) $(THREE_TASKS) --risk $$risk --discount $$g \
			$< -o $(THREE)/report-$$risk-g$$g.txt || exit 1; \
	done; done
	$(RUN) $(THREE_TASKS) $(DECOY)/map.txt --svg $(THREE)/partition.svg --picture partition \
		> /dev/null
	$(RUN) $(THREE_TASKS) $(DECOY)/map.txt --svg $(THREE)/trace.svg --picture trace > /dev/null
	$(RUN) $(THREE_TASKS) --discount 0.95 $(DECOY)/map.txt --svg $(THREE)/value-g0.95.svg \
		--picture value > /dev/null
	$(RUN) $(THREE_TASKS) --discount 0.95 $(DECOY)/map.txt --html $(THREE)/explorer.html \
		> /dev/null
