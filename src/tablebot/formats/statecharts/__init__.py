"""A robot's tables as statecharts in the standard formats: SCXML and XState 5 (docs/statecharts.md), written by
``export --to scxml|xstate`` and read back by ``import --from scxml|xstate``."""

from tablebot.formats.statecharts.chart import TICK, state_id, state_of

__all__ = ["TICK", "state_id", "state_of"]
