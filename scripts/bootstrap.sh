#!/usr/bin/env bash
# Set up everything tablebot needs on a fresh Debian-like machine: system packages (graphviz, which
# diagrams fall back to where graphviz-pure from PyPI is missing: the tests check that it still draws;
# avr-gcc/avr-libc/simavr for firmware and its emulation, chromium for the studio's browser tests, node
# and npm for the studio's JavaScript linter), a virtual environment, and ESLint from npm.
# The system packages install while the Python packages do (two downloads at once: on a fresh machine
# each takes about 40 s, one after the other 80).
set -euo pipefail
cd "$(dirname "$0")/.."

SYSTEM_PACKAGES=(graphviz gcc-avr avr-libc simavr libsimavr-dev libelf-dev pkg-config chromium)
missing=()
for pkg in "${SYSTEM_PACKAGES[@]}"; do
  dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")
done
command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)  # any node with npm will do (Debian's, or another)
apt_pid=""
apt_log=""
if [ ${#missing[@]} -gt 0 ]; then
  if command -v apt-get >/dev/null 2>&1; then
    SUDO=""; [ "$(id -u)" -eq 0 ] || SUDO="sudo"
    [ -z "$SUDO" ] || sudo -v  # ask for the password now, not in the middle of the Python packages' output
    echo "installing system packages (in the background): ${missing[*]}"
    apt_log=$(mktemp)
    ( $SUDO apt-get update -qq && DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -qq "${missing[@]}" ) \
      >"$apt_log" 2>&1 &
    apt_pid=$!
    # a Python step that fails (set -e) must not leave apt running unseen, holding dpkg's lock for the next try
    trap 'if [ -n "$apt_pid" ]; then wait "$apt_pid" || cat "$apt_log" >&2; rm -f "$apt_log"; fi' EXIT
  else
    echo "warning: cannot install ${missing[*]} (no apt-get); firmware tests will fail" >&2
  fi
fi

# Each step says what it does before it starts: the first set-up takes minutes, and must not look hung.
PYTHON=${PYTHON:-python3}
if [ ! -x .venv/bin/python ]; then
  echo "creating .venv (a Python virtual environment for tablebot) with $PYTHON"
  "$PYTHON" -m venv .venv
fi
# The Python packages exactly as requirements/dev.lock pins them (versions and hashes; `make lock` writes it
# from pyproject.toml), then tablebot itself, editable, with no packages of its own. .venv/.installed keeps a
# checksum of the two files: when either changes (a pull, `make lock`), the next set-up installs again.
LOCK=requirements/dev.lock
stamp="$(cat pyproject.toml "$LOCK" | cksum)"
if [ "$(cat .venv/.installed 2>/dev/null)" != "$stamp" ]; then
  echo "installing tablebot's Python packages into .venv as $LOCK pins them (numpy, numba, matplotlib, typer,"
  echo "  rich, dask, playwright, ...): a few minutes the first time"
  # uv (from PyPI, like everything else) fetches and installs in parallel: seconds where pip takes minutes.
  # `uv pip sync` makes .venv hold exactly the lock's packages (a package dropped from it is removed; pip and
  # uv stay). --compile-bytecode: the tests start tablebot in a hundred processes, each would compile numpy,
  # numba and matplotlib again; --system-certs: the machine's own certificate store, as pip uses it.
  .venv/bin/python -m pip install -q uv
  .venv/bin/uv pip sync -q --python .venv/bin/python --compile-bytecode --system-certs --require-hashes "$LOCK"
  .venv/bin/uv pip install -q --python .venv/bin/python --compile-bytecode --system-certs --no-deps -e .
  echo "$stamp" >.venv/.installed
  echo "installed; .venv/bin/tablebot --help lists the commands"
fi

if [ -n "$apt_pid" ]; then
  pid=$apt_pid; apt_pid=""  # waited for here: the exit trap has nothing left to do
  if ! wait "$pid"; then
    cat "$apt_log" >&2
    echo "error: installing the system packages failed (above); run this script again once apt-get works" >&2
    rm -f "$apt_log"
    exit 1
  fi
  rm -f "$apt_log"
  echo "system packages installed"
fi

# ESLint for the studio's front end, exactly as package-lock.json pins it (node_modules/ is not in git).
# After the system packages: on a machine without npm, they bring it.
if [ ! -f node_modules/.package-lock.json ] || [ package-lock.json -nt node_modules/.package-lock.json ]; then
  npm ci --no-audit --no-fund --loglevel=error
fi
