"""Every subcommand's --help describes every option, with its default."""
from __future__ import annotations

import argparse
import re

import pytest

from harness.cli import _parser, main


def _subcommands() -> dict[str, argparse.ArgumentParser]:
    p = _parser()
    sub = next(a for a in p._actions if isinstance(a, argparse._SubParsersAction))
    return dict(sub.choices)


@pytest.mark.parametrize("name", sorted(_subcommands()))
def test_help_describes_every_option_with_its_default(name, capsys):
    with pytest.raises(SystemExit) as stop:
        main([name, "--help"])
    assert stop.value.code == 0
    text = capsys.readouterr().out
    assert text.startswith(f"usage: sidbench {name}")
    parser = _subcommands()[name]
    formatter = parser._get_formatter()
    for action in parser._actions:
        if isinstance(action, argparse._HelpAction):
            continue
        what = f"sidbench {name} {action.option_strings[-1] if action.option_strings else action.dest}"
        assert action.help and action.help.strip(), f"{what} has no help"
        shown = " ".join(formatter._expand_help(action).split())
        assert " ".join(shown.split()[:3]) in " ".join(text.split()), f"{what}: help not printed"
        if action.option_strings and not action.required:
            assert "default" in shown.lower(), f"{what}: no default in {shown!r}"
