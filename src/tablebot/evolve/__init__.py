"""``tablebot evolve``: the computer writes the table. Candidates are tables (rows added, removed,
reordered; motor cells, timers and next states changed), each proved against the robot's properties
before the fleet runs it, kept in a quality-diversity archive (MAP-Elites, pyribs) of tables that
behave differently, and written back as tables a person can read.

Modules, in the order data flows: ``space`` (what may change), ``operators`` (how it changes),
``proofs`` (the proof cache over ``check``), ``repair`` (counterexample-guided guard rows),
``measures`` (objectives and behaviour descriptors), ``evaluate`` (candidates on the fleet),
``archive`` (the MAP-Elites archive and emitter), ``run`` (the loop, its store and resume),
``report`` (tables, check reports, heat map, before/after).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
