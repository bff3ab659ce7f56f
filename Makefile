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
