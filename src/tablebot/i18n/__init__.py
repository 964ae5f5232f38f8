"""The reader's language: German or English, for every word tablebot says (issue 38).

One gettext catalog per language under ``tablebot/locale/<lang>/LC_MESSAGES/tablebot.mo`` (domain ``tablebot``),
made from the ``.po`` files beside them, whose template ``tablebot/locale/tablebot.pot`` is extracted from the code
(``scripts/catalog.py``). Three ways to mark a text:

* ``_("...")``: translated now, into the language in use (help and progress lines, printed at once);
* ``ngettext(singular, plural, n)``: the same, with the plural form of ``n``;
* ``N_("... {name} ...", name=...)``: a :class:`Message`, translated when it is shown. A diagnostic carries one
  (its id and arguments), so the command line and the studio each render it in their reader's language.

The language is chosen once per command (:func:`choose`: ``--lang``, else ``TABLEBOT_LANG``, else the system's
locale) and set with :func:`use`. A table file's meaning never depends on it: tables are data.
"""

from __future__ import annotations

import gettext as _gettext
import numbers
import os
import string
import sys
from collections.abc import Callable, Iterator, Mapping, Sequence
from contextlib import contextmanager
from contextvars import ContextVar
from pathlib import Path
from typing import Any, cast

__all__ = [
    "DOMAIN",
    "ENV",
    "LANGUAGES",
    "LOCALE_DIR",
    "NP_",
    "N_",
    "PSEUDO",
    "LanguageError",
    "Message",
    "_",
    "as_typed",
    "asked",
    "choose",
    "current",
    "from_json",
    "gettext",
    "localise",
    "named",
    "ngettext",
    "number",
    "set_from",
    "speaking",
    "system_language",
    "to_json",
    "translation",
    "use",
]

DOMAIN = "tablebot"
LOCALE_DIR = Path(__file__).resolve().parent.parent / "locale"
#: The languages a reader may choose; the first is the one the code is written in.
LANGUAGES = ("en", "de")
ENV = "TABLEBOT_LANG"
#: Not a language: every translated text wrapped in markers, so a test sees any text that was never
#: translated (it stands outside them). Chosen by TABLEBOT_LANG only, never offered in --lang's help.
PSEUDO = "pseudo"
PSEUDO_OPEN, PSEUDO_CLOSE = "⟦", "⟧"


class LanguageError(ValueError):
    """A language asked for that tablebot does not speak; ``where`` is the option or variable that asked."""

    def __init__(self, where: str, value: str) -> None:
        super().__init__(f"{where}: {value!r} is not a language tablebot speaks")
        self.where, self.value = where, value


class _Pseudo(_gettext.NullTranslations):
    """The pseudo-locale: the English text between markers."""

    def gettext(self, message: str) -> str:
        return f"{PSEUDO_OPEN}{message}{PSEUDO_CLOSE}"

    def ngettext(self, msgid1: str, msgid2: str, n: int) -> str:
        return self.gettext(msgid1 if n == 1 else msgid2)


_loaded: dict[str, _gettext.NullTranslations] = {}
_language = LANGUAGES[0]
#: The language of one piece of work, in its thread or task alone (:func:`speaking`): the studio draws a tab's
#: diagram in that tab's language while another tab speaks another, in the same process.
_speaking: ContextVar[str | None] = ContextVar("tablebot_speaking", default=None)


def translation(language: str | None = None) -> _gettext.NullTranslations:
    """The catalog of ``language`` (default: the one in use), loaded once. English is the code's own text."""
    language = language or current()
    if language not in _loaded:
        if language == PSEUDO:
            _loaded[language] = _Pseudo()
        elif language == LANGUAGES[0]:
            _loaded[language] = _gettext.NullTranslations()
        else:  # a missing .mo would be a broken install: fail loudly rather than speak English silently
            with open(LOCALE_DIR / language / "LC_MESSAGES" / f"{DOMAIN}.mo", "rb") as mo:
                _loaded[language] = _gettext.GNUTranslations(mo)
    return _loaded[language]


def use(language: str) -> None:
    """Speak ``language`` (one of :data:`LANGUAGES`, or :data:`PSEUDO`) from now on, in this process."""
    global _language
    if language not in (*LANGUAGES, PSEUDO):
        raise LanguageError("language", language)
    translation(language)
    _language = language


def current() -> str:
    """The language in use: :func:`speaking`'s in its block, else the process's (:func:`use`)."""
    return _speaking.get() or _language


@contextmanager
def speaking(language: str) -> Iterator[None]:
    """Speak ``language`` inside the block, in this thread or asyncio task only (a context variable:
    ``asyncio.to_thread`` carries it into the thread). When to use which: :func:`use` for a command, which
    speaks one language throughout; this for one reader's piece of work in a process that serves several,
    as the studio's tabs."""
    if language not in (*LANGUAGES, PSEUDO):
        raise LanguageError("language", language)
    translation(language)
    token = _speaking.set(language)
    try:
        yield
    finally:
        _speaking.reset(token)


