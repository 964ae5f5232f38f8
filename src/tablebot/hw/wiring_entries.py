"""The entries of a controller's wiring section, read one robot name at a time (:class:`EntryReader`): which
terminal an input, motor, lamp or counter is wired to, how an input measures (a switch's level, an analog
reading against a threshold, a declared sensor's limits), each terminal taken once. :mod:`tablebot.hw.wiring`
reads the whole section with it and checks the wiring against the table."""

from __future__ import annotations

from collections.abc import Sequence
from typing import TYPE_CHECKING, Any

from tablebot.hw.terminals import Digital, InputWire, OutputWire, Terminals
from tablebot.i18n import N_, Message
from tablebot.tomlfile import Source

#: How a message names each kind of signal (the kinds are the code's words).
KINDS = {"input": N_("input"), "motor": N_("motor"), "lamp": N_("lamp"), "counter": N_("counter")}

if TYPE_CHECKING:  # read when a robot file is: only what the section needs is imported
    from tablebot.robot import Robot
    from tablebot.sensors import Sensor


def error(src: Source, line: int | None, message: Message, hint: Message) -> None:
    """A mistake of the section at ``line`` of the robot file (column 1; none where the line is unknown)."""
    src.out.error(line, None if line is None else 1, message, hint)


def _joined(parts: list[Message]) -> Message:
    """``parts`` as one text, each part in the reader's language, joined by "; "."""
    joined = parts[-1]
    for part in reversed(parts[:-1]):
        joined = N_("{first}; {rest}", first=part, rest=joined)
    return joined


