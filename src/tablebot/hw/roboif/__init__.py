"""The fischertechnik ROBO Interface (2004) driven live over its serial online protocol (as libroboint speaks
it): wire format, link, wiring section and :class:`~tablebot.loop.RobotIO`."""
