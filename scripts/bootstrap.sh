#!/usr/bin/env bash
# Set up tablebot in .venv/, at one of two levels:
#
#   scripts/bootstrap.sh user   what a user's commands need (`make demo`): a virtual environment with
#                               tablebot and its Python packages from PyPI, as requirements/user.lock pins
#                               them. No system package, no sudo, no compiler, no Node: any OS with Python 3.11+.
#   scripts/bootstrap.sh        everything the tests need (`make setup`, `make test`): the same, plus the
#                               dev packages (requirements/dev.lock), and on a Debian-like machine the system
#                               packages (graphviz, which diagrams fall back to where graphviz-pure from PyPI
#                               is missing: the tests check that it still draws; avr-gcc/avr-libc/simavr for
#                               firmware and its emulation, chromium and its headless shell for the studio's
#                               browser tests, node and npm for the studio's JavaScript linter, gettext's
#                               msgfmt for the message catalogs' check) and ESLint from npm.
#
# The system packages install while the Python packages do (two downloads at once: on a fresh machine
# each takes about 40 s, one after the other 80).
set -euo pipefail
cd "$(dirname "$0")/.."

LEVEL=${1:-dev}
case "$LEVEL" in
  user|dev) ;;
  *) echo "usage: scripts/bootstrap.sh [user|dev]  (user: what tablebot's commands need; dev, the default: the tests too)" >&2
     exit 2 ;;
esac

apt_pid=""
apt_log=""
if [ "$LEVEL" = dev ]; then
  SYSTEM_PACKAGES=(graphviz gcc-avr avr-libc simavr libsimavr-dev libelf-dev pkg-config chromium chromium-headless-shell gettext)
  missing=()
  for pkg in "${SYSTEM_PACKAGES[@]}"; do
    dpkg -s "$pkg" >/dev/null 2>&1 || missing+=("$pkg")  # no dpkg (not Debian-like): all missing, said below
  done
  command -v npm >/dev/null 2>&1 || missing+=(nodejs npm)  # any node with npm will do (Debian's, or another)
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
      echo "warning: cannot install ${missing[*]} (no apt-get); firmware, browser and ESLint checks will fail" >&2
    fi
  fi
fi

# Each step says what it does before it starts: the first set-up takes a while, and must not look hung.
# The Python: $PYTHON, else the first new enough of these on PATH, else pyenv's (its shims answer only for the
# versions pyenv has selected). A user's commands (`make demo`) need 3.11 or newer; the tests (`make setup`, `make
# test`) 3.12 or newer: coverage measures there through sys.monitoring (PEP 669), which costs the test pass a few
# per cent where 3.11's line tracer costs 40 to 90 % (docs/development.md has the figures).
if [ "$LEVEL" = dev ]; then
  MINOR=12; CANDIDATES=(python3.12 python3 python3.13 python)
else
  MINOR=11; CANDIDATES=(python3 python3.13 python3.12 python3.11 python)
fi
new_enough() { "$1" -c "import sys; sys.exit(sys.version_info < (3, $MINOR))" 2>/dev/null; }
if [ -z "${PYTHON:-}" ]; then
  for candidate in "${CANDIDATES[@]}"; do
    if command -v "$candidate" >/dev/null 2>&1 && new_enough "$candidate"; then
      PYTHON=$candidate
      break
    fi
  done
fi
if [ -z "${PYTHON:-}" ] && command -v pyenv >/dev/null 2>&1; then
  # 3.12 first (what the tests are run and timed on), then the newest
  for candidate in $(ls -d "$(pyenv root)"/versions/3.12*/bin/python3 2>/dev/null | sort -V -r) \
                   $(ls -d "$(pyenv root)"/versions/3.*/bin/python3 2>/dev/null | sort -V -r); do
    if new_enough "$candidate"; then
      PYTHON=$candidate
      break
    fi
  done
fi
if [ ! -x .venv/bin/python ]; then
  if [ -z "${PYTHON:-}" ] || ! new_enough "$PYTHON"; then
    if [ "$LEVEL" = dev ]; then
      echo "error: tablebot's tests need Python 3.12 or newer (its commands alone, make demo, 3.11), and none was found" >&2
      echo "  on PATH (${CANDIDATES[*]}) or in pyenv; install one (docs/install.md says how on each system) or name it:" >&2
      echo "  make test PYTHON=/path/to/python3.12" >&2
    else
      echo "error: tablebot needs Python 3.11 or newer, and none was found on PATH (python3, python3.13, python3.12," >&2
      echo "  python3.11); install one (docs/install.md says how on each system) or name it: make demo PYTHON=/path/to/python3.12" >&2
    fi
    exit 1
  fi
  echo "creating .venv (a Python virtual environment for tablebot) with $PYTHON ($("$PYTHON" -c 'import platform; print(platform.python_version())'))"
  # without pip: a venv's own pip costs seconds to set up, and Debian's Python has none without the
  # python3-venv package (a system package); uv installs everything, pip included where the tests want it
  "$PYTHON" -m venv --without-pip .venv
