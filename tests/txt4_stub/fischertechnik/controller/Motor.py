"""``fischertechnik.controller.Motor`` as in the real package (controller/Motor.py): the direction is a
sign that multiplies the speed."""


class Motor:
    CCW = 1  # "positive values, direction of rotation is left (0 to +512)"
    CW = -1  # "negative values, direction of rotation is right (0 to -512)"
    MIN_SPEED = -512
    MAX_SPEED = 512
