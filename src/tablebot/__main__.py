"""``python -m tablebot``: the command line."""

from tablebot.cli import main

main()
