"""The simulator's model: a robot's parameters (:mod:`.params`), the world it drives in (:mod:`.world`), both
put together with the table (:mod:`.scene`), the tape a line follower laps (:mod:`.track`) and what a learning agent
observes (:mod:`.observation`). Plain Python and numpy; the compiled code it packs for is in :mod:`tablebot.sim.physics`."""

__all__ = ["observation", "params", "scene", "track", "world"]