fi
if [ "$LEVEL" = dev ] && ! new_enough .venv/bin/python; then
  echo "note: .venv has Python $(.venv/bin/python -c 'import platform; print(platform.python_version())'); the tests run on it, but their"
  echo "  coverage costs 40 to 90 % more than on 3.12 or newer: remove .venv and run make setup again to make it anew"
fi

# The Python packages exactly as the lock pins them (versions and hashes; `make lock` writes both locks from
# pyproject.toml, user.lock with dev.lock's versions), then tablebot itself, editable, with no packages of its
# own. A stamp in .venv keeps a checksum of pyproject.toml and the lock: when either changes (a pull, `make
# lock`), the next set-up installs again. The dev packages include every user package, so a venv set up for
# the tests serves the demo as it is.
stamp_of() { cat pyproject.toml "$1" | cksum; }
DEV_LOCK=requirements/dev.lock
USER_LOCK=requirements/user.lock
dev_stamp="$(stamp_of "$DEV_LOCK")"
user_stamp="$(stamp_of "$USER_LOCK")"
installed() { [ "$(cat ".venv/$1" 2>/dev/null)" = "$2" ]; }

# "$@" with a line every 10 s while it runs: a step of tens of seconds (uv's quiet downloads) must not look hung.
talking() {
  local what=$1; shift
  "$@" &
  local pid=$! started=$SECONDS said=$SECONDS
  while kill -0 "$pid" 2>/dev/null; do
    sleep 0.5
    if [ $((SECONDS - said)) -ge 10 ] && kill -0 "$pid" 2>/dev/null; then
      said=$SECONDS
      echo "  still $what: $((SECONDS - started)) s"
    fi
  done
  wait "$pid"
}

install_user() {
  # install, not sync: a venv that also holds the dev packages (make test) keeps them
  .venv/bin/uv pip install -q --python .venv/bin/python --system-certs --require-hashes -r "$USER_LOCK"
  .venv/bin/uv pip install -q --python .venv/bin/python --system-certs --no-deps -e .
}

uv_ready() {
  # uv (from PyPI, like everything else) fetches and installs in parallel: seconds where pip takes minutes.
  # Into .venv with whichever installer there is: a uv on PATH, the Python's own pip (22.3+: --python), or a
  # pip that ensurepip puts into .venv.
  [ -x .venv/bin/uv ] && return
  if command -v uv >/dev/null 2>&1 && uv pip install -q --python .venv/bin/python uv; then return; fi
  if "${PYTHON:-python3}" -m pip --version >/dev/null 2>&1 \
     && "${PYTHON:-python3}" -m pip --python .venv/bin/python install -q --disable-pip-version-check uv 2>/dev/null; then
    return
  fi
  if .venv/bin/python -m ensurepip -q >/dev/null 2>&1; then
    .venv/bin/python -m pip install -q --disable-pip-version-check uv
    return
  fi
  # no pip at all (Debian's python3 without python3-pip and python3-venv): pip's own wheel from PyPI runs as it is
  echo "  (this Python has no pip: fetching pip's wheel from PyPI to install uv with)"
  local wheels wheel
  wheels=$(mktemp -d)
  wheel=$(.venv/bin/python scripts/fetch_pip.py "$wheels")
  .venv/bin/python "$wheel/pip" install -q --disable-pip-version-check uv
  rm -rf "$wheels"
}

if [ "$LEVEL" = user ]; then
  if ! installed .installed "$dev_stamp" && ! installed .installed-user "$user_stamp"; then
    echo "installing tablebot and the Python packages its commands need into .venv, as $USER_LOCK pins them"
    echo "  (numpy, numba, matplotlib, graphviz-pure, ...; no system packages): 10-30 s the first time"
    uv_ready
    talking "installing" install_user
    echo "$user_stamp" >.venv/.installed-user
    echo "installed; .venv/bin/tablebot --help lists the commands"
  fi
elif ! installed .installed "$dev_stamp"; then
  echo "installing tablebot's Python packages and the developer tools into .venv as $DEV_LOCK pins them"
  echo "  (numpy, numba, matplotlib, typer, rich, dask, playwright, pytest, mypy, ...): a few minutes the first time"
  uv_ready
  # `uv pip sync` makes .venv hold exactly the lock's packages (a package dropped from it is removed; pip and
  # uv stay). --compile-bytecode: the tests start tablebot in a hundred processes, each would compile numpy,
  # numba and matplotlib again; --system-certs: the machine's own certificate store, as pip uses it.
  talking "installing" .venv/bin/uv pip sync -q --python .venv/bin/python --compile-bytecode --system-certs \
    --require-hashes "$DEV_LOCK"
  .venv/bin/uv pip install -q --python .venv/bin/python --compile-bytecode --system-certs --no-deps -e .
  echo "$dev_stamp" >.venv/.installed
  echo "installed; .venv/bin/tablebot --help lists the commands"
fi

[ "$LEVEL" = dev ] || exit 0

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
