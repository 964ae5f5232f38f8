"""A stub of the TXT 4.0's on-board ``fischertechnik`` package (6.4.2) for the tests, written to behave as
the real package's Python sources do (leosdad/ft-rc-vehicle, folder ``fischertechnik/``): the same
module layout, the SIGTERM handler and exit hooks it installs, the values its calls take and return.
Only the native ``ft`` module under it is replaced: inputs and encoder pulses come from a script, every
call goes to a log. See factories/__init__.py."""
