# The two commands: `make run` and `make test`.
CARGO ?= cargo
# Mesa's WSI complains without it; nothing here opens a window.
export XDG_RUNTIME_DIR ?= /tmp

.PHONY: run test web check-web setup build bench clean

setup:
	@bash scripts/setup.sh

build: setup
	$(CARGO) build --release --locked

# Compare the baseline techniques on the default scene; writes report/index.html.
run: build
	./target/release/shadowlab compare --out report

# The whole suite, GPU tests included (lavapipe where there is no GPU), and the page in headless
# Chromium (crates/shadowlab-web/tests/page.rs, after `make web`).
test: setup web
	$(CARGO) test --workspace --locked

# The lab on the web: a static site in web/dist (any static file server, offline), docs/web.md.
WASM := target/wasm32-unknown-unknown/release/shadowlab_web.wasm
web: setup
	$(CARGO) build --release --locked --target wasm32-unknown-unknown -p shadowlab-web
	rm -rf web/dist && mkdir -p web/dist
	wasm-bindgen --target web --out-dir web/dist/pkg $(WASM)
	cp web/index.html web/main.js web/dist/
	@echo "web: web/dist ($$(du -k web/dist/pkg/shadowlab_web_bg.wasm | cut -f1) KiB of wasm); serve it, e.g. python3 -m http.server -d web/dist"

# The library crates alone for wasm32 (quicker than `make web`).
check-web: setup
	$(CARGO) check --locked --target wasm32-unknown-unknown -p shadowlab-core -p shadowlab-gpu

bench: build
	./target/release/shadowlab bench --out bench.md

clean:
	$(CARGO) clean
	rm -rf report web/dist
