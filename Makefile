# The two commands of the README: `make demo` and `make test` (pytest, the import layers, ruff's lint and format, the docs site, ESLint);
# both set themselves up first.
.PHONY: setup demo test bench lock audit docs golden

# Python keeps its compiled bytecode (in __pycache__, which git ignores): without it every one of the
# hundred tablebot processes the tests start compiles numpy, numba and tablebot again, seconds each.
unexport PYTHONDONTWRITEBYTECODE

setup:
	@./scripts/bootstrap.sh

# The demo sets up only what a user's commands need (scripts/bootstrap.sh user: Python packages from PyPI, no
# sudo, no system packages, no developer tools) and shows the simulated BumberBot: scripts/demo.sh.
demo:
	@./scripts/demo.sh

# pytest twice: every test but the wall-clock ones on all cores (tests/conftest.py compiles numba's kernels
# once first), then the wall-clock ones (marked realtime there) two at a time with nothing CPU-bound beside
# them but the checks that read the code at the lowest priority (nice 19: scripts/checks.sh). The wall-clock
# tests mostly wait on the clock (14 CPU-s in 56 s one by one; 31-34 s two at a time, passing even beside two
# busy loops at normal priority), so mypy's 45 s of CPU from an empty cache (the sources, tests and benchmarks),
# lint-imports, ruff, the docs site and ESLint mostly fit in what they leave idle; their reports are printed after
# the pass.
test: setup
	@mkdir -p build/coverage
	.venv/bin/python -m pytest -n auto --dist loadgroup -m "not realtime" --durations=15 -rs \
	  --cov --cov-report=
	@echo "coverage of the pass above, least covered first (all: .venv/bin/coverage html, then build/coverage/html):"
	@.venv/bin/coverage report | sed -n 1,27p; .venv/bin/coverage report --format=total | sed 's/^/total: /;s/$$/ %/'
	@# the wall-clock tests, with mypy, lint-imports, ruff, the docs site and ESLint beside them (niced)
	scripts/checks.sh $(MKDOCS)

# The documentation site, from docs/ (mkdocs.yml) into site/: strict, so a warning fails it, a link, anchor or
# file that is not there and a page made from the code (scripts/docs_reference.py) that is out of date included.
MKDOCS = NO_MKDOCS_2_WARNING=1 .venv/bin/mkdocs build --strict --quiet
docs: setup
	$(MKDOCS)

# The golden files of tests/golden/ (what tablebot writes for the BumberBot, compared byte for byte by
# tests/project/test_golden.py) made again from the code as it is: review them with git diff, then commit them.
golden: setup
	.venv/bin/python scripts/golden.py

bench: setup
	status=0; for b in engine sim check limits mcu turn_drift studio studio_tabs fleet evolve controllers statecharts harness_several demo; do .venv/bin/python benchmarks/$$b.py || status=1; done; exit $$status

# The Python lock, requirements/dev.lock (what `make setup` installs): pyproject.toml's packages with the dev
# extra, resolved once for every platform and Python 3.11+, with their hashes. Pins already in the lock are
# kept unless pyproject.toml now refuses them; `make lock UPGRADE=1` moves every package to its newest allowed
# version. Written beside the lock and renamed over it: a failed resolution leaves the old lock as it was.
# requirements/user.lock (what `make demo` installs) is the same for the packages without the extras, held
# to dev.lock's versions: a user and the tests run the same numpy, numba, ...
lock:
	@[ -x .venv/bin/uv ] || ./scripts/bootstrap.sh
	cp requirements/dev.lock requirements/.dev.lock.tmp
	.venv/bin/uv pip compile pyproject.toml --extra dev --universal --python-version 3.11 --generate-hashes \
	  --custom-compile-command "make lock" $(if $(UPGRADE),--upgrade) -q -o requirements/.dev.lock.tmp \
	  || { rm -f requirements/.dev.lock.tmp; exit 1; }
	mv requirements/.dev.lock.tmp requirements/dev.lock
	.venv/bin/uv pip compile pyproject.toml --constraint requirements/dev.lock --universal --python-version 3.11 \
	  --generate-hashes --custom-compile-command "make lock" -q -o requirements/.user.lock.tmp \
	  || { rm -f requirements/.user.lock.tmp; exit 1; }
	mv requirements/.user.lock.tmp requirements/user.lock

# Every pin of the lock (other platforms' and Pythons' too) against the vulnerability database, by pip-audit
# (from the lock): exit 0 no known vulnerabilities, 1 some (listed), 2 not checked (the database could not be
# reached or had no answer): scripts/audit.py. `make audit AUDIT_ARGS="-s osv"` asks OSV instead of PyPI.
audit: setup
	.venv/bin/python scripts/audit.py requirements/dev.lock $(AUDIT_ARGS)
