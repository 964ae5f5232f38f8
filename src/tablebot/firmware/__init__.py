"""Firmware for real boards: a table on an AVR (Arduino Uno, ftDuino) with a UART trace stream.

Board files, wiring, the build with avr-gcc, avrdude, the trace framing and the simavr harness.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
