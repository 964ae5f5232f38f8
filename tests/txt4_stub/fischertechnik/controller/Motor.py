"""``fischertechnik.controller.Motor``: only the two directions the exported program uses."""


class Motor:
    CW = "CW"
    CCW = "CCW"
