"""docs/python.md's table of the command line beside Python has a row for every command
`piezoshift --help` lists, and no row for a command that does not exist, so that the table stays
complete as commands are added."""
import os
import pathlib
import re
import subprocess

import pytest

from conftest import SOURCE_DIR

SECTION = "## The command line and Python side by side"


def cli_path():
    path = os.environ.get("PIEZOSHIFT_CLI")
    if path:
        return pathlib.Path(path)
    return SOURCE_DIR / "build" / "release" / "apps" / "piezoshift" / "piezoshift"


def cli_commands():
    cli = cli_path()
    if not cli.exists() and "PIEZOSHIFT_CLI" not in os.environ:  # ctest sets it: never skipped
        pytest.skip(f"no piezoshift program at {cli} (set PIEZOSHIFT_CLI)")
    text = subprocess.run([str(cli), "--help"], check=True, capture_output=True,
                          text=True).stdout
    listed = text.split("Subcommands:", 1)[1]
    return [m.group(1) for m in re.finditer(r"^  ([a-z][a-z-]*)\s", listed, re.MULTILINE)]


def table_commands():
    doc = (SOURCE_DIR / "docs" / "python.md").read_text(encoding="utf-8")
    assert SECTION in doc, f"docs/python.md has no section '{SECTION}'"
    section = doc.split(SECTION, 1)[1].split("\n## ", 1)[0]
    rows = {}
    for line in section.splitlines():
        m = re.match(r"^\| `piezoshift ([a-z][a-z-]*)` \| (.+) \|$", line)
        if m:
            assert m.group(1) not in rows, f"two rows for `piezoshift {m.group(1)}`"
            rows[m.group(1)] = m.group(2).strip()
    return rows


def test_every_cli_command_has_a_python_row():
    commands = cli_commands()
    assert {"serve", "measure", "calibrate"} <= set(commands), commands
    rows = table_commands()
    assert [c for c in commands if c not in rows] == []
    assert [r for r in rows if r not in commands] == []
    assert all(rows[c] for c in commands)  # a Python name, or "not yet"


def test_the_stage_is_the_python_side_of_serve():
    assert "Stage(" in table_commands()["serve"]
