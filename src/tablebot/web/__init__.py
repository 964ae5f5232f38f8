"""The studio: a local web app to edit a table, check it and watch the simulated robot run it live,
plus the self-contained HTML replay of a run (:mod:`tablebot.web.replay`).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
