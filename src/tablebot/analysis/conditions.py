"""The small condition language of properties, parsed by hand (never eval'd) into predicates on one tick.

A condition looks at one tick as the trace records it: the events of the tick (``I3``, ``T``, ``C1``),
the row that fired (``line == 14``, ``fired``), and the state and outputs after it
(``state == 20``, ``state in [22, 24]``, ``M1 < 0``); combine with ``and``, ``or``, ``not`` and
parentheses. ``true`` and ``false`` are conditions too.

In a robot of several tables (:mod:`tablebot.tables`) a condition may name any table's state by the table's name
(``drive == 20 and lights == 3``, ``lights in [1, 2]``); ``state``, ``line`` and ``fired`` are the main table's,
``T`` the main table's timer event, and a tick is seen as :mod:`tablebot.analysis.product` describes it.
"""

from __future__ import annotations

import operator
import re
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from tablebot.durations import MAX_NUMBER_CHARS
from tablebot.i18n import N_, Message
from tablebot.machine import Machine
from tablebot.table import TIMER_EVENT
from tablebot.tables import RobotTables

#: One tick as conditions see it: (event mask, fired row index or -1, state index after, outputs after); in a
#: robot of several tables the state is the tuple of every table's state index.
Obs = tuple[int, int, Any, tuple[int, ...]]
Predicate = Callable[[int, int, Any, tuple[int, ...]], bool]

TOKEN_RE = re.compile(r"\s*(?:(?P<num>-?\d+)|(?P<op>==|!=|<=|>=|<|>|\(|\)|\[|\]|,)|(?P<word>[A-Za-z_][\w.-]*))")
COMPARE = {
    "==": operator.eq,
    "!=": operator.ne,
    "<": operator.lt,
    "<=": operator.le,
    ">": operator.gt,
    ">=": operator.ge,
}
KEYWORDS = {"and", "or", "not", "in", "true", "false", "state", "line", "fired"}
#: Parentheses and ``not`` nest at most this deep: the parser (and ``not``) recurse once per level, and a
#: condition a person writes never comes near it.
MAX_DEPTH = 50


class ConditionError(ValueError):
    """A condition that does not parse or names something the table does not have; its argument is a
    :class:`~tablebot.i18n.Message`, said in the reader's language where it is shown (:attr:`problem`)."""

    def __init__(self, problem: Message) -> None:
        super().__init__(problem)
        self.problem = problem


@dataclass(frozen=True)
class Condition:
    """A parsed condition: its text, its predicate, and the input bits it reads (they must stay visible)."""

    text: str
    test: Predicate
    input_bits: int
    #: In a robot of several tables: the tables whose state or outputs it reads (indices; 0 the main table).
    tables: frozenset[int] = frozenset()

    def __call__(self, obs: Obs) -> bool:
        return self.test(*obs)


def parse_condition(text: str, machine: Machine, tables: RobotTables | None = None) -> Condition:
    """Parse ``text`` against the names of ``machine`` (``tables``: of every table of the robot, ``machine`` the
    main one's); raises :class:`ConditionError` with a hint."""
    parser = _Parser(_tokens(text), machine, tables)
    test = parser.expression()
    if parser.peek() is not None:
        raise ConditionError(N_("unexpected {token!r} in {text!r}", token=parser.peek(), text=text))
    return Condition(text, test, parser.input_bits, frozenset(parser.reads))


def _tokens(text: str) -> list[str]:
    tokens, pos = [], 0
    text = text.strip()
    while pos < len(text):
        match = TOKEN_RE.match(text, pos)
        if not match or match.end() == pos:
            raise ConditionError(N_("cannot read {rest!r} in condition {text!r}", rest=text[pos:], text=text))
        if match["num"] and len(match["num"]) > MAX_NUMBER_CHARS:  # int() of it may fail; none is that large
            raise ConditionError(
                N_(
                    "a number of {count:,} characters in condition: no state, line or output value "
                    "has more than {most}",
                    count=len(match["num"]),
                    most=MAX_NUMBER_CHARS,
                )
            )
        tokens.append(match.group().strip())
        pos = match.end()
    if not tokens:
        raise ConditionError(N_("the condition is empty"))
    return tokens


