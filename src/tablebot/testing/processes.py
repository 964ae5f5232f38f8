"""The environment benchmarks time a fresh tablebot process in: as a user's installed tablebot runs."""

from __future__ import annotations

import os


def child_env(**changes: str | None) -> dict[str, str]:
    """This process's environment for a child, without PYTHONDONTWRITEBYTECODE: bytecode files are written
    and read as a user's would be -- with it set, an editable install compiles every tablebot module from
    source again in every process (~0.2 s of a sweep's start-up that no user of an installed tablebot has).
    ``changes``: variables to set (None: to remove)."""
    env = {k: v for k, v in os.environ.items() if k != "PYTHONDONTWRITEBYTECODE"}
    for key, value in changes.items():
        if value is None:
            env.pop(key, None)
        else:
            env[key] = value
    return env
