"""Shared pytest set-up: doctests and tests run from the project root."""

from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent


@pytest.fixture(autouse=True)
def _run_from_project_root(monkeypatch):
    monkeypatch.chdir(ROOT)


def pytest_collection_modifyitems(config, items):
    """Tests marked ``slow`` (a minute or more of CPU each) go first: pytest-xdist hands tests out in this
    order, so the long ones start at once and the short ones fill the workers' remaining time, instead of a
    long test starting last and running alone."""
    items.sort(key=lambda item: item.get_closest_marker("slow") is None)  # stable: the rest keep their order
