"""The studio: a local web app to edit a table, check it and watch the simulated robot run it live,
plus the self-contained HTML replay of a run (:mod:`tablebot.web.replay`)."""
