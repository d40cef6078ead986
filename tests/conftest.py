"""Shared fixtures: the paper's study as shipped, and a cheap variant for fast tests."""

import pytest

from foldopt.config import default_study_path, load_study


@pytest.fixture(scope="session")
def shin_study():
    """configs/shin2015.yaml, resolved (paper mode, azimuth-split, 1-min steps)."""
    return load_study(default_study_path())
