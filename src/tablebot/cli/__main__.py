"""``python -m tablebot.cli``: the command line."""

from tablebot.cli import main

main()
