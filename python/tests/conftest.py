"""Shared fixtures: the paper's configuration and the paper's controller."""
import os
import pathlib

import pytest

import piezoshift as ps

SOURCE_DIR = pathlib.Path(
    os.environ.get("PIEZOSHIFT_SOURCE_DIR", pathlib.Path(__file__).resolve().parents[2]))


@pytest.fixture
def config():
    return ps.ProjectConfig()


@pytest.fixture
def paper_toml():
    return str(SOURCE_DIR / "configs" / "paper.toml")


@pytest.fixture
def controller():
    return ps.SemiClosedLoopParams()
