"""File formats: each one's reader and writer side by side (tables, robot and world TOML, inputs, ROBO Pro).

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
