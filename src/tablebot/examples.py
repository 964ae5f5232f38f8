"""Where the shipped example tables live, in a source checkout and in an installed package alike."""

from pathlib import Path

from tablebot.diagnostics import fail
from tablebot.i18n import N_

_CANDIDATES = (
    Path(__file__).resolve().parent / "_examples",  # installed wheel (force-included)
    Path(__file__).resolve().parents[2] / "examples",  # source checkout / editable install
)


def example_path(name: str) -> Path:
    for root in _CANDIDATES:
        if (root / name).is_dir():
            return root / name
    raise fail(name, N_("example not found"), N_("run from a tablebot checkout or reinstall the package"))