def gettext(message: str) -> str:
    """``message`` in the language in use; its ``.format`` writes numbers as that language does (:func:`number`)."""
    return _Text(translation().gettext(message))


_ = gettext


def ngettext(singular: str, plural: str, n: int) -> str:
    """The singular or plural of a text, as the language in use counts ``n`` (its numbers as :func:`gettext`'s)."""
    return _Text(translation().ngettext(singular, plural, n))


class _Text(str):
    """A translated text: ``.format`` fills it as :class:`Message` does, every number written by :func:`number` in
    the language in use (``{rate:.2f}`` is ``29,20`` in German), so no caller formats a number by hand."""

    __slots__ = ()

    def format(self, *args: Any, **kwargs: Any) -> str:
        return _NumberFormatter(None).format(str(self), *args, **kwargs)


class Message(str):
    """A text to translate when it is shown: its value as a ``str`` is the English text (so logs, JSON and
    comparisons do not depend on the reader), its id and arguments let :meth:`render` say it in any language.

    An argument that is itself a Message is rendered in the same language (a hint made of parts)."""

    msgid: str
    plural: str | None
    args: Mapping[str, Any]

    def __new__(cls, msgid: str, args: Mapping[str, Any] | None = None, plural: str | None = None) -> Message:
        args = dict(args or {})
        english = plural if plural is not None and args.get("n") != 1 else msgid
        self = super().__new__(cls, _fill(english, args, LANGUAGES[0]))
        self.msgid, self.plural, self.args = msgid, plural, args
        return self

    def render(self, language: str | None = None) -> str:
        """The text in ``language`` (default: the language in use)."""
        catalog = translation(language)
        text = (
            catalog.gettext(self.msgid)
            if self.plural is None
            else catalog.ngettext(self.msgid, self.plural, int(self.args["n"]))
        )
        return _fill(text, self.args, language)

    def __reduce__(self) -> tuple[Any, ...]:  # pickled between processes (evolve's and sweep's workers)
        return Message, (self.msgid, self.args, self.plural)


def _fill(text: str, args: Mapping[str, Any], language: str | None) -> str:
    """``text`` with its fields filled: a Message argument in ``language``, a tuple of them as a list (``a, b``),
    a number as ``language`` writes it (:func:`number`: ``{seconds:.1f}`` is ``0,5`` in German)."""
    if not args:
        return text
    return _NumberFormatter(language).format(
        text,
        **{
            k: ", ".join(str(localise(item, language)) for item in v) if isinstance(v, tuple) else localise(v, language)
            for k, v in args.items()
        },
    )


#: German writes the decimal comma and groups thousands with a point: the two swapped (issue 38).
_DECIMALS = {"de": str.maketrans(".,", ",.")}


def number(value: float, spec: str = "g", language: str | None = None) -> str:
    """``value`` formatted by ``spec`` (Python's format mini-language: ``.2f``, ``+.3f``, ``,``, ``.0%``) as
    ``language`` (default: the one in use) writes numbers for people: ``0,5`` and ``12.000`` in German. Only
    for text a person reads; machine-readable output (CSV, JSON, trace files, ``--format json``) keeps
    Python's point in every language."""
    text = format(value, spec)
    table = _DECIMALS.get(language or current())
    return text.translate(table) if table else text


def as_typed(value: float, spec: str = "") -> str:
    """``value`` as the reader types it, the point in every language: a number a hint tells them to write in a
    file or on the command line (``--seconds`` from 0.01 to 3600), which :func:`number` must not turn into
    German (the command line and TOML read 0.01, not 0,01). A text field, so a message leaves it as it is."""
    return format(value, spec)


class _NumberFormatter(string.Formatter):
    """str.format, with every int or float field written by :func:`number` in one language."""

    def __init__(self, language: str | None) -> None:
        self.language = language

    def format_field(self, value: Any, format_spec: str) -> Any:
        if isinstance(value, numbers.Real) and not isinstance(value, bool):  # numpy's numbers too
            return number(cast(float, value), format_spec, self.language)
        return super().format_field(value, format_spec)


def to_json(text: Any) -> Any:
    """``text`` as JSON keeps it: a :class:`Message` as its id, plural and arguments (so a file written in one
    run says it in the reader's language when read back in another: evolve's ``repairs.json``), a tuple of
    them as a list, anything else as it is."""
    if isinstance(text, Message):
        return {"msgid": text.msgid, "plural": text.plural, "args": {k: to_json(v) for k, v in text.args.items()}}
    if isinstance(text, tuple):
        return {"items": [to_json(item) for item in text]}
    return text


