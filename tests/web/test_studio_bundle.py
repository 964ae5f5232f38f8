"""The replay file's bundler: ES modules into one script that runs the same (checked by running it in
node), in dependency order, each module once; forms it does not understand are refused, not mangled.
The replay page built from the real modules is driven in Chromium by test_studio_browser.py."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import pytest

from tablebot.web.app import STATIC
from tablebot.web.bundle import bundle

pytestmark = [pytest.mark.kernel_free]

needs_node = pytest.mark.skipif(
    shutil.which("node") is None,
    reason="node is not installed (scripts/bootstrap.sh installs it for the studio's linter)",
)


def write(folder: Path, files: dict[str, str]) -> Path:
    for name, text in files.items():
        (folder / name).parent.mkdir(parents=True, exist_ok=True)
        (folder / name).write_text(text, encoding="utf-8")
    return folder


@needs_node
def test_a_bundle_runs_as_the_modules_would(tmp_path: Path) -> None:
    root = write(
        tmp_path,
        {
            "lib/a.js": 'export const base = 40;\nexport function twice(x) { return 2 * x; }\nconsole.log("a");\n',
            "lib/b.js": 'import { base, twice as double } from "./a.js";\nexport class Adder {\n'
            '  add(x) { return base + double(x) / 2; }\n}\nconsole.log("b");\n',
            "app/main.js": 'import { Adder } from "../lib/b.js";\nimport { base } from "../lib/a.js";\n'
            "console.log(new Adder().add(2), base);\n",
        },
    )
    script = bundle(root, "app/main.js")
    assert script.count('modules["lib/a.js"] =') == 1
    ran = subprocess.run(["node", "--input-type=module", "-e", script], capture_output=True, text=True, check=True)
    assert ran.stdout.split("\n") == ["a", "b", "42 40", ""]  # each module once, dependencies first


def test_forms_the_bundler_does_not_understand_are_refused(tmp_path: Path) -> None:
    cases = {
        "export default 1;\n": "export",
        'import * as a from "./a.js";\n': "import",
        "const x = 1;\nexport { x };\n": "export",
        'export { y } from "./a.js";\n': "export",
    }
    write(tmp_path, {"a.js": "export const y = 1;\n"})
    for text, word in cases.items():
        write(tmp_path, {"main.js": text})
        with pytest.raises(ValueError, match=f"an {word} the bundler does not understand"):
            bundle(tmp_path, "main.js")
    write(
        tmp_path,
        {
            "a.js": 'import { b } from "./b.js";\nexport const a = 1;\n',
            "b.js": 'import { a } from "./a.js";\nexport const b = 2;\n',
        },
    )
    with pytest.raises(ValueError, match=r"in a circle: a\.js -> b\.js -> a\.js"):
        bundle(tmp_path, "a.js")


@needs_node
def test_the_replay_bundle_is_valid_javascript_with_every_module_once(tmp_path: Path) -> None:
    script = bundle(STATIC / "js", "replay/main.js")
    names = [line.split('"')[1] for line in script.splitlines() if line.startswith("modules[")]
    assert names[-1] == "replay/main.js" and len(names) == len(set(names)) >= 7
    assert "lib/dom.js" in names and "studio/main.js" not in names  # only what the replay page imports
    (tmp_path / "replay.mjs").write_text(script)
    subprocess.run(["node", "--check", str(tmp_path / "replay.mjs")], check=True)
