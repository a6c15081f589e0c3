# The two commands: `make run` and `make test`.
CARGO ?= cargo
# Mesa's WSI complains without it; nothing here opens a window.
export XDG_RUNTIME_DIR ?= /tmp

.PHONY: run test check-web setup build bench clean

setup:
	@bash scripts/setup.sh

build: setup
	$(CARGO) build --release --locked

# Compare the baseline techniques on the default scene; writes report/index.html.
run: build
	./target/release/shadowlab compare --out report

# The whole suite, GPU tests included (lavapipe where there is no GPU), then the web build's
# check: the library crates compile for wasm32 (WebGPU), docs/web.md.
test: setup
	$(CARGO) test --workspace --locked
	$(MAKE) --no-print-directory check-web

check-web: setup
	$(CARGO) check --locked --target wasm32-unknown-unknown -p shadowlab-core -p shadowlab-gpu

bench: build
	./target/release/shadowlab bench --out bench.md

clean:
	$(CARGO) clean
	rm -rf report
