"""The fischertechnik ROBO TX Controller (2009) driven live over its "fish.X1" online protocol, on its USB
serial port or a Bluetooth serial port: wire format, link, wiring section and :class:`~tablebot.loop.RobotIO`."""
