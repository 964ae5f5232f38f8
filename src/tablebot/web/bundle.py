"""The page's ES modules as one inline script, for a page that must load nothing (the replay file).

Each module becomes a function run once, in dependency order, returning its exports; its imports read
them. It understands only the forms the modules are written in, which the linter enforces
(``eslint.config.js``): ``import { a, b as c } from "./x.js";`` and ``export`` before a ``function``,
``class`` or ``const`` declaration; anything else is refused rather than bundled wrong.
"""

from __future__ import annotations

import json
import posixpath
import re
from pathlib import Path

IMPORT_RE = re.compile(r'^import \{([^}]*)\} from "(\.{1,2}/[^"]+\.js)";[ \t]*\n', re.M)
EXPORT_RE = re.compile(r"^export (?=(?:async )?function\*? |class |const )", re.M)
EXPORT_NAME_RE = re.compile(r"^export (?:async )?(?:function\*? |class |const )([A-Za-z_$][\w$]*)", re.M)
LEFT_OVER_RE = re.compile(r"^\s*(import|export)\b", re.M)


def bundle(root: Path, entry: str) -> str:
    """The module ``entry`` (a path under ``root``) and everything it imports, as one classic script body."""
    parts = ["const modules = {};"]
    for name in module_order(root, entry):
        parts.append(_wrapped(root, name))
    return "\n".join(parts) + "\n"


def module_order(root: Path, entry: str) -> list[str]:
    """``entry`` (a path under ``root``) and every module it imports, each once, a module after its imports."""
    order: list[str] = []
    _visit(root, entry, order, ())
    return order


def _visit(root: Path, name: str, order: list[str], stack: tuple[str, ...]) -> None:
    if name in order:
        return
    if name in stack:
        raise ValueError(f"the modules import each other in a circle: {' -> '.join((*stack, name))}")
    for _, spec in IMPORT_RE.findall(_read(root, name)):
        _visit(root, _resolve(name, spec), order, (*stack, name))
    order.append(name)


def _read(root: Path, name: str) -> str:
    return (root / name).read_text(encoding="utf-8")


def _resolve(importer: str, spec: str) -> str:
    return posixpath.normpath(posixpath.join(posixpath.dirname(importer), spec))


def _wrapped(root: Path, name: str) -> str:
    text = _read(root, name)
    exports = EXPORT_NAME_RE.findall(text)

    def local(match: re.Match[str]) -> str:
        names = ", ".join(part.strip().replace(" as ", ": ") for part in match[1].split(",") if part.strip())
        return f"const {{ {names} }} = modules[{json.dumps(_resolve(name, match[2]))}];\n"

    body = EXPORT_RE.sub("", IMPORT_RE.sub(local, text))
    left = LEFT_OVER_RE.search(body)
    if left:
        line = body[: left.start()].count("\n") + 1
        raise ValueError(f"{name}: an {left[1]} the bundler does not understand near line {line}")
    return f"modules[{json.dumps(name)}] = (() => {{\n{body}\nreturn {{ {', '.join(exports)} }};\n}})();"
