"""Generic sinks of the run loop (:mod:`tablebot.loop`): the trace file, a live run's trace and summary, and the
live terminal view. Any robot's run feeds them, simulated or real."""
