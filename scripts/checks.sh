#!/usr/bin/env bash
# The end of `make test`, after the parallel pytest pass: the wall-clock tests (pytest -m realtime, two at a
# time) in the foreground, and beside them, niced so the timed tests keep their cores, the checks that read the
# code: mypy, lint-imports (the layers), ruff check, ruff format --check, the documentation site (strict) and
# ESLint. Each check's output is kept and printed whole, in that order, once all have ended; the exit status is
# 1 if any failed. Run one after the other they added ~25 s to the 8-15 s of mypy on a 2-core machine.
#
#   scripts/checks.sh MKDOCS-COMMAND...    (the Makefile passes its $(MKDOCS))
set -uo pipefail
cd "$(dirname "$0")/.."
logs=$(mktemp -d)
trap 'rm -rf "$logs"' EXIT

names=(mypy lint-imports "ruff check" "ruff format" mkdocs eslint)
commands=(
  ".venv/bin/mypy"
  ".venv/bin/lint-imports"
  ".venv/bin/ruff check ."
  ".venv/bin/ruff format --check ."
  "$*"
  "node_modules/.bin/eslint src/tablebot/web/static src/tablebot/formats/statecharts eslint.config.js"
)
pids=()
for k in "${!commands[@]}"; do
  nice -n 19 bash -c "${commands[$k]}" >"$logs/$k" 2>&1 &
  pids+=($!)
done

echo '.venv/bin/python -m pytest -n 2 -m realtime --durations=5 -rs  (and the checks below, beside it)'
.venv/bin/python -m pytest -n 2 -m realtime --durations=5 -rs
status=$?

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
exit $status
