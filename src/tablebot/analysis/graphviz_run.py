"""The Graphviz program that lays out and draws the diagrams.

graphviz-pure, one of tablebot's dependencies from PyPI (a port of Graphviz 16.1 to Rust with its fonts
compiled in: no system package, and the same picture on every platform), comes first. It is looked for
in the scripts folder of the Python running tablebot, so ``.venv/bin/tablebot`` finds it with the
virtual environment off PATH. Where it has no wheel (pyproject.toml's marker: it is then not installed),
the system's Graphviz ``dot`` on PATH draws instead: both take the same command line."""

from __future__ import annotations

import contextlib
import os
import shutil
import subprocess
import sysconfig

from tablebot.i18n import N_

PACKAGED = "graphviz-pure"
SYSTEM = "dot"
INSTALL = N_(
    "pip install {packaged} (into the Python that runs tablebot), or install Graphviz (its dot program, on PATH)",
    packaged=PACKAGED,
)
NOT_FOUND = N_("neither {packaged} nor {system} was found", packaged=PACKAGED, system=SYSTEM)


class NoGraphviz(Exception):
    """Neither graphviz-pure nor dot is installed."""

    def __init__(self) -> None:
        super().__init__(N_("no Graphviz to draw the diagram: {why}", why=NOT_FOUND))


class GraphvizFailed(Exception):
    """The program ran and failed; the message is what it said."""


def script_folders() -> list[str]:
    """Where pip puts this Python's commands: its environment's scripts folder, then the user's
    (``pip install --user``)."""
    folders = [sysconfig.get_path("scripts")]
    with contextlib.suppress(KeyError):  # a Python built without a user scheme
        folders.append(sysconfig.get_path("scripts", sysconfig.get_preferred_scheme("user")))
    return folders


def find_graphviz() -> str | None:
    """The program that draws: graphviz-pure beside this Python (or on PATH), else ``dot`` on PATH."""
    path = os.environ.get("PATH", os.defpath)
    packaged = shutil.which(PACKAGED, path=os.pathsep.join([*script_folders(), path]))
    return packaged or shutil.which(SYSTEM, path=path)


def draw(source: str, fmt: str) -> bytes:
    """``source`` (DOT) laid out and drawn as ``fmt`` (svg or png)."""
    program = find_graphviz()
    if program is None:
        raise NoGraphviz
    try:
        done = subprocess.run([program, f"-T{fmt}"], input=source.encode(), capture_output=True, check=False)
    except OSError as exc:  # found but not runnable (a wheel for another machine, no execute bit)
        raise GraphvizFailed(
            N_("{program} could not be started: {error}", program=program, error=str(exc.strerror or exc))
        ) from None
    if done.returncode != 0 or not done.stdout:
        said = done.stderr.decode(errors="replace").strip() or N_("exit status {code}", code=done.returncode)
        raise GraphvizFailed(N_("{program} failed: {said}", program=program, said=said))
    return done.stdout
