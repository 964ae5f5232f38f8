"""Generic sinks of the run loop (:mod:`tablebot.loop`): the trace file, a live run's trace and summary, and the
live terminal view. Any robot's run feeds them, simulated or real.

Internal to tablebot: its public API is ``tablebot`` and ``tablebot.api`` (docs/api.md, which also names the
modules stable enough to use beside them); anything here may change in any release.
"""
