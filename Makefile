# The two commands of the README: `make demo` and `make test` (pytest, the import layers, ruff, ESLint);
# both set themselves up first.
.PHONY: setup demo test bench

# Python keeps its compiled bytecode (in __pycache__, which git ignores): without it every one of the
# hundred tablebot processes the tests start compiles numpy, numba and tablebot again, seconds each.
unexport PYTHONDONTWRITEBYTECODE

setup:
	@./scripts/bootstrap.sh

demo: setup
	.venv/bin/tablebot sim examples/bumberbot --out out/demo

# pytest twice: every test but the wall-clock ones on all cores (tests/conftest.py compiles numba's kernels
# once first), then the wall-clock ones (marked realtime there) two at a time with nothing CPU-bound beside
# them but mypy at the lowest priority (nice 19). The wall-clock tests mostly wait on the clock (14 CPU-s in
# 56 s one by one; 31-34 s two at a time, passing even beside two busy loops at normal priority), so mypy's
# 45 s of CPU from an empty cache (the sources, tests and benchmarks) mostly fit in what they leave idle; its
# report is printed after the pass.
test: setup
	.venv/bin/python -m pytest -n auto --dist loadgroup -m "not realtime" --durations=15
	@log=$$(mktemp); nice -n 19 .venv/bin/mypy >"$$log" 2>&1 & mypy=$$!; \
	echo '.venv/bin/python -m pytest -n 2 -m realtime --durations=5  (and .venv/bin/mypy)'; \
	.venv/bin/python -m pytest -n 2 -m realtime --durations=5; tests=$$?; \
	wait $$mypy; types=$$?; echo ".venv/bin/mypy"; cat "$$log"; rm -f "$$log"; \
	[ $$tests -eq 0 ] && [ $$types -eq 0 ]
	.venv/bin/lint-imports
	.venv/bin/ruff check .
	node_modules/.bin/eslint src/tablebot/web/static eslint.config.js

bench: setup
	status=0; for b in engine sim check mcu turn_drift studio fleet evolve controllers; do .venv/bin/python benchmarks/$$b.py || status=1; done; exit $$status
