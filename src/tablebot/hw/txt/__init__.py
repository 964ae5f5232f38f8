"""The fischertechnik TXT (or a TXT 4.0 running ftrobopy_server), driven live over its TCP protocol: the wire
protocol (:mod:`.protocol`), the link (:mod:`.link`), the robot's wiring (:mod:`.wiring`, the ``[txt]`` section)
and the controller as a :class:`~tablebot.loop.RobotIO` (:mod:`.controller`)."""
