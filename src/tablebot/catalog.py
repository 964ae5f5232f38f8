"""Every back-end tablebot has, imported once so that each registers itself (:mod:`tablebot.registry`) and its
robot-file section can be read (:data:`tablebot.robot.SECTION_READERS`).

Importing ``tablebot`` defers :func:`load_all` to the first use of the registry or of a robot file's reader
(:mod:`tablebot.plugins`), so a robot file's ``[sim]``, ``[board]``, ``[txt]`` and ``[properties]`` are known to
every command and every library use that reads one, and ``tablebot --help`` imports none of them. Each module
it imports is light (what it needs to run is imported when it runs). A new back-end adds its one line here.
"""

from __future__ import annotations

from functools import partial
from importlib import import_module

from tablebot import plugins

#: Each robot-file section and the module whose import registers its reader, in the order :func:`load_all`
#: registers them (a robot file's error lists them so). A file's reader imports only the modules of the
#: sections it has (:func:`tablebot.plugins.load_sections`); tests/test_plugins.py holds this to what
#: :func:`load_all` registers.
SECTIONS = {
    "tables": "tablebot.robot_tables",  # first: the ROBO Pro back-end's module imports it
    "groups": "tablebot.robot_tables",
    "robopro": "tablebot.robopro.backend",
    "board": "tablebot.firmware.backend",
    "txt": "tablebot.hw.txt.backend",
    "robotx": "tablebot.hw.robotx.backend",
    "roboif": "tablebot.hw.roboif.backend",
    "sim": "tablebot.sim.backend",
    "properties": "tablebot.analysis.section",
}


#: Every back-end, in the order the commands list them (``--to``, ``--board``, ``--on``, ``check --target``): the
#: order of :func:`load_all`'s imports; tests/test_plugins.py holds it to them.
BACKENDS = (
    "robopro",
    "robopro-rpp",
    "robopro-program",
    "c",
    "scxml",
    "xstate",
    "uno",
    "ftduino",
    "txt",
    "robotx",
    "roboif",
    "txt4",
    "sim",
)


def defer() -> None:
    """Hand :func:`load_all` and each section's module to :mod:`tablebot.plugins`, which imports them when
    first needed (by name: nothing here imports a back-end before then)."""
    plugins.defer(load_all)
    for section, module in SECTIONS.items():
        plugins.defer_section(section, partial(import_module, module))


def load_all() -> None:
    """Import every back-end module (in the order commands list them) and the analysis's section."""
    # The order is the order of --to, --board, --on and check --target: keep it (noqa: not sorted).
    from tablebot.robopro import backend as _robopro  # noqa: I001  robopro, robopro-rpp, robopro-program; [robopro]
    from tablebot.codegen import backend as _c  # c
    from tablebot.codegen import statecharts as _statecharts  # scxml, xstate
    from tablebot.firmware import backend as _boards  # uno, ftduino; [board]
    from tablebot.hw.txt import backend as _txt  # txt; [txt]
    from tablebot.hw.robotx import backend as _robotx  # robotx; [robotx]
    from tablebot.hw.roboif import backend as _roboif  # roboif; [roboif]
    from tablebot.hw.txt4 import backend as _txt4  # txt4
    from tablebot.sim import backend as _sim  # sim; [sim]
    from tablebot.analysis import section as _properties  # [properties]
    from tablebot import robot_tables as _tables  # [tables], [groups]

    del _robopro, _c, _statecharts, _boards, _txt, _robotx, _roboif, _txt4, _sim, _properties, _tables
    from tablebot import registry

    # a robot file read first registered its sections' back-ends first (tablebot.plugins.load_sections)
    registry.put_in_order(BACKENDS)
