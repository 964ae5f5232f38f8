"""Static and exhaustive analysis of a table: findings, properties, generated tests and diagrams.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
