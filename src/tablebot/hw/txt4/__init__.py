"""The fischertechnik TXT 4.0 running a table by itself: the exported program (:mod:`.export`), the runtime it
carries (:mod:`.runtime` and how it stops, :mod:`.runtime_stop`: one standalone file shipped to the controller)
and its upload (:mod:`.upload`)."""