class _Parser:
    """Recursive descent: or > and > not > atom; builds closures as it goes (a chain of ``and`` or ``or``
    as one closure over all its terms, so a thousand terms do not nest a thousand calls)."""

    def __init__(self, tokens: list[str], machine: Machine, tables: RobotTables | None = None) -> None:
        self.tokens, self.pos, self.machine, self.tables = tokens, 0, machine, tables
        self.input_bits = 0
        self.reads: set[int] = set()  # the tables whose state or outputs it reads (several tables)
        self.depth = 0

    def deeper(self) -> None:
        """One more level of parentheses or ``not``: refused past MAX_DEPTH."""
        self.depth += 1
        if self.depth > MAX_DEPTH:
            raise ConditionError(N_("the condition nests parentheses or 'not' more than {most} deep", most=MAX_DEPTH))

    def peek(self) -> str | None:
        return self.tokens[self.pos] if self.pos < len(self.tokens) else None

    def take(self, what: str = N_("more")) -> str:
        """The next token, whatever it is; ``what`` says what was wanted if there is none."""
        token = self.peek()
        if token is None:
            raise ConditionError(N_("the condition ends too early (expected {what})", what=what))
        self.pos += 1
        return token

    def expect(self, token: str) -> None:
        found = self.take(repr(token))
        if found != token:
            raise ConditionError(N_("expected {token!r} but found {found!r}", token=token, found=found))

    def expression(self) -> Predicate:
        terms = [self.conjunction()]
        while self.peek() == "or":
            self.take()
            terms.append(self.conjunction())
        return _any(terms)

    def conjunction(self) -> Predicate:
        terms = [self.negation()]
        while self.peek() == "and":
            self.take()
            terms.append(self.negation())
        return _all(terms)

    def negation(self) -> Predicate:
        if self.peek() == "not":
            self.take()
            self.deeper()
            inner = self.negation()
            self.depth -= 1
            return lambda e, r, s, o: not inner(e, r, s, o)
        return self.atom()

    def atom(self) -> Predicate:
        token = self.take(N_("a condition"))
        if token == "(":
            self.deeper()
            inner = self.expression()
            self.depth -= 1
            self.expect(")")
            return inner
        if token in ("true", "false"):
            value = token == "true"
            return lambda e, r, s, o: value
        if token in ("fired", "state", "line"):
            self.reads.add(0)  # the main table's
        if token == "fired":
            return lambda e, r, s, o: r >= 0
        if token == "state":
            return self.state_test()
        if self.tables is not None and token in self.tables.names:
            self.reads.add(self.tables.index(token))
            return self.state_test(self.tables.index(token))
        if token == "line":
            return self.line_test()
        return self.name_test(token)

    # --- atoms ----------------------------------------------------------------------------------

    def values(self) -> list[str]:
        """After ``==``/``!=``: one value; after ``in``: a bracketed list."""
        if self.peek() == "in":
            self.take()
            self.expect("[")
            items = [self.take(N_("a value"))]
            while self.peek() == ",":
                self.take()
                items.append(self.take(N_("a value")))
            self.expect("]")
            return items
        return [self.take(N_("a value"))]

    def state_test(self, table: int = 0) -> Predicate:
        """``state`` (the main table's) or ``NAME`` (table ``table`` of several) ``==``, ``!=`` or ``in``."""
        word = "state" if self.tables is None or self.tokens[self.pos - 1] == "state" else self.tokens[self.pos - 1]
        op = self.take(N_("== or != or in"))
        if op not in ("==", "!=", "in"):
            raise ConditionError(N_("{word} can be compared with ==, != or in, not {op!r}", word=word, op=op))
        if op == "in":
            self.pos -= 1
        indices = frozenset(self.state_index(v, table) for v in self.values())
        if self.tables is not None:
            negate = op == "!="
            return lambda e, r, s, o: (s[table] in indices) != negate
        if op == "!=":
            return lambda e, r, s, o: s not in indices
        return lambda e, r, s, o: s in indices

    def state_index(self, text: str, table: int = 0) -> int:
        machine = self.machine if self.tables is None else self.tables.machines[table]
        states = machine.states
        for index, state in enumerate(states):
            if str(state) == text:
                return index
        if self.tables is None:
            raise ConditionError(
                N_(
                    "there is no state {state} in the table (states: {states})",
                    state=text,
                    states=tuple(map(str, states)),
                )
            )
        raise ConditionError(
            N_(
                "there is no state {state} in table {table} (states: {states})",
                state=text,
                table=self.tables.names[table],
                states=tuple(map(str, states)),
            )
        )

    def line_test(self) -> Predicate:
        op = self.take(N_("== or in"))
        if op not in ("==", "in"):
            raise ConditionError(N_("line can be compared with == or in, not {op!r}", op=op))
        if op == "in":
            self.pos -= 1
        by_line = {row.line: row.index for row in self.machine.table.rows}
        rows = set()
        for value in self.values():
            if not value.isdigit() or int(value) not in by_line:
                raise ConditionError(N_("no row of the table is on line {line}", line=value))
            rows.add(by_line[int(value)])
        frozen = frozenset(rows)
        return lambda e, r, s, o: r in frozen

    def name_test(self, name: str) -> Predicate:
        machine = self.machine
        if name == TIMER_EVENT or name in self.input_names() or name in machine.table.robot.counter_names:
            bit = self.event_bit(name)
            if self.peek() in COMPARE:
                raise ConditionError(N_("{name} is an event: write just {name} (or not {name})", name=name))
            return lambda e, r, s, o: e & bit != 0
        if name in machine.output_names:
            index = machine.output_names.index(name)
            if self.tables is not None and (writer := self.tables.writer(name)) is not None:
                self.reads.add(writer)
            op = self.take(N_("a comparison such as < 0"))
            if op not in COMPARE:
                raise ConditionError(N_("compare {name} with a number, like {name} < 0 or {name} == 0", name=name))
            value = self.take(N_("a number"))
            if not re.fullmatch(r"-?\d+", value):
                raise ConditionError(N_("{name} {op} needs a number, not {value!r}", name=name, op=op, value=value))
            compare, number = COMPARE[op], int(value)
            return lambda e, r, s, o: compare(o[index], number)
        known = [
            TIMER_EVENT,
            *self.input_names(),
            *machine.table.robot.counter_names,
            *machine.output_names,
            *(self.tables.names if self.tables else ()),
        ]
        raise ConditionError(
            N_(
                "unknown name {name!r}; use state, line, fired or one of {known}",
                name=name,
                known=tuple(map(str, known)),
            )
        )

    def input_names(self) -> list[str]:
        return list((self.tables or self.machine).input_bits)

    def event_bit(self, name: str) -> int:
        machine = self.machine
        if self.tables is not None:  # the event word of tablebot.analysis.product
            return self.product_bit(name)
        if name == TIMER_EVENT:
            return machine.timer_bit
        if name in machine.input_bits:
            self.input_bits |= machine.input_bits[name]
            return machine.input_bits[name]
        bit = machine.counter_bits[machine.table.robot.counter_names.index(name)]
        if not bit:
            raise ConditionError(
                N_("counter {name} has no event column in the table, so it is never an event", name=name)
            )
        return bit

    def product_bit(self, name: str) -> int:
        """An event's bit in the event word of several tables: the robot's inputs, the main T, each counter."""
        assert self.tables is not None
        bits = self.tables.input_bits
        if name in bits:
            self.input_bits |= bits[name]
            return bits[name]
        if name == TIMER_EVENT:
            self.reads.add(0)
            if not self.machine.timer_bit:
                raise ConditionError(N_("the main table ({name}) has no T column", name=self.tables.names[0]))
            return 1 << len(bits)
        if (writer := self.tables.writer(name)) is not None:
            self.reads.add(writer)
        return 1 << (len(bits) + 1 + self.machine.table.robot.counter_names.index(name))


def _all(terms: list[Predicate]) -> Predicate:
    if len(terms) == 1:
        return terms[0]
    return lambda e, r, s, o: all(term(e, r, s, o) for term in terms)


def _any(terms: list[Predicate]) -> Predicate:
    if len(terms) == 1:
        return terms[0]
    return lambda e, r, s, o: any(term(e, r, s, o) for term in terms)
