"""Fetch pip's wheel from PyPI into a folder and print its path, for a Python that has no pip and no ensurepip
(Debian's and Ubuntu's python3 without the python3-pip and python3-venv packages): a wheel of pip runs as it is,
``python pip-X-py3-none-any.whl/pip install uv``, so the set-up needs no system package. The wheel's SHA-256 is
checked against the one PyPI publishes. Standard library only (this runs before anything is installed).

Usage: python3 scripts/fetch_pip.py FOLDER
"""

from __future__ import annotations

import hashlib
import json
import sys
import urllib.parse
import urllib.request
from pathlib import Path

INDEX = "https://pypi.org/pypi/pip/json"


def newest_wheel() -> tuple[str, str, str]:
    """The file name, address and SHA-256 of the newest release's wheel."""
    with urllib.request.urlopen(INDEX, timeout=60) as answer:
        release = json.load(answer)
    for file in release["urls"]:
        if file["packagetype"] == "bdist_wheel" and file["filename"].endswith("-py3-none-any.whl"):
            # a mirror may answer with addresses relative to the index's
            return file["filename"], urllib.parse.urljoin(INDEX, file["url"]), file["digests"]["sha256"]
    raise SystemExit(f"no wheel of pip found at {INDEX}")


def main() -> None:
    folder = Path(sys.argv[1])
    folder.mkdir(parents=True, exist_ok=True)
    name, url, sha256 = newest_wheel()
    with urllib.request.urlopen(url, timeout=120) as answer:
        data = answer.read()
    if hashlib.sha256(data).hexdigest() != sha256:
        raise SystemExit(f"{url}: the download does not match PyPI's SHA-256 (a proxy or a cut download?)")
    wheel = folder / name
    wheel.write_bytes(data)
    print(wheel)


if __name__ == "__main__":
    main()
