"""Real fischertechnik controllers: the TXT "online" protocol (also served on a TXT 4.0 by ftrobopy_server),
the robot file's ``[txt]`` wiring, a :class:`~tablebot.loop.RobotIO` for the link, and the TXT 4.0 export.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