class EntryReader:
    """Reads the section's entries one robot name at a time, remembering terminals already taken."""

    def __init__(self, spec: Terminals, robot: Robot, src: Source, section: dict[str, Any]) -> None:
        self.spec, self.robot, self.src, self.section = spec, robot, src, section
        self.taken: dict[tuple[str, str], str] = {}  # (input/output/counter, terminal) -> name

    def line(self, name: str) -> int | None:
        key = self.spec.section
        return self.src.line(key, None, name) or self.src.line(f"{key}.{name}") or self.src.line(key)

    def error(self, name: str, message: Message, hint: Message) -> None:
        error(self.src, self.line(name), message, hint)

    def terminal(self, name: str, kind: str, value: Any, allowed: Sequence[str] | None = None) -> str | None:
        """``value`` checked as a terminal of ``kind`` (one of ``allowed`` if given), or None after an error."""
        key, names = self.spec.section, list(allowed if allowed is not None else self.spec.names(kind))
        if not names:
            self.error(
                name,
                N_(
                    "{kind} {name}: the {controller} has no {kind} terminals",
                    kind=KINDS[kind],
                    name=name,
                    controller=self.spec.controller,
                ),
                N_("remove {name} from [{section}]", name=name, section=key),
            )
            return None
        if value is None:
            self.error(
                name,
                N_("[{section}] {name}: which terminal is it wired to?", section=key, name=name),
                N_('say it with terminal = "{first}" (one of {names})', first=names[0], names=", ".join(names)),
            )
            return None
        if not isinstance(value, str):
            self.error(
                name,
                N_(
                    "[{section}] {name}: the terminal must be text like {first!r}, not {value!r}",
                    section=key,
                    name=name,
                    first=names[0],
                    value=value,
                ),
                N_('write it in quotes: {name} = "{first}"', name=name, first=names[0]),
            )
            return None
        if value not in names:
            same = [n for n in names if n.lower() == value.strip().lower()]
            hint = (
                N_("terminal names are case-sensitive: write {same!r}", same=same[0])
                if same
                else N_(
                    "the {controller}'s terminals for this are {names}",
                    controller=self.spec.controller,
                    names=", ".join(names),
                )
            )
            self.error(
                name,
                N_(
                    "{kind} {name}: the {controller} has no {kind} terminal {value!r}",
                    kind=KINDS[kind],
                    name=name,
                    controller=self.spec.controller,
                    value=value,
                ),
                hint,
            )
            return None
        return value if self._take(name, kind, value) else None

    def _take(self, name: str, kind: str, value: str) -> bool:
        """Claim ``value``'s pins: a motor Mn takes its pair of outputs O(2n-1) and O(2n)."""
        if kind == "motor":
            n = int(value[1:])
            needs = [("output", f"O{2 * n - 1}"), ("output", f"O{2 * n}")]
        else:
            needs = [("output" if kind == "lamp" else kind, value)]
        for used in needs:
            if used in self.taken:
                taken = dict(kind=KINDS[kind], name=name, terminal=value, user=self.taken[used])
                self.error(
                    name,
                    N_(
                        "{kind} {name}: terminal {terminal} is already used by {user} (a motor drives both "
                        "outputs of its pair)",
                        **taken,
                    )
                    if used[0] == "output"
                    else N_("{kind} {name}: terminal {terminal} is already used by {user}", **taken),
                    N_("give {name} a terminal of its own in [{section}]", name=name, section=self.spec.section),
                )
                return False
        self.taken.update(dict.fromkeys(needs, name))
        return True

    def input(self, name: str) -> InputWire | None:
        key, value = self.spec.section, self.section[name]
        if not isinstance(value, dict):
            self.error(
                name,
                N_("[{section}] {name} must say its terminal, mode and polarity", section=key, name=name),
                N_(
                    "for example: {example}",
                    example=f'{name} = {{ terminal = "{self.spec.digital_inputs[0]}", mode = "switch", pressed = 1 }}',
                ),
            )
            return None
        mode = value.get("mode")
        if mode not in self.spec.modes:
            self.error(
                name,
                N_(
                    "[{section}] {name}: mode must be one of {modes}, not {mode!r}",
                    section=key,
                    name=name,
                    modes=", ".join(self.spec.modes),
                    mode=mode,
                ),
                _joined(
                    [
                        N_('{device} is mode = "{mode}"', device=d.device, mode=m)
                        for m, d in self.spec.digital_modes.items()
                    ]
                ),
            )
            return None
        digital = self.spec.digital_modes.get(mode)
        known = ("terminal", "mode", digital.key) if digital else ("terminal", "mode", "below", "above")
        for k in value:
            if k not in known:
                self.error(
                    name,
                    N_(
                        "[{section}] {name}: unknown key {key!r} for mode {mode!r}",
                        section=key,
                        name=name,
                        key=k,
                        mode=mode,
                    ),
                    N_("keys: {keys}", keys=", ".join(known)),
                )
        allowed = self.spec.digital_inputs if digital else self.spec.analog[mode].terminals
        default = name if name in allowed else None
        terminal = self.terminal(name, "input", value.get("terminal", default), allowed)
        polarity = self._digital(name, digital, value) if digital else self._analog(name, mode, value)
        if terminal is None or polarity is None:
            return None
        return InputWire(name, terminal, mode, digital is not None, *polarity)

    def _digital(self, name: str, mode: Digital, value: dict[str, Any]) -> tuple[bool] | None:
        reads = value.get(mode.key)
        if reads not in (0, 1) or isinstance(reads, bool):
            said = dict(section=self.spec.section, name=name, meaning=mode.meaning, key=mode.key, reads=reads)
            self.error(
                name,
                N_("[{section}] {name}: say what the table reads {meaning}: {key} = 1 or {key} = 0", **said)
                if reads is None
                else N_(
                    "[{section}] {name}: say what the table reads {meaning}: {key} = 1 or {key} = 0, not {reads!r}",
                    **said,
                ),
                N_("{key} = 1 is the usual wiring (see docs/controllers.md, 'Input polarity')", key=mode.key),
            )
            return None
        return (reads != mode.reports,)

    def _analog(self, name: str, mode: str, value: dict[str, Any]) -> tuple[bool, int | None, int | None, int] | None:
        analog, key = self.spec.analog[mode], self.spec.section
        limits: dict[str, Any] = {k: value[k] for k in ("below", "above") if k in value}
        declared = next((s for s in self.robot.sensors if s.name == name), None)
        if declared is not None and declared.sensor_kind.units:  # a kind with a threshold
            return self._declared(name, mode, declared, limits)
        if len(limits) != 1:
            self.error(
                name,
                N_(
                    "[{section}] {name}: a {mode} input needs exactly one of below = N or above = N ({unit})",
                    section=key,
                    name=name,
                    mode=mode,
                    unit=analog.unit,
                ),
                N_(
                    "the table reads 1 while the value is below (or above) N, for example: below = {example}",
                    example=analog.most // 50,
                ),
            )
            return None
        ((which, limit),) = limits.items()
        if isinstance(limit, bool) or not isinstance(limit, int) or not 0 <= limit <= analog.most:
            self.error(
                name,
                N_(
                    "[{section}] {name}: {which} must be a whole number 0..{most} ({unit}), not {limit!r}",
                    section=key,
                    name=name,
                    which=which,
                    most=analog.most,
                    unit=analog.unit,
                    limit=limit,
                ),
                N_("for example: {example}", example=f"{which} = {analog.most // 50}"),
            )
            return None
        return (False, limit if which == "below" else None, limit if which == "above" else None, 0)

    def _declared(
        self, name: str, mode: str, sensor: Sensor, limits: dict[str, Any]
    ) -> tuple[bool, int | None, int | None, int] | None:
        """Threshold and hysteresis from the input's ``[sensors]`` declaration (the one the simulator uses), so
        the table reads the same on the robot: only a distance sensor in the controller's distance mode (cm)."""
        key = self.spec.section
        if limits:
            self.error(
                name,
                N_(
                    "[{section}] {name}: its threshold is declared in [sensors] ({sensor})",
                    section=key,
                    name=name,
                    sensor=sensor.describe(),
                ),
                N_(
                    "remove {keys} here: the simulator and the controller read the one declaration",
                    keys=", ".join(limits),
                ),
            )
            return None
        scale = sensor.sensor_kind.modes.get(mode)  # from the declaration's units into the mode's
        if scale is None or mode not in self.spec.analog:
            where = (
                N_(
                    'wire a distance sensor as mode = "{mode}"; or give a calibrated threshold here in the '
                    "controller's units and drop the input from [sensors]",
                    mode=self.spec.distance_mode,
                )
                if self.spec.distance_mode
                else N_(
                    "the {controller} measures no distance in cm; or give a calibrated threshold here in the "
                    "controller's units and drop the input from [sensors]",
                    controller=self.spec.controller,
                )
            )
            self.error(
                name,
                N_(
                    "[{section}] {name}: a {model} sensor ({sensor}) cannot be read in {mode} mode with "
                    "its declared threshold",
                    section=key,
                    name=name,
                    model=sensor.model,
                    sensor=sensor.describe(),
                    mode=mode,
                ),
                where,
            )
            return None
        limit, slack = round(sensor.threshold * scale, 6), round(sensor.hysteresis * scale, 6)
        if limit != int(limit) or slack != int(slack):
            self.error(
                name,
                N_(
                    "[{section}] {name}: the {controller} measures whole centimetres; [sensors] says {sensor}",
                    section=key,
                    name=name,
                    controller=self.spec.controller,
                    sensor=sensor.describe(),
                ),
                N_("declare the threshold and hysteresis in whole cm"),
            )
            return None
        below = sensor.direction == "below"
        return (False, int(limit) if below else None, None if below else int(limit), int(slack))

    def output(self, name: str) -> OutputWire | None:
        kind = "motor" if name in self.robot.motors else "lamp"
        value, reverse = self.section[name], False
        if isinstance(value, dict) and kind == "motor":
            for k in value:
                if k not in ("terminal", "reverse"):
                    self.error(
                        name,
                        N_("[{section}] {name}: unknown key {key!r}", section=self.spec.section, name=name, key=k),
                        N_("keys: {keys}", keys="terminal, reverse"),
                    )
            reverse = value.get("reverse", False)
            if not isinstance(reverse, bool):
                self.error(
                    name,
                    N_(
                        "[{section}] {name}: reverse must be true or false, not {value!r}",
                        section=self.spec.section,
                        name=name,
                        value=reverse,
                    ),
                    N_("reverse = true swaps the motor's forward and backward"),
                )
                reverse = False
            value = value.get("terminal", name if name in self.spec.motors else None)
        terminal = self.terminal(name, kind, value)
        return None if terminal is None else OutputWire(name, kind, terminal, reverse)
