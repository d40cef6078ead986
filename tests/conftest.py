"""Shared fixtures: the paper's study as shipped, and a cheap variant for fast tests."""

import os

import pytest

from foldopt.config import default_study_path, load_study


@pytest.fixture(scope="session")
def shin_study():
    """configs/shin2015.yaml, resolved (paper mode, azimuth-split, 1-min steps)."""
    return load_study(default_study_path())


def pytest_configure(config):
    # Electrical tables are cached on disk; tests keep theirs in pytest's own cache folder (kept
    # between runs, ignored by git) rather than in the user's ~/.cache.
    if config.cache is not None:
        os.environ.setdefault("FOLDOPT_CACHE_DIR", str(config.cache.mkdir("foldopt")))
