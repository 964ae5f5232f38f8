"""The fischertechnik TXT 4.0 running a table by itself: the exported program (:mod:`.export`), the runtime it
carries (:mod:`.runtime`, a standalone file shipped to the controller) and its upload (:mod:`.upload`)."""
