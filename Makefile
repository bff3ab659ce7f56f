# Build, test and check hypersynth; regenerate and run the bundled case study.
CARGO ?= cargo

.PHONY: build test check

build:
	$(CARGO) build --release

test:
	$(CARGO) test

check:
	$(CARGO) fmt --check
	$(CARGO) clippy --all-targets -- -D warnings
	$(CARGO) test

# The case study's arena. The generator's parameters live only in gridworld.args, which this
# rule and tests/gridworld_cli.rs both read.
CASE_STUDY := specs/case-study
SOURCES := Cargo.toml Cargo.lock $(shell find src -name '*.rs')

.PHONY: arena-case-study
arena-case-study: $(CASE_STUDY)/arena.txt

$(CASE_STUDY)/arena.txt: $(CASE_STUDY)/gridworld.args $(SOURCES)
	$(CARGO) run --release --quiet -- gridworld $$(cat $<) -o $@
