# The two commands of the README: `make demo` and `make test` (pytest, the import layers, ruff, ESLint);
# both set themselves up first.
.PHONY: setup demo test bench

setup:
	@./scripts/bootstrap.sh

demo: setup
	.venv/bin/tablebot sim examples/bumberbot --out out/demo

test: setup
	.venv/bin/python -m pytest
	.venv/bin/lint-imports
	.venv/bin/ruff check .
	node_modules/.bin/eslint src/tablebot/web/static eslint.config.js

bench: setup
	status=0; for b in engine sim check mcu turn_drift studio fleet evolve controllers; do .venv/bin/python benchmarks/$$b.py || status=1; done; exit $$status
