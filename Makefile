# The two commands of the README: `make demo` and `make test`; both set themselves up first.
.PHONY: setup demo test lint bench

setup:
	@./scripts/bootstrap.sh

demo: setup
	.venv/bin/tablebot demo

test: setup
	.venv/bin/python -m pytest
	.venv/bin/ruff check .

bench: setup
	.venv/bin/python benchmarks/engine.py