def from_json(item: Any) -> Any:
    """:func:`to_json`'s value back; a plain string (a file written before Messages were kept) as it is."""
    if isinstance(item, dict) and "msgid" in item:
        return Message(item["msgid"], {k: from_json(v) for k, v in item["args"].items()}, item["plural"])
    if isinstance(item, dict) and "items" in item:
        return tuple(from_json(v) for v in item["items"])
    return item


def N_(msgid: str, /, **args: Any) -> Message:
    """A text translated when shown, with its ``{name}`` fields filled from ``args``."""
    return Message(msgid, args)


def NP_(singular: str, plural: str, n: int, /, **args: Any) -> Message:
    """:func:`N_` with a plural: ``n`` chooses the form (and fills ``{n}``)."""
    return Message(singular, {**args, "n": n}, plural)


def localise(text: Any, language: str | None = None) -> Any:
    """A :class:`Message` in ``language`` (default: the one in use); any other value as it is."""
    return text.render(language) if isinstance(text, Message) else text


# --- choosing the language ------------------------------------------------------------------------


def choose(
    argv: Sequence[str], environ: Mapping[str, str], system: Callable[[], str | None] | None = None
) -> tuple[str, list[str], bool]:
    """The language a command speaks and its arguments without ``--lang``: ``--lang de|en`` (anywhere before
    ``--``, so ``tablebot sim --lang de`` works as ``tablebot --lang de sim``), else ``TABLEBOT_LANG``, else the
    system's locale (:func:`system_language`), else English; and whether it was asked for by name (--lang or
    TABLEBOT_LANG). An unknown language asked for by name raises :class:`LanguageError`; a system locale tablebot
    does not speak (``fr_FR``) is English."""
    rest: list[str] = []
    asked: tuple[str, str] | None = None
    words = iter(argv)
    for word in words:
        if word == "--":
            rest += [word, *words]
            break
        if word == "--lang":
            asked = ("--lang", next(words, ""))
        elif word.startswith("--lang="):
            asked = ("--lang", word.partition("=")[2])
        else:
            rest.append(word)
    if asked is None and environ.get(ENV, "").strip():
        asked = (ENV, environ[ENV].strip())
    if asked is not None:
        value = asked[1].strip().lower()
        if value not in LANGUAGES and not (asked[0] == ENV and value == PSEUDO):
            raise LanguageError(*asked)
        return value, rest, True
    found = (system or (lambda: system_language(environ)))()
    return (found if found in LANGUAGES else LANGUAGES[0]), rest, False


def system_language(
    environ: Mapping[str, str], platform: str = sys.platform, windows_ui: Callable[[], int] | None = None
) -> str | None:
    """The language of the system's locale: POSIX's LC_ALL, LC_MESSAGES, LANG (the first set; ``de_DE.UTF-8``
    is ``de``; ``C`` and ``POSIX`` are none), and on Windows, where those are rarely set, the user's interface
    language (GetUserDefaultUILanguage, a Windows language id named through Python's table of them)."""
    for name in ("LC_ALL", "LC_MESSAGES", "LANG"):
        value = environ.get(name, "").strip()
        if value:
            return _language_of(value)
    if platform == "win32":
        import locale

        ui = windows_ui or _windows_ui_language
        try:
            name = locale.windows_locale.get(ui(), "")
        except OSError:  # no such call on this Windows: its user locale instead
            name = locale.getlocale()[0] or ""
        return _language_of(name) if name else None
    return None


def _language_of(locale_name: str) -> str | None:
    """``de_DE.UTF-8`` -> ``de``; ``C``/``POSIX`` -> None; Windows' ``German_Germany`` -> ``de``."""
    base = locale_name.split(".")[0].split("@")[0]
    if base in ("C", "POSIX", ""):
        return None
    code = base.replace("-", "_").split("_")[0].lower()
    return {"german": "de", "english": "en"}.get(code, code)


def _windows_ui_language() -> int:
    import ctypes

    windll = getattr(ctypes, "windll")  # noqa: B009  (Windows only: mypy on other systems knows no windll)
    return int(windll.kernel32.GetUserDefaultUILanguage())


_asked: str | None = None


def set_from(argv: Sequence[str], environ: Mapping[str, str] | None = None) -> list[str]:
    """Choose and use the language for a command line; the arguments without ``--lang``."""
    global _asked
    language, rest, named = choose(argv, os.environ if environ is None else environ)
    use(language)
    _asked = language if named else None
    return rest


def named() -> str | None:
    """The language asked for by name (--lang, TABLEBOT_LANG), or None when the system's locale chose it: the
    studio's page then speaks its browser's language (issue 38)."""
    return _asked if _asked in LANGUAGES else None


def asked() -> str:
    """The language a user asked for by name (--lang, TABLEBOT_LANG), else English: the language of the files a
    command writes for people to edit (the header of a table from ``new`` or ``import``), which a system's
    locale alone does not change (a table written on one computer is read on another)."""
    return _asked if _asked in LANGUAGES else LANGUAGES[0]
