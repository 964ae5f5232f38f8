#!/usr/bin/env bash
# `make demo`: set up only what tablebot's commands need (scripts/bootstrap.sh user: .venv with packages from
# PyPI; no sudo, no system packages, no developer tools), simulate the BumberBot in its arena into out/demo,
# and show the two pictures. Every step says what it does; the first simulation compiles the simulator and
# says so while it does (tablebot.jit).
set -euo pipefail
cd "$(dirname "$0")/.."

./scripts/bootstrap.sh user
echo "simulating the BumberBot in its arena: .venv/bin/tablebot sim examples/bumberbot --out out/demo"
echo "  (a first start takes a few seconds to load numpy, numba and matplotlib, then compiles the simulator)"
.venv/bin/tablebot sim examples/bumberbot --out out/demo

pictures=(out/demo/trajectory.png out/demo/timeline.png)
# Shown in the system's picture viewer when there is a screen to show them on (and someone at the terminal:
# not in a pipe or a CI log); SHOW=0 never opens them.
viewer=""
if [ "${SHOW:-1}" != 0 ] && [ -t 1 ]; then
  case "$(uname -s 2>/dev/null)" in
    Darwin) viewer=open ;;
    MINGW*|MSYS*|CYGWIN*) viewer="cmd //c start" ;;
    *) if [ -n "${DISPLAY:-}${WAYLAND_DISPLAY:-}" ] && command -v xdg-open >/dev/null 2>&1; then viewer=xdg-open; fi ;;
  esac
fi
if [ -n "$viewer" ]; then
  echo "showing ${pictures[*]}"
  for picture in "${pictures[@]}"; do $viewer "$picture" >/dev/null 2>&1 || true; done
else
  echo "the pictures: ${pictures[*]} (open them in any picture viewer or browser)"
fi
echo "next: .venv/bin/tablebot --help lists every command; docs/tutorial.md makes a robot of your own"
