"""The simulator's model: a robot's parameters (:mod:`.params`), the world it drives in (read from its file by
:mod:`.world`, made of :mod:`.shapes`, checked with the plane geometry of :mod:`.plane`), both put together with
the table (:mod:`.scene`), the tape a line follower laps (:mod:`.track`) and what a learning agent observes
(:mod:`.observation`). Plain Python and numpy; it packs the arrays :mod:`tablebot.sim.physics` computes on, and
calls a few of its functions to do so (a body's corners, a battery's volts, a shadow grid)."""

__all__ = ["observation", "params", "plane", "scene", "shapes", "track", "world"]
