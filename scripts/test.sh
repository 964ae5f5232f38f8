#!/usr/bin/env bash
# `make test` after its set-up: the checks that read the code (mypy, lint-imports, ruff check, ruff format
# --check, the documentation site (strict) and ESLint) start at once, at the lowest priority (nice 19), and run
# beside both pytest passes: every test but the wall-clock ones on all cores (tests/conftest.py compiles numba's
# kernels once first) with coverage, whose report follows it; then the wall-clock ones (marked realtime) two at
# a time. The first pass keeps the cores busy but for a few idle seconds (the numba warm-up's end, a test
# waiting on a child process), which the niced checks take; the wall-clock tests mostly wait on the clock, and
# the checks take the rest of their ~80 CPU-s there. Each check's output is kept and printed whole, in that
# order, once both passes and all checks have ended. Exit status 1 if anything failed; a check still running
# when this script is stopped is stopped with it.
#
#   scripts/test.sh MKDOCS-COMMAND...    (the Makefile passes its $(MKDOCS))
set -uo pipefail
cd "$(dirname "$0")/.."
logs=$(mktemp -d)
pids=()
stop_checks() {
  for pid in "${pids[@]}"; do kill -- "-$pid" 2>/dev/null; done
  rm -rf "$logs"
}
trap stop_checks EXIT
trap 'exit 130' INT
trap 'exit 143' TERM

names=(mypy lint-imports "ruff check" "ruff format" mkdocs eslint)
commands=(
  ".venv/bin/mypy"
  ".venv/bin/lint-imports"
  ".venv/bin/ruff check ."
  ".venv/bin/ruff format --check ."
  "$*"
  "node_modules/.bin/eslint src/tablebot/web/static src/tablebot/formats/statecharts eslint.config.js"
)
for k in "${!commands[@]}"; do
  # a session (and process group) of its own: stop_checks ends the check's children with it
  setsid nice -n 19 bash -c "${commands[$k]}" >"$logs/$k" 2>&1 &
  pids+=($!)
done

status=0
mkdir -p build/coverage
first=(.venv/bin/python -m pytest -n auto --dist loadgroup -m "not realtime" --durations=15 -rs --cov --cov-report=)
echo "${first[*]}  (the checks below beside it, niced)"
"${first[@]}" || status=1
echo "coverage of the pass above, least covered first (all: .venv/bin/coverage html, then build/coverage/html):"
.venv/bin/coverage report | sed -n 1,27p
.venv/bin/coverage report --format=total | sed 's/^/total: /;s/$/ %/'

realtime=(.venv/bin/python -m pytest -n 2 -m realtime --durations=5 -rs)
echo "${realtime[*]}  (the checks below beside it, niced)"
"${realtime[@]}" || status=1

for k in "${!commands[@]}"; do
  wait "${pids[$k]}"
  code=$?
  echo "${commands[$k]}"
  cat "$logs/$k"
  if [ "$code" -ne 0 ]; then
    echo "${names[$k]} failed (exit $code)"
    status=1
  fi
done
pids=()
exit $status
