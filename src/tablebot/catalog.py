"""Every back-end tablebot has, imported once so that each registers itself (:mod:`tablebot.registry`) and its
robot-file section can be read (:data:`tablebot.robot.SECTION_READERS`).

Importing ``tablebot`` defers :func:`load_all` to the first use of the registry or of a robot file's reader
(:mod:`tablebot.plugins`), so a robot file's ``[sim]``, ``[board]``, ``[txt]`` and ``[properties]`` are known to
every command and every library use that reads one, and ``tablebot --help`` imports none of them. Each module
it imports is light (what it needs to run is imported when it runs). A new back-end adds its one line here.
"""

from __future__ import annotations


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
