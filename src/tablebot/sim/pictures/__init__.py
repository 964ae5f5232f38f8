"""The simulator's pictures (matplotlib): the arena and its pieces (:mod:`.draw`), what a run's pictures share
(:mod:`.picture`, :mod:`.view`), the trajectory (:mod:`.plots`, its path cut and thinned by :mod:`.path`), the
timeline (:mod:`.timeline`), the animation (:mod:`.animate`), and drawing in a forked copy of the process while
the command runs on (:mod:`.painter`, :mod:`.forked`). Importing the package imports no matplotlib: the modules
that draw do."""

__all__ = ["animate", "draw", "forked", "painter", "path", "picture", "plots", "timeline", "view"]
