"""C generation: a table as const C data plus the portable C99 engine that runs it (``export --to c``, and the
base of every AVR board's firmware): :mod:`.source` (the generated files), :mod:`.packing` (the data layout),
:mod:`.host` (the C engine run on this machine, for tests).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
