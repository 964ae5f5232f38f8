"""Firmware for real boards: a table on an AVR (Arduino Uno, ftDuino) with a UART trace stream.

Board files, wiring, the build with avr-gcc, avrdude, the trace framing and the simavr harness.
"""
