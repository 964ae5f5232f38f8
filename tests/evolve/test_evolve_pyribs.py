"""evolve's lighter pyribs import: the two classes without scikit-learn, and a later ``import ribs`` gets the same
classes (tablebot.evolve.pyribs)."""

from __future__ import annotations

import subprocess
import sys

import pytest

pytestmark = [pytest.mark.kernel_free]

PROBE = """
import sys
from tablebot.evolve import pyribs
light = sorted(m for m in ("sklearn", "ribs.archives._cvt_archive") if m in sys.modules)
import ribs
from ribs.archives import GridArchive
from ribs.emitters import EmitterBase
print(light, GridArchive is pyribs.GridArchive, EmitterBase is pyribs.EmitterBase, "ribs.archives" in sys.modules)
"""


def test_the_two_classes_come_alone_and_stay_the_packages_own() -> None:
    done = subprocess.run([sys.executable, "-c", PROBE], capture_output=True, text=True, check=True)
    assert done.stdout.split() == ["[]", "True", "True", "True"]
