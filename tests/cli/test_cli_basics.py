"""What every invocation shares: --version, -h as --help on every command, shell completion."""

from __future__ import annotations

import pytest
import typer.main
from typer.testing import CliRunner

from tablebot import __version__
from tablebot.cli import app

pytestmark = [pytest.mark.kernel_free]


def test_version_is_printed() -> None:
    result = CliRunner().invoke(app, ["--version"])
    assert result.exit_code == 0
    assert result.output.strip() == f"tablebot {__version__}"


def test_dash_h_is_help_on_every_command() -> None:
    group = typer.main.get_command(app)
    names = sorted(group.commands)  # type: ignore[attr-defined]
    assert {"check", "sim", "trace", "new"} <= set(names)
    for name in names:
        short = CliRunner().invoke(app, [name, "-h"])
        assert short.exit_code == 0, (name, short.output)
        assert "Usage:" in short.output and short.output == CliRunner().invoke(app, [name, "--help"]).output


def test_shell_completion_is_offered() -> None:
    result = CliRunner().invoke(app, ["-h"])
    assert result.exit_code == 0
    assert "--install-completion" in result.output and "--show-completion" in result.output
