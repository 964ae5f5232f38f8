"""Real fischertechnik controllers: the TXT "online" protocol (also served on a TXT 4.0 by ftrobopy_server),
the robot file's ``[txt]`` wiring, a :class:`~tablebot.loop.RobotIO` for the link, and the TXT 4.0 export."""
