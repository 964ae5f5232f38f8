"""A stub of the TXT 4.0's on-board ``fischertechnik`` package for the tests: exactly the calls tablebot's
exported program makes (as Open Roberta's TXT 4.0 generator emits them), nothing more. Inputs come from a
script, every call goes to a log; see factories.py."""
